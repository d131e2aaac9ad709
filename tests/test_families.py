"""Richer gait families (3 and 5 interior knots): they hold the paper's spline, the graph is
the numeric model, and their optima are never worse than the paper's spline's."""

import numpy as np
import pytest

import biped
from biped.model.criteria import PAPER_SAFETY, Safety, evaluate_step
from biped.model.gait import (
    KNOTS,
    build_step,
    check_knots,
    embedded,
    evaluate,
    parameter_names,
)
from biped.optimization.optimize import CHECK_SAMPLES, PAPER_START, optimize
from biped.optimization.problem import GaitProblem, scales, variable_names
from biped.optimization.symbolic import StepGraph
from tests.conftest import optimal_gait

ROBOT = biped.Robot.paper()


def test_the_families_are_named_and_others_refused():
    assert KNOTS == (1, 3, 5)
    assert len(parameter_names(1)) == 21
    assert [len(parameter_names(k)) for k in (3, 5)] == [45, 69]
    assert len(variable_names(3)) == len(scales(3)) == 45
    for bad in (2, 0, True, "3"):
        with pytest.raises(biped.BipedError, match="knots = .*allowed 1, 3, 5"):
            check_knots(bad)


@pytest.mark.parametrize("knots", [3, 5])
def test_a_richer_family_holds_the_papers_spline(knots):
    """The paper's optimal spline, its knots' angles and rates given to the richer family,
    is the same motion: angles, rates and accelerations equal to 1e-12 on every piece."""
    optimum = optimal_gait("rolling")
    problem = optimum.problem
    step = optimum.step
    rich = build_step(
        problem.model,
        problem.speed,
        np.concatenate([optimum.parameters[:8], embedded(step, knots).ravel(), [step.period]]),
        knots,
    )
    for piece in range(knots + 1):
        t = np.linspace(piece, piece + 1, 7) / (knots + 1)
        paper = evaluate(step, t, 0 if t[-1] <= 0.5 else 1)
        for found, expected in zip(evaluate(rich, t, piece), paper, strict=True):
            np.testing.assert_allclose(found, expected, rtol=0, atol=1e-12 * np.abs(expected).max())
    assert np.allclose(rich.start[1], step.start[1]) and np.allclose(rich.impulse, step.impulse)


def test_a_family_without_the_papers_knot_does_not_hold_it():
    from biped.model.gait import check_embedding

    with pytest.raises(biped.BipedError, match="do not include"):
        check_embedding(3, 5)  # 0.25 is no knot of the 5-knot family


@pytest.mark.parametrize("knee", biped.KNEES)
def test_richer_graph_equals_the_numeric_model(knee):
    """The CasADi graph of a 3-knot gait gives the numeric model's torques, constraints and
    criteria to 1e-12 at random variables."""
    robot = (
        biped.Robot.paper()
        if knee == "revolute"
        else biped.Robot(**{**ROBOT.to_dict(), "r1": 0.03, "r2": 0.08})
    )
    safety = Safety(clearance=0.02)
    problem = GaitProblem(biped.Biped(robot, knee), 0.3, safety=safety, knots=3)
    function = StepGraph(problem.model, problem.samples_per_half, safety, knots=3).function()
    rng = np.random.default_rng(5)
    z = problem.first_guess() + 0.3 * scales(3) * rng.standard_normal(45)
    z[:2] = rng.uniform(0.05, 0.3, 2)
    out = function(z=z, speed=problem.speed)
    step = build_step(problem.model, problem.speed, problem.to_parameters(z), 3)
    ev = evaluate_step(problem.model, step, problem.samples_per_half, safety=safety)
    checked = ~np.isnan(ev.constraints)
    for found, expected in (
        (out["torques"].full().T, ev.torques),
        (out["psi"].full().T[checked], ev.constraints[checked]),
        (float(out["sthenic"]), ev.sthenic),
        (float(out["energy"]), ev.energy),
    ):
        scale = np.max(np.abs(expected))
        np.testing.assert_allclose(found, expected, rtol=1e-12, atol=1e-12 * scale)


@pytest.mark.parametrize("speed", [0.2, 0.3, 0.4])
def test_a_richer_familys_optimum_is_never_worse(speed):
    """With 3 knots the sthenic optimum is at most the paper's spline's (on the check grid,
    whose samples are the same for both), at several speeds; it starts from it too."""
    model = biped.Biped(ROBOT, "revolute")
    paper = optimize(GaitProblem(model, speed))
    rich = optimize(GaitProblem(model, speed, knots=3))
    assert paper.certified and rich.certified
    assert PAPER_START in [s.kind for s in rich.report.history]
    assert rich.evaluation.sthenic <= paper.evaluation.sthenic * (1 + 1e-9)
    assert CHECK_SAMPLES[3] * 4 == CHECK_SAMPLES[1] * 2  # the same check grid


def test_the_papers_method_is_for_the_papers_spline():
    problem = GaitProblem(biped.Biped(ROBOT, "revolute"), 0.3, knots=3)
    with pytest.raises(biped.BipedError, match="knots = 3 with the paper's Nelder-Mead"):
        optimize(problem, method="nelder-mead")
    assert PAPER_SAFETY == Safety()
