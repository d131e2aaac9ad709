"""The paper's Nelder-Mead over seeds, beside certified optima (``biped.studies.paper_method``)."""

from __future__ import annotations

import os

import pytest

import biped
from biped.errors import BipedError
from biped.studies.paper_method import (
    FOLDER,
    paper_settings,
    read_runs,
    run_paper_method,
    spread_lines,
)
from tests.conftest import optimal_gait

SEEDS = 2


@pytest.fixture(scope="module")
def runs(tmp_path_factory):
    folder = tmp_path_factory.mktemp("sweep")
    with open(folder.parent / "log.txt", "w") as stream:
        settings = paper_settings(biped.Robot.paper(), seeds=SEEDS)
        files = run_paper_method(folder, settings, criteria=("sthenic",), jobs=1, stream=stream)
    return folder, files


def test_every_run_line_gives_its_criterion_with_its_unit_and_grid(runs):
    """Each run's line gives its criterion with its unit, on the check grid with the
    penalty included (the paper's method may end infeasible)."""
    folder, _ = runs
    lines = [
        line for line in (folder.parent / "log.txt").read_text().splitlines() if "C = " in line
    ]
    assert len(lines) == 2 * SEEDS, lines
    assert all("N²·m·s on the check grid, penalty included" in line for line in lines), lines


def _certified():
    return {(knee, "sthenic"): {0.3: optimal_gait(knee).value} for knee in ("revolute", "rolling")}


def test_no_seed_of_the_paper_method_goes_below_the_certified_optimum(runs):
    """A method that stops early ends above a certified minimum, never below: a run below it
    would mean the certified optimum is not one (or the two evaluate different criteria)."""
    folder, _ = runs
    values, speed = read_runs(folder)
    assert speed == 0.3
    for knee in ("revolute", "rolling"):
        optimum = optimal_gait(knee).value
        assert len(values[(knee, "sthenic")]) == SEEDS
        assert min(values[(knee, "sthenic")]) > optimum
    # and the seeds do change the answer (the spread the comparison is about)
    assert len(set(values[("rolling", "sthenic")])) == SEEDS


def test_a_rerun_keeps_the_runs_and_other_settings_are_refused(runs):
    folder, files = runs
    before = {f: os.stat(f).st_mtime_ns for f in files}
    settings = paper_settings(biped.Robot.paper(), seeds=SEEDS)
    run_paper_method(folder, settings, criteria=("sthenic",), jobs=1, stream=None)
    assert {f: os.stat(f).st_mtime_ns for f in files} == before
    with pytest.raises(BipedError, match="seeds = 2"):
        more = paper_settings(biped.Robot.paper(), seeds=SEEDS + 1)
        run_paper_method(folder, more, jobs=1, stream=None)
    assert not list((folder / FOLDER).glob("*.tmp"))


def test_the_table_sets_each_seed_beside_the_certified_difference(runs):
    folder, _ = runs
    certified = _certified()
    text = "\n".join(spread_lines(folder, certified))
    true = certified[("rolling", "sthenic")][0.3] / certified[("revolute", "sthenic")][0.3] - 1
    assert f"certified optima {100 * true:+.1f} %" in text
    values, _ = read_runs(folder)
    for rolling, revolute in zip(
        values[("rolling", "sthenic")], values[("revolute", "sthenic")], strict=True
    ):
        assert f"{100 * (rolling / revolute - 1):+.1f} %" in text
    # The sentence on wrong winners appears only when a seed's sign differs from the truth:
    # with the knees' certified values swapped, every seed that agreed now disagrees.
    swapped = {
        ("revolute", "sthenic"): certified[("rolling", "sthenic")],
        ("rolling", "sthenic"): certified[("revolute", "sthenic")],
    }
    signs = [
        r < v
        for r, v in zip(
            values[("rolling", "sthenic")], values[("revolute", "sthenic")], strict=True
        )
    ]
    wrong_now = "report the wrong knee" in text
    wrong_swapped = "report the wrong knee" in "\n".join(spread_lines(folder, swapped))
    assert wrong_now == (not all(signs) if true < 0 else any(signs))
    assert wrong_swapped == (any(signs) if true < 0 else not all(signs))


def test_bad_seed_count_is_refused(tmp_path):
    with pytest.raises(BipedError, match="seeds = 0"):
        paper_settings(biped.Robot.paper(), seeds=0)
