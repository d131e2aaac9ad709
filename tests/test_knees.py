"""The two knees' optima compared: each cost's difference with what moves it and a verdict,
a move that could not be measured unknown, never zero."""

import dataclasses

import pytest

from biped import Robot
from biped.model.criteria import PAPER_SAFETY
from biped.optimization import knees
from biped.optimization.comparison import relative_change
from biped.optimization.knees import compare_knees, knee_lines
from tests.conftest import optimal_gait


@pytest.fixture(scope="module")
def optima():
    """Both knees' sthenic optima at 0.3 m/s (the optimiser's defaults)."""
    return {knee: optimal_gait(knee) for knee in ("revolute", "rolling")}


def test_each_cost_says_what_it_compares_with_its_uncertainty_and_verdict(optima):
    """The criterion both optima minimise comes first, the costs neither minimises after;
    each difference is the check grid's, its uncertainty the sum of what moves it, and the
    verdict follows from both."""
    found = compare_knees(optima)
    assert [d.cost for d in found] == ["sthenic", "energy", "electrical"]
    assert [d.minimised for d in found] == [True, False, False]
    for difference in found:
        costs = {knee: optimum.costs()[difference.cost] for knee, optimum in optima.items()}
        assert difference.value == relative_change(costs["rolling"], costs["revolute"])
        moves = difference.moves.values()
        assert difference.uncertainty == pytest.approx(sum(abs(m) for m in moves))
        assert difference.moves["finer grid"] != 0.0  # the finer grid moves every cost
        verdict = difference.verdict()
        if abs(difference.value) > difference.uncertainty:
            assert verdict.endswith("needs less" if difference.value < 0 else "needs more")
        else:
            assert verdict.startswith("the knees are not distinguishable")
    lines = knee_lines(found, 0.3, "sthenic")
    assert "each knee's sthenic-optimal gait at 0.3 m/s" in lines[0]
    assert "which both minimise" in lines[1] and "which neither minimises" in lines[2]
    assert "energy criterion [J per step]" in lines[2] and "± " in lines[2]


def test_a_move_not_measured_is_unknown_never_zero(optima, monkeypatch):
    """A re-solve that does not converge, or a knee's optimum one start alone reached with
    no other start converged, leaves the uncertainty and the verdict unknown."""
    real = knees.refine

    def refine(problem, start, barrier="adaptive"):  # a re-solve that stops short
        optimum = real(problem, start, barrier)
        report = dataclasses.replace(optimum.report, status="Maximum_Iterations_Exceeded")
        return dataclasses.replace(optimum, report=report)

    monkeypatch.setattr(knees, "refine", refine)
    first = compare_knees(optima)[0]
    assert first.uncertainty is None and "Maximum_Iterations_Exceeded" in first.verdict()
    assert first.verdict().startswith("unknown") and "± unknown" in first.line()
    monkeypatch.setattr(knees, "refine", real)
    alone = dataclasses.replace(
        optima["rolling"],
        report=dataclasses.replace(optima["rolling"].report, starts_at_best=1, history=()),
    )
    found = compare_knees({**optima, "rolling": alone})
    assert found[0].moves["starts"] == "not known (rolling: no other start converged)"
    assert "reached by a single start" in found[1].moves["starts"]
    assert all(d.uncertainty is None and d.verdict().startswith("unknown") for d in found)


def test_the_pipeline_prints_the_knees_compared_with_their_verdict(optima, tmp_path, monkeypatch):
    """biped pipeline answers with each cost's difference, uncertainty and verdict, saying
    which criterion both gaits minimise."""
    from validate import workflows

    monkeypatch.setattr(workflows, "_optimum", lambda pipeline, knee, found, say: optima[knee])
    monkeypatch.setattr(workflows.Pipeline, "validated", lambda *args: ((), []))
    pipeline = workflows.Pipeline(
        Robot.paper(), 0.3, ("revolute", "rolling"), "sthenic", PAPER_SAFETY, 1, tmp_path,
        tmp_path, {}, video=False,
    )  # fmt: skip
    said = []
    assert workflows.run_pipeline(pipeline, said.append)
    [sthenic] = [line for line in said if "which both minimise" in line]
    assert sthenic.startswith("  sthenic criterion") and " ± " in sthenic
    assert sum("which neither minimises" in line for line in said) == 2
