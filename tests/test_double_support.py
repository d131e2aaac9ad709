"""The double support phase: closed chain, its motion and the split of the load."""

import dataclasses

import numpy as np
import pytest

import biped
from biped.errors import BipedError
from biped.model import double_support as ds
from biped.model.dynamics import JOINT_MATRIX
from tests.test_two_phase import guess_step

SPEED = 0.3  # [m/s]


@pytest.fixture
def phase(model):
    """The double support phase of a two-phase step of each knee (a rough guess, not an
    optimum: both feet move the hip and the trunk through a cubic of 0.3 s)."""
    return guess_step(model, "impact").double


def states(model, phase, t):
    """q, q̇, q̈ (N, 9) of ``phase`` at times t [s]."""
    return ds.chain_state(model, phase.step_length, *ds.phase_coordinates(phase, t))


def test_both_soles_stay_in_place_over_the_phase(model, phase):
    """The chain closes: both soles' corners stay at their places and both feet at rest, to
    1e-12, at 401 times of the phase."""
    t = np.linspace(0.0, phase.duration, 401)
    q, qd, _ = states(model, phase, t)
    assert ds.held_feet_residual(model, phase.step_length, q, qd) < 1e-12
    assert ds.held_feet_residual(model, phase.step_length + 1e-6, q) > 0.9e-6


def test_rates_and_accelerations_are_the_postures_derivatives(model, phase):
    """q̇ and q̈ of the chain are central differences of q and q̇ in time (all nine
    coordinates, including the knees' angles from the inverse geometric model)."""
    t = np.linspace(0.02, phase.duration - 0.02, 9)
    h = 1e-6
    q, qd, qdd = states(model, phase, t)
    q_plus, qd_plus, _ = states(model, phase, t + h)
    q_minus, qd_minus, _ = states(model, phase, t - h)
    np.testing.assert_allclose((q_plus - q_minus) / (2 * h), qd, atol=1e-7)
    np.testing.assert_allclose((qd_plus - qd_minus) / (2 * h), qdd, atol=2e-6)


def test_motor_power_is_the_rate_of_energy(model, phase):
    """Σ Γ_i θ̇_i plus the ground wrenches' power (A q̇ · F, zero: the feet do not move)
    equals dE/dt; a motion whose accelerations drop the closure's bias H_c breaks it."""
    t = np.linspace(0.02, phase.duration - 0.02, 9)
    h = 1e-5
    q, qd, qdd = states(model, phase, t)
    torques, stance, swing = ds.split_load(model, q, qd, qdd)
    rows = ds.contact_rows(model, q)
    ground = ((rows @ qd[..., None])[..., 0] * np.concatenate([stance, swing], -1)).sum(-1)
    power = model.motor_power(qd, torques) + ground

    def energy(time):
        q, qd, _ = states(model, phase, time)
        return model.kinetic_energy(q, qd) + model.potential_energy(q)

    rate = (energy(t + h) - energy(t - h)) / (2 * h)
    np.testing.assert_allclose(power, rate, atol=1e-5)
    assert np.max(np.abs(power)) > 1.0  # the motors work
    # The wrong model: accelerations that ignore the closure's bias, A q̈ = 0 for H_c.
    wrong = qdd.copy()
    wrong[..., ds.BOUND] = -np.linalg.solve(
        rows[..., ds.BOUND], rows[..., ds.FREE] @ qdd[..., ds.FREE, None]
    )[..., 0]
    torques_wrong, *_ = ds.split_load(model, q, qd, wrong)
    assert np.max(np.abs(model.motor_power(qd, torques_wrong) - rate)) > 1.0


def test_ground_forces_carry_the_weight_and_accelerate_the_centre_of_mass(model, phase):
    """F_s + F_w = M (a_G + g e_z), a_G the second central difference of the centre of mass
    of the seven bodies; both feet carry part of the load."""
    t = np.linspace(0.02, phase.duration - 0.02, 9)
    h = 1e-4
    q, qd, qdd = states(model, phase, t)
    _, stance, swing = ds.split_load(model, q, qd, qdd)
    names = [body.com for body in model.bodies]
    masses = np.array([body.mass for body in model.bodies])

    def com(time):
        q, _, _ = states(model, phase, time)
        return (masses[:, None] * model.points(q, names)).sum(-2) / masses.sum()

    accel = (com(t + h) - 2 * com(t) + com(t - h)) / h**2
    weight = masses.sum() * (accel + np.array([0.0, model.gravity]))
    np.testing.assert_allclose(stance[:, :2] + swing[:, :2], weight, atol=1e-3)
    assert masses.sum() == pytest.approx(model.mass)


def test_each_feet_moment_about_its_ankle_is_its_ankle_torque(model, phase):
    """A flat foot at rest with its centre of mass below its ankle: C_y of the stance foot
    is Γ1, of the swing foot Γ6, so the ZMP of either is (Γ_ankle − h_p Fx) / Fz."""
    q, qd, qdd = states(model, phase, np.linspace(0.0, phase.duration, 7))
    torques, stance, swing = ds.split_load(model, q, qd, qdd)
    np.testing.assert_allclose(stance[:, 2], torques[:, 0], atol=1e-9)
    np.testing.assert_allclose(swing[:, 2], torques[:, 5], atol=1e-9)


def test_the_split_solves_the_dynamics_with_least_squared_torque(model, phase):
    """B Γ + A_sᵀ F_s + A_wᵀ F_w = D q̈ + H + Q (eq. 19') and every other solution, the split
    moved along the redundancy's three directions, has a larger Σ Γ_i²."""
    q, qd, qdd = states(model, phase, np.linspace(0.0, phase.duration, 5))
    torques, stance, swing = ds.split_load(model, q, qd, qdd)
    rows = ds.contact_rows(model, q)
    lhs = (
        torques @ JOINT_MATRIX
        + (np.swapaxes(rows, -1, -2) @ np.concatenate([stance, swing], -1)[..., None])[..., 0]
    )
    np.testing.assert_allclose(lhs, model.generalized_forces(q, qd, qdd), atol=1e-9)
    rng = np.random.default_rng(7)
    for k in range(len(q)):
        matrix = np.hstack([JOINT_MATRIX.T, rows[k].T])  # (9, 12)
        null = np.linalg.svd(matrix)[2][9:].T  # (12, 3)
        assert null.shape == (12, 3)
        for _ in range(5):
            moved = null @ rng.normal(0.0, 5.0, 3)
            assert np.sum((torques[k] + moved[:6]) ** 2) > np.sum(torques[k] ** 2)


def test_rolling_knee_tends_to_the_revolute_knee_as_the_radii_vanish():
    """The chain's posture, torques and both wrenches of a rolling knee of radii ε approach
    the revolute knee's linearly in ε (a thousand times closer at ε = 1e-6 than at 1e-3)."""
    revolute = biped.Biped(biped.Robot.paper(), "revolute")
    phase = guess_step(revolute, "impact").double
    t = np.linspace(0.0, phase.duration, 7)

    def load(model):
        q, qd, qdd = states(model, phase, t)
        return np.concatenate([q, *ds.split_load(model, q, qd, qdd)], -1)

    exact = load(revolute)
    gaps = []
    for radius in (1e-3, 1e-6):
        robot = dataclasses.replace(biped.Robot.paper(), r1=radius, r2=radius)
        gaps.append(np.max(np.abs(load(biped.Biped(robot, "rolling")) - exact)))
    assert gaps[0] > 1e-4  # the knee's geometry is seen
    assert gaps[1] < 3e-3 * gaps[0]


def test_foot_margins_are_the_feet_constraints():
    """Ψ of a foot: its normal force, both sides of its friction cone, its ZMP from the heel
    and from the toe; a foot pulled or sliding or tipping has a negative one."""
    robot = biped.Robot.paper()
    hp, heel, length = robot.ankle_height, robot.foot_heel, robot.foot_length
    margins = ds.foot_margins(robot, np.array([10.0, 100.0, 10.0 * hp]), friction=1.0)
    np.testing.assert_allclose(margins, [100.0, 90.0, 110.0, heel, length - heel], atol=1e-12)
    assert ds.foot_margins(robot, np.array([0.0, -1.0, 0.0]))[0] < 0.0
    assert ds.foot_margins(robot, np.array([150.0, 100.0, 0.0]))[1] < 0.0
    assert ds.foot_margins(robot, np.array([0.0, 100.0, 100.0 * length]))[4] < 0.0


def test_a_state_off_the_chain_or_a_null_duration_is_refused(model, phase):
    """``build_phase`` refuses an end whose front foot moves, and a duration <= 0; a profiled
    knee is refused by name."""
    q, qd = phase.start
    moving = qd.copy()
    moving[ds.XH] += 0.1  # the hip moves, the legs' angles do not: both feet slide
    with pytest.raises(BipedError, match="off the closed chain"):
        ds.build_phase(model, phase.step_length, 0.2, (q, moving), phase.end)
    with pytest.raises(BipedError, match="allowed > 0"):
        ds.build_phase(model, phase.step_length, 0.0, phase.start, phase.end)
    profiled = dataclasses.replace(biped.Robot.paper(), k1=0.5)
    with pytest.raises(BipedError, match="profiled"):
        ds.check_model(biped.Biped(profiled, "rolling"))


def test_a_given_swing_wrench_fixes_the_rest_of_the_split(model, phase):
    """``split_with_swing_wrench`` solves eq. (19') for any front-foot wrench, and with the
    least-squared split's front wrench it gives that split back."""
    q, qd, qdd = states(model, phase, np.linspace(0.0, phase.duration, 5))
    torques, stance, swing = ds.split_load(model, q, qd, qdd)
    again, rear = ds.split_with_swing_wrench(model, q, qd, qdd, swing)
    np.testing.assert_allclose(again, torques, atol=1e-8)
    np.testing.assert_allclose(rear, stance, atol=1e-8)
    other = swing + np.array([30.0, -200.0, 4.0])
    torques, stance = ds.split_with_swing_wrench(model, q, qd, qdd, other)
    rows = ds.contact_rows(model, q)
    wrenches = np.concatenate([stance, other], -1)
    lhs = torques @ JOINT_MATRIX + (np.swapaxes(rows, -1, -2) @ wrenches[..., None])[..., 0]
    np.testing.assert_allclose(lhs, model.generalized_forces(q, qd, qdd), atol=1e-9)


def test_the_fine_grid_holds_the_front_wrench_linear_between_the_samples(model, phase):
    """``sample_split``: ``FINE_PER_INTERVAL`` samples per interval of the given front
    wrenches, the front wrench equal to them at their samples and linear in time between
    (its second differences vanish within an interval), the split eq. (19')'s there."""
    front = np.array([[0.0, 100.0, 0.0], [10.0, 300.0, 5.0], [20.0, 500.0, -5.0]])
    fine = ds.sample_split(model, phase, front)
    f = ds.FINE_PER_INTERVAL
    assert len(fine.time) == 2 * f + 1
    np.testing.assert_array_equal(fine.swing_wrench[::f], front)
    np.testing.assert_allclose(np.diff(fine.swing_wrench[: f + 1], 2, axis=0), 0.0, atol=1e-9)
    torques, rear = ds.split_with_swing_wrench(model, fine.q, fine.qd, fine.qdd, fine.swing_wrench)
    np.testing.assert_allclose(fine.torques, torques, atol=1e-12)
    np.testing.assert_allclose(fine.stance_wrench, rear, atol=1e-12)
    # The front foot's constraints are linear in its wrench: held at the samples, they hold
    # between them (only the rear foot's, which follow the motion, can fail there).
    front_margins = ds.foot_margins(model.robot, fine.swing_wrench)
    assert np.min(ds.foot_margins(model.robot, front)) > 0.0
    assert np.min(front_margins) > 0.0


def test_a_foot_that_lifts_or_lands_carrying_load_is_not_a_handover():
    """The handover (``HANDOVERS``) of a zero-speed landing: the rear foot's wrench at
    lift-off and the front foot's at its landing are judged by their largest
    component against ``HANDOVER_TOLERANCE``; there the foot's Ψ are not judged (+inf),
    everywhere else they are. A foot lifting off with 300 N on it fails; one with none
    passes."""
    robot = biped.Robot.paper()
    n = 5
    loaded = np.tile([10.0, 300.0, 5.0], (n, 1))
    zeros = np.zeros((n, 9))

    def samples(stance, swing):
        return ds.DoubleSupportSamples(
            np.linspace(0.0, 0.1, n), zeros, zeros, zeros, np.zeros((n, 6)), stance, swing
        )

    carrying = samples(loaded, loaded)
    loads = ds.handover_loads(carrying.handover(zero_speed=True), zero_speed=True)
    assert loads == {"rear_at_lift_off": 300.0, "front_at_landing": 300.0}
    # the impact landing jumps the loads as it jumps the velocities: nothing judged
    assert ds.handover_loads(carrying.handover(False), False) == {}
    rear, front = loaded.copy(), loaded.copy()
    rear[-1], front[0] = 0.0, 0.0
    handed = samples(rear, front)
    loads = ds.handover_loads(handed.handover(zero_speed=True), zero_speed=True)
    assert max(loads.values()) <= ds.HANDOVER_TOLERANCE
    margins = handed.margins(robot, zero_speed=True)
    assert np.all(np.isinf(margins[-1, 0])) and np.all(np.isinf(margins[0, 1]))
    assert np.all(np.isfinite(margins[:-1, 0])) and np.all(np.isfinite(margins[1:, 1]))
    np.testing.assert_allclose(margins[1, 0], ds.foot_margins(robot, loaded[1]))
