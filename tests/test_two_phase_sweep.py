"""A sweep with double support: each point's two-phase optimum beside its single-support one,
its summary's figures those of the gait files, a resume with other settings refused, bad
input refused before any work, the summary's file read back to the same record."""

import json

import pytest

from biped.model.units import is_unit, missing
from biped.records.gait_file import Gait
from biped.records.two_phase_sweep import (
    KneeDifference,
    Phases,
    PointSummary,
    TwoPhaseSweepSummary,
)
from biped.studies import two_phase_sweep as study
from biped.studies.two_phase_sweep import differences
from biped_cli import main
from tests.conftest import exit_status

SPEED = 0.3  # [m/s]
TINY = ["--speeds", str(SPEED), "--starts", "1", "--paper-seeds", "0", "--jobs", "1"]
DOUBLE = ["--double-support", "0.1:0.2", "--landing", "zero-speed"]


def _summary() -> TwoPhaseSweepSummary:
    """A summary with a point not certified (its two-phase optimum unknown)."""
    rows = (
        PointSummary(
            "revolute",
            0.3,
            Phases(30.36, 0.0, 0.178, 101.0, 79.98),
            Phases(1078.5, 0.1, 0.165, 109.3, 102.88),
        ),
        PointSummary(
            "rolling",
            0.3,
            Phases(30.18, 0.0, 0.178, 101.0, 80.69),
            Phases(1038.0, 0.1, 0.168, 107.1, 103.63),
        ),
        PointSummary("revolute", 0.4, Phases(59.5, 0.0, 0.2, 120.0), None, "NOT CONVERGED: x"),
        PointSummary("rolling", 0.4, Phases(59.0, 0.0, 0.2, 120.0), Phases(1.0, 0.2, 0.3, 80.0)),
    )
    return TwoPhaseSweepSummary((0.1, 0.2), "zero-speed", rows, differences(rows))


def test_the_summarys_file_reads_back_to_the_same_record(tmp_path):
    """Written and read, the summary is the same record, every number has a unit, and an
    unknown two-phase optimum stays unknown (null), never zero."""
    summary = _summary()
    path = summary.write(tmp_path / "summary.json")
    assert TwoPhaseSweepSummary.read(path) == summary
    content = json.loads(path.read_text())
    assert missing(content, content["units"]) == []
    assert all(is_unit(u) or u == "steps/min" for u in content["units"].values())
    assert set(content["points"][2]["double"].values()) == {None}
    assert content["differences"][1] == {
        "speed": 0.4,
        "single": pytest.approx(-0.8403, abs=1e-4),
        "double": None,
        "energy_single": None,  # neither knee's energy per metre known there
        "energy_double": None,
    }


def test_the_knees_difference_has_the_comparisons_sign():
    """(rolling − revolute) / revolute: negative where the rolling knee needs less, for C_Γ
    and for the same optima's energy per metre."""
    (at_03, _) = differences(_summary().points)
    assert at_03 == KneeDifference(
        0.3,
        pytest.approx(-0.5929, abs=1e-4),
        pytest.approx(-3.755, abs=1e-3),
        pytest.approx(100 * (80.69 / 79.98 - 1), abs=1e-9),
        pytest.approx(100 * (103.63 / 102.88 - 1), abs=1e-9),
    )


def test_a_file_of_another_kind_is_refused_naming_it(tmp_path):
    """A gait file is not a summary: refused by its format."""
    path = tmp_path / "summary.json"
    path.write_text(json.dumps({"format": "biped-gait/3"}))
    with pytest.raises(Exception, match="biped-gait/3"):
        TwoPhaseSweepSummary.read(path)


@pytest.mark.parametrize(
    "bad, named",
    [
        (["--double-support", "0.6"], "0.6"),
        (["--double-support", "0.1:0.2", "--criteria", "energy"], "--criteria energy"),
        (["--double-support", "0.1:0.2", "--criteria", "sthenic", "energy"], "allowed sthenic"),
        (["--double-support", "0.1", "--landing", "soft"], "soft"),
        (["--double-support", "0.1", "--knots", "2"], "knots"),
    ],
)
def test_bad_input_is_refused_with_exit_2_before_any_work(tmp_path, capsys, bad, named):
    """A share out of [0, 0.5), a criterion other than sthenic, an unknown landing, another
    gait family: one line naming the value, exit 2, nothing written."""
    out = tmp_path / "out"
    assert exit_status(["sweep", *TINY, *bad, "--out", str(out)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert named in err[-1], err
    assert not out.exists()


@pytest.fixture(scope="module")
def tiny(tmp_path_factory):
    """One speed, both knees, one start: the sweep, then its two-phase optima."""
    folder = tmp_path_factory.mktemp("ds-sweep")
    status = main(["sweep", *TINY, *DOUBLE, "--out", str(folder)])
    return folder, status


def test_a_tiny_sweep_with_double_support_has_both_optima_of_every_point(tiny):
    """Every point: a certified single-support file in the sweep, a two-phase file in
    ``double-support/`` whose share lies in the range, whose step length is V (T + T_ds) and
    whose cadence is 60 / (T + T_ds); the summary's figures are the files'."""
    folder, status = tiny
    assert status == 0
    summary = TwoPhaseSweepSummary.read(folder / study.FOLDER / study.SUMMARY)
    assert summary.share_range == (0.1, 0.2) and summary.landing == "zero-speed"
    assert {(p.knee, p.speed) for p in summary.points} == {("revolute", SPEED), ("rolling", SPEED)}
    for point in summary.points:
        gait = Gait.read(folder / study.FOLDER / f"{point.knee}-sthenic-0.300.json", two_phase=True)
        double = gait.double_support
        step = gait.period + double.duration
        # IPOPT holds the share's bounds T_ds − LOW (T + T_ds) >= 0 to its constraint
        # tolerance, 1e-9 s: a share off by 1e-9 / (T + T_ds) at most
        assert 0.1 - 1e-8 <= point.double.share <= 0.2 + 1e-8
        assert point.double.share == pytest.approx(double.duration / step, rel=1e-12)
        assert point.double.step_length == pytest.approx(SPEED * step, rel=1e-9)
        assert point.double.cadence == pytest.approx(60.0 / step, rel=1e-12)
        assert point.double.sthenic == double.sthenic
        single = Gait.read(folder / f"{point.knee}-sthenic-0.300.json")
        assert point.single.sthenic == single.costs.sthenic and point.single.share == 0.0
        assert point.single.step_length == pytest.approx(SPEED * single.period, rel=1e-9)
    (difference,) = summary.differences
    assert difference.single is not None and difference.double is not None
    assert (folder / study.FOLDER / study.FIGURE).stat().st_size > 10_000


def test_a_resume_runs_nothing_and_writes_the_same_summary(tiny, capsys):
    """Run again with the same settings: no optimization, the same summary's bytes."""
    folder, _ = tiny
    before = (folder / study.FOLDER / study.SUMMARY).read_bytes()
    capsys.readouterr()
    assert main(["sweep", *TINY, *DOUBLE, "--out", str(folder)]) == 0
    err = capsys.readouterr().err
    assert "0 to run" in err and "[two phases]" not in err
    assert (folder / study.FOLDER / study.SUMMARY).read_bytes() == before


@pytest.mark.parametrize(
    "other, named",
    [(["--landing", "impact"], "landing"), (["--double-support", "0.1:0.3"], "share")],
)
def test_a_resume_with_other_settings_is_refused_writing_nothing(tiny, capsys, other, named):
    """Another landing or share range on the folder: one line naming the setting, exit 2,
    nothing written (the sweep's own files untouched)."""
    folder, _ = tiny
    before = {p: p.read_bytes() for p in sorted(folder.rglob("*")) if p.is_file()}
    capsys.readouterr()
    args = [*DOUBLE]
    at = args.index(other[0])
    args[at + 1] = other[1]
    assert main(["sweep", *TINY, *args, "--out", str(folder)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and named in err[0], err
    assert {p: p.read_bytes() for p in sorted(folder.rglob("*")) if p.is_file()} == before


def test_a_point_without_its_single_support_optimum_is_unknown_not_zero(tmp_path):
    """No certified single-support optimum: the point's file says why, no solve is run, and
    the summary leaves both its figures and the knees' difference unknown (None)."""
    import biped
    from biped.model.criteria import PAPER_SAFETY
    from biped.studies.campaign import Task

    settings = study.Settings(biped.Robot.paper(), PAPER_SAFETY, (0.3,), 0, 1, (0.1, 0.2), "impact")
    folder = tmp_path / study.FOLDER
    folder.mkdir()
    point = study.Point("rolling", 0.3)
    line = study.solve_two_phase(Task(study.solve_two_phase, settings, point, str(folder)))
    assert "NO OPTIMUM: single support missing" in line
    summary = study.summarize(tmp_path, settings, [point, study.Point("revolute", 0.3)])
    rolling = summary.points[0]
    assert rolling.single is None and rolling.double is None
    assert rolling.why == "single support missing"
    assert summary.differences == (KneeDifference(0.3, None, None),)


SOLVE_ALONE = """
import sys
from pathlib import Path
import biped
from biped.model.criteria import PAPER_SAFETY
from biped.studies import two_phase_sweep as study
from biped.studies.campaign import Task
settings = study.Settings(
    biped.Robot.paper(), PAPER_SAFETY, (0.3,), 0, 1, (0.1, 0.2), "zero-speed"
)
point = study.Point("revolute", 0.3)
study.solve_two_phase(Task(study.solve_two_phase, settings, point, sys.argv[1]))
"""


def test_a_point_solved_in_a_fresh_process_is_the_same_bits(tiny, tmp_path):
    """A resumed run's process has solved no single support: its two-phase optimum is the
    same bits as the one solved after the sweep's (MUMPS on one thread in both)."""
    import os
    import shutil
    import subprocess
    import sys

    folder, _ = tiny
    name = "revolute-sthenic-0.300.json"
    shutil.copy(folder / name, tmp_path / name)
    (tmp_path / study.FOLDER).mkdir()
    env = {**os.environ, "PYTHONPATH": os.getcwd()}
    command = [sys.executable, "-c", SOLVE_ALONE, str(tmp_path / study.FOLDER)]
    subprocess.run(command, check=True, env=env, timeout=300)
    alone = json.loads((tmp_path / study.FOLDER / name).read_text())
    after = json.loads((folder / study.FOLDER / name).read_text())
    for key in ("parameters", "double_support", "costs", "samples"):
        assert alone[key] == after[key], key
