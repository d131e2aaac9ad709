"""The optimiser: deterministic, feasible optima have zero penalty, bad input rejected."""

import numpy as np
import pytest

import biped
from biped.criteria import Safety
from biped.optimize import cost, initial_parameters, max_walking_speed, optimize

ROBOT = biped.Robot.paper()
# A small budget: one Nelder-Mead run and a short polish, enough to reach a feasible gait.
SMALL = dict(max_restarts=0, evaluations_per_run=400, polish_iterations=30)


@pytest.fixture(scope="module")
def optima():
    """One small optimisation per knee at 0.3 m/s, from the default first guess only."""
    result = {}
    for knee in biped.KNEES:
        model = biped.Biped(ROBOT, knee)
        result[knee] = optimize(
            model, 0.3, "sthenic", starts=initial_parameters(model, 0.3), **SMALL
        )
    return result


@pytest.mark.parametrize("knee", biped.KNEES)
def test_feasible_optimum_has_zero_penalty(optima, knee):
    """The optimum holds every constraint on the fine grid, so its penalty is zero."""
    optimum = optima[knee]
    assert optimum.feasible
    assert optimum.evaluation.penalty == 0.0
    assert np.nanmin(optimum.evaluation.constraints) >= 0.0
    assert optimum.value == optimum.evaluation.sthenic
    assert len(optimum.evaluation.t) >= 200


@pytest.mark.parametrize("knee", biped.KNEES)
def test_optimum_improves_on_the_first_guess(optima, knee):
    """The optimum's criterion is below that of the first guess."""
    model = biped.Biped(ROBOT, knee)
    first = cost(model, 0.3, "sthenic", initial_parameters(model, 0.3), 40)
    assert optima[knee].value < first


def test_optimizer_is_deterministic(optima):
    """The same seed and budget give the same parameters, bit for bit."""
    model = biped.Biped(ROBOT, "rolling")
    again = optimize(model, 0.3, "sthenic", starts=initial_parameters(model, 0.3), **SMALL)
    np.testing.assert_array_equal(again.parameters, optima["rolling"].parameters)


@pytest.mark.parametrize(
    "speed, criterion, needle",
    [
        (0.0, "sthenic", "speed = 0.0"),
        (-0.1, "sthenic", "allowed 0 < speed"),
        (float("nan"), "sthenic", "speed = nan"),
        (5.0, "sthenic", "stance foot leaves the ground"),
        (0.3, "power", "criterion = 'power'"),
    ],
)
def test_bad_input_is_rejected(speed, criterion, needle):
    """Bad speeds and criteria raise a clear error naming the value."""
    model = biped.Biped(ROBOT, "revolute")
    with pytest.raises(biped.BipedError, match=needle):
        optimize(model, speed, criterion)
    assert 2.5 < max_walking_speed(model) < 3.0


def test_clearance_is_kept_by_the_optimum():
    """With a required clearance the optimal swing foot stays that high away from the ends,
    and the gait costs more than without it (the constraint is active)."""
    from biped.criteria import clearance_profile

    model = biped.Biped(ROBOT, "rolling")
    optimum = optimize(model, 0.3, "sthenic", safety=Safety(clearance=0.02))
    assert optimum.feasible and optimum.safety.clearance == 0.02
    feet = model.points(optimum.evaluation.q, ["swing_heel", "swing_toe"])[..., 1]
    required = clearance_profile(100, 0.02)
    assert np.all(feet[1:-1] >= required[1:-1, None] - 1e-12)
    assert required.max() == pytest.approx(0.02)
    free = optimize(model, 0.3, "sthenic")
    assert optimum.value > free.value


def test_bad_safety_margins_are_rejected():
    """A negative or huge clearance or ZMP margin is a clear error."""
    for bad in (-0.01, 1.0, float("nan")):
        with pytest.raises(biped.BipedError, match="clearance"):
            Safety(clearance=bad)
    with pytest.raises(biped.BipedError, match="zmp_margin"):
        Safety(zmp_margin=0.2)
