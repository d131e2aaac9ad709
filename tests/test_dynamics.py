"""Dynamics, eq. (19): properties that a wrong model breaks."""

import numpy as np
import pytest

import biped
from biped.model.dynamics import JOINT_MATRIX
from biped.model.kinematics import XH, ZH
from tests.conftest import complex_step_velocity, random_state, smooth_motion

ROBOT = biped.Robot.paper()


def body_energy(model, q, qd):
    """T + V summed body by body from the geometry alone (no mass matrix)."""
    names = [body.com for body in model.bodies]
    velocity = complex_step_velocity(model, q, qd, names)
    height = model.points(q, names)[..., 1]
    rates = model.direction_angles(qd)
    index = {name: k for k, name in enumerate(model.direction_names)}
    energy = 0.0
    for i, body in enumerate(model.bodies):
        omega = rates[..., index[body.direction]]
        energy = energy + 0.5 * body.mass * (velocity[..., i, :] ** 2).sum(-1)
        energy = energy + 0.5 * body.inertia * omega**2 + body.mass * ROBOT.gravity * height[..., i]
    return energy


def test_mass_matrix_is_symmetric_positive_definite(model):
    """D(q) is symmetric positive definite for random postures."""
    q, _, _ = random_state(model, seed=10, n=200, spread=np.pi)
    d = model.mass_matrix(q)
    np.testing.assert_allclose(d, np.swapaxes(d, -1, -2), atol=1e-13)
    assert np.linalg.eigvalsh(d).min() > 1e-4


def test_mass_matrix_matches_appendix_a():
    """Entries of D printed in Appendix A (rolling knee) hold for random configurations."""
    model = biped.Biped(ROBOT, "rolling")
    rng = np.random.default_rng(11)
    mp, sp, ip = ROBOT.foot_mass, ROBOT.foot_com, ROBOT.foot_inertia
    m1, s1, i1 = ROBOT.shank_mass, ROBOT.shank_com, ROBOT.shank_inertia
    m2, s2 = ROBOT.thigh_mass, ROBOT.thigh_com
    r1, r2 = ROBOT.r1, ROBOT.r2
    link, l1, l2 = r1 + r2, ROBOT.shank_length, ROBOT.thigh_length
    l1p, l2p = l1 - r1, l2 - r2
    for q in rng.uniform(-1.5, 1.5, (20, 9)):
        qp1, qp2, q1, q2, q3, q4, q5, _, _ = q
        g1 = (r1 * q1 + r2 * q2) / link
        th2, th5 = q1 - q2, q4 - q3
        a1, a2, a3, a4 = r1 * th2 / link, r2 * th2 / link, r1 * th5 / link, r2 * th5 / link
        a5 = g1 - qp1
        a6 = (r1 * q4 + r2 * q3) / link - qp2
        expected = {
            (0, 0): ip + mp * sp**2,
            (0, 2): mp * sp * l1p * np.cos(q1 - qp1) + mp * sp * r1 * np.cos(a5),
            (0, 3): mp * sp * l2p * np.cos(q2 - qp1) + mp * sp * r2 * np.cos(a5),
            (0, 7): mp * sp * np.cos(qp1),
            (0, 8): mp * sp * np.sin(qp1),
            (1, 1): mp * sp**2 + ip,
            # d25, d26 as printed swap l'1 and l'2; this is the swing-leg image of d13, d14.
            (1, 4): mp * sp * l2p * np.cos(q3 - qp2) + mp * sp * r2 * np.cos(a6),
            (1, 5): mp * sp * l1p * np.cos(q4 - qp2) + mp * sp * r1 * np.cos(a6),
            (1, 7): mp * sp * np.cos(qp2),
            (1, 8): mp * sp * np.sin(qp2),
            (2, 2): i1
            + m1 * (s1 - r1) ** 2
            + mp * l1p**2
            + (m1 + mp) * r1**2
            + 2 * m1 * (s1 - r1) * r1 * np.cos(a2)
            + 2 * mp * l1p * r1 * np.cos(a2),
            (2, 3): (m1 + mp) * r1 * r2
            - (m1 + mp) * r1 * l2p * np.cos(th2)
            + (mp * l1 + m1 * s1) * l2p * np.cos(th2)
            + (m1 + mp) * r1 * (l2 - r2) * np.cos(a1)
            + (m1 * s1 + mp * l1 - (m1 + mp) * r1) * r2 * np.cos(a2),
            (3, 7): ((m1 + mp) * l2p + m2 * s2) * np.cos(q2) + (m1 + mp) * r2 * np.cos(g1),
            (3, 8): ((m1 + mp) * l2p + m2 * s2) * np.sin(q2) + (m1 + mp) * r2 * np.sin(g1),
            (4, 4): ROBOT.thigh_inertia
            + (m1 + mp) * (l2p**2 + r2**2)
            + m2 * s2**2
            + 2 * (m1 + mp) * l2p * r2 * np.cos(a3),
            (4, 5): (m1 + mp) * r1 * r2
            + mp * l2p * (l1 - r1) * np.cos(th5)
            + m1 * l2p * (s1 - r1) * np.cos(th5)
            + (m1 + mp) * l2p * r1 * np.cos(a3)
            + m1 * r2 * (s1 - r1) * np.cos(a4)
            + mp * r2 * l1p * np.cos(a4),
        }
        d = model.mass_matrix(q)
        for (i, j), value in expected.items():
            assert d[i, j] == pytest.approx(value, abs=1e-12), f"d{i + 1}{j + 1}"
        # Structural zeros of (A.1): the legs do not couple to each other or to the trunk.
        for i, j in [(0, 1), (0, 4), (0, 5), (0, 6), (2, 4), (3, 5), (4, 6), (7, 8)]:
            assert d[i, j] == 0.0, f"d{i + 1}{j + 1}"


def test_kinetic_energy_matches_body_velocities(model):
    """½ q̇ᵀ D q̇ equals Σ ½ m v² + ½ I ω² from the geometry, for unconstrained states too."""
    rng = np.random.default_rng(12)
    q, qd = rng.uniform(-1, 1, (30, 9)), rng.normal(size=(30, 9))
    potential = model.potential_energy(q)
    np.testing.assert_allclose(
        model.kinetic_energy(q, qd) + potential, body_energy(model, q, qd), rtol=1e-12
    )


def test_bias_forces_are_christoffel_symbols_of_d(model):
    """H_i = Σ_jk (∂D_ij/∂q_k - ½ ∂D_jk/∂q_i) q̇_j q̇_k with ∂D by finite differences."""
    rng = np.random.default_rng(13)
    h = 1e-6
    for q, qd in zip(rng.uniform(-1, 1, (5, 9)), rng.normal(size=(5, 9)), strict=True):
        steps = np.eye(9) * h
        dd = (model.mass_matrix(q + steps) - model.mass_matrix(q - steps)) / (2 * h)  # [k, i, j]
        expected = np.einsum("kij,j,k->i", dd, qd, qd) - 0.5 * np.einsum("ijk,j,k->i", dd, qd, qd)
        np.testing.assert_allclose(model.bias_forces(q, qd), expected, atol=1e-7)


def test_gravity_forces_are_gradient_of_potential(model):
    """Q = ∂V/∂q by central differences."""
    q = np.random.default_rng(14).uniform(-1, 1, 9)
    h = 1e-6
    steps = np.eye(9) * h
    gradient = (model.potential_energy(q + steps) - model.potential_energy(q - steps)) / (2 * h)
    np.testing.assert_allclose(model.gravity_forces(q), gradient, atol=1e-6)


def test_generalized_forces_equal_d_qdd_plus_h_plus_q(model):
    """The one-pass inverse dynamics equals D q̈ + H + Q assembled from the matrices."""
    rng = np.random.default_rng(15)
    q, qd, qdd = rng.uniform(-1, 1, (3, 20, 9))
    expected = (
        (model.mass_matrix(q) @ qdd[..., None])[..., 0]
        + model.bias_forces(q, qd)
        + model.gravity_forces(q)
    )
    np.testing.assert_allclose(model.generalized_forces(q, qd, qdd), expected, atol=1e-10)


def test_inverse_dynamics_solves_eq_19(model):
    """B Γ + A_cᵀ F_e reproduces D q̈ + H + Q; the closed form equals a generic solve."""
    q, qd, qdd = random_state(model, seed=16, n=50)
    torques, wrench = model.inverse_dynamics(q, qd, qdd)
    ac = model.contact_jacobian(q)
    rhs = torques @ JOINT_MATRIX + (np.swapaxes(ac, -1, -2) @ wrench[..., None])[..., 0]
    np.testing.assert_allclose(rhs, model.generalized_forces(q, qd, qdd), atol=1e-9)
    system = np.concatenate(
        [np.broadcast_to(JOINT_MATRIX.T, ac.shape[:-2] + (9, 6)), np.swapaxes(ac, -1, -2)], -1
    )
    solution = np.linalg.solve(system, model.generalized_forces(q, qd, qdd)[..., None])[..., 0]
    np.testing.assert_allclose(np.concatenate([torques, wrench], -1), solution, atol=1e-8)


def test_motor_power_equals_rate_of_energy(model):
    """Σ Γ_i θ̇_i = d(T + V)/dt along smooth motions: the fixed foot does no work."""
    t = np.linspace(0.0, 1.0, 41)
    h = 1e-4
    stencil = [(-2, 1 / 12), (-1, -8 / 12), (1, 8 / 12), (2, -1 / 12)]
    energy_rate = 0.0
    for k, weight in stencil:
        q_k, qd_k, _ = smooth_motion(model, seed=17, t=t + k * h)
        energy_rate = energy_rate + weight * body_energy(model, q_k, qd_k) / h
    q, qd, qdd = smooth_motion(model, seed=17, t=t)
    torques, _ = model.inverse_dynamics(q, qd, qdd)
    power = model.motor_power(qd, torques)
    assert np.abs(power).max() > 10.0  # the motion is not trivial
    np.testing.assert_allclose(power, energy_rate, atol=1e-6 * np.abs(power).max())


def test_ground_force_is_total_mass_times_com_acceleration(model):
    """(Fx, Fz) = M (p̈_G - g) with the centre of mass from the geometry."""
    t = np.linspace(0.0, 1.0, 21)
    names = [body.com for body in model.bodies]
    masses = np.array([body.mass for body in model.bodies])

    def com(times):
        q, _, _ = smooth_motion(model, seed=18, t=times)
        return (masses[:, None] * model.points(q, names)).sum(-2) / masses.sum()

    h = 1e-3
    accel = (-com(t + 2 * h) + 16 * com(t + h) - 30 * com(t) + 16 * com(t - h) - com(t - 2 * h)) / (
        12 * h * h
    )
    q, qd, qdd = smooth_motion(model, seed=18, t=t)
    _, wrench = model.inverse_dynamics(q, qd, qdd)
    expected = masses.sum() * (accel + [0.0, ROBOT.gravity])
    np.testing.assert_allclose(wrench[:, :2], expected, atol=1e-4)


def test_zmp_equals_whole_body_angular_momentum_formula(model):
    """Eq. (29) equals x_ZMP = [Σ m x (z̈+g) - Σ m z ẍ + Σ I φ̈] / Σ m (z̈+g)."""
    t = np.linspace(0.0, 1.0, 21)
    names = [body.com for body in model.bodies]
    index = {name: k for k, name in enumerate(model.direction_names)}
    h = 1e-3

    def positions(times):
        q, _, _ = smooth_motion(model, seed=19, t=times)
        return model.points(q, names)

    accel = (
        -positions(t + 2 * h)
        + 16 * positions(t + h)
        - 30 * positions(t)
        + 16 * positions(t - h)
        - positions(t - 2 * h)
    ) / (12 * h * h)
    q, qd, qdd = smooth_motion(model, seed=19, t=t)
    p = model.points(q, names)
    phidd = model.direction_angles(qdd)
    numerator = 0.0
    denominator = 0.0
    for i, body in enumerate(model.bodies):
        x, z = p[:, i, 0], p[:, i, 1]
        xdd, zdd = accel[:, i, 0], accel[:, i, 1]
        numerator = (
            numerator
            + body.mass * (x * (zdd + ROBOT.gravity) - z * xdd)
            + body.inertia * phidd[:, index[body.direction]]
        )
        denominator = denominator + body.mass * (zdd + ROBOT.gravity)
    np.testing.assert_allclose(model.zmp(q, qd, qdd), numerator / denominator, atol=1e-7)


def test_rolling_knee_tends_to_revolute_knee():
    """As r1, r2 → 0 the rolling-knee model converges (linearly) to the revolute one."""
    revolute = biped.Biped(ROBOT, "revolute")
    q, qd, qdd = random_state(revolute, seed=20, n=20)
    torques_0, wrench_0 = revolute.inverse_dynamics(q, qd, qdd)
    d_0 = revolute.mass_matrix(q)
    errors = []
    for radius in (1e-2, 1e-3, 1e-4):
        robot = biped.Robot.from_mapping({"r1": radius, "r2": 0.7 * radius})
        rolling = biped.Biped(robot, "rolling")
        # Same angles; the hip moves with the knee geometry, so rebuild the state.
        q_r, qd_r, qdd_r = rolling.stance_state(q[:, 1:7], qd[:, 1:7], qdd[:, 1:7])
        torques, wrench = rolling.inverse_dynamics(q_r, qd_r, qdd_r)
        error = max(np.abs(torques - torques_0).max(), np.abs(wrench - wrench_0).max())
        errors.append(error)
        np.testing.assert_allclose(rolling.mass_matrix(q_r), d_0, atol=50 * radius)
    assert errors[0] > 1e-3  # the knees do differ
    assert errors[1] < errors[0] / 5 and errors[2] < errors[1] / 5
    scale = max(np.abs(torques_0).max(), np.abs(wrench_0).max())
    assert errors[2] < 1e-4 * scale
    zero = biped.Biped(biped.Robot.from_mapping({"r1": 0.0, "r2": 0.0}), "rolling")
    np.testing.assert_array_equal(zero.inverse_dynamics(q, qd, qdd)[0], torques_0)


def test_static_standing_torques():
    """Standing straight and still: Fz is the weight, the trunk needs no hip torque."""
    for knee in biped.KNEES:
        model = biped.Biped(ROBOT, knee)
        q, qd, qdd = model.stance_state(np.zeros(6))
        torques, wrench = model.inverse_dynamics(q, qd, qdd)
        np.testing.assert_allclose(wrench, [0.0, ROBOT.total_mass * ROBOT.gravity, 0.0], atol=1e-9)
        np.testing.assert_allclose(torques, 0.0, atol=1e-9)
        assert q[ZH] == pytest.approx(ROBOT.height - ROBOT.trunk_length)
        assert q[XH] == pytest.approx(0.0)


def test_batch_shapes(model):
    """Every method takes leading batch dimensions."""
    q, qd, qdd = random_state(model, seed=21, n=12)
    q, qd, qdd = (x.reshape(3, 4, 9) for x in (q, qd, qdd))
    torques, wrench = model.inverse_dynamics(q, qd, qdd)
    assert torques.shape == (3, 4, 6) and wrench.shape == (3, 4, 3)
    assert model.mass_matrix(q).shape == (3, 4, 9, 9)
    assert model.zmp(q, qd, qdd).shape == (3, 4)
    single = model.inverse_dynamics(q[1, 2], qd[1, 2], qdd[1, 2])
    np.testing.assert_allclose(single[0], torques[1, 2])
