"""Forward simulation in MuJoCo with contact: the optimal gaits walk, and a walk with wrong
torques is told apart from one with the gait's."""

import numpy as np
import pytest

from biped import Biped, Robot
from tests.conftest import optimal_gait, small_optimum
from validate.report import MAX_SLIP, ZMP_AGREEMENT, forward_figures
from validate.simulate import FALLEN, RESYNC, joint_matrix, simulate

STEPS = 20


@pytest.fixture(scope="module", params=["revolute", "rolling"])
def walk(request):
    """Both robots' optimal gaits at 0.3 m/s walked for 20 steps, with their figures."""
    knee = request.param
    optimum = optimal_gait(knee)
    model = Biped(Robot.paper(), knee)
    sim = simulate(model, optimum.step, steps=STEPS)
    return model, optimum, sim, forward_figures(model, optimum.step, sim, optimum.costs()["energy"])


def test_optimal_gait_walks_twenty_steps_without_slip_or_fall(walk):
    """Every step lands on time with the hip and trunk held, the stance foot does not slide
    (< 1 mm on the ground while it carries the robot), no MuJoCo warning."""
    _, _, sim, figures = walk
    assert figures["steps"] == STEPS and all(sim.landed) and len(sim.landed) == STEPS
    assert not figures["fell"]
    assert figures["max_slip"] < MAX_SLIP
    assert figures["warnings"] == 0
    # The robot covers the gait's distance: 20 steps of S = V T.
    _, optimum, _, _ = walk
    assert figures["distance"] == pytest.approx(STEPS * optimum.step.step_length, rel=0.05)


def test_walk_follows_the_gait(walk):
    """Away from the landings the centre of pressure lies on the gait's ZMP, the ground force
    is the gait's, and the joints follow their references to a few milliradians."""
    _, _, sim, figures = walk
    assert figures["zmp_in_foot"]
    assert figures["zmp_relative_error"] < ZMP_AGREEMENT
    assert figures["zmp_rms_error"] < 0.5e-3  # [m]
    assert figures["ground_force_rms_error"] < 0.01  # fraction of the weight
    first, second = sim.step_starts[0], sim.step_starts[1]
    errors = sim.ctrl[first:second, 6:12] - sim.qpos[first:second] @ joint_matrix(sim.model).T
    assert np.abs(errors).max() < 0.005


def test_rolling_knee_equality_holds_in_the_walk(walk):
    """The joint equality of the rolling knee holds to a milliradian over the whole walk."""
    model, _, _, figures = walk
    if model.knee == "rolling":
        assert figures["max_knee_equality_violation"] < 1e-3
    else:
        assert "max_knee_equality_violation" not in figures


@pytest.mark.parametrize("scale", [0.0, 0.5, 1.5, 2.0])
def test_wrong_torques_are_detected(scale):
    """With no, half, 1.5 times or twice the gait's feedforward torques the feedback still
    carries the robot a while, but it does not walk the gait: its centre of pressure leaves
    the gait's ZMP, or it falls."""
    optimum = optimal_gait("rolling")
    model = Biped(Robot.paper(), "rolling")
    steps = 8
    sim = simulate(model, optimum.step, steps=steps, feedforward=scale)
    figures = forward_figures(model, optimum.step, sim, optimum.costs()["energy"])
    assert figures["zmp_relative_error"] > ZMP_AGREEMENT or figures["steps"] < steps


def test_fall_ends_the_simulation():
    """Without feedforward and feedback the robot collapses: the simulation stops once the
    hip has dropped by a quarter, in the first step, and the report says fell."""
    optimum = small_optimum("revolute")
    model = Biped(Robot.paper(), "revolute")
    sim = simulate(model, optimum.step, steps=3, kp=0.0, kv=0.0, feedforward=0.0)
    assert sim.landed == [False]
    start_height = optimum.step.start[0][-1]
    assert sim.qpos[-1, 1] == pytest.approx(FALLEN * start_height, abs=0.01)
    figures = forward_figures(model, optimum.step, sim, optimum.costs()["energy"])
    assert figures["fell"] and figures["steps"] == 0


def test_phase_follows_the_hip():
    """The controller's phase is the gait's time at the hip's advance over the stance ankle:
    0 at the start of the walk, through the whole step by its touchdown, and moving back
    only by what a 10 ms reading of the state corrects (the hip's speed changes in between)."""
    optimum = small_optimum("rolling")
    model = Biped(Robot.paper(), "rolling")
    sim = simulate(model, optimum.step, steps=1)
    assert sim.landed == [True]
    assert sim.phase[0] == pytest.approx(0.0, abs=1e-9)
    assert sim.phase[-1] > 0.9 * optimum.step.period
    assert np.diff(sim.phase).min() > -RESYNC


@pytest.mark.parametrize("knee", ["revolute", "rolling"])
def test_walk_spends_the_gait_energy(knee):
    """For a gait whose motors work (a small-budget optimum, about 4 N·m RMS), the energy
    MuJoCo's actuators spend per step, feedback and landings included, is the gait's
    energy criterion to a few per cent."""
    optimum = small_optimum(knee)
    model = Biped(Robot.paper(), knee)
    sim = simulate(model, optimum.step, steps=4)
    figures = forward_figures(model, optimum.step, sim, optimum.costs()["energy"])
    assert figures["steps"] == 4
    assert figures["feedforward_rms"] > 3.0
    assert figures["energy_per_step"] == pytest.approx(optimum.costs()["energy"], rel=0.05)


def test_simulation_is_deterministic():
    """The same gait simulated twice gives the same states, bit for bit."""
    optimum = small_optimum("rolling")
    model = Biped(Robot.paper(), "rolling")
    first, second = (simulate(model, optimum.step, steps=2) for _ in range(2))
    assert np.array_equal(first.qpos, second.qpos) and np.array_equal(first.ctrl, second.ctrl)
