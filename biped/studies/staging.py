"""The stages of a campaign and the neighbours that start a point, once for every study.

A campaign's optimizations come in stages (a point's own starts; the same point again from
its neighbours' optima; the final optimum re-solved): each ``Stage`` names its points, the
solve of one (a ``campaign.Task``), the folder its results go to, and which results a point
reads (``Seed``: those given to its solve as starts, and its own result of an earlier stage).
``schedule`` turns the stages into the waves ``campaign.Campaign.run`` runs one after the
other: a task runs in the wave after the last of the tasks whose results it reads, so tasks
of different stages run side by side where nothing orders them, and a result already in the
folder orders nothing. A stage whose results are a means, not an answer (``needed_only``:
the sweep's own starts, in a hidden folder), runs only the points that a task still to run
reads.

A point's neighbours (``Neighbours``) are the points one step away along each axis of the
campaign's grid (``Axis``: the neighbouring speeds, clearances) and the points at the other
values of a category (the other knee: the solver's variables mean the same for both knees).
A work criterion's point also starts from the sthenic optimum of its own problem
(``sthenic_twin``).
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any

from biped.errors import BipedError
from biped.model.criteria import WORK_CRITERIA
from biped.studies.campaign import Task


def _value(record, field: str):
    """``record``'s ``field``, dotted through nested records ("cell.speed")."""
    for name in field.split("."):
        record = getattr(record, name)
    return record


def _replaced(record, field: str, value):
    """``record`` with its ``field`` (dotted through nested records) set to ``value``."""
    head, _, rest = field.partition(".")
    inner = _replaced(getattr(record, head), rest, value) if rest else value
    return dataclasses.replace(record, **{head: inner})


@dataclass(frozen=True)
class Axis:
    """One axis of a campaign's grid.

    Attributes:
        field: the points' field it varies, dotted through a nested record ("cell.speed").
        values: its values in the grid's order (the speeds [m/s] sorted, the knees).
    """

    field: str
    values: tuple

    def of(self, point):
        return _value(point, self.field)

    def index(self, point) -> int:
        """Where ``point`` lies on the axis; a BipedError if its value is not on the grid."""
        value = self.of(point)
        if value not in self.values:
            raise BipedError(
                f"{self.field} = {value!r}: allowed one of the grid's {list(self.values)}"
            )
        return list(self.values).index(value)

    def at(self, point, value):
        """``point`` moved to ``value`` on this axis."""
        return _replaced(point, self.field, value)


@dataclass(frozen=True)
class Neighbours:
    """A point's neighbours on a campaign's grid: along each axis of ``steps``, one axis
    after the other, the values on either side of the point's (below, then above, where the
    grid has them); then at every other value of each axis of ``across`` (the other knee), in
    the axis's order."""

    steps: tuple[Axis, ...] = ()
    across: tuple[Axis, ...] = ()

    def of(self, point) -> list:
        found = []
        for axis in self.steps:
            at = axis.index(point)
            sides = (at - 1, at + 1)
            found += [axis.at(point, axis.values[j]) for j in sides if 0 <= j < len(axis.values)]
        for axis in self.across:
            found += [axis.at(point, value) for value in axis.values if value != axis.of(point)]
        return found


def sthenic_twin(criteria: Sequence[str]) -> Callable[[Any], tuple]:
    """The relation of a work criterion's point to the sthenic point of its own problem,
    whose optimum starts it, in a campaign of ``criteria`` that has the sthenic criterion;
    no point for the others."""
    sthenic = "sthenic" in criteria

    def of(point) -> tuple:
        if sthenic and point.criterion in WORK_CRITERIA:
            return (dataclasses.replace(point, criterion="sthenic"),)
        return ()

    return of


@dataclass(frozen=True)
class Seed:
    """Which results a point's solve reads: those of the stage named ``stage`` (an earlier
    one, or its own for other points of it) at the points ``of(point)``."""

    stage: str
    of: Callable[[Any], Sequence]


@dataclass(frozen=True)
class Stage:
    """One stage of a campaign.

    Attributes:
        name: the stage among the campaign's ("own", "final"), named by the ``Seed`` of
            another stage.
        solve: writes a point's result whole and returns its line (a ``campaign.Task``'s).
        folder: where the stage's results are written.
        points: every point of the stage, done or not, in the order its tasks run.
        given: the results that start a point's solve (``Task.given``: its neighbours').
        reads: a result the solve reads besides (its own of an earlier stage).
        needed_only: a means, not an answer: a point runs only if a task to run reads it.
    """

    name: str
    solve: Callable[[Task], str]
    folder: str
    points: tuple
    given: Seed | None = None
    reads: Seed | None = None
    needed_only: bool = False

    def needs(self, point) -> list[tuple[str, Any]]:
        """(stage name, point) of every result ``point``'s solve reads."""
        seeds = [seed for seed in (self.reads, self.given) if seed is not None]
        return [(seed.stage, other) for seed in seeds for other in seed.of(point)]

    def task(self, settings, point) -> Task:
        given = () if self.given is None else tuple(self.given.of(point))
        return Task(self.solve, settings, point, self.folder, given)


def schedule(stages: Sequence[Stage], settings, done: Callable[[Stage, Any], bool]) -> list:
    """The tasks still to run (``done(stage, point)``: its result is in the folder), in
    waves (lists of tasks independent of each other, each reading only results already
    there or of the waves before): a task in the wave after the last of the tasks it reads,
    each wave's tasks in the order of the stages, then of their points."""
    named = {stage.name: stage for stage in stages}
    if len(named) != len(stages):
        raise BipedError(f"stages {[s.name for s in stages]}: allowed each name once")
    members = {stage.name: set(stage.points) for stage in stages}
    to_run: set = set()
    queue = [(s, p) for s in stages if not s.needed_only for p in s.points if not done(s, p)]
    while queue:  # the stages' points not done, and those of ``needed_only`` stages they read
        stage, point = queue.pop()
        if (stage.name, point) in to_run:
            continue
        to_run.add((stage.name, point))
        for name, other in stage.needs(point):
            source = named.get(name)
            if source is not None and source.needed_only and other in members[name]:
                if not done(source, other):
                    queue.append((source, other))
    waves: dict[tuple, int] = {}

    def wave(key, path=()) -> int:
        if key not in waves:
            if key in path:
                raise BipedError(f"stage {key[0]} reads its own result at {key[1]}: a cycle")
            before = [wave(k, (*path, key)) for k in named[key[0]].needs(key[1]) if k in to_run]
            waves[key] = 1 + max(before, default=-1)
        return waves[key]

    ordered: list[list[Task]] = []
    for stage in stages:
        for point in stage.points:
            if (stage.name, point) in to_run:
                at = wave((stage.name, point))
                ordered += [[] for _ in range(at + 1 - len(ordered))]
                ordered[at].append(stage.task(settings, point))
    return ordered
