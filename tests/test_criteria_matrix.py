"""Each criterion's optimum with every criterion measured on it (``biped.studies.criteria_matrix``,
``biped criteria``): each optimum is the least of its own criterion, which a wrong evaluation
breaks; an optimum beaten in its own criterion is started again from the one that beats it;
the record's codec round-trips with every number's unit; unknown figures stay unknown and
exit 1; bad input exits 2."""

import dataclasses
import json
import math

import pytest

import biped
from biped.optimization.optimize import AGREEMENT, checked
from biped.studies import criteria_matrix
from biped.studies.criteria_matrix import (
    FIELDS,
    STUDIED,
    CriteriaStudy,
    KneeMatrix,
    Values,
    braking_work,
    cross_started,
    electrical_without,
)
from biped_cli import main
from biped_cli.criteria import _verdict


@pytest.fixture(scope="module")
def run(tmp_path_factory):
    """``biped criteria --speed 0.3 --starts 1`` (the paper's spline and constraints): its
    exit status, printed lines, folder, and each knee's optima (``KneeOptima``) as
    ``optimize_criteria`` returned them."""
    out = tmp_path_factory.mktemp("criteria")
    solved = []
    real = criteria_matrix.optimize_criteria

    def kept(*args, **kwargs):
        solved.append(real(*args, **kwargs))
        return solved[-1]

    with pytest.MonkeyPatch.context() as patch:
        patch.setattr(criteria_matrix, "optimize_criteria", kept)
        status = main(["criteria", "--speed", "0.3", "--starts", "1", "--jobs", "2",
                       "--out", str(out)])  # fmt: skip
    study = CriteriaStudy.from_dict(json.loads((out / "criteria.json").read_text()))
    return {
        "status": status,
        "folder": out,
        "study": study,
        "optima": dict(zip(biped.KNEES, solved, strict=True)),
    }


def test_each_optimum_is_the_least_of_its_own_criterion(run):
    """On each knee every optimum is certified and no other criterion's optimum is lower in
    its criterion (within AGREEMENT, relative): the diagonal is the least of its column."""
    assert run["status"] == 0
    for matrix in run["study"].knees:
        assert matrix.certified and matrix.diagonal_least() is True
        for measured in STUDIED:
            own = matrix.value(measured, measured)
            column = [matrix.value(optimized, measured) for optimized in STUDIED]
            assert min(column) >= own * (1 - AGREEMENT), (matrix.knee, measured, column)


def test_a_wrong_evaluation_breaks_the_diagonal(run):
    """Each criterion measured and filed under the next one's name (sthenic under
    energy-per-metre, ...): the optima are no longer the least of what their columns say."""
    for matrix in run["study"].knees:
        shifted = dict(zip(STUDIED, STUDIED[1:] + STUDIED[:1], strict=True))
        rows = []
        for row in matrix.rows:
            wrong = {FIELDS[shifted[c]]: row.values.of(c) for c in STUDIED}
            rows.append(dataclasses.replace(row, values=Values(**wrong)))
        wrong_matrix = KneeMatrix(matrix.knee, tuple(rows))
        assert wrong_matrix.diagonal_least() is False and wrong_matrix.exceptions()


def test_costs_and_differences_are_relative_to_the_own_optimum(run):
    """The cost of optimizing a for b is M[a][b] / M[b][b] − 1; the knees' difference is
    rolling / revolute − 1 in the same cell; both as written in the JSON."""
    study = run["study"]
    content = json.loads((run["folder"] / "criteria.json").read_text())
    for matrix, written in zip(study.knees, content["knees"], strict=True):
        for a in STUDIED:
            for b in STUDIED:
                if a != b:
                    expected = 100 * (matrix.value(a, b) / matrix.value(b, b) - 1)
                    assert math.isclose(matrix.cost(a, b), expected, rel_tol=1e-12)
                    assert written["costs"][a][b] == matrix.cost(a, b)
    revolute, rolling = study.knees
    for a in STUDIED:
        for b in STUDIED:
            expected = 100 * (rolling.value(a, b) / revolute.value(a, b) - 1)
            assert math.isclose(study.difference(a, b), expected, rel_tol=1e-12)
            assert content["differences"][a][b] == study.difference(a, b)


def test_the_record_round_trips_with_every_unit(run):
    """criteria.json read back is the study, written again the same JSON; every number has a
    unit; the figure and the page are written, the page with each knee's table."""
    from biped.model.units import is_unit, missing

    content = json.loads((run["folder"] / "criteria.json").read_text())
    study = CriteriaStudy.from_dict(content)
    assert json.loads(json.dumps(study.to_dict())) == content
    assert missing(content, content["units"]) == []
    assert all(is_unit(unit) for unit in content["units"].values())
    assert content["family"] == 1 and content["parameters"] == 21
    assert (run["folder"] / "criteria.png").stat().st_size > 10_000
    page = (run["folder"] / "criteria.md").read_text()
    assert "## revolute knee" in page and "## rolling knee" in page
    assert "| optimum of | sthenic [N²·m·s] | energy-per-metre [J/m] | electrical [J/m]" in page


def test_an_optimum_beaten_in_its_own_criterion_is_started_again(run):
    """The sthenic optimum replaced by the electrical optimum's gait (far more torque): the
    energy-per-metre optimum is lower in sthenic, so sthenic is solved again from it and
    reaches the sthenic optimum's value; none other is started again."""
    found = run["optima"]["revolute"]
    optima = dict(found.optima)
    sthenic = optima["sthenic"]
    electrical = optima["electrical"]
    optima["sthenic"] = checked(sthenic.problem, electrical.variables, electrical.report)
    assert optima["sthenic"].value > 2 * sthenic.value
    again = cross_started(optima)
    assert again.restarted == {"sthenic": "energy-per-metre"}
    assert again.optima["sthenic"].certified
    assert again.optima["sthenic"].value == pytest.approx(sthenic.value, rel=1e-5)


@pytest.mark.parametrize(
    "removed, kept",
    [
        (criteria_matrix.FRICTION, {"viscous_friction": 0.0, "coulomb_friction": 0.0}),
        (criteria_matrix.ROTORS, {"rotor_inertia": 0.0}),
    ],
)
def test_the_energy_without_a_part_is_that_of_drives_without_it(run, removed, kept):
    """The sthenic optimum's gait on drives without friction (or without rotor inertia): its
    electrical energy is what ``electrical_without`` gives on the real drives, and there
    without the part itself; the part costs energy here. Braking work is (|work| − net
    work) / 2 per metre, never negative."""
    optimum = run["optima"]["revolute"].optima["sthenic"]
    length = optimum.step.step_length
    robot = biped.Robot.from_mapping({"actuator": kept})
    problem = dataclasses.replace(optimum.problem, model=biped.Biped(robot, "revolute"))
    free = checked(problem, optimum.variables, optimum.report)
    energy_free = free.evaluation.value("electrical", length)
    assert electrical_without(optimum, removed) == pytest.approx(energy_free, rel=1e-12)
    assert electrical_without(free, removed) == pytest.approx(energy_free, rel=1e-12)
    assert energy_free < optimum.evaluation.value("electrical", length)
    ev = optimum.evaluation
    net = ev.weights @ (ev.torques * ev.joint_rates).sum(-1)
    assert braking_work(optimum) == pytest.approx((ev.energy - net) / (2 * length), rel=1e-9)
    assert braking_work(optimum) >= 0.0


def test_an_optimum_not_certified_leaves_its_figures_unknown_and_exits_1(run, capsys):
    """A row not certified: its costs and the knees' differences in its row are None (null
    in the JSON, never 0), the diagonal's verdict unknown, and the command's verdict 1."""
    study = run["study"]
    revolute = study.knees[0]
    rows = (dataclasses.replace(revolute.rows[0], certified=False, status="Maximum_Iterations"),)
    broken = dataclasses.replace(
        study, knees=(KneeMatrix("revolute", rows + revolute.rows[1:]), study.knees[1])
    )
    matrix = broken.knees[0]
    assert matrix.cost("sthenic", "electrical") is None
    assert matrix.cost("electrical", "sthenic") is None  # against an unknown own optimum
    assert matrix.diagonal_least() is None
    assert broken.difference("sthenic", "sthenic") is None
    content = broken.to_dict()
    assert content["knees"][0]["costs"]["sthenic"]["electrical"] is None
    assert "diagonal_least" not in content["knees"][0]
    assert CriteriaStudy.from_dict(json.loads(json.dumps(content))) == broken
    assert _verdict(broken) == 1
    err = capsys.readouterr().err
    assert "NOT CERTIFIED: revolute sthenic (Maximum_Iterations)" in err


@pytest.mark.parametrize(
    "argv, needle",
    [
        (["--family", "bezier"], "--family bezier without --degree"),
        (["--degree", "11"], "--degree 11 with --family spline"),
        (["--family", "bezier", "--degree", "2"], "--degree"),
        (["--family", "bezier", "--degree", "11", "--knots", "3"], "--knots 3 with --family"),
        (["--knots", "0"], "--knots"),
        (["--speed", "-1"], "speed"),
        (["--starts", "0"], "'0'"),
        (["--clearance", "2"], "clearance"),
        (["--criterion", "sthenic"], "unrecognized arguments: --criterion"),
    ],
)
def test_bad_input_is_one_line_and_exit_2(capsys, tmp_path, argv, needle):
    full = ["criteria", "--speed", "0.3", "--out", str(tmp_path), *argv]
    assert main(full) == 2
    captured = capsys.readouterr()
    lines = captured.err.strip().splitlines()
    assert len(lines) == 1 and needle in lines[0] and "Traceback" not in captured.err
