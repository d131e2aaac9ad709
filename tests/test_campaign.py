"""The one campaign mechanism (``biped.studies.campaign``): settings recorded and read back,
a folder claimed once and refused to other settings, stages run in order, a summary."""

import io
import json
from dataclasses import dataclass

import pytest

import biped
from biped.model.criteria import PAPER_SAFETY, Safety
from biped.studies import campaign
from biped.studies.campaign import Campaign, Task

TOY = Campaign("toy", "toy.json", "toy record", "this folder's toy was", "a toy's")


@dataclass(frozen=True)
class ToySettings(campaign.Settings):
    FORMAT = "biped-toy/1"
    robot: biped.Robot
    safety: Safety
    speeds: tuple
    seed: int


@dataclass(frozen=True)
class Cell:
    speed: float

    def filename(self) -> str:
        return f"cell-{self.speed:.3f}.json"


def _solve(task: Task) -> str:
    """Writes the cell's file with the files it was given, as they are when it runs."""
    found = [(task.path.parent / p.filename()).exists() for p in task.given]
    task.path.write_text(json.dumps({"given": found}))
    return f"cell {task.point.speed:.3f}"


SETTINGS = ToySettings(biped.Robot.paper(), PAPER_SAFETY, (0.25, 0.3), 0)


def test_settings_are_recorded_in_order_and_read_back():
    """The record starts with the format, then every field in order (tuples as lists), then
    the method and versions; read back it is the same settings."""
    content = SETTINGS.to_dict()
    assert list(content)[:5] == ["format", "robot", "safety", "speeds", "seed"]
    assert content["format"] == "biped-toy/1" and content["speeds"] == [0.25, 0.3]
    assert {"method", "version", "casadi"} <= set(content)
    assert ToySettings.from_dict(json.loads(json.dumps(content))) == SETTINGS


def test_a_folder_is_claimed_once_and_refused_to_other_settings(tmp_path):
    """A first claim writes the record and removes stale temporaries; the same settings are
    accepted again; others are refused naming the field, writing nothing."""
    folder = tmp_path / "toy"
    TOY.claim(folder, SETTINGS, "inner")
    (folder / "inner" / ".cell-0.300.json.abc.tmp").write_text("{")
    TOY.claim(folder, SETTINGS, "inner")
    assert not list(folder.rglob("*.tmp"))
    other = ToySettings(biped.Robot.paper(), PAPER_SAFETY, (0.25, 0.3), 1)
    with pytest.raises(biped.BipedError, match="seed = 0, this run has 1"):
        TOY.claim(folder, other)
    foreign = tmp_path / "foreign"
    foreign.mkdir()
    (foreign / "a.json").write_text("{}")
    with pytest.raises(biped.BipedError, match="no toy.json"):
        TOY.claim(foreign, SETTINGS)


def test_stages_run_in_order_with_their_lines_and_summary(tmp_path):
    """A task of the second stage sees the files of the first; each task's line is printed,
    then the summary; a bar counts every task."""
    folder = TOY.claim(tmp_path, SETTINGS)
    first, second = Cell(0.25), Cell(0.3)
    stages = [[Task(_solve, SETTINGS, first, str(folder))]]
    stages.append([Task(_solve, SETTINGS, second, str(folder), (first,))])
    log, bars = io.StringIO(), []

    class Bar:
        def __init__(self, total):
            self.total, self.done = total, 0
            bars.append(self)

        def advance(self, units=1, note=None):
            self.done += units

        def clear(self):
            pass

    def why_not(cell):
        return None if (folder / cell.filename()).exists() else "missing"

    def summary():
        return campaign.tally([first, second, Cell(0.35)], why_not, "cells certified")

    TOY.run("plan", stages, summary, jobs=1, stream=log, progress=Bar)
    lines = log.getvalue().splitlines()
    assert lines[:3] == ["plan", "cell 0.250", "cell 0.300"]
    assert lines[3].startswith("toy: done in ")
    assert lines[3].endswith("; 2 of 3 cells certified; NOT: cell-0.350.json missing")
    assert json.loads((folder / second.filename()).read_text()) == {"given": [True]}
    assert [(bar.total, bar.done) for bar in bars] == [(2, 2)]


def test_a_failure_is_named_as_the_lines_name_it():
    """Not converged names the solver's status; converged but infeasible is INFEASIBLE."""
    assert campaign.failure("Maximum_Iterations_Exceeded", True) == (
        "NOT CONVERGED: Maximum_Iterations_Exceeded"
    )
    assert campaign.failure("converged", False) == "INFEASIBLE"
    assert campaign.failure("converged", True) is None
