"""Forward simulation in MuJoCo: an optimal gait's first step is played as planned."""

import numpy as np
import pytest

from tests.conftest import small_optimum
from validate.simulate import joint_matrix, simulate


@pytest.mark.parametrize("knee", ["revolute", "rolling"])
def test_first_step_lands_as_planned(knee):
    """Feedforward torques plus feedback reproduce the planned step in MuJoCo with contact:
    joint errors stay under 0.01 rad, the swing foot lands within 10 % of the period, the
    stance foot moves less than 2 mm."""
    from biped import Biped, Robot

    optimum = small_optimum(knee)
    model = Biped(Robot.paper(), knee)
    sim = simulate(model, optimum.step, steps=2)
    first, second = sim.step_starts[0], sim.step_starts[1]
    assert sim.landed[0] and sim.warnings == 0
    errors = sim.ctrl[first:second, 6:12] - sim.qpos[first:second] @ joint_matrix(sim.model).T
    assert np.abs(errors).max() < 0.01
    duration = sim.time[second - 1] - sim.time[first] + sim.model.opt.timestep
    assert duration == pytest.approx(optimum.step.period, rel=0.1)
    ankle = sim.sensor("left_ankle_pos")[first:second, 0]
    assert np.ptp(ankle) < 2e-3
