"""The words and the sign of comparisons (``biped.optimization.comparison``): one sign for a difference
between knees, the two values of a gait file's criterion named for what they are, and
"certified" said of a sweep's final optima only."""

import math
from types import SimpleNamespace

import pytest

from biped.optimization.comparison import (
    CHECK_SAMPLES_PER_STEP,
    CHECKED_VALUE,
    SOLVER_SAMPLES_PER_STEP,
    SOLVER_VALUE,
    relative_change,
)
from biped.optimization.problem import SOLVER_SAMPLES
from biped.records.gait_file import Gait
from biped.studies.sweep import Point, _line


def test_a_difference_is_negative_where_the_first_needs_less():
    """relative_change is (value − reference) / reference in %, and nothing to print
    (NaN) where a value is missing or the reference is zero."""
    assert relative_change(0.93, 1.0) == pytest.approx(-7.0)
    assert relative_change(1.071, 1.0) == pytest.approx(7.1)
    assert math.isnan(relative_change(1.0, 0.0)) and math.isnan(relative_change(math.nan, 1.0))


def test_the_two_values_of_a_criterion_are_named_for_what_they_are():
    """A gait file's optimizer.value (the criterion on the solver's samples, which ranks the
    starts) and its costs (on the check grid, which the comparisons use) carry the
    criterion's unit alone; what each is, the optimizer's record says in words; the grids
    are the solver's and the check's."""
    import inspect

    from biped.optimization import report

    assert (SOLVER_SAMPLES_PER_STEP, CHECK_SAMPLES_PER_STEP) == (52, 202)
    for criterion, unit in (("sthenic", "N²·m·s"), ("energy", "J")):
        units = Gait.units(criterion)
        assert units[f"costs.{criterion}"] == unit
        assert units["optimizer.value"] == units["optimizer.history[].value"] == unit
    source = inspect.getsource(report.Report)
    assert "SOLVER_VALUE; costs.<criterion> of a gait file is CHECKED_VALUE" in source
    assert "ranks the starts" in SOLVER_VALUE and "comparisons use" in CHECKED_VALUE


def _optimum(converged=True, feasible=True, value=27.77, solver_value=27.78, knots=1):
    report = SimpleNamespace(
        method="ipopt",
        converged=converged,
        status="converged" if converged else "Maximum_Iterations_Exceeded",
        starts_at_best=3,
        starts=3,
        seconds=1.0,
        value=solver_value,
    )
    evaluation = SimpleNamespace(sthenic=value, energy=1.25, electrical=0.9)
    step = SimpleNamespace(period=0.6, step_length=0.18)
    problem = SimpleNamespace(knots=knots, samples_per_half=SOLVER_SAMPLES[knots])
    return SimpleNamespace(
        report=report,
        feasible=feasible,
        value=value,
        evaluation=evaluation,
        step=step,
        problem=problem,
    )


def test_the_optimize_lines_name_both_values_of_the_criterion():
    """biped optimize prints the costs as the check grid's, what the comparisons use, and
    optimizer.value as the solver's samples', what ranks the starts, each with its unit."""
    from biped_cli.commands import optimum_line

    text = optimum_line("rolling", "sthenic", 0.3, _optimum())
    costs, solver = text.splitlines()[1:]
    assert "check grid (202 samples per step" in costs and "comparisons use" in costs
    assert "sthenic 27.77 N²·m·s, energy 1.25 J, electrical 5 J/m (no regeneration)" in costs
    assert "optimizer.value" in solver and "52 per step" in solver
    assert "ranks the starts" in solver and "sthenic 27.78 N²·m·s" in solver
    assert (
        len(optimum_line("rolling", "sthenic", 0.3, _optimum(solver_value=math.nan)).splitlines())
        == 2
    )
    # a richer family's grids: 16 pieces of 27 and of 7 samples
    richer = optimum_line("rolling", "sthenic", 0.3, _optimum(knots=15))
    assert "check grid (432 samples per step" in richer and "(112 per step" in richer


def test_only_a_final_optimum_is_called_certified():
    """A sweep's line says 'certified' only of a final, converged, feasible optimum; a
    stage-1 line says what it is, and every line gives the criterion's unit and grid."""
    point = Point("revolute", "sthenic", 0.175)
    stage1 = _line("independent", point, _optimum())
    final = _line("final", point, _optimum())
    assert "certified" not in stage1.lower() and "stage 1/2" in stage1 and "not final" in stage1
    assert "certified;" in final and "stage 2/2" in final
    for line in (stage1, final):
        assert "27.770000 N²·m·s" in line and "check grid" in line
    failed = _line("final", point, _optimum(feasible=False))
    assert "NOT CERTIFIED, INFEASIBLE" in failed
    energy = _line("independent", Point("rolling", "energy", 0.3), _optimum(converged=False))
    assert " J " in energy and "NOT CONVERGED: Maximum_Iterations_Exceeded" in energy
