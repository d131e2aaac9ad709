"""A profiled knee in MuJoCo (``validate.scene.profile_mjcf``): its joints and equalities are the
exact rolling relation, so MuJoCo's knee, kinematics, inverse dynamics and impact are the
analytical model's to rounding; another profile's model is told apart."""

import dataclasses

import mujoco
import numpy as np
import pytest

import biped
from biped.model.profile import KneeProfile
from tests.conftest import random_state
from validate.checks.checks import check_model
from validate.checks.crosscheck import mujoco_impact, mujoco_inverse_dynamics, rigid_copy
from validate.checks.knee_fit import TARGET, knee_fit
from validate.scene.mapping import mapping
from validate.scene.mjcf import robot_xml, scene_model
from validate.scene.model import model_parameters

ROBOT = biped.Robot.paper()
# Round numbers, so that the MJCF's ten digits hold them exactly.
PROFILED = dataclasses.replace(ROBOT, r1=0.18, r2=0.23, k1=-0.1, k2=-0.15)
OTHER = dataclasses.replace(PROFILED, k1=-0.08)


@pytest.fixture(scope="module")
def model():
    return scene_model(PROFILED, "rolling")


@pytest.fixture(scope="module")
def biped_model():
    return biped.Biped(PROFILED, "rolling")


def test_mujocos_knee_is_the_analytical_one_over_the_knees_range(model):
    """Solved from MuJoCo's own equalities, the shank's pose is the analytical one to 1e-12
    over the whole range of flexion; another profile's model misses by far more than the
    target (0.1 mm, 1 mrad)."""
    fit = knee_fit(model, KneeProfile.of(PROFILED))
    assert fit.position < 1e-12 and fit.angle < 1e-12 and fit.residual < 1e-13
    wrong = knee_fit(scene_model(OTHER, "rolling"), KneeProfile.of(PROFILED))
    assert wrong.position > TARGET[0] and wrong.angle > TARGET[1]


def test_mapped_states_are_the_analytical_points_and_keep_the_equalities(model, biped_model):
    """At q mapped to qpos (and q̇ to qvel) MuJoCo's sites are the analytical points, its
    equality residuals and their rates zero; the back map recovers q."""
    data = mujoco.MjData(model)
    q, qd, _ = random_state(biped_model, seed=1, n=6, spread=0.4)
    mapped = mapping(model, "left", biped_model.radii)
    assert mapped.profile == KneeProfile.of(PROFILED)
    for k in range(len(q)):
        data.qpos[:], data.qvel[:] = mapped.qpos(q[k]), mapped.qvel(q[k], qd[k])
        mujoco.mj_forward(model, data)
        for site, point in (("left_ankle", "stance_ankle"), ("right_toe", "swing_toe")):
            found = data.site_xpos[model.site(site).id][[0, 2]]
            np.testing.assert_allclose(found, biped_model.point(q[k], point), atol=1e-14)
        n = data.nefc
        equality = data.efc_type[:n] == mujoco.mjtConstraint.mjCNSTR_EQUALITY
        assert equality.sum() == 6
        assert np.abs(data.efc_pos[:n][equality]).max() < 1e-15
        rates = data.efc_J[: n * model.nv].reshape(n, model.nv)[equality] @ data.qvel
        assert np.abs(rates).max() < 1e-14
        np.testing.assert_allclose(mapped.to_paper @ data.qpos, q[k], atol=1e-14)


def test_mapped_rates_and_accelerations_are_derivatives_of_the_map(model, biped_model):
    q, qd, qdd = random_state(biped_model, seed=2, n=3, spread=0.4)
    mapped = mapping(model, "right", biped_model.radii)
    h = 1e-6
    for k in range(3):

        def at(t, k=k):  # q(t) = q + t q̇ + t² q̈ / 2
            return mapped.qpos(q[k] + t * qd[k] + 0.5 * t * t * qdd[k])

        np.testing.assert_allclose(mapped.qvel(q[k], qd[k]), (at(h) - at(-h)) / (2 * h), atol=1e-8)
        np.testing.assert_allclose(
            mapped.qacc(q[k], qd[k], qdd[k]), (at(h) - 2 * at(0.0) + at(-h)) / h**2, atol=1e-3
        )


def test_mujocos_inverse_dynamics_and_impact_are_the_models(biped_model):
    """MuJoCo's rigid-body dynamics of the MJCF with its equalities give the analytical
    torques, ground wrench and impact to rounding; another profile's do not."""
    exact = rigid_copy(mujoco.MjModel.from_xml_string(robot_xml(PROFILED, "rolling")))
    q, qd, qdd = random_state(biped_model, seed=3, n=10, spread=0.3)
    torques, wrench = biped_model.inverse_dynamics(q, qd, qdd)
    found = mujoco_inverse_dynamics(exact, biped_model, q, qd, qdd)
    assert np.abs(found.torques - torques).max() < 1e-9 * np.abs(torques).max()
    assert np.abs(found.wrench - wrench).max() < 1e-9 * np.abs(wrench).max()
    qd_plus, impulse = biped_model.impact(q[0], qd[0])
    mj_qd_plus, mj_impulse = mujoco_impact(exact, biped_model, q[0], qd[0])
    np.testing.assert_allclose(mj_impulse, impulse, atol=1e-9 * np.abs(impulse).max())
    mapped = mapping(exact, "left", biped_model.radii)
    np.testing.assert_allclose(mj_qd_plus, mapped.qvel(q[0], qd_plus), atol=1e-9)
    other = rigid_copy(mujoco.MjModel.from_xml_string(robot_xml(OTHER, "rolling")))
    wrong = mujoco_inverse_dynamics(other, biped_model, q, qd, qdd)
    assert np.abs(wrong.torques - torques).max() > 1e-3


def test_the_model_check_reads_the_profile_back_and_tells_another(model, biped_model):
    held = model_parameters(model, "rolling")
    for name in ("r1", "r2", "k1", "k2"):
        for _, value in held[name]:
            assert value == pytest.approx(getattr(PROFILED, name), rel=1e-12, abs=1e-15)
    check = check_model(model, biped_model)
    assert check.passed and check.figures["knee_position_error"] < 1e-12
    wrong = check_model(scene_model(OTHER, "rolling"), biped_model)
    assert not wrong.passed and any("k1" in note for note in wrong.notes)
    circles = check_model(scene_model(ROBOT, "rolling"), biped_model)
    assert not circles.passed and "no profiled knee's equalities" in circles.notes[0]
    circle_gait = check_model(model, biped.Biped(ROBOT, "rolling"))
    assert not circle_gait.passed and "circles in the gait's robot" in circle_gait.notes[0]


def test_rotor_torques_are_the_armatures_power(model, biped_model):
    """The rotors' torques per joint (``rotor_torques``) times the joints' rates are the
    power of every armature, Σ_j a_j q̈_j q̇_j, though a profiled knee's joints turn at rates
    that vary with its flexion; the circles' keep ``Layout.rotor_inertia`` exactly."""
    from validate.scene.layout import Layout
    from validate.scene.mapping import rotor_torques

    q, qd, qdd = random_state(biped_model, seed=4, n=8, spread=0.5)
    layout = Layout(model)
    mapped = mapping(model, "left", biped_model.radii)
    torques = rotor_torques(mapped, layout, q, qd, qdd)
    qvel, qacc = mapped.qvel(q, qd), mapped.qacc(q, qd, qdd)
    power = (model.dof_armature * qacc * qvel).sum(-1)
    joints = layout.joint_angles(qvel)
    np.testing.assert_allclose((torques * joints).sum(-1), power, rtol=1e-12, atol=1e-12)
    circles = scene_model(ROBOT, "rolling")
    flat = mapping(circles, "left", (ROBOT.r1, ROBOT.r2))
    circle_layout = Layout(circles)
    expected = circle_layout.rotor_inertia * circle_layout.joint_angles(flat.qacc(q, qd, qdd))
    assert np.array_equal(rotor_torques(flat, circle_layout, q, qd, qdd), expected)


def test_the_stretchs_armature_never_enters_the_knees_motion(model, biped_model):
    """The stretch tendon's armature (``STRETCH_ARMATURE``) is an inertia of a length that
    is zero, with its rate and acceleration, on the rolling motion: MuJoCo's inertial forces
    M q̈ at mapped states are those without it to rounding (1e-13 N of 300 N measured); an
    acceleration off the motion, a slide's 1 m/s² alone, meets it in full."""
    from validate.scene.profile_mjcf import STRETCH_ARMATURE

    bare = mujoco.MjModel.from_xml_string(robot_xml(PROFILED, "rolling"))
    bare.tendon_armature[:] = 0.0
    heavy = mujoco.MjModel.from_xml_string(robot_xml(PROFILED, "rolling"))
    assert STRETCH_ARMATURE > 0.0 and heavy.tendon_armature.max() == STRETCH_ARMATURE
    q, qd, qdd = random_state(biped_model, seed=5, n=6, spread=0.4)
    mapped = mapping(heavy, "left", biped_model.radii)
    slide = heavy.joint("left_knee_slide").dofadr[0]

    def inertial(m, k, extra=0.0):  # M q̈ [N, N·m] at state k, the slide accelerated by extra
        data = mujoco.MjData(m)
        data.qpos[:] = mapped.qpos(q[k])
        mujoco.mj_forward(m, data)
        qacc = mapped.qacc(q[k], qd[k], qdd[k])
        qacc[slide] += extra
        out = np.zeros(m.nv)
        mujoco.mj_mulM(m, data, out, qacc)
        return out

    for k in range(len(q)):
        on_motion = inertial(heavy, k) - inertial(bare, k)
        assert np.abs(on_motion).max() < 1e-12 * np.abs(inertial(bare, k)).max()
        off_motion = inertial(heavy, k, 1.0) - inertial(bare, k, 1.0)
        assert off_motion[slide] == pytest.approx(STRETCH_ARMATURE, rel=1e-9)


def test_the_walks_equality_figures_are_mujocos_residuals(model, biped_model):
    """The walk's equality figures are MuJoCo's own residuals, each in its unit: zero on
    mapped states, and a knee slide moved by 5 µm off the rolling motion shows as 5 µm of
    the profiled knee's length equalities (MuJoCo's efc_pos says the same), not as radians."""
    from types import SimpleNamespace

    from validate.checks.checks import knee_equality_violations

    q, _, _ = random_state(biped_model, seed=2, n=4, spread=0.4)
    mapped = mapping(model, "left", biped_model.radii)
    qpos = np.array([mapped.qpos(state) for state in q])
    exact = knee_equality_violations(SimpleNamespace(model=model, qpos=qpos))
    assert exact["max_knee_equality_violation"] < 1e-13
    assert exact["max_knee_length_violation"] < 1e-13
    moved = qpos.copy()
    moved[:, model.jnt_qposadr[model.joint("left_knee_slide").id]] += 5e-6
    figures = knee_equality_violations(SimpleNamespace(model=model, qpos=moved))
    assert figures["max_knee_length_violation"] == pytest.approx(5e-6, rel=1e-6)
    assert figures["max_knee_equality_violation"] < 1e-13
    data = mujoco.MjData(model)
    data.qpos[:] = moved[0]
    mujoco.mj_forward(model, data)
    equality = data.efc_type[: data.nefc] == mujoco.mjtConstraint.mjCNSTR_EQUALITY
    assert np.abs(data.efc_pos[: data.nefc][equality]).max() == pytest.approx(5e-6, rel=1e-6)
