"""The stages of every campaign and the neighbours that start a point, once
(``biped.studies.staging``): waves that respect what each solve reads, neighbours one step
away on the grid, the sthenic twin of a work criterion."""

import io
import json
from dataclasses import dataclass

import pytest

import biped
from biped.studies import campaign, staging
from biped.studies.campaign import Campaign, Task

TOY = Campaign("toy", "toy.json", "toy record", "this folder's toy was", "a toy's")


@dataclass(frozen=True)
class ToySettings(campaign.Settings):
    FORMAT = "biped-toy/1"
    robot: biped.Robot
    seed: int


SETTINGS = ToySettings(biped.Robot.paper(), 0)


@dataclass(frozen=True)
class Cell:
    speed: float  # [m/s]
    clearance: float  # [m]


@dataclass(frozen=True)
class Point:
    stage: str
    knee: str
    criterion: str
    cell: Cell

    def filename(self) -> str:
        cell = f"{self.cell.speed:.3f}-{1000 * self.cell.clearance:.0f}"
        return f"{self.stage}-{self.knee}-{self.criterion}-{cell}.json"


SPEEDS = (0.2, 0.3, 0.4)  # [m/s]
CLEARANCES = (0.0, 0.02)  # [m]
GRID = staging.Neighbours(
    steps=(staging.Axis("cell.speed", SPEEDS), staging.Axis("cell.clearance", CLEARANCES)),
    across=(staging.Axis("knee", biped.KNEES),),
)


def test_neighbours_are_one_step_along_each_axis_then_the_other_knee():
    """Inside the grid both sides of each axis, at its edge the one side it has, then the
    same cell with the other knee; a point off the grid is refused naming its value."""
    inside = Point("own", "rolling", "sthenic", Cell(0.3, 0.0))
    assert GRID.of(inside) == [
        Point("own", "rolling", "sthenic", Cell(0.2, 0.0)),
        Point("own", "rolling", "sthenic", Cell(0.4, 0.0)),
        Point("own", "rolling", "sthenic", Cell(0.3, 0.02)),
        Point("own", "revolute", "sthenic", Cell(0.3, 0.0)),
    ]
    edge = Point("own", "revolute", "energy", Cell(0.4, 0.02))
    assert [(p.knee, p.cell) for p in GRID.of(edge)] == [
        ("revolute", Cell(0.3, 0.02)),
        ("revolute", Cell(0.4, 0.0)),
        ("rolling", Cell(0.4, 0.02)),
    ]
    with pytest.raises(biped.BipedError, match=r"cell.speed = 0.25: allowed one of"):
        GRID.of(Point("own", "rolling", "sthenic", Cell(0.25, 0.0)))


def test_a_work_criterion_starts_from_its_sthenic_twin_only_beside_the_sthenic():
    """The energy point's twin is the sthenic point of its problem when the campaign has the
    sthenic criterion; the sthenic point has none, nor has a campaign without it."""
    energy = Point("own", "rolling", "energy", Cell(0.3, 0.0))
    twin = staging.sthenic_twin(("sthenic", "energy"))
    assert twin(energy) == (Point("own", "rolling", "sthenic", Cell(0.3, 0.0)),)
    assert twin(twin(energy)[0]) == ()
    assert staging.sthenic_twin(("energy",))(energy) == ()


def _solve(task: Task) -> str:
    """Writes the point's file with whether each file it was given exists when it runs."""
    found = [(task.path.parent / p.filename()).exists() for p in task.given]
    task.path.write_text(json.dumps({"given": found}))
    return task.point.filename()


def _stages(folder, needed_only=False) -> list[staging.Stage]:
    """The atlas's shape on the toy grid: own starts (energy from the sthenic twin), a final
    solve from the neighbours' own optima; listed last stage first: the waves, not the
    order of the list, order the solves."""

    def points(stage):
        return tuple(
            Point(stage, k, c, Cell(s, h))
            for c in ("sthenic", "energy")
            for s in SPEEDS
            for h in CLEARANCES
            for k in biped.KNEES
        )

    def own(relation):
        return staging.Seed("own", lambda p: relation(Point("own", p.knee, p.criterion, p.cell)))

    twin = staging.sthenic_twin(("sthenic", "energy"))
    final = staging.Stage(
        "final", _solve, str(folder), points("final"), own(GRID.of), own(lambda p: (p,))
    )
    first = staging.Stage("own", _solve, str(folder), points("own"), own(twin), None, needed_only)
    return [final, first]


def test_each_solve_runs_after_every_result_it_reads(tmp_path):
    """Each task's given files exist when it runs, run by ``Campaign.run`` one wave after
    the other, though the stages are listed final first; the sthenic finals run beside the
    energy own starts (nothing orders them), the energy finals last."""
    stages = _stages(tmp_path)
    waves = staging.schedule(stages, SETTINGS, lambda stage, p: False)
    kinds = [sorted({(t.point.stage, t.point.criterion) for t in wave}) for wave in waves]
    assert kinds == [
        [("own", "sthenic")],
        [("final", "sthenic"), ("own", "energy")],
        [("final", "energy")],
    ]
    TOY.run(None, waves, jobs=1, stream=io.StringIO())
    for path in tmp_path.glob("*.json"):
        assert all(json.loads(path.read_text())["given"]), path.name
    assert len(list(tmp_path.glob("*.json"))) == 2 * 24


def test_a_result_in_the_folder_orders_nothing_and_is_not_run_again(tmp_path):
    """With the own starts done only the finals run, all in one wave."""
    stages = _stages(tmp_path)
    waves = staging.schedule(stages, SETTINGS, lambda stage, p: stage.name == "own")
    assert len(waves) == 1 and {t.point.stage for t in waves[0]} == {"final"}
    assert len(waves[0]) == 24


def test_a_means_stage_runs_only_what_a_solve_still_to_run_reads(tmp_path):
    """With ``needed_only`` own starts and one energy final left, only that final's own
    start, its neighbours' and their sthenic twins run; a stage that is an answer runs
    every point not done."""
    left = Point("final", "rolling", "energy", Cell(0.2, 0.0))
    needed = [Point("own", left.knee, left.criterion, left.cell), *GRID.of(left)]
    needed = [Point("own", p.knee, p.criterion, p.cell) for p in needed]
    twins = [Point("own", p.knee, "sthenic", p.cell) for p in needed]

    def done(stage, point):
        return stage.name == "final" and point != left

    waves = staging.schedule(_stages(tmp_path, needed_only=True), SETTINGS, done)
    ran = [t.point for wave in waves for t in wave]
    assert sorted(ran, key=repr) == sorted([*needed, *twins, left], key=repr)
    every = staging.schedule(_stages(tmp_path), SETTINGS, done)
    assert sum(map(len, every)) == 24 + 1


def test_a_stage_reading_itself_in_a_cycle_is_refused(tmp_path):
    """Two points each started from the other cannot be ordered: refused, not run."""
    cells = (Point("own", "rolling", "sthenic", Cell(s, 0.0)) for s in SPEEDS[:2])
    swap = staging.Neighbours(steps=(staging.Axis("cell.speed", SPEEDS[:2]),))
    stage = staging.Stage("own", _solve, str(tmp_path), tuple(cells), staging.Seed("own", swap.of))
    with pytest.raises(biped.BipedError, match="stage own reads its own result"):
        staging.schedule([stage], SETTINGS, lambda stage, p: False)
