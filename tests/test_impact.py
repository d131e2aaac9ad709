"""Flat-foot impact, eqs. (21)-(24), and the leg relabelling that starts the next step."""

import numpy as np

import biped
from biped.model.kinematics import QP2, XH, ZH
from tests.conftest import complex_step_velocity, random_state


def touchdown_state(model, seed, n=20):
    """Postures with the swing foot flat, moving down and forward, the stance foot fixed."""
    q, qd, _ = random_state(model, seed=seed, n=n, spread=0.4)
    q[:, QP2] = 0.0
    rng = np.random.default_rng(seed)
    qd = qd + rng.normal(0, 0.5, qd.shape)  # a general pre-impact velocity
    # Make the swing ankle move down, as when the foot lands.
    jac = model.point_jacobian(q, "swing_ankle")[:, 1, :]
    down = -np.abs(rng.normal(0.5, 0.2, n)) - (jac * qd).sum(-1)
    qd[:, ZH] += down
    return q, qd


def test_landing_foot_is_at_rest_after_impact(model):
    """A_c q̇⁺ = 0 (eq. 22): the landing foot neither moves nor turns."""
    q, qd = touchdown_state(model, seed=30)
    qd_plus, _ = model.impact(q, qd)
    np.testing.assert_allclose(
        (model.contact_jacobian(q, "swing") @ qd_plus[..., None])[..., 0], 0.0, atol=1e-12
    )


def test_momentum_changes_only_along_the_contact(model):
    """D (q̇⁺ - q̇⁻) = A_cᵀ I_R (eq. 21): the impulse is the only change of momentum."""
    q, qd = touchdown_state(model, seed=31)
    qd_plus, impulse = model.impact(q, qd)
    jac = model.contact_jacobian(q, "swing")
    lhs = (model.mass_matrix(q) @ (qd_plus - qd)[..., None])[..., 0]
    np.testing.assert_allclose(
        lhs, (np.swapaxes(jac, -1, -2) @ impulse[..., None])[..., 0], atol=1e-10
    )


def test_impulse_changes_linear_and_angular_momentum(model):
    """ΔP = (Ix, Iz) and the angular momentum about the landing ankle changes by Iy only."""
    q, qd = touchdown_state(model, seed=32)
    qd_plus, impulse = model.impact(q, qd)
    names = [body.com for body in model.bodies]
    masses = np.array([body.mass for body in model.bodies])
    inertias = np.array([body.inertia for body in model.bodies])
    index = {name: k for k, name in enumerate(model.direction_names)}
    columns = [index[body.direction] for body in model.bodies]
    ankle = model.point(q, "swing_ankle")
    r = model.points(q, names) - ankle[:, None, :]

    def momenta(velocity):
        v = complex_step_velocity(model, q, velocity, names)
        linear = (masses[:, None] * v).sum(-2)
        spin = inertias * model.direction_angles(velocity)[:, columns]
        angular = (masses * (r[..., 0] * v[..., 1] - r[..., 1] * v[..., 0]) + spin).sum(-1)
        return linear, angular

    linear_minus, angular_minus = momenta(qd)
    linear_plus, angular_plus = momenta(qd_plus)
    np.testing.assert_allclose(linear_plus - linear_minus, impulse[:, :2], atol=1e-10)
    np.testing.assert_allclose(angular_plus - angular_minus, impulse[:, 2], atol=1e-10)


def test_ground_pushes_up_on_a_falling_robot(model):
    """A robot translating straight down lands with Iz > 0 and at most the robot's momentum."""
    q, _, _ = random_state(model, seed=36, n=10, spread=0.3)
    q[:, QP2] = 0.0
    qd = np.zeros_like(q)
    qd[:, ZH] = -0.4
    _, impulse = model.impact(q, qd)
    assert np.all(impulse[:, 1] > 0.0)
    # The impulse cannot exceed the momentum of the whole robot.
    assert np.all(impulse[:, 1] <= 0.4 * model.mass + 1e-12)


def test_impact_dissipates_exactly_the_relative_energy(model):
    """T⁻ - T⁺ = ½ (q̇⁻ - q̇⁺)ᵀ D (q̇⁻ - q̇⁺) ≥ 0: a plastic impact never gains energy."""
    q, qd = touchdown_state(model, seed=33)
    qd_plus, _ = model.impact(q, qd)
    loss = model.kinetic_energy(q, qd) - model.kinetic_energy(q, qd_plus)
    assert np.all(loss > 0.0)
    np.testing.assert_allclose(loss, model.kinetic_energy(q, qd - qd_plus), rtol=1e-10)


def test_impact_at_rest_foot_changes_nothing(model):
    """A foot that lands with zero velocity receives no impulse."""
    q, qd, _ = random_state(model, seed=34, n=5)
    q[:, QP2] = 0.0
    jac = model.contact_jacobian(q, "swing")
    # Project q̇ onto the null space of A_c: the swing foot is already at rest.
    projector = np.eye(9) - np.linalg.pinv(jac) @ jac
    qd = (projector @ qd[..., None])[..., 0]
    qd_plus, impulse = model.impact(q, qd)
    np.testing.assert_allclose(impulse, 0.0, atol=1e-9)
    np.testing.assert_allclose(qd_plus, qd, atol=1e-10)


def test_next_step_starts_on_the_new_stance_foot(model):
    """After the impact and the leg swap the new stance foot is fixed: A_c q̇ = 0."""
    q, qd = touchdown_state(model, seed=35)
    qd_plus, _ = model.impact(q, qd)
    new_q, new_qd = biped.swap_legs(model, q, qd_plus)
    np.testing.assert_allclose(
        (model.contact_jacobian(new_q) @ new_qd[..., None])[..., 0], 0.0, atol=1e-12
    )
    np.testing.assert_allclose(new_q[:, ZH], q[:, ZH])
    np.testing.assert_allclose(
        model.point(new_q, "stance_ankle"),
        model.point(q, "swing_ankle") - model.point(q, "swing_ankle") * [1, 0],
        atol=1e-12,
    )
    assert np.all(new_q[:, XH] != q[:, XH])


def test_trailing_foot_lift_is_the_stance_foot_velocity(model):
    """trailing_foot_lift equals the vertical velocity of the old stance heel and toe."""
    from biped.model.impact import trailing_foot_lift

    q, qd = touchdown_state(model, seed=37, n=5)
    qd_plus, _ = model.impact(q, qd)
    velocity = complex_step_velocity(model, q, qd_plus, ["stance_heel", "stance_toe"])[..., 1]
    np.testing.assert_allclose(trailing_foot_lift(model, q, qd_plus), velocity, atol=1e-12)


def test_both_feet_impact_stops_both_feet_by_impulses_along_their_contacts(model):
    """Both feet held (the start of double support): A q̇⁺ = 0 for the six rows of both feet
    and D (q̇⁺ − q̇⁻) = Aᵀ I_R; the one-foot impact leaves the stance foot moving."""
    from biped.model.impact import both_feet_impact

    q, qd = touchdown_state(model, seed=33)
    qd_plus, impulse = both_feet_impact(model, q, qd)
    rows = np.concatenate([model.contact_jacobian(q, f) for f in ("stance", "swing")], axis=-2)
    np.testing.assert_allclose((rows @ qd_plus[..., None])[..., 0], 0.0, atol=1e-12)
    lhs = (model.mass_matrix(q) @ (qd_plus - qd)[..., None])[..., 0]
    rhs = (np.swapaxes(rows, -1, -2) @ impulse[..., None])[..., 0]
    np.testing.assert_allclose(lhs, rhs, atol=1e-10)
    one_foot, _ = model.impact(q, qd)
    stance = (model.contact_jacobian(q, "stance") @ one_foot[..., None])[..., 0]
    assert np.max(np.abs(stance)) > 1e-3
