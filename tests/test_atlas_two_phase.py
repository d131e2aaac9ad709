"""An atlas with double support: at every built cell each knee's two-phase optimum (or a named
failure) beside the atlas's single-support one, the cells not built listed with why, what the
phase does to the rolling knee's pay-off said by its sign, a resume that runs nothing, bad
combinations refused before any work, the summary's file read back to the same record."""

import json

import pytest

import biped
from biped.model.criteria import PAPER_SAFETY, WALKABLE
from biped.model.units import is_unit, missing
from biped.records.atlas_two_phase import AtlasTwoPhaseSummary, CellDifference, CellPoint, NotBuilt
from biped.records.gait_file import Gait
from biped.records.two_phase_sweep import KneeDifference, Phases, PointSummary
from biped.studies import atlas
from biped.studies import atlas_two_phase as study
from biped_cli import main
from tests.conftest import exit_status

SPEED = 0.3  # [m/s]
CLEARANCES = (0.0, 0.02)  # [m]
RUN_CLEARANCES = (0.02,)  # [m] the run's one cell: its margins, not the base's, reach the gait
TINY = ["atlas", "--speeds", str(SPEED), "--clearances", "0.02", "--criteria", "sthenic",
        "--starts", "1", "--no-walks", "--paper-constraints", "--jobs", "1"]  # fmt: skip
DOUBLE = ["--double-support", "0.1:0.2", "--landing", "zero-speed"]


def _summary() -> AtlasTwoPhaseSummary:
    """Two cells: one whose rolling knee's two-phase optimum is unknown; a cell not built."""
    one = Phases(30.36, 0.0, 0.178, 101.0)
    rows = (
        CellPoint(0.0, 0.0, PointSummary("revolute", 0.3, one, Phases(1078.5, 0.1, 0.165, 109.3))),
        CellPoint(0.0, 0.0, PointSummary("rolling", 0.3, one, None, "NOT CONVERGED: x")),
    )
    differences = (CellDifference(0.0, 0.0, KneeDifference(0.3, -0.59, None)),)
    gone = (NotBuilt("energy", 0.3, 0.0, 0.0, "double support is not built for criterion"),)
    return AtlasTwoPhaseSummary((0.1, 0.2), "zero-speed", rows, differences, gone)


def test_the_summarys_file_reads_back_to_the_same_record(tmp_path):
    """Written and read, the same record; every number has a unit; an unknown optimum and
    difference stay unknown (null), never zero; the cell not built is in the table."""
    summary = _summary()
    path = summary.write(tmp_path / "summary.json")
    assert AtlasTwoPhaseSummary.read(path) == summary
    content = json.loads(path.read_text())
    assert missing(content, content["units"]) == []
    assert all(is_unit(u) or u == "steps/min" for u in content["units"].values())
    assert set(content["points"][1]["point"]["double"].values()) == {None}
    assert content["differences"][0]["difference"]["double"] is None
    assert summary.missing() == [summary.points[1]]
    assert "not built (double support is not built for criterion)" in summary.table()
    assert "unknown" in summary.differences[0].line()


@pytest.mark.parametrize(
    "single, double, said",
    [
        (-12.6, 8.0, "CHANGES THE SIGN: the rolling knee pays off in single support"),
        (3.0, -1.0, "CHANGES THE SIGN: the rolling knee costs more in single support"),
        (-0.6, -4.5, "pay-off larger"),
        (-3.4, -1.0, "pay-off smaller"),
        (2.0, 5.0, "extra cost larger"),
    ],
)
def test_what_double_support_does_follows_the_signs(single, double, said):
    """A sign changed is said as such; else the size, larger or smaller, of the pay-off
    (negative: the rolling knee needs less) or of the extra cost."""
    cell = CellDifference(0.02, 0.0, KneeDifference(0.2, single, double))
    assert said in cell.change()


def test_the_cells_not_built_are_named_with_the_problems_refusal():
    """An atlas of two criteria under the paper's constraints builds its sthenic cells only;
    each other criterion's cell is listed with why. Under the walkable constraints none is
    built, and the settings are refused naming why."""
    cells = dict(speeds=(0.3,), clearances=CLEARANCES, knee_bends=(0.0,), knots=1, seed=0)
    both = ("sthenic", "energy-per-metre")
    paper = atlas.Settings(
        biped.Robot.paper(), criteria=both, starts=1, safety=PAPER_SAFETY, **cells
    )
    ours = study.of_atlas(paper, (0.1, 0.2), "zero-speed")
    assert study.built_cells(paper, ours) == paper.cells()
    gone = study.not_built(paper, ours)
    assert [(n.criterion, n.clearance) for n in gone] == [
        ("energy-per-metre", c) for c in CLEARANCES
    ]
    assert all("criterion = 'energy-per-metre'" in n.why for n in gone)
    walkable = atlas.Settings(
        biped.Robot.paper(), criteria=both, starts=1, safety=WALKABLE, **cells
    )
    with pytest.raises(Exception, match="walkable constraints"):
        study.of_atlas(walkable, (0.1, 0.2), "zero-speed")


@pytest.mark.parametrize(
    "bad, named",
    [
        (["--double-support", "0.6"], "0.6"),
        (["--criteria", "energy"], "--criteria energy"),
        (["--walkable"], "--paper-constraints"),
        (["--actuator-limits"], "--actuator-limits"),
        (["--knots", "3"], "--knots 3"),
        (["--landing", "soft"], "soft"),
    ],
)
def test_what_does_not_combine_is_refused_with_exit_2_before_any_work(tmp_path, capsys, bad, named):
    """No cell that can take double support (another criterion alone, the walkable
    constraints, actuator limits, another gait family), a share out of [0, 0.5), an unknown
    landing: one line naming the value, exit 2, nothing written."""
    out = tmp_path / "out"
    argv = [*TINY, *DOUBLE, "--out", str(out)]
    if bad == ["--walkable"]:
        argv.remove("--paper-constraints")
    else:
        option = bad[0]
        argv = (
            argv[: argv.index(option)] + argv[argv.index(option) + 2 :] if option in argv else argv
        )
        argv += bad
    assert exit_status(argv) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and named in err[0], err
    assert not out.exists()


@pytest.fixture(scope="module")
def tiny(tmp_path_factory):
    """One speed, one clearance, one start: the atlas, then its two-phase optima."""
    folder = tmp_path_factory.mktemp("ds-atlas")
    status = main([*TINY, *DOUBLE, "--out", str(folder)])
    return folder, status


def test_every_cell_has_both_knees_two_phase_optimum_or_a_named_failure(tiny):
    """Every cell and knee: a file in ``double-support/``, a two-phase gait whose share lies in
    the range, whose step length is V (T + T_ds) and cadence 60 / (T + T_ds), its figures
    the summary's; or a failure record naming why, which the summary repeats and the exit
    status counts (1)."""
    folder, status = tiny
    summary = AtlasTwoPhaseSummary.read(folder / study.FOLDER / study.SUMMARY)
    assert summary.share_range == (0.1, 0.2) and summary.landing == "zero-speed"
    assert summary.not_built == ()
    found = {(p.clearance, p.point.knee) for p in summary.points}
    assert found == {(c, k) for c in RUN_CLEARANCES for k in ("revolute", "rolling")}
    for row in summary.points:
        cell = atlas.Cell(SPEED, row.clearance, 0.0)
        path = folder / study.FOLDER / study.Point(row.point.knee, cell).filename()
        assert path.exists()
        if row.point.double is None:
            assert row.point.why and row.point.why in path.read_text()
            assert status == 1
            continue
        gait = Gait.read(path, two_phase=True)
        step = gait.period + gait.double_support.duration
        assert 0.1 - 1e-8 <= row.point.double.share <= 0.2 + 1e-8
        assert row.point.double.step_length == pytest.approx(SPEED * step, rel=1e-9)
        assert row.point.double.cadence == pytest.approx(60.0 / step, rel=1e-12)
        assert row.point.double.sthenic == gait.double_support.sthenic
        assert gait.safety.clearance == row.clearance  # the cell's margins, not the base's
        single = Gait.read(folder / study.Point(row.point.knee, cell).single().gait_filename())
        assert row.point.single.sthenic == single.costs.sthenic
    assert {d.clearance for d in summary.differences} == set(RUN_CLEARANCES)
    assert (folder / study.FOLDER / study.FIGURE).stat().st_size > 10_000


def test_a_resume_runs_nothing_and_writes_the_same_summary(tiny, capsys):
    """Run again with the same settings: no optimization, the same summary's bytes."""
    folder, status = tiny
    before = (folder / study.FOLDER / study.SUMMARY).read_bytes()
    capsys.readouterr()
    assert main([*TINY, *DOUBLE, "--out", str(folder)]) == status
    out, err = capsys.readouterr()
    assert "0 to run" in err and "[two phases]" not in err + out
    assert (folder / study.FOLDER / study.SUMMARY).read_bytes() == before


def test_a_resume_with_another_landing_is_refused_writing_nothing(tiny, capsys):
    """Another landing on the folder: one line naming it, exit 2, nothing written."""
    folder, _ = tiny
    before = {p: p.read_bytes() for p in sorted(folder.rglob("*")) if p.is_file()}
    capsys.readouterr()
    argv = [*TINY, "--double-support", "0.1:0.2", "--landing", "impact", "--out", str(folder)]
    assert main(argv) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "landing" in err[0], err
    assert {p: p.read_bytes() for p in sorted(folder.rglob("*")) if p.is_file()} == before


def test_a_run_stopped_before_a_point_redoes_that_point_alone_to_the_same_optimum(tiny, capsys):
    """A point's file gone (a run stopped before it was written): the next run solves that
    point alone, to the same optimum (its parameters, double support, costs and samples, bit
    for bit; only the solver's wall time differs) and the same summary."""
    folder, status = tiny
    path = folder / study.FOLDER / study.Point("rolling", atlas.Cell(SPEED, 0.02, 0.0)).filename()
    summary = folder / study.FOLDER / study.SUMMARY
    before, summary_before = json.loads(path.read_text()), summary.read_bytes()
    path.unlink()
    capsys.readouterr()
    assert main([*TINY, *DOUBLE, "--out", str(folder)]) == status
    out, err = capsys.readouterr()
    assert "1 already done, 1 to run" in err
    assert (err + out).count("[two phases]") == 1
    after = json.loads(path.read_text())
    for key in ("parameters", "double_support", "costs", "samples"):
        assert after[key] == before[key], key
    assert summary.read_bytes() == summary_before
