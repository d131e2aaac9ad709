"""Knee profiles (``biped.model.profile``): the surfaces roll without slip with the curvature
they are given, the model is the circles' at constant curvature and the revolute knee's at
zero size, its dynamics conserve energy."""

import dataclasses

import numpy as np
import pytest

import biped
from biped.errors import ParameterError
from biped.model.profile import KneeProfile, knee_vectors, rolling, surface_margins
from biped.model.profile_biped import ProfileBiped
from tests import test_dynamics, test_kinematics
from tests.conftest import random_state

ROBOT = biped.Robot.paper()
# A profile of each sign: the shank's curvature radius grows with its tangent angle, the
# thigh's shrinks.
PROFILED = dataclasses.replace(ROBOT, r1=0.1, r2=0.15, k1=0.03, k2=-0.04)
CIRCLES = dataclasses.replace(ROBOT, r1=0.1, r2=0.15)


@pytest.fixture(scope="module")
def model():
    return biped.Biped(PROFILED, "rolling")


def test_a_profiled_robot_is_the_profile_model_and_circles_keep_theirs():
    assert type(biped.Biped(PROFILED, "rolling")) is ProfileBiped
    assert type(biped.Biped(CIRCLES, "rolling")) is biped.Biped
    assert type(biped.Biped(PROFILED, "revolute")) is biped.Biped
    assert "k1" not in CIRCLES.to_dict() and PROFILED.to_dict()["k2"] == -0.04


@pytest.mark.parametrize("profile", [PROFILED, dataclasses.replace(PROFILED, k1=-0.02, k2=0.05)])
def test_each_surface_has_the_curvature_it_is_given_and_rolls_without_slip(profile):
    """The contact point's path drawn in the thigh's frame is a curve of radius of
    curvature r2 + k2 ψ2 whose normal turns by ψ2, in the shank's frame one of r1 + k1 ψ1;
    the two paths run the same arc length (no slip). From positions alone, by finite
    differences over the flexion."""
    p = KneeProfile.of(profile)
    theta, h = np.linspace(-0.04, 2.3, 40), 1e-5

    def paths(t):
        vectors = knee_vectors(p, np.zeros_like(t), -t)  # thigh at 0, shank at −θ
        contact = np.stack(vectors["contact"].position, -1)  # K − C2, the thigh's frame
        link = np.stack(vectors["link"].position, -1)
        c, s = np.cos(t), np.sin(t)  # K − C1 turned by +θ into the shank's frame
        shank = contact - link
        in_shank = np.stack(
            [c * shank[:, 0] - s * shank[:, 1], s * shank[:, 0] + c * shank[:, 1]], -1
        )
        return contact, in_shank

    (thigh_up, shank_up), (thigh_down, shank_down) = paths(theta + h), paths(theta - h)
    thigh_speed = np.linalg.norm(thigh_up - thigh_down, axis=-1) / (2 * h)
    shank_speed = np.linalg.norm(shank_up - shank_down, axis=-1) / (2 * h)
    roll = rolling(p, theta)
    psi1_rate = (rolling(p, theta + h).psi1 - rolling(p, theta - h).psi1) / (2 * h)
    np.testing.assert_allclose(thigh_speed, shank_speed, rtol=1e-8)
    np.testing.assert_allclose(thigh_speed / (1 - psi1_rate), p.r2 + p.k2 * roll.psi2, rtol=1e-7)
    np.testing.assert_allclose(shank_speed / psi1_rate, p.r1 + p.k1 * roll.psi1, rtol=1e-7)
    # The contact is on the common normal: the path's tangent is across u(γ), γ = −ψ2.
    tangent = thigh_up - thigh_down
    normal = np.stack([np.sin(-roll.psi2), -np.cos(-roll.psi2)], -1)
    assert np.abs((tangent * normal).sum(-1)).max() < 1e-9 * h


def test_rolling_relation_derivatives_are_finite_differences():
    theta, h = np.linspace(-0.05, 2.4, 30), 1e-5
    for profile in (KneeProfile(0.1, 0.15, 0.03, -0.04), KneeProfile(0.18, 0.2, -0.06, -0.07)):
        up, down, here = (
            rolling(profile, theta + h),
            rolling(profile, theta - h),
            rolling(profile, theta),
        )
        np.testing.assert_allclose((up.psi1 - down.psi1) / (2 * h), here.rate, rtol=1e-8)
        np.testing.assert_allclose((up.rate - down.rate) / (2 * h), here.curvature, atol=1e-8)
        np.testing.assert_allclose(here.psi1 + here.psi2, theta, atol=1e-15)


def test_knee_vectors_derivatives_are_finite_differences():
    """∂X/∂q and the bias acceleration (dJ/dt) q̇ of the link and the contact."""
    rng = np.random.default_rng(3)
    thigh, shank = rng.uniform(-0.5, 1.0, 20), rng.uniform(-1.5, 0.5, 20)
    rates = rng.normal(0, 2, (2, 20))
    shank = np.minimum(shank, thigh - 0.01)
    h = 1e-6
    PROFILED_P = KneeProfile.of(PROFILED)
    here = knee_vectors(PROFILED_P, thigh, shank, *rates)
    for name in ("link", "contact"):
        for which, moved in (("by_thigh", (thigh + h, shank, thigh - h, shank)),
                             ("by_shank", (thigh, shank + h, thigh, shank - h))):  # fmt: skip
            up = knee_vectors(PROFILED_P, *moved[:2])[name].position
            down = knee_vectors(PROFILED_P, *moved[2:])[name].position
            for axis in range(2):
                difference = (up[axis] - down[axis]) / (2 * h)
                np.testing.assert_allclose(getattr(here[name], which)[axis], difference, atol=1e-8)

        # bias: d/dt (J q̇) along q(t) = q + t q̇, q̈ = 0
        def velocity(t, name=name):
            v = knee_vectors(PROFILED_P, thigh + t * rates[0], shank + t * rates[1])[name]
            return [v.by_thigh[i] * rates[0] + v.by_shank[i] * rates[1] for i in range(2)]

        ahead, behind = velocity(h), velocity(-h)
        for axis in range(2):
            difference = (ahead[axis] - behind[axis]) / (2 * h)
            np.testing.assert_allclose(here[name].bias[axis], difference, atol=1e-6)


def test_constant_curvature_is_the_circles_model_to_1e_12():
    """The profile model with k1 = k2 = 0 gives the circles' points, mass matrix, forces,
    stance states, torques and reach (``biped.Biped``) to 1e-12 of their scale."""
    profile, circles = ProfileBiped(CIRCLES), biped.Biped(CIRCLES, "rolling")
    q, qd, qdd = random_state(circles, seed=3, n=30)

    def same(a, b):
        a, b = np.asarray(a), np.asarray(b)
        assert np.abs(a - b).max() <= 1e-12 * max(np.abs(b).max(), 1.0)

    same(profile.points(q), circles.points(q))
    same(profile.mass_matrix(q), circles.mass_matrix(q))
    same(profile.generalized_forces(q, qd, qdd), circles.generalized_forces(q, qd, qdd))
    for a, b in zip(
        profile.stance_state(q[:, 1:7], qd[:, 1:7], qdd[:, 1:7]),
        circles.stance_state(q[:, 1:7], qd[:, 1:7], qdd[:, 1:7]),
        strict=True,
    ):
        same(a, b)
    for a, b in zip(
        profile.inverse_dynamics(q, qd, qdd), circles.inverse_dynamics(q, qd, qdd), strict=True
    ):
        same(a, b)
    flexion = np.linspace(0.0, 2.4, 50)
    same(profile.reach_squared(flexion), circles.reach_squared(flexion))
    same(
        profile.leg_angles([[0.1, 0.8], [-0.2, 0.7]]), circles.leg_angles([[0.1, 0.8], [-0.2, 0.7]])
    )
    # and the profile matters: k far from 0 moves the torques
    other = biped.Biped(PROFILED, "rolling")
    assert (
        np.abs(
            other.inverse_dynamics(q, qd, qdd)[0] - circles.inverse_dynamics(q, qd, qdd)[0]
        ).max()
        > 1e-2
    )


def test_zero_size_tends_to_the_revolute_knee():
    """Scaling r1, r2, k1, k2 by ε → 0, the torques converge linearly to the revolute knee's."""
    revolute = biped.Biped(ROBOT, "revolute")
    q, qd, qdd = random_state(revolute, seed=20, n=20)
    reference = revolute.inverse_dynamics(q, qd, qdd)[0]
    errors = []
    for scale in (1e-1, 1e-2, 1e-3):
        robot = dataclasses.replace(
            ROBOT, **{k: scale * getattr(PROFILED, k) for k in ("r1", "r2", "k1", "k2")}
        )
        model = biped.Biped(robot, "rolling")
        state = model.stance_state(q[:, 1:7], qd[:, 1:7], qdd[:, 1:7])
        errors.append(np.abs(model.inverse_dynamics(*state)[0] - reference).max())
    assert errors[0] > 1e-2
    assert errors[1] < errors[0] / 5 and errors[2] < errors[1] / 5
    assert errors[2] < 1e-4 * np.abs(reference).max()


@pytest.mark.parametrize(
    "check",
    [
        test_dynamics.test_kinetic_energy_matches_body_velocities,
        test_dynamics.test_bias_forces_are_christoffel_symbols_of_d,
        test_dynamics.test_gravity_forces_are_gradient_of_potential,
        test_dynamics.test_generalized_forces_equal_d_qdd_plus_h_plus_q,
        test_dynamics.test_inverse_dynamics_solves_eq_19,
        test_dynamics.test_motor_power_equals_rate_of_energy,
        test_dynamics.test_mass_matrix_is_symmetric_positive_definite,
        test_dynamics.test_ground_force_is_total_mass_times_com_acceleration,
        test_kinematics.test_stance_state_keeps_the_foot_fixed,
    ],
    ids=lambda f: f.__name__.removeprefix("test_"),
)
def test_the_dynamics_hold_for_a_profile(model, check):
    """Every property of the circles' dynamics holds for the profile: the energy of the
    bodies from their velocities alone (complex step) is ½ q̇ᵀ D q̇ + V, H the Christoffel
    symbols of D, Q the gradient of V, the motors' power the rate of the total energy."""
    check(model)


@pytest.mark.parametrize("name", ["swing_toe", "stance_ankle", "swing_knee", "stance_shank_com"])
def test_point_jacobians_and_biases_are_finite_differences(model, name):
    test_kinematics.test_point_jacobian_matches_finite_differences(model, name)
    q, qd, _ = random_state(model, seed=5, n=4)
    h = 1e-6
    ahead = model.point_jacobian(q + h * qd, name) @ qd[..., None]
    behind = model.point_jacobian(q - h * qd, name) @ qd[..., None]
    np.testing.assert_allclose(
        model.point_bias_acceleration(q, qd, name), (ahead - behind)[..., 0] / (2 * h), atol=1e-6
    )


def test_inverse_geometry_round_trip(model):
    angles = np.array([[-0.1, 0.2], [0.3, 0.35], [0.05, 1.4]])  # (shank, thigh)
    q = np.zeros((3, 9))
    q[:, 2], q[:, 3] = angles[:, 0], angles[:, 1]
    q, *_ = model.stance_state(q[:, 1:7])
    hip = q[:, 7:9] - model.point(q, "stance_ankle")
    np.testing.assert_allclose(model.leg_angles(hip), angles, atol=1e-10)


def test_a_profile_that_is_not_convex_over_the_knees_range_is_refused():
    with pytest.raises(ParameterError, match="k2 = -0.03 .*thigh convex at flexion"):
        dataclasses.replace(ROBOT, r1=0.1, r2=0.05, k2=-0.03)
    with pytest.raises(ParameterError, match="k1 = 0.3 .*shank convex at extension"):
        dataclasses.replace(ROBOT, r1=0.01, r2=0.05, k1=0.3)
    with pytest.raises(ParameterError, match="k1, k2 .*stop rolling"):
        dataclasses.replace(ROBOT, r1=0.1, r2=0.05, k2=-0.1)
    margins = surface_margins(KneeProfile(0.1, 0.15, 0.03, -0.04), (0.18, 0.23))
    assert all(m > 0 for m in margins)
