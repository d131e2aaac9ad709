"""The analytical model against MuJoCo's dynamics of the MJCF: the same robot, to rounding."""

import numpy as np
import pytest

import biped
from tests.conftest import random_state, small_optimum
from validate.checks.crosscheck import knee_link_effect, load_model, mujoco_inverse_dynamics

ROBOT = biped.Robot.paper()


@pytest.mark.parametrize("stance", ["left", "right"])
def test_inverse_dynamics_agree_on_random_motions(model, stance):
    """Torques, ground wrench and ZMP agree with MuJoCo's to 1e-9 on random motions."""
    q, qd, qdd = random_state(model, seed=40, n=30)
    torques, wrench = model.inverse_dynamics(q, qd, qdd)
    result = mujoco_inverse_dynamics(load_model(model, exact=True), model, q, qd, qdd, stance)
    np.testing.assert_allclose(result.torques, torques, atol=1e-9)
    np.testing.assert_allclose(result.wrench, wrench, atol=1e-9)
    np.testing.assert_allclose(result.zmp, model.zmp(q, qd, qdd), atol=1e-12)


def test_inverse_dynamics_agree_on_an_optimal_gait(model):
    """Along a gait produced by the optimiser, MuJoCo reproduces Γ, F_e and the ZMP to 1e-6."""
    optimum = small_optimum(model.knee)
    assert optimum.feasible
    ev = optimum.evaluation
    result = mujoco_inverse_dynamics(load_model(model, exact=True), model, ev.q, ev.qd, ev.qdd)
    assert np.abs(result.torques - ev.torques).max() < 1e-6
    assert np.abs(result.wrench - ev.wrench).max() < 1e-6
    assert np.abs(result.zmp - ev.zmp).max() < 1e-6


def test_rolling_knee_couplings_carry_the_knee_load():
    """The equality forces of the rolling knee are not zero: the knee links are loaded."""
    model = biped.Biped(ROBOT, "rolling")
    q, qd, qdd = random_state(model, seed=41, n=10)
    result = mujoco_inverse_dynamics(load_model(model, exact=True), model, q, qd, qdd)
    assert np.abs(result.coupling).max() > 1.0


def test_knee_link_mass_is_negligible():
    """The MJCF's near-massless knee link changes the torques by less than 1e-4 N·m."""
    model = biped.Biped(ROBOT, "rolling")
    q, qd, qdd = random_state(model, seed=42, n=20)
    assert knee_link_effect(model, q, qd, qdd) < 1e-4


def test_impact_map_agrees_with_mujoco(model):
    """MuJoCo's mass matrix and landing-foot Jacobian give the same q̇⁺ and impulse (eq. 23-24)."""
    from tests.test_impact import touchdown_state
    from validate.checks.crosscheck import mujoco_impact
    from validate.scene.mapping import mapping

    q, qd = touchdown_state(model, seed=44, n=8)
    qd_plus, impulse = model.impact(q, qd)
    mj = load_model(model, exact=True)
    mapped = mapping(mj, "left", model.radii)
    for k in range(len(q)):
        mj_qd_plus, mj_impulse = mujoco_impact(mj, model, q[k], qd[k])
        np.testing.assert_allclose(mj_qd_plus, mapped.qpos(qd_plus[k]), atol=1e-9)
        np.testing.assert_allclose(mj_impulse, impulse[k], atol=1e-9)


@pytest.mark.parametrize("stance", ["left", "right"])
def test_knee_forces_agree_with_mujoco_on_random_motions(model, stance):
    """The force of the thigh on the lower leg through each knee is MuJoCo's (``cfrc_int`` of
    the body below the knee, the ground's force from its own inverse dynamics) to 1e-9 N, and
    so are its parts along and across the axes taken from MuJoCo's joints."""
    from biped.model.knee_loads import knee_forces
    from validate.checks.crosscheck import mujoco_knee_forces

    q, qd, qdd = random_state(model, seed=45, n=30)
    expected = knee_forces(model, q, qd, qdd)
    exact = load_model(model, exact=True)
    wrench = mujoco_inverse_dynamics(exact, model, q, qd, qdd, stance).wrench
    found = mujoco_knee_forces(exact, model, q, qd, qdd, wrench, stance)
    assert np.abs(expected.force).max() > 100.0
    np.testing.assert_allclose(found.force, expected.force, atol=1e-9)
    np.testing.assert_allclose(found.axis, expected.axis, atol=1e-12)
    np.testing.assert_allclose(found.normal, expected.normal, atol=1e-9)
    np.testing.assert_allclose(found.tangential, expected.tangential, atol=1e-9)


@pytest.mark.parametrize("stance", ["left", "right"])
def test_double_support_split_agrees_with_mujoco(model, stance):
    """Along a double support phase, with the front foot's wrench given (the least-squared
    split's, then one moved by 200 N), MuJoCo's Newton-Euler gives the model's six torques
    and the rear foot's wrench (``split_with_swing_wrench``) to 1e-8: both feet's forces
    cross-checked; a front wrench MuJoCo is not told of moves its answer by newtons."""
    from biped.model import double_support as ds
    from tests.test_two_phase import guess_step

    phase = guess_step(model, "impact").double
    time = np.linspace(0.0, phase.duration, 9)
    q, qd, qdd = ds.chain_state(model, phase.step_length, *ds.phase_coordinates(phase, time))
    _, _, least = ds.split_load(model, q, qd, qdd)
    exact = load_model(model, exact=True)
    for front in (least, least + np.array([40.0, -200.0, 3.0])):
        torques, rear = ds.split_with_swing_wrench(model, q, qd, qdd, front)
        result = mujoco_inverse_dynamics(exact, model, q, qd, qdd, stance, swing_wrench=front)
        np.testing.assert_allclose(result.torques, torques, atol=1e-8)
        np.testing.assert_allclose(result.wrench, rear, atol=1e-8)
    blind = mujoco_inverse_dynamics(exact, model, q, qd, qdd, stance, swing_wrench=0 * least)
    assert np.max(np.abs(blind.wrench[:, :2] - rear[:, :2])) > 100.0
