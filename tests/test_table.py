"""The table of optima that starts every optimization: the neighbours' optima, never the
point's own; the shipped table holds certified optima of its robot."""

import dataclasses
import json

import numpy as np
import pytest

import biped
from biped.model.criteria import PAPER_SAFETY, evaluate_step
from biped.model.gait import build_step
from biped.optimization import table
from biped.optimization.optimize import optimize
from biped.optimization.problem import CHECK_SAMPLES_PER_HALF, VARIABLES, GaitProblem

ROBOT = biped.Robot.paper()


def _write(path, series):
    content = table.content(series, ROBOT, PAPER_SAFETY, "a test")
    path.write_text(json.dumps(content))
    return path


@pytest.fixture
def small(tmp_path):
    """A table of three speeds whose optima are the numbers 1, 2, 3 (every variable)."""
    series = {
        ("rolling", "energy"): [(s, np.full(21, k + 1.0)) for k, s in enumerate((0.2, 0.3, 0.4))]
    }
    series[("revolute", "energy")] = [(0.3, np.full(21, 7.0))]
    return _write(tmp_path / "table.json", series)


def _problem(knee, speed, criterion="energy"):
    return GaitProblem(biped.Biped(ROBOT, knee), speed, criterion)


def test_a_tabled_speed_starts_from_its_neighbours_not_itself(small):
    """At a tabled speed the start is the mean of the two neighbours (2 at 0.3 m/s is left
    out); between speeds the interpolation; beyond them the nearest; another knee's optimum
    at the speed itself is the other-knee start."""
    assert np.allclose(table.start(_problem("rolling", 0.3), small), 2.0, rtol=1e-12)  # (1 + 3) / 2
    assert np.allclose(table.start(_problem("rolling", 0.25), small), 1.5)
    assert np.all(table.start(_problem("rolling", 0.2), small) == 2.0)  # itself left out: 0.3
    assert np.all(table.start(_problem("rolling", 0.5), small) == 3.0)
    assert np.all(table.other_knee_start(_problem("rolling", 0.3), small) == 7.0)
    assert np.all(table.other_knee_start(_problem("revolute", 0.3), small) == 2.0)
    assert table.start(_problem("revolute", 0.3), small) is None  # its only speed is its own
    assert table.start(_problem("rolling", 0.3, "sthenic"), small) is None


def test_a_file_that_is_no_table_is_named(tmp_path):
    path = tmp_path / "other.json"
    path.write_text(json.dumps({"format": "biped-gait/2"}))
    with pytest.raises(biped.BipedError, match="other.json: not a table of optima"):
        table.start(_problem("rolling", 0.3), path)


@pytest.mark.parametrize("knee", biped.KNEES)
def test_shipped_table_holds_certified_optima(knee):
    """Every optimum of the shipped table is feasible on the check grid for its robot, both
    criteria of each knee are there, and the campaigns can record its fingerprint."""
    content = json.loads(table.SHIPPED.read_text())
    assert content["variables"] == list(VARIABLES)
    robot = biped.Robot.from_mapping(content["robot"], source="robot")
    series = [s for s in content["series"] if s["knee"] == knee]
    assert {s["criterion"] for s in series} == {"sthenic", "energy"}
    for entry in series:
        for speed, variables in zip(entry["speeds"], entry["optima"], strict=True):
            problem = GaitProblem(biped.Biped(robot, knee), speed, entry["criterion"])
            step = build_step(problem.model, speed, problem.to_parameters(np.array(variables)))
            evaluation = evaluate_step(problem.model, step, CHECK_SAMPLES_PER_HALF)
            assert evaluation.feasible, (knee, entry["criterion"], speed)
    assert table.digest() == table.digest(table.SHIPPED) is not None


def test_optimization_starts_from_the_table():
    """The sthenic optimum at 0.3 m/s is reached from the table's start too (the optima at
    0.275 and 0.325 m/s interpolated); a solve from given starts alone (starts = 0, a
    sweep's second stage) takes none from the table."""
    problem = _problem("revolute", 0.3, "sthenic")
    optimum = optimize(problem)
    kinds = {s.kind: s for s in optimum.report.history}
    assert abs(kinds[table.TABLE_START].value / optimum.report.value - 1) < 1e-6
    again = optimize(problem, starts=0, given=[optimum.variables])
    assert [s.kind for s in again.report.history] == ["given"]


def test_the_table_covers_its_robot_safety_knee_criterion_and_speeds(small):
    """A table covers a problem of its robot's body, safety, knee and criterion between its
    speeds; another robot, a clearance, a knee bend, a speed beyond them, a series it lacks
    or a richer spline family are not covered."""
    from biped.model.criteria import Safety

    assert table.covers(_problem("rolling", 0.25), small)
    assert table.covers(_problem("rolling", 0.2), small) and table.covers(
        _problem("rolling", 0.4), small
    )
    assert not table.covers(_problem("rolling", 0.45), small)  # beyond its speeds
    assert not table.covers(_problem("revolute", 0.3), small)  # only its own speed
    from biped.model.actuators import Actuators

    driven = dataclasses.replace(ROBOT, actuators=Actuators.default())  # the same body
    assert table.covers(GaitProblem(biped.Biped(driven, "rolling"), 0.3, "energy"), small)
    coarse = GaitProblem(biped.Biped(ROBOT, "rolling"), 0.3, "energy", samples_per_half=8)
    assert not table.covers(coarse, small)
    assert not table.covers(_problem("rolling", 0.3, "sthenic"), small)  # no such series
    heavier = biped.Robot.from_mapping({**ROBOT.to_dict(), "trunk_mass": 40.0}, source="test")
    assert not table.covers(GaitProblem(biped.Biped(heavier, "rolling"), 0.3, "energy"), small)
    for safety in (Safety(clearance=0.02), Safety(zmp_margin=0.01), Safety(knee_bend=0.1)):
        model = biped.Biped(ROBOT, "rolling")
        assert not table.covers(GaitProblem(model, 0.3, "energy", safety), small)
    richer = GaitProblem(biped.Biped(ROBOT, "rolling"), 0.3, "energy", knots=3)
    assert not table.covers(richer, small)
    assert not table.covers(_problem("rolling", 0.3), small.parent / "missing.json")


def test_the_energy_criterion_replaces_its_first_guesses_by_the_table_where_it_covers():
    """Where the shipped table covers an energy problem its starts (the neighbours' optima,
    from mu = 1e-4 too; the other knee's, under the monotone barrier too) take the place of
    the default first guesses, and only the starts asked beyond the default are first
    guesses; beyond the table's speeds, or asked for by_table=False, all are solved."""
    from biped.optimization.optimize import (
        DEFAULT_STARTS,
        MONOTONE,
        NEAR,
        barriers_of,
        first_guesses,
        table_starts,
    )

    covered, beyond = _problem("revolute", 0.3), _problem("revolute", 0.6)
    assert table.covers(covered) and not table.covers(beyond)
    assert first_guesses(covered, DEFAULT_STARTS, 0) == []
    assert len(first_guesses(covered, DEFAULT_STARTS + 2, 0)) == 2
    assert len(first_guesses(beyond, DEFAULT_STARTS, 0)) == DEFAULT_STARTS
    assert len(first_guesses(covered, DEFAULT_STARTS, 0, by_table=False)) == DEFAULT_STARTS
    assert [start.kind for start in table_starts(covered, 1)] == [
        table.TABLE_START,
        table.TABLE_START + NEAR,
        table.OTHER_KNEE_START,
        table.OTHER_KNEE_START + MONOTONE,
        table.OTHER_KNEE_START + NEAR,
    ]
    assert [start.kind for start in table_starts(beyond, 1)] == [  # as before the table covered
        table.TABLE_START,
        table.TABLE_START + MONOTONE,
        table.OTHER_KNEE_START,
    ]
    sthenic = _problem("revolute", 0.3, "sthenic")
    assert [start.kind for start in table_starts(sthenic, 1)] == [
        table.TABLE_START,
        table.OTHER_KNEE_START,
    ]
    assert "near" in barriers_of(covered)
    assert "near" not in barriers_of(_problem("revolute", 0.3, "energy-per-metre"))


def test_biped_table_says_which_table_optimizations_read(tmp_path, monkeypatch, capsys):
    """`biped table --out FILE` says that optimizations read the installed package's table,
    naming its path, and not FILE; written there, it says that file starts them."""
    from biped.studies import sweep
    from biped_cli import main

    series = {("rolling", "energy"): [(0.3, np.full(21, 1.0))]}
    content = table.content(series, ROBOT, PAPER_SAFETY, "a test")
    monkeypatch.setattr(sweep, "optima_table", lambda folder: content)
    out = tmp_path / "optima.json"
    assert main(["table", "--out", str(out)]) == 0
    printed = capsys.readouterr().out
    assert f"optimizations read the package's table, {table.SHIPPED}, not this file" in printed
    monkeypatch.setattr(table, "SHIPPED", out)
    assert main(["table", "--out", str(out)]) == 0
    assert f"it is the package's table, {out}" in capsys.readouterr().out
    assert json.loads(out.read_text()) == content
