"""Two atlases in two gait families compared cell by cell: a shift beyond both error bars is
a pay-off the base family hides (lower in the rich one) or invents (higher); within them the
same; an error bar not measured leaves the cell unknown, never the same; atlases of two
problems, of one family, without a common cell or criterion are refused (exit 2)."""

import json

import pytest

import biped
from biped.model.bezier import Bezier
from biped.model.kinematics import KNEES
from biped.pages import atlas_families as pages
from biped.studies import atlas
from biped.studies.atlas_families import Side, compare_atlases, verdict
from biped_cli import main
from tests.test_atlas import stage_record

ROBOT = biped.Robot.paper()


def test_a_shift_beyond_both_error_bars_is_a_hidden_or_invented_pay_off():
    """The paper's −0.59 % ± 0.04 beside a rich −6.07 % ± 0.01: the base family hides a
    pay-off (shift −5.48 points); −3 % beside +1 % (each told apart from 0): it invents
    one, and the families disagree on which knee needs less."""
    found, shift, flip = verdict(Side(-0.59, 0.04), Side(-6.07, 0.01))
    assert found == "hides" and shift == pytest.approx(-5.48) and not flip
    found, shift, flip = verdict(Side(-3.0, 0.1), Side(1.0, 0.1))
    assert found == "invents" and shift == pytest.approx(4.0) and flip


def test_a_shift_within_both_error_bars_is_the_same_not_within_one():
    """A shift of 0.5 points with error bars of 0.3 each is within their sum (the same):
    judged by either bar alone it would be a hidden pay-off."""
    found, shift, flip = verdict(Side(-1.0, 0.3), Side(-1.5, 0.3))
    assert found == "same" and shift == pytest.approx(-0.5) and not flip
    assert abs(shift) > 0.3  # beyond each bar alone


def test_an_unknown_error_bar_leaves_the_cell_unknown_never_the_same():
    """An error bar not measured (a re-solve that did not converge) keeps the cell unknown,
    however small or large the shift; a cell without a difference is unknown too."""
    for base, rich in (
        (Side(-1.0, None), Side(-1.0, 0.01)),
        (Side(-0.5, 0.04), Side(-6.0, None)),
        (Side(None, None, "rolling INFEASIBLE"), Side(-6.0, 0.01)),
    ):
        found, _, _ = verdict(base, rich)
        assert found == "unknown"
    assert verdict(Side(-0.5, 0.04), Side(-6.0, None))[1] == pytest.approx(-5.5)


def test_signs_change_only_where_both_differences_are_told_apart():
    """Opposite signs within an error bar are no sign change."""
    assert not verdict(Side(-0.01, 0.05), Side(3.0, 0.1))[2]
    assert verdict(Side(-0.5, 0.05), Side(3.0, 0.1))[2]


def _atlas(folder, family, cells: dict) -> atlas.Settings:
    """A made-up atlas of one clearance: {speed: (final, fine, tight) (revolute, rolling)
    sthenic values}, a tight value None for a re-solve that stopped at IPOPT's acceptable
    level."""
    speeds = tuple(cells)
    settings = atlas.Settings(ROBOT, speeds, (0.0,), (0.0,), ("sthenic",), family, 0, 1)
    atlas.ATLAS.claim(folder, settings, *atlas.STAGES)
    for cell in settings.cells():
        for stage, values in zip(("final", "fine", "tight"), cells[cell.speed], strict=True):
            for knee, value in zip(KNEES, values, strict=True):
                content = stage_record(100.0, "Solved_To_Acceptable_Level")
                if value is not None:
                    content = stage_record(value)
                path = folder / atlas.Point(stage, knee, "sthenic", cell).filename()
                path.write_text(content.to_json())
    return settings


# Three speeds: a pay-off the paper's spline hides (0.2), one it invents (0.3), one the same
# (0.4); and a tighter re-solve not converged in the rich atlas (0.5).
PAPER = {
    0.2: ((100.0, 99.0), (100.0, 99.0), (100.0, 99.0)),
    0.3: ((100.0, 97.0), (100.0, 97.0), (100.0, 97.0)),
    0.4: ((100.0, 99.0), (100.0, 99.01), (100.0, 99.0)),
    0.5: ((100.0, 99.0), (100.0, 99.0), (100.0, 99.0)),
}
RICH = {
    0.2: ((50.0, 46.0), (50.0, 46.0), (50.0, 46.0)),
    0.3: ((50.0, 50.5), (50.0, 50.5), (50.0, 50.5)),
    0.4: ((50.0, 49.5), (50.0, 49.5), (50.0, 49.5)),
    0.5: ((50.0, 46.0), (50.0, 46.0), (None, 46.0)),
}


def _walk(folder, speed: float, knee: str, passed: bool) -> None:
    """A made-up walk record of a knee's final sthenic optimum (the forward walk alone)."""
    cell = atlas.Cell(speed, 0.0, 0.0)
    path = folder / atlas.Point(atlas.WALKS, knee, "sthenic", cell).filename()
    path.parent.mkdir(parents=True, exist_ok=True)
    check = {"passed": passed, "cause": "" if passed else "slipped", "notes": []}
    content = {"format": atlas.WALK_FORMAT, "every_check": False, "figures": {}}
    path.write_text(json.dumps({**content, "checks": {"forward": check}}))


@pytest.fixture
def pair(tmp_path):
    """The two atlases; at 0.2 m/s the rich one's gaits walked, the rolling knee's not
    walking; the base one's not walked."""
    base, rich = tmp_path / "paper", tmp_path / "rich"
    _atlas(base, 1, PAPER)
    _atlas(rich, Bezier(11), RICH)
    _walk(rich, 0.2, "revolute", True)
    _walk(rich, 0.2, "rolling", False)
    return base, rich


def test_two_atlases_compare_cell_by_cell(pair):
    """Each cell's verdict follows from both atlases' differences and error bars."""
    comparison = compare_atlases(*pair)
    verdicts = {s.cell.speed: s.verdict for s in comparison.shifts}
    assert verdicts == {0.2: "hides", 0.3: "invents", 0.4: "same", 0.5: "unknown"}
    (at_03,) = [s for s in comparison.shifts if s.cell.speed == 0.3]
    assert at_03.base.value == pytest.approx(-3.0) and at_03.rich.value == pytest.approx(1.0)
    assert at_03.sign_change
    (at_05,) = [s for s in comparison.shifts if s.cell.speed == 0.5]
    assert at_05.rich.uncertainty is None and "tighter tolerance" in at_05.rich.why
    counts = comparison.counts("sthenic")
    (at_02,) = [s for s in comparison.shifts if s.cell.speed == 0.2]
    assert at_02.rich.walks is False and at_02.base.walks is None
    assert counts == {
        "hides": 1, "invents": 1, "same": 1, "unknown": 1, "sign_changes": 1, "cells": 4
    }  # fmt: skip


def test_compare_atlas_writes_its_json_figure_and_page(pair, tmp_path, capsys):
    """`biped compare-atlas BASE RICH --out DIR`: families.json (units declared), the figure
    and families.md, a sentence per criterion on stdout; exit 1 while a cell is unknown."""
    out = tmp_path / "out"
    assert main(["compare-atlas", str(pair[0]), str(pair[1]), "--out", str(out)]) == 1
    printed = capsys.readouterr().out
    assert "hides a pay-off of the rolling knee in 1" in printed and "1 are unknown" in printed
    content = json.loads((out / "families.json").read_text())
    assert content["rich"]["family"] == {"bezier": 11} and content["base"]["family"] == 1
    assert content["units"]["cells[].shift"] == "percentage points"
    assert [c["verdict"] for c in content["cells"]] == ["hides", "invents", "same", "unknown"]
    assert (out / "families.png").read_bytes()[:4] == b"\x89PNG"
    page = (out / "families.md").read_text()
    assert "Bézier curves of degree 11 (57 parameters)" in page and "| unknown (" in page
    assert "| hides | not walked / no |" in page


def test_the_figure_shows_both_families_with_their_error_bars(pair):
    """Two series per panel (base and rich), an error bar where it is known, none where not,
    the verdict over each cell, the axis in percent."""
    fig = pages.figure(compare_atlases(*pair))
    (ax,) = fig.axes
    assert "[%]" in ax.get_ylabel()
    labels = [t.get_text() for t in ax.get_legend().get_texts()]
    assert labels[0].startswith("K = 1") and labels[1].startswith("n = 11")
    marks = [t.get_text() for t in ax.texts]
    assert {"hides", "invents\nsign flips", "=", "?", "±?"} <= set(marks)


def test_atlases_that_do_not_compare_are_refused(pair, tmp_path, capsys):
    """Two atlases of one family, of two problems, without a common cell, or a folder that
    is no atlas: one line on stderr naming it, exit 2, nothing written."""
    base, rich = pair
    same = tmp_path / "same"
    _atlas(same, 1, {0.2: PAPER[0.2]})
    apart = tmp_path / "apart"
    _atlas(apart, Bezier(11), {0.6: RICH[0.2]})
    out = tmp_path / "out"
    for args, named in (
        ([str(base), str(same)], "two gait families"),
        ([str(base), str(apart)], "no cell"),
        ([str(tmp_path / "nothing"), str(rich)], "no atlas there"),
    ):
        assert main(["compare-atlas", *args, "--out", str(out)]) == 2
        err = capsys.readouterr().err.strip().splitlines()
        assert len(err) == 1 and named in err[0], err
    other = tmp_path / "other"
    settings = _atlas(other, Bezier(11), RICH)
    record = json.loads((other / atlas.MANIFEST).read_text())
    record["criteria"] = ["energy-per-metre"]
    (other / atlas.MANIFEST).write_text(json.dumps(record))
    assert settings.criteria == ("sthenic",)
    assert main(["compare-atlas", str(base), str(other), "--out", str(out)]) == 2
    assert "allowed two atlases sharing a criterion" in capsys.readouterr().err
    record["criteria"] = ["sthenic"]
    record["safety"] = {**record["safety"], "friction": 0.9}
    (other / atlas.MANIFEST).write_text(json.dumps(record))
    assert main(["compare-atlas", str(base), str(other), "--out", str(out)]) == 2
    assert "safety" in capsys.readouterr().err
    assert not out.exists()


def test_only_the_criteria_of_both_atlases_are_compared(tmp_path):
    """A rich atlas of one criterion beside a base of two: that criterion alone."""
    base, rich = tmp_path / "paper", tmp_path / "rich"
    settings = _atlas(base, 1, PAPER)
    record = json.loads((base / atlas.MANIFEST).read_text())
    record["criteria"] = ["energy-per-metre", "sthenic"]
    (base / atlas.MANIFEST).write_text(json.dumps(record))
    _atlas(rich, Bezier(11), RICH)
    comparison = compare_atlases(base, rich)
    assert comparison.criteria == ("sthenic",) and settings.criteria == ("sthenic",)
    assert len(comparison.shifts) == len(PAPER)
