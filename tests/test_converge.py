"""Nested gait families climbed (``biped.optimization.ladder``) and the comparison over them
(``biped.studies.converge``, ``biped converge``): the ladder is monotone, the convergence rule
stops where a sequence of known limit has settled and not before, bad input exits 2."""

import json
import math

import numpy as np
import pytest

import biped
from biped.optimization.ladder import MONOTONE_TOLERANCE, climb
from biped.optimization.optimize import BELOW_START, PAPER_START
from biped.optimization.problem import GaitProblem
from biped.studies.converge import (
    KneeRung,
    RungRecord,
    convergence,
    sentence,
    settled,
)
from biped_cli import main


@pytest.fixture(scope="module")
def rungs():
    """The rolling knee's sthenic optima at 0.3 m/s on the ladder 1, 3, 7."""
    problem = GaitProblem(biped.Biped(biped.Robot.paper(), "rolling"), 0.3)
    return climb(problem, (1, 3, 7), starts=1)


def test_the_ladder_is_monotone_and_certified(rungs):
    """Each rung certified, started from the rung below's optimum, and no worse than it on
    its own grid (1e-9 relative); the embedded gait's cost is the rung below's within the
    quadrature's error (the same to round-off from K = 1 to 3, whose check grids coincide)."""
    assert [r.knots for r in rungs] == [1, 3, 7]
    assert all(r.certified for r in rungs)
    for below, rung in zip(rungs, rungs[1:], strict=False):
        kinds = [s.kind for s in rung.optimum.report.history]
        assert (PAPER_START if below.knots == 1 else BELOW_START) in kinds
        assert rung.monotone and rung.value <= rung.start_value * (1 + MONOTONE_TOLERANCE)
        assert rung.start_value == pytest.approx(below.value, rel=1e-5)
        assert rung.value < below.value  # a richer family walks with less torque here
    assert rungs[1].start_value == pytest.approx(rungs[0].value, rel=1e-13)


def _synthetic(values, errors) -> list:
    """Rung records of both knees with ``values`` and relative ``errors`` [%] each, the
    difference between them (rolling 2 % below) with its error bar."""
    records = []
    for k, (value, error) in enumerate(zip(values, errors, strict=True)):
        knees = {
            knee: KneeRung(value * scale, error, None, True, "converged", True, None, 0.0, 0.0, 0.0)
            for knee, scale in (("revolute", 1.0), ("rolling", 0.98))
        }
        records.append(RungRecord(2 ** (k + 1) - 1, 21 + 24 * k, knees, -2.0, 0.01))
    return records


def test_the_rule_stops_where_a_sequence_of_known_limit_has_settled():
    """v_k = 10 (1 + 2^(-5k)): the change from rung k − 1 is 31 x 10 x 2^(-5k), below an
    error bar of 0.01 % (1e-3 absolute) from k = 4 on (9.5e-3 at k = 3); the limit 10 is
    within the error bar there."""
    values = [10.0 * (1.0 + 2.0 ** (-5 * k)) for k in range(6)]
    errors = [0.01 * v / 100 for v in values]  # [value's unit]
    at = settled(values, errors)
    assert at == 4
    assert abs(values[at] - 10.0) <= errors[at]
    records = _synthetic(values, [0.01] * 6)
    verdict = convergence(records)
    assert verdict.converged_at == 31 and verdict.stops_improving == {"revolute": 31, "rolling": 31}
    said = sentence(records, verdict, "N²·m·s")
    assert said[-1].startswith("Converged at K = 31 (117 parameters)")
    assert "by -2.00 % ± 0.01 %" in said[-1] and len(said) == 7


def test_the_rule_does_not_stop_before_a_sequence_has_settled():
    """v_k = 10 (1 + 1/(k + 1)), whose steps stay far above the error bar, never settles; an
    unknown error bar never lets a sequence settle."""
    values = [10.0 * (1.0 + 1.0 / (k + 1)) for k in range(6)]
    assert settled(values, [1e-3] * 6) is None
    assert settled([1.0, 1.0, 1.0], [None, None, None]) is None
    records = _synthetic(values, [0.01] * 6)
    assert convergence(records).converged_at is None
    assert sentence(records, convergence(records), "N²·m·s")[-1].startswith("Not converged")
    flat = _synthetic([10.0] * 3, [0.01] * 3)
    moving = [
        RungRecord(r.knots, r.parameters, r.knees, -2.0 - 0.5 * i, 0.01) for i, r in enumerate(flat)
    ]
    assert convergence(moving).converged_at is None  # the optima settle, the difference not
    assert convergence(flat).converged_at == 3


@pytest.mark.parametrize(
    "argv, needle",
    [
        (["--ladder", "3,5"], "do not include"),
        (["--ladder", "3,1"], "increasing"),
        (["--ladder", "1,x"], "not integers"),
        (["--ladder", "1,64"], "from 1 to 31"),
        (["--family", "bezier", "--ladder", "7,5"], "increasing degrees"),
        (["--family", "bezier", "--ladder", "2,5"], "degree = 2: allowed an integer from 3"),
        (["--family", "cartesian"], "'cartesian'"),
        (["--speed", "-1"], "speed"),
        (["--starts", "0"], "'0'"),
        (["--clearance", "2"], "clearance"),
    ],
)
def test_bad_input_is_one_line_and_exit_2(capsys, tmp_path, argv, needle):
    full = ["converge", "--speed", "0.3", "--out", str(tmp_path), *argv]
    assert main(full) == 2
    captured = capsys.readouterr()
    lines = captured.err.strip().splitlines()
    assert len(lines) == 1 and needle in lines[0] and "Traceback" not in captured.err


def test_converge_writes_its_record_figure_and_sentence(capsys, tmp_path):
    """On the ladder 1, 3: both rungs certified, the JSON's every number with its unit, the
    figure, the sentence naming the difference and each rung's time."""
    assert main(["converge", "--speed", "0.3", "--ladder", "1,3", "--out", str(tmp_path)]) == 0
    out = capsys.readouterr().out
    content = json.loads((tmp_path / "converge.json").read_text())
    assert (tmp_path / "converge.png").stat().st_size > 10_000
    from biped.model.units import is_unit, missing

    assert missing(content, content["units"]) == []
    assert all(is_unit(unit) for unit in content["units"].values())
    rungs = content["rungs"]
    assert [r["knots"] for r in rungs] == [1, 3] and [r["parameters"] for r in rungs] == [21, 45]
    for r in rungs:
        for rung in r["knees"].values():
            assert rung["certified"] and rung["monotone"] and rung["seconds"] > 0
    assert rungs[1]["knees"]["rolling"]["value"] < rungs[0]["knees"]["rolling"]["value"]
    assert math.isclose(
        rungs[0]["difference"],
        100 * (rungs[0]["knees"]["rolling"]["value"] / rungs[0]["knees"]["revolute"]["value"] - 1),
    )
    assert "K = 3 (45 parameters)" in out and "difference" in out.splitlines()[-1]
    assert np.isfinite(rungs[1]["difference_error"])


def test_converge_climbs_bezier_degrees(capsys, tmp_path):
    """With --family bezier the ladder is of degrees: each rung certified and no worse than
    the one below (its curve raised), the JSON naming each family {"bezier": n} with its
    unit, the sentence naming the degree."""
    argv = ["converge", "--speed", "0.3", "--family", "bezier", "--ladder", "5,7"]
    assert main([*argv, "--out", str(tmp_path)]) == 0
    out = capsys.readouterr().out
    content = json.loads((tmp_path / "converge.json").read_text())
    from biped.model.units import missing

    assert missing(content, content["units"]) == []
    rungs = content["rungs"]
    assert [r["knots"] for r in rungs] == [{"bezier": 5}, {"bezier": 7}]
    assert [r["parameters"] for r in rungs] == [21, 33]
    for knee in ("revolute", "rolling"):
        low, high = (r["knees"][knee] for r in rungs)
        assert low["certified"] and high["certified"] and high["monotone"]
        assert high["value"] <= high["start_value"] * (1 + 1e-9)
    assert "n = 7 (33 parameters)" in out
