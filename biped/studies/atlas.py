"""The atlas: where the rolling knee pays off, over speed x swing-foot clearance (x a least
stance-knee bend), each difference between the knees with its error bar.

Each cell (speed, clearance, knee bend) holds, for each knee and criterion, a certified
optimum of the atlas's gait family (``Settings.knots``: the paper's spline by default, K
interior knots, or a ``Bezier``), in the campaign's stages (``biped.studies.staging``):

1. ``own``: the point's own starts (``biped.optimization.optimize.optimize``); the
   criteria of the joints' work start from the sthenic optimum of the same point;
2. ``final``: again from the ``own`` optima of the neighbouring cells (speed and clearance)
   and of the other knee; the best of both is the point's answer, written as a gait file;
3. ``fine``, ``tight``, ``richer``: the final optimum re-solved with twice the samples per
   piece (the discretization), to ten times tighter tolerance (the solver's), and, at
   the corner cells of an atlas of the paper's spline, in the family of 3 interior knots
   (``biped.model.gait``), which holds it: how much the difference moves when the gait is
   richer (``biped.studies.atlas_families`` compares two whole atlases).

The difference of a cell is (rolling − revolute) / revolute of the criterion on the check
grid (``biped.optimization.comparison.relative_change``). Its uncertainty (``Difference``) adds
what moves it: the finer grid's difference less the cell's, the tighter tolerance's less
the cell's, and the spread of the starts (for a knee whose best value one start alone reached,
the distance to the next optimum the starts reached). A difference no larger than its
uncertainty is not distinguishable. A re-solve that did not converge measures nothing: its
term is unknown, never 0, and the difference not distinguishable until it is measured, with
why (``Difference.unmeasured``). A point whose solver did not converge, or whose optimum
is infeasible, leaves its cell empty, with why.

The margins of every cell are the settings' (``Settings.safety``: the walkable constraints by
default, the paper's on request), each cell's clearance and knee bend replacing the base's.
After the optimizations ``validate.studies.atlas_walks`` walks every certified final optimum in
MuJoCo (this package never imports it); its records are read here as plain JSON (``Walk``).
"""

from __future__ import annotations

import dataclasses
import json
import math
import time
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from biped.errors import BipedError
from biped.model.bezier import Bezier
from biped.model.criteria import (
    CRITERION_UNITS,
    PAPER_SAFETY,
    WALKABLE,
    Safety,
)
from biped.model.dynamics import Biped
from biped.model.gait import check_knots, family_words
from biped.model.kinematics import KNEES
from biped.model.robot import Robot
from biped.optimization.comparison import relative_change
from biped.optimization.optimize import (
    Optimum,
    apart_from_table,
    best_of,
    checked,
    confirm,
    optimize,
    refine,
)
from biped.optimization.problem import (
    GaitProblem,
    check_criterion,
    check_speed,
    walkable_description,
)
from biped.records import gait_file
from biped.records.atlas_optimum import AtlasOptimum
from biped.runtime.claims import claimed
from biped.runtime.files import atomic_write_text, distinct_values
from biped.studies import campaign, staging
from biped.studies.campaign import Task

MANIFEST = "atlas.json"
ATLAS = campaign.Campaign(
    "atlas", MANIFEST, "atlas record", "this folder's atlas was", "an atlas's", "atlas files"
)
# The defaults: the speeds from 0.2 m/s to 1 m/s, the clearances, the per-metre criteria.
DEFAULT_SPEEDS = tuple(float(v) for v in np.round(np.arange(0.2, 1.0001, 0.1), 6))
DEFAULT_CLEARANCES = (0.0, 0.01, 0.02, 0.03, 0.05)
DEFAULT_CRITERIA = ("sthenic", "energy-per-metre")
# The richer family of the corner cells, and the factor of the finer grid.
RICHER_KNOTS = 3
FINER = 2
STAGES = ("own", "final", "fine", "tight", "richer")


@dataclass(frozen=True)
class Cell:
    speed: float  # [m/s]
    clearance: float  # [m]
    knee_bend: float  # [rad]

    def name(self) -> str:
        return f"{self.speed:.3f}-c{1000 * self.clearance:.0f}mm-b{1000 * self.knee_bend:.0f}mrad"


@dataclass(frozen=True)
class Point:
    """One optimization of the atlas: a ``stage`` (``STAGES``) of a knee and criterion in a
    cell."""

    stage: str
    knee: str
    criterion: str
    cell: Cell

    def filename(self) -> str:
        return f"{self.stage}/{self.knee}-{self.criterion}-{self.cell.name()}.json"

    def gait_filename(self) -> str:
        """The final optimum's gait file, in the atlas's folder."""
        return f"{self.knee}-{self.criterion}-{self.cell.name()}.json"

    def at(self, stage: str, knee: str | None = None) -> Point:
        return Point(stage, knee or self.knee, self.criterion, self.cell)


@dataclass(frozen=True)
class Settings(campaign.Settings):
    """What shapes an atlas's numbers, recorded in its folder. ``safety``: the margins of every
    cell, whose own clearance and knee bend replace the base's (``problem``): by default the
    walkable constraints (``WALKABLE``); the paper's problem (``PAPER_SAFETY``) is recorded as
    an atlas made before them was, without the field."""

    # 2: a robot without actuators has the catalog's default set (biped-gait/3)
    FORMAT = "biped-atlas/2"
    robot: Robot
    speeds: tuple  # [m/s]
    clearances: tuple  # [m] of the swing foot (Safety.clearance)
    knee_bends: tuple  # [rad] least flexion of the stance knee (Safety.knee_bend)
    criteria: tuple
    knots: int | Bezier  # the gaits' family: a spline's interior knots, or a ``Bezier``
    seed: int
    starts: int
    actuator_limits: bool = False  # Safety.actuator_limits; recorded only when asked
    safety: Safety = WALKABLE  # the base margins of every cell; recorded unless the paper's

    def to_dict(self) -> dict:
        content = super().to_dict()
        if not self.actuator_limits:  # an atlas without them records what it did before
            del content["actuator_limits"]
        if self.safety == PAPER_SAFETY:  # the paper's problem, as an atlas made before
            del content["safety"]
        return content

    @classmethod
    def from_dict(cls, content: dict):
        return super().from_dict({"actuator_limits": False, "safety": {}, **content})

    def cells(self) -> list[Cell]:
        return [
            Cell(s, c, b) for b in self.knee_bends for c in self.clearances for s in self.speeds
        ]

    def corners(self) -> list[Cell]:
        """The cells of the richer family: the corners of speed x clearance, every bend (none
        unless the atlas is of the paper's spline, which the richer family holds)."""
        if self.knots != 1:
            return []
        return self.grid_corners()

    def grid_corners(self) -> list[Cell]:
        """The corners of speed x clearance, every bend."""
        return [
            Cell(s, c, b)
            for b in self.knee_bends
            for c in sorted({self.clearances[0], self.clearances[-1]})
            for s in sorted({self.speeds[0], self.speeds[-1]})
        ]

    def cell_safety(self, cell: Cell) -> Safety:
        """The margins of ``cell``: the base's, with the cell's clearance and knee bend."""
        return dataclasses.replace(
            self.safety,
            clearance=cell.clearance,
            knee_bend=cell.knee_bend,
            actuator_limits=self.actuator_limits or self.safety.actuator_limits,
        )

    def problem(self, point: Point, knots: int | None = None, samples=None) -> GaitProblem:
        cell = point.cell
        model = Biped(self.robot, point.knee)
        knots = self.knots if knots is None else knots
        return GaitProblem(
            model, cell.speed, point.criterion, self.cell_safety(cell), samples, knots
        )

    def constraints_words(self) -> str:
        """Which problem the atlas answers (``constraints_words``)."""
        asked = self.actuator_limits or self.safety.actuator_limits
        return constraints_words(dataclasses.replace(self.safety, actuator_limits=asked))


def constraints_words(safety: Safety) -> str:
    """Which problem an atlas of base margins ``safety`` answers, its cells' clearances and
    knee bends aside: "the paper's constraints", "the walkable constraints: ..."
    (``WALKABLE``'s) or "margins of ours: ..."."""
    base = dataclasses.replace(safety, clearance=0.0, knee_bend=0.0)
    parts = [f"ZMP {base.zmp_margin:g} m inside the sole"] if base.zmp_margin else []
    parts += [part for part in walkable_description(base).split(", ") if part]
    if base.clearance_window != PAPER_SAFETY.clearance_window:
        parts.append(f"clearance windows {base.clearance_window:g} T")
    parts += ["the motors within their limits"] if base.actuator_limits else []
    if not parts:
        return "the paper's constraints"
    walkable = dataclasses.replace(WALKABLE, clearance=0.0, knee_bend=0.0)
    name = "the walkable constraints" if base == walkable else "margins of ours"
    return f"{name}: {', '.join(parts)}"


def check_folder(folder, settings: Settings) -> bool:
    """Whether ``folder``'s atlas record holds ``settings`` (False: it has none yet, a run may
    claim it); writes nothing.

    Raises:
        BipedError: the record is unreadable or holds other settings: other margins named
            first, in words (an atlas made before them is the paper's problem).
    """
    found = ATLAS.read(folder)
    wanted = settings.to_dict()
    if found is not None and found.get("safety", {}) != wanted.get("safety", {}):
        try:
            made = constraints_words(Safety(**found.get("safety", {})))
        except (TypeError, BipedError):
            made = f"safety = {found.get('safety')!r}"
        flag = "without" if settings.safety == PAPER_SAFETY else "with"
        raise BipedError(
            f"{Path(folder) / MANIFEST}: this folder's atlas answers {made}, this run asks "
            f"{settings.constraints_words()}: allowed only the same margins, run {flag} "
            "--paper-constraints or choose another --out folder"
        )
    return ATLAS.check(folder, wanted)


def check_settings(settings: Settings) -> Settings:
    """The settings if every value is allowed (each speed walkable, distinct at the files'
    resolution; clearances and bends margins of ``Safety``), else a clear error."""
    for speed in settings.speeds:
        check_speed(Biped(settings.robot, "revolute"), speed)
    distinct_values(settings.speeds, "speeds", "m/s", 3, "1 mm/s")
    distinct_values(settings.clearances, "clearances", "m", 3, "1 mm")
    distinct_values(settings.knee_bends, "knee bends", "rad", 3, "1 mrad")
    if not isinstance(settings.safety, Safety):
        raise BipedError(f"safety = {settings.safety!r}: allowed a biped.model.criteria.Safety")
    for clearance in settings.clearances:
        dataclasses.replace(settings.safety, clearance=clearance)
    for bend in settings.knee_bends:
        dataclasses.replace(settings.safety, knee_bend=bend)
    for criterion in settings.criteria:
        check_criterion(criterion)
    check_knots(settings.knots)
    return settings


def read(folder, point: Point) -> AtlasOptimum | None:
    """The record of ``point`` in ``folder``, None if missing or unreadable."""
    return AtlasOptimum.read(Path(folder) / point.filename())


def _optimum(settings: Settings, point: Point, record: AtlasOptimum | None) -> Optimum | None:
    """The optimum a record holds (its numbers again: JSON keeps every bit)."""
    if record is None or not record.solved:
        return None
    return checked(settings.problem(point), np.array(record.variables), record.report)


def _write(task: Task, optimum: Optimum, began: float) -> AtlasOptimum:
    record = AtlasOptimum.from_optimum(optimum, time.perf_counter() - began)
    atomic_write_text(task.path, record.to_json())
    return record


def _line(point: Point, record: AtlasOptimum) -> str:
    status = campaign.failure(record.status, record.feasible)
    if status is None:
        status = "certified" if point.stage == "final" else "converged, feasible"
    value = record.costs[point.criterion]
    return (
        f"[{point.stage:6}] {point.knee:8} {point.criterion:16} {point.cell.speed:.3f} m/s "
        f"clearance {100 * point.cell.clearance:4.1f} cm bend {point.cell.knee_bend:.3f} rad  "
        f"C = {value:12.6f} {CRITERION_UNITS[point.criterion]:6} {status}; "
        f"{record.starts_at_best}/{record.starts} starts at best  "
        f"{record.seconds:5.1f} s"
    )


def _solve_own(task: Task) -> str:
    """A point's own starts; a work criterion's also from the sthenic optimum (``given``)."""
    settings, point, began = task.settings, task.point, time.perf_counter()
    sthenic = None
    for twin in task.given:
        sthenic = _optimum(settings, twin, read(task.folder, twin))
    problem = settings.problem(point)
    optimum = optimize(problem, seed=settings.seed, starts=settings.starts, sthenic=sthenic, jobs=1)
    return _line(point, _write(task, optimum, began))


def _solve_final(task: Task) -> str:
    """A point's answer: its own optimum, or better from its neighbours' (``given``)."""
    settings, point, began = task.settings, task.point, time.perf_counter()
    own = _optimum(settings, point.at("own"), read(task.folder, point.at("own")))
    problem = settings.problem(point)
    given = [read(task.folder, p) for p in task.given]
    starts = [np.array(r.variables) for r in given if r is not None and r.solved]
    starts = apart_from_table(problem, starts)  # the table's were among the point's own
    optimum = own
    if starts:
        again = optimize(problem, seed=settings.seed, starts=0, given=starts, jobs=1)
        optimum = again if own is None else best_of(problem, [own, again])
    if optimum is not None:  # a best reached by one start tried again
        optimum = confirm(problem, optimum, starts, jobs=1)
    record = _write(task, optimum, began)
    gait = gait_file.Gait.from_optimum(optimum, settings.robot)
    gait.write(Path(task.folder) / point.gait_filename())
    return _line(point, record)


def _solve_refined(task: Task) -> str:
    """The final optimum re-solved: on the finer grid (``fine``), more tightly (``tight``),
    or in the richer family from it and from the other knee's (``richer``)."""
    settings, point, began = task.settings, task.point, time.perf_counter()
    final = read(task.folder, point.at("final"))
    if final is None or not final.solved:
        raise BipedError(f"{point.at('final').filename()}: no final optimum to refine")
    start = np.array(final.variables)
    if point.stage == "fine":
        samples = FINER * settings.problem(point).samples_per_half
        optimum = refine(settings.problem(point, samples=samples), start)
    elif point.stage == "tight":
        optimum = refine(settings.problem(point), start, "tight")
    else:
        richer = settings.problem(point, knots=RICHER_KNOTS)
        others = [read(task.folder, p) for p in task.given]
        starts = [start] + [np.array(r.variables) for r in others if r is not None and r.solved]
        optimum = optimize(richer, starts=0, given=[richer.embedded(z) for z in starts], jobs=1)
    return _line(point, _write(task, optimum, began))


def stages(folder: Path, settings: Settings) -> list[list[Task]]:
    """The tasks still to run, in waves whose inputs the waves before write
    (``staging.schedule``): each point's own starts (a work criterion's from the sthenic
    optimum of its problem), its final solve from its neighbours' own optima
    (``neighbourhood``), its re-solves from its final optimum (the richer family's also from
    the other knee's)."""
    folder = str(folder)

    def points(stage: str, cells=None) -> tuple:
        cells = settings.cells() if cells is None else cells
        return tuple(
            Point(stage, k, c, cell) for c in settings.criteria for cell in cells for k in KNEES
        )

    def at(stage: str, relation=lambda p: (p,)) -> staging.Seed:
        """The results of ``stage`` at the points ``relation`` relates to a point's."""
        return staging.Seed(stage, lambda p: relation(p.at(stage)))

    knees = staging.Neighbours(across=(staging.Axis("knee", KNEES),))
    refined = [
        staging.Stage(s, _solve_refined, folder, points(s), reads=at("final"))
        for s in ("fine", "tight")
    ]
    plan = [
        staging.Stage(
            "own",
            _solve_own,
            folder,
            points("own"),
            given=at("own", staging.sthenic_twin(settings.criteria)),
        ),
        staging.Stage(
            "final",
            _solve_final,
            folder,
            points("final"),
            given=at("own", neighbourhood(settings).of),
            reads=at("own"),
        ),
        *refined,
        staging.Stage(
            "richer",
            _solve_refined,
            folder,
            points("richer", settings.corners()),
            given=at("final", knees.of),
            reads=at("final"),
        ),
    ]
    return staging.schedule(plan, settings, lambda _, point: read(folder, point) is not None)


def neighbourhood(settings: Settings) -> staging.Neighbours:
    """The neighbours whose ``own`` optima start a point's final solve: the neighbouring
    speeds and clearances of its cell, and the other knee."""
    return staging.Neighbours(
        steps=(
            staging.Axis("cell.speed", tuple(settings.speeds)),
            staging.Axis("cell.clearance", tuple(settings.clearances)),
        ),
        across=(staging.Axis("knee", KNEES),),
    )


def run_atlas(folder, settings: Settings, **where) -> Settings:
    """Every optimization of the atlas not yet in ``folder``; returns its settings.
    ``where``: ``jobs``, ``dask``, ``stream``, ``progress``, as ``campaign.Campaign.run``."""
    check_settings(settings)
    with claimed(folder):  # one run at a time on the folder
        check_folder(folder, settings)
        folder = ATLAS.claim(folder, settings, *STAGES)
        tasks = stages(folder, settings)
        total = len(settings.cells()) * len(settings.criteria) * len(KNEES) * 4
        total += len(settings.corners()) * len(settings.criteria) * len(KNEES)
        remaining = sum(map(len, tasks))
        corners = f", {RICHER_KNOTS} knots at the corners" if settings.corners() else ""
        plan = (
            f"atlas under {settings.constraints_words()}: {total} optimizations of "
            f"{len(settings.cells())} cells x {len(settings.criteria)} criteria x 2 knees in "
            f"{folder}, {family_words(settings.knots)} (own starts, final, finer grid, tighter "
            f"tolerance{corners}): {total - remaining} already done, {remaining} to run"
        )
        ATLAS.run(plan, tasks, lambda: summarize(folder, settings), **where)
    return settings


def summarize(folder, settings: Settings) -> str:
    """How many final optima are certified, which are not and why; how many optimizations
    the stages hold and their median time (each record's own solve, not the walls')."""
    finals = [
        Point("final", k, c, cell)
        for c in settings.criteria
        for cell in settings.cells()
        for k in KNEES
    ]

    def why_not(point):
        record = read(folder, point)
        if record is None:
            return "missing"
        why = campaign.failure(record.status, record.feasible)
        return f"{why} ({record.violations})" if why == "INFEASIBLE" else why

    counted = "points certified (final optima, solver converged, feasible on the check grid)"
    records = [
        AtlasOptimum.read(path)
        for stage in STAGES
        for path in sorted((Path(folder) / stage).glob("*.json"))
    ]
    seconds = [record.seconds for record in records if record is not None]
    note = (
        f"; {len(seconds)} optimizations, median {np.median(seconds):.2f} s each" if seconds else ""
    )
    text = campaign.tally(finals, why_not, counted, note, most=8)
    missing = unmeasured(folder, settings)
    if missing:
        text += f"; NOT MEASURED by {len(missing)} re-solves: " + ", ".join(missing[:8])
        text += " ..." if len(missing) > 8 else ""
    return text


def unmeasured(folder, settings: Settings) -> list[str]:
    """Each re-solve of a cell with a difference that measured nothing, and why, a line each
    (``Difference.unmeasured``: the finer grid's or the tighter tolerance's leave the cell's
    uncertainty unknown)."""
    lines = []
    for criterion in settings.criteria:
        for cell in settings.cells():
            diff, _ = difference(folder, settings, criterion, cell)
            lines += [f"{criterion} {cell.name()} {what} ({why})" for what, why in diff.unmeasured]
    return lines


# What each re-solve of a cell measures, in words.
MEASURES = {
    "fine": "finer grid",
    "tight": "tighter tolerance",
    "richer": f"{RICHER_KNOTS} knots",
}


@dataclass(frozen=True)
class Difference:
    """The knees compared in one cell for one criterion [%], with what moves the difference.

    A term that was not measured (a re-solve that did not converge) is None, never 0: the
    uncertainty is then unknown and the difference not distinguishable until it is measured.

    Attributes:
        value: (rolling − revolute) / revolute on the check grid [%], None without both.
        discretization: the finer grid's difference less ``value`` [%], None if not measured.
        tolerance: the tighter tolerance's less ``value`` [%], None if not measured.
        starts: the spread of the starts [%]: √ of the squared distances to the next optimum
            of each knee whose best one start alone reached; None without ``value``.
        richer: the difference with the richer family (corner cells) [%], else None.
        why: why there is no difference (a knee not certified), else "".
        unmeasured: (re-solve, why) of each re-solve asked of the cell that gave no
            difference (``MEASURES``' words: a knee's optimum missing or not certified).
    """

    value: float | None
    discretization: float | None
    tolerance: float | None
    starts: float | None
    richer: float | None
    why: str
    unmeasured: tuple = ()

    @property
    def uncertainty(self) -> float | None:
        """[%] The sum of the three; None (unknown) while one of them is not measured."""
        terms = (self.discretization, self.tolerance, self.starts)
        if any(term is None for term in terms):
            return None
        return abs(self.discretization) + abs(self.tolerance) + self.starts

    @property
    def distinguishable(self) -> bool:
        """Larger than its uncertainty, which is measured."""
        uncertainty = self.uncertainty
        return self.value is not None and uncertainty is not None and abs(self.value) > uncertainty


def _not_certified(records: dict) -> str:
    """Why the knees' records of one stage give no difference ("" when both are certified)."""
    reasons = []
    for knee in KNEES:
        record = records[knee]
        if record is None:
            reasons.append(f"{knee} missing")
        elif not record.certified:
            why = campaign.failure(record.status, record.feasible)
            detail = f": {record.violations}" if record.violations else ""
            reasons.append(f"{knee} {why}{detail}")
    return "; ".join(reasons)


def difference(folder, settings: Settings, criterion: str, cell: Cell) -> tuple[Difference, dict]:
    """The cell's ``Difference`` for ``criterion`` and each knee's final record
    (``AtlasOptimum``, None where missing), by knee."""
    records = {
        stage: {k: read(folder, Point(stage, k, criterion, cell)) for k in KNEES}
        for stage in STAGES
    }
    finals = records["final"]
    why = _not_certified(finals)
    if why:
        return Difference(None, None, None, None, None, why), finals

    def change(stage):
        knees = records[stage]
        return relative_change(
            knees["rolling"].costs[criterion], knees["revolute"].costs[criterion]
        )

    value = change("final")
    asked = ("fine", "tight") + (("richer",) if cell in settings.corners() else ())
    missing = {stage: _not_certified(records[stage]) for stage in asked}
    moved = {stage: None if missing[stage] else change(stage) for stage in asked}
    spread = 100 * math.sqrt(sum(finals[k].next_optimum ** 2 for k in KNEES))
    return (
        Difference(
            value=value,
            discretization=None if moved["fine"] is None else moved["fine"] - value,
            tolerance=None if moved["tight"] is None else moved["tight"] - value,
            starts=spread,
            richer=moved.get("richer"),
            why="",
            unmeasured=tuple((MEASURES[s], why) for s, why in missing.items() if why),
        ),
        finals,
    )


def load(folder) -> Settings:
    """The settings of the atlas in ``folder``."""
    found = ATLAS.read(folder)
    if found is None:
        raise BipedError(f"{Path(folder) / MANIFEST}: no atlas there: run 'biped atlas'")
    return Settings.from_dict(found)


# MuJoCo's walks of the final optima (``validate.studies.atlas_walks``, which writes them; read here
# as plain JSON: this package never imports the simulator): a record per certified final
# optimum, ``walks/<knee>-<criterion>-<cell>.json``, the ``Point`` of stage ``WALKS``.
WALKS = "walks"
WALK_FORMAT = "biped-atlas-walk/1"


@dataclass(frozen=True)
class WalkCheck:
    """One check of a walk as its record holds it: its verdict, why it failed in one note
    (the orbit's verdict, another check's first note; "" if it passed) and all its notes."""

    passed: bool
    cause: str = ""
    notes: tuple[str, ...] = ()

    def to_dict(self) -> dict:
        return {"passed": bool(self.passed), "cause": self.cause, "notes": list(self.notes)}

    @classmethod
    def from_dict(cls, content: dict) -> WalkCheck:
        notes = tuple(str(note) for note in content.get("notes") or ())
        return cls(bool(content["passed"]), str(content.get("cause") or ""), notes)


@dataclass(frozen=True)
class Walk:
    """What MuJoCo's walk of one final optimum says, as its record holds it.

    Attributes:
        every_check: every check of ``biped validate`` was run (the corners, the best
            pay-off), else the forward walk with contact and the feedforward replay.
        checks: each check run, by name, in the order run (``WalkCheck``).
        figures: the key figures (steps walked, fell, slip, feedback shares, energies per
            step, the orbit's spectral radius and verdict where checked), None where not
            measured; their units in the record's ``units``.
        error: why the walk could not be measured (then it neither walks nor fails).
        steps: the steps of the forward walk asked.
    """

    every_check: bool
    checks: Mapping[str, WalkCheck]
    figures: dict
    error: str | None = None
    steps: int | None = None

    @property
    def walks(self) -> bool | None:
        """Every check run passes (an orbit only 'undecided' does not); None: not measured."""
        if self.error is not None or not self.checks:
            return None
        return all(check.passed for check in self.checks.values())

    def causes(self) -> str:
        """Why the gait does not walk: each failed check with its cause ("" when it walks),
        or why the walk was not measured."""
        if self.error is not None:
            return f"not measured: {self.error}"
        return "; ".join(
            f"{name}: {check.cause or 'failed'}"
            for name, check in self.checks.items()
            if not check.passed
        )

    @classmethod
    def from_dict(cls, content: dict) -> Walk:
        return cls(
            bool(content["every_check"]),
            {name: WalkCheck.from_dict(check) for name, check in content["checks"].items()},
            dict(content["figures"]),
            content.get("error"),
            content.get("steps_asked"),
        )


def read_walk(folder, point: Point) -> Walk | None:
    """The walk of ``point``'s final optimum in ``folder`` (any stage's point names it), None
    if it has no readable record."""
    path = Path(folder) / point.at(WALKS).filename()
    try:
        content = json.loads(path.read_text())
        if content.get("format") != WALK_FORMAT:
            return None
        return Walk.from_dict(content)
    except (OSError, ValueError, UnicodeDecodeError, AttributeError, KeyError, TypeError):
        return None


def best_payoff(folder, settings: Settings, criterion: str, among=None) -> Cell | None:
    """The cell where the rolling knee needs distinguishably the least for ``criterion`` (of
    the cells ``among``, default all), else None."""
    found = []
    for cell in settings.cells() if among is None else among:
        diff, _ = difference(folder, settings, criterion, cell)
        if diff.distinguishable and diff.value < 0:
            found.append((diff.value, cell))
    return min(found, key=lambda pair: pair[0])[1] if found else None


def fully_checked(folder, settings: Settings, criterion: str) -> list[Cell]:
    """The cells whose optima of ``criterion`` MuJoCo checks with every check: the corners of
    speed x clearance (every knee bend) and the best pay-off."""
    cells = settings.grid_corners()
    best = best_payoff(folder, settings, criterion)
    return cells + ([best] if best is not None and best not in cells else [])
