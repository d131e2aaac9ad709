"""Richer gait families (K interior knots): they hold the paper's spline (odd K) and the
ladder's each the one below (1, 3, 7, 15), the graph is the numeric model, and their optima
are never worse than the paper's spline's."""

import dataclasses

import numpy as np
import pytest

import biped
from biped.model.criteria import PAPER_SAFETY, Safety, evaluate_step
from biped.model.gait import (
    KNOTS,
    MAX_KNOTS,
    build_step,
    check_knots,
    embedded,
    evaluate,
    ladder,
    parameter_names,
)
from biped.optimization.ladder import check_ladder
from biped.optimization.optimize import CHECK_SAMPLES, PAPER_START, optimize
from biped.optimization.problem import SCALES, SOLVER_SAMPLES, GaitProblem, scales, variable_names
from tests.conftest import assert_graph_is_the_model, optimal_gait

ROBOT = biped.Robot.paper()


def test_the_families_are_named_and_others_refused():
    assert KNOTS == tuple(range(1, MAX_KNOTS + 1)) and MAX_KNOTS >= 15
    assert len(parameter_names(1)) == 21
    assert [len(parameter_names(k)) for k in (2, 3, 5, 7, 15)] == [33, 45, 69, 93, 189]
    assert len(variable_names(15)) == len(scales(15)) == 189
    for bad in (0, MAX_KNOTS + 1, True, "3", 2.0):
        with pytest.raises(biped.BipedError, match="knots = .*allowed an integer from 1 to"):
            check_knots(bad)


def test_the_paper_and_small_families_keep_their_samples_and_scales():
    """K = 1, 3, 5 as before the families grew (the sweep's and the atlas's bits); richer
    families' pieces keep enough samples, an even number on the check grid."""
    assert [(SOLVER_SAMPLES[k], CHECK_SAMPLES[k]) for k in (1, 3, 5)] == [
        (25, 50 * 2),
        (13, 50),
        (9, 34),
    ]
    assert scales(1) is SCALES
    assert np.array_equal(scales(3)[:8], SCALES[:8]) and np.all(scales(3)[8:20:12] == 0.03)
    for k in KNOTS:
        assert SOLVER_SAMPLES[k] >= 6 and CHECK_SAMPLES[k] >= 26 and CHECK_SAMPLES[k] % 2 == 0
    assert np.all(scales(15) < scales(7)[:8].max())  # shrunk with the pieces


@pytest.mark.parametrize("below, above", [(1, 3), (3, 7), (7, 15), (1, 15)])
def test_a_ladder_rung_holds_the_one_below(below, above):
    """A gait of K knots (the paper's optimum, its knots' angles and rates perturbed) given
    to a family of more knots holding it is the same motion (angles, rates, accelerations to
    1e-12 on a fine grid) and the same costs where the check grids coincide, within the
    quadrature's error elsewhere."""
    optimum = optimal_gait("rolling")
    paper = optimum.problem
    low = dataclasses.replace(paper, knots=below, samples_per_half=None)
    z = low.embedded(optimum.variables) if below > 1 else optimum.variables
    if below > 1:  # a gait of its own family, not the paper's
        z = z + 0.05 * scales(below) * np.random.default_rng(below).standard_normal(z.size)
    high = dataclasses.replace(paper, knots=above, samples_per_half=None)
    step = build_step(paper.model, paper.speed, low.to_parameters(z), below)
    rich = build_step(paper.model, paper.speed, high.to_parameters(high.embedded(z, below)), above)
    t = np.linspace(0.0, 1.0, 641)
    for found, expected in zip(_motion(rich, t), _motion(step, t), strict=True):
        np.testing.assert_allclose(found, expected, rtol=0, atol=1e-12 * np.abs(expected).max())
    cost = {
        k: evaluate_step(paper.model, s, CHECK_SAMPLES[k]).sthenic
        for k, s in ((below, step), (above, rich))
    }
    on_rich_grid = evaluate_step(
        paper.model, step, CHECK_SAMPLES[above] * (above + 1) // (below + 1)
    )
    # the same instants and weights on the richer family's grid: round-off
    if (above + 1) * CHECK_SAMPLES[above] % ((below + 1) * CHECK_SAMPLES[below]) == 0:
        assert cost[above] == pytest.approx(on_rich_grid.sthenic, rel=1e-12)
    assert cost[above] == pytest.approx(cost[below], rel=1e-5)


def _motion(step, t):
    """Angles, rates and accelerations of ``step`` at the normalised times ``t``, each
    piece's own where two meet (the left one)."""
    ends = np.linspace(0.0, 1.0, step.knots + 2)
    pieces = np.clip(np.searchsorted(ends, t, side="left") - 1, 0, step.knots)
    rows = [evaluate(step, [time], int(piece)) for time, piece in zip(t, pieces, strict=True)]
    return tuple(np.concatenate([row[i] for row in rows]) for i in range(3))


def test_a_ladder_is_nested_or_refused():
    assert ladder(4) == (1, 3, 7, 15)
    assert check_ladder([1, 3, 7, 15]) == (1, 3, 7, 15)
    for bad, why in (([3, 1], "increasing"), ([1, 2], "do not include"), ([], "one family")):
        with pytest.raises(biped.BipedError, match=why):
            check_ladder(bad)


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
    assert_graph_is_the_model(problem, safety, 3, seed=5)


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
