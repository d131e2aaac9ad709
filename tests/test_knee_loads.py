"""The force through each knee (``biped.model.knee_loads``): Newton's law on the bodies below
and above the knees, checked against the geometry alone, and what a wrong model breaks."""

import dataclasses

import numpy as np
import pytest

import biped
from biped.model.kinematics import Q1, Q2, Q3, Q4
from biped.model.knee_loads import knee_forces
from tests.conftest import complex_step_velocity, random_state, smooth_motion

ROBOT = biped.Robot.paper()
LOWER = {
    "stance": ("stance_shank", "stance_foot"),
    "swing": ("swing_shank", "swing_foot"),
}
UPPER = ("stance_thigh", "swing_thigh", "trunk")
TIMES = np.linspace(0.0, 1.0, 21)
# Central differences of the fourth order: (offset, weight) of d/dt over h.
STENCIL = ((-2, 1 / 12), (-1, -8 / 12), (1, 8 / 12), (2, -1 / 12))


def _bodies(model, names):
    by_name = {body.name: body for body in model.bodies}
    return [by_name[name] for name in names]


def momentum(model, names, times, seed):
    """Σ m v (N, 2) [N·s] of the named bodies along ``smooth_motion``, the centres of mass'
    velocities by complex step from the geometry alone."""
    bodies = _bodies(model, names)
    q, qd, _ = smooth_motion(model, seed=seed, t=times)
    velocity = complex_step_velocity(model, q, qd, [body.com for body in bodies])
    return sum(body.mass * velocity[:, i] for i, body in enumerate(bodies))


def momentum_rate_minus_weight(model, names, seed, h=1e-4):
    """d(Σ m v)/dt - Σ m g (N, 2) [N] at ``TIMES``, by finite differences of the momentum."""
    rate = sum(w * momentum(model, names, TIMES + k * h, seed) / h for k, w in STENCIL)
    weight = sum(body.mass for body in _bodies(model, names)) * ROBOT.gravity
    return rate + np.array([0.0, weight])


def test_each_knee_force_is_the_lower_legs_momentum_rate(model):
    """Swing knee: F = dP/dt - m g of the swing shank and foot. Stance knee: F + F_ground =
    dP/dt - m g of the stance shank and foot (the ground's force from inverse dynamics)."""
    q, qd, qdd = smooth_motion(model, seed=31, t=TIMES)
    loads = knee_forces(model, q, qd, qdd)
    _, wrench = model.inverse_dynamics(q, qd, qdd)
    swing = momentum_rate_minus_weight(model, LOWER["swing"], seed=31)
    stance = momentum_rate_minus_weight(model, LOWER["stance"], seed=31)
    assert np.ptp(loads.force[:, 1], axis=0).max() > 20.0  # the swing moves the force
    np.testing.assert_allclose(loads.force[:, 1], swing, atol=1e-7)
    np.testing.assert_allclose(loads.force[:, 0] + wrench[:, :2], stance, atol=1e-7)


def test_the_knees_and_the_ground_balance_the_whole_robot(model):
    """Only the knees' reactions and gravity act on the thighs and trunk: dP/dt - m g of the
    upper bodies is -(F_stance + F_swing); the ground's force is that of the whole robot."""
    q, qd, qdd = smooth_motion(model, seed=32, t=TIMES)
    loads = knee_forces(model, q, qd, qdd)
    _, wrench = model.inverse_dynamics(q, qd, qdd)
    upper = momentum_rate_minus_weight(model, UPPER, seed=32)
    whole = momentum_rate_minus_weight(model, [body.name for body in model.bodies], seed=32)
    np.testing.assert_allclose(loads.force.sum(-2), -upper, atol=1e-7)
    np.testing.assert_allclose(loads.force.sum(-2) + wrench[:, :2], whole - upper, atol=1e-7)
    np.testing.assert_allclose(wrench[:, :2], whole, atol=1e-7)


def test_standing_still_the_knees_carry_the_weights(model):
    """Standing straight and still: the stance knee pushes up the weight above it
    (compression), the swing knee holds up its shank and foot, 41.9 N for Table 1, in
    tension; neither across its axis."""
    q, qd, qdd = model.stance_state(np.zeros(6))
    loads = knee_forces(model, q, qd, qdd)
    lower = (ROBOT.shank_mass + ROBOT.foot_mass) * ROBOT.gravity
    above = ROBOT.weight - lower
    np.testing.assert_allclose(loads.force, [[0.0, -above], [0.0, lower]], atol=1e-9)
    np.testing.assert_allclose(loads.normal, [above, -lower], rtol=1e-12)
    np.testing.assert_allclose(loads.tangential, 0.0, atol=1e-9)
    assert lower == pytest.approx(41.89, abs=0.01)
    np.testing.assert_array_equal(loads.tension, [0.0, lower])
    assert np.isnan(loads.slip_ratio[1]) and loads.slip_ratio[0] == 0.0


def test_a_still_bent_leg_splits_its_weight_along_the_line_of_centres(model):
    """Still, with the legs bent: each knee's force is vertical (the weights), and its normal
    and tangential parts are those along e = u(γ) of the paper's γ = (r1 q_shank + r2
    q_thigh) / l (the shank's angle for the revolute knee), e' = u'(γ)."""
    angles = np.array([[0.1, -0.2, 0.3, 0.6, -0.4, 0.05], [-0.2, 0.4, 0.1, -0.3, -0.9, 0.2]])
    q, qd, qdd = model.stance_state(angles)
    loads = knee_forces(model, q, qd, qdd)
    lower = (ROBOT.shank_mass + ROBOT.foot_mass) * ROBOT.gravity
    above = ROBOT.weight - lower
    r1, r2 = model.radii
    for knee, (shank, thigh), vertical in ((0, (Q1, Q2), -above), (1, (Q4, Q3), lower)):
        if r1 + r2 > 0.0:
            gamma = (r1 * q[:, shank] + r2 * q[:, thigh]) / (r1 + r2)
        else:
            gamma = q[:, shank]
        np.testing.assert_allclose(loads.force[:, knee], [[0.0, vertical]] * 2, atol=1e-9)
        np.testing.assert_allclose(loads.normal[:, knee], -vertical * np.cos(gamma), atol=1e-9)
        np.testing.assert_allclose(loads.tangential[:, knee], vertical * np.sin(gamma), atol=1e-9)


@pytest.mark.parametrize("radius", [1e-4, 1e-7])
def test_the_rolling_knee_tends_to_the_revolute_knee(radius):
    """As r1, r2 → 0 the rolling knee's forces tend to the revolute knee's, as O(r) (the line
    of centres then has no limit: the force vectors are compared)."""
    revolute = biped.Biped(ROBOT, "revolute")
    rolling = biped.Biped(dataclasses.replace(ROBOT, r1=radius, r2=radius), "rolling")
    state = np.random.default_rng(33)
    angles = state.uniform(-0.6, 0.6, (16, 6))
    rates, accelerations = state.normal(0, 2, (16, 6)), state.normal(0, 10, (16, 6))
    expected = knee_forces(revolute, *revolute.stance_state(angles, rates, accelerations))
    found = knee_forces(rolling, *rolling.stance_state(angles, rates, accelerations))
    difference = np.abs(found.force - expected.force).max()
    assert np.abs(expected.force).max() > 100.0
    assert difference < 1e4 * radius, difference  # N per m of radius: O(r)


def test_batches_of_any_shape_are_the_samples_one_by_one(model):
    """Vectorised: (4, 4) samples give what each sample gives alone."""
    q, qd, qdd = random_state(model, seed=34, n=16)
    flat = knee_forces(model, q, qd, qdd)
    square = knee_forces(model, *(x.reshape(4, 4, -1) for x in (q, qd, qdd)))
    assert square.force.shape == (4, 4, 2, 2) and square.normal.shape == (4, 4, 2)
    np.testing.assert_array_equal(square.normal.reshape(16, 2), flat.normal)
    one = knee_forces(model, q[5], qd[5], qdd[5])
    np.testing.assert_allclose(one.tangential, flat.tangential[5], rtol=1e-12, atol=1e-12)


@pytest.mark.parametrize("knee", biped.KNEES)
def test_a_gait_records_its_knee_loads_and_the_ligaments_they_need(knee):
    """The gait's record holds the loads of its samples on the check grid, the largest
    tension and compression of each knee, its largest |T| / N where compressed (None: never),
    and whether it needs ligaments: the rolling knee's swing knee pulls (N < 0), which the
    revolute knee's pin carries; in stance the knee is pressed by the body's weight."""
    from biped.records.gait_file import Gait
    from tests.conftest import small_optimum

    gait = Gait.from_optimum(small_optimum(knee), ROBOT)
    record, samples = gait.knee_loads, gait.samples
    loads = knee_forces(gait.biped, samples.q, samples.qd, samples.qdd, samples.wrench)
    np.testing.assert_array_equal(record.normal, loads.normal)
    np.testing.assert_array_equal(record.tangential, loads.tangential)
    normal = np.asarray(record.normal)
    np.testing.assert_array_equal(record.max_tension, np.maximum(-normal.min(0), 0.0))
    np.testing.assert_array_equal(record.max_compression, np.maximum(normal.max(0), 0.0))
    assert normal.shape == (len(samples.t), 2)
    assert record.max_tension[0] == 0.0 and record.max_compression[1] == 0.0  # this gait's
    assert 0.5 * ROBOT.weight < record.max_compression[0] < 1.5 * ROBOT.weight
    assert record.max_tension[1] > 30.0
    pressed = normal[:, 0] > 0.0
    ratio = np.abs(np.asarray(record.tangential)[pressed, 0]) / normal[pressed, 0]
    assert record.max_slip_ratio == [ratio.max(), None]
    assert record.needs_ligaments is (knee == "rolling")
    assert Gait.units("sthenic")["knee_loads.max_tension"] == "N"
