"""Design maps: the optimal gait's criterion over a grid of knee radii (r1, r2), at one or
several speeds, with the joint optimum of radii and gait (``biped.optimization.design``).

At each speed the map holds, each an independent optimization:

- ``grid``: the optimal gait of the rolling knee at every (r1, r2) of the grid
  (``biped.optimization.design.optimize_at``: ``biped.optimization.optimize.optimize``'s
  starts on the design graph with the radii held, one graph per process for every radius);
- ``revolute``: the optimal gait of the revolute knee, the map's reference contour (the
  grid's rows r1 = 0 and r2 = 0 are hinges too: a circle rolling on a point turns about it);
- ``table1``: the rolling knee at the robot's own radii (Table 1: 5 cm);
- ``design``: the radii and gait optimised together, in a second stage that also starts
  from the best grid point and the Table 1 and revolute gaits at that speed.

The optimizations run through ``biped.runtime.runner.run_tasks``: local processes, or the
workers of a Dask cluster. Each writes its result as one small JSON file
(``biped.runtime.files``: whole or not at all), so a map stopped at any moment and run
again ends with the files of an uninterrupted run; the folder's ``design-map.json``
records what shapes the numbers and resuming with any of it changed is refused. Points
whose solver did not converge, or whose optimum is infeasible, are kept with their status
and left out of the figures.

Its figures are drawn by ``biped.pages.design_map_figures``: per speed, ``map-<speed>.png``,
the criterion over (r1, r2) with the joint optimum and the Table 1 point marked and the
revolute knee's value as a contour; with several speeds, ``speeds.png``, the optimal radii
and the gains against the revolute knee as functions of speed; ``summary.csv`` (this
module's ``summary_csv``), one line per speed.
"""

from __future__ import annotations

import dataclasses
import json
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from biped.errors import BipedError
from biped.model.criteria import CRITERION_UNITS, PAPER_SAFETY, Safety
from biped.model.robot import Robot
from biped.optimization.comparison import relative_change
from biped.optimization.design import (
    RADII,
    DesignProblem,
    check_radii,
    optimize_at,
    optimize_design,
)
from biped.optimization.optimize import DEFAULT_STARTS, optimize
from biped.optimization.problem import VARIABLES
from biped.runtime.claims import claimed
from biped.runtime.files import atomic_write_text, distinct_values
from biped.studies import campaign, staging
from biped.studies.campaign import Task

MANIFEST = "design-map.json"
MAP = campaign.Campaign(
    "design map", MANIFEST, "design-map record", "this folder's map was", "a design map's"
)
KINDS = ("grid", "revolute", "table1", "design")
# Grid points per radius by default, from 0 to the radius's upper bound.
DEFAULT_GRID = 10


@dataclass(frozen=True)
class MapPoint:
    """One optimization of a map: ``kind`` (``KINDS``) at ``speed`` [m/s], with radii
    (r1, r2) [m] for the grid."""

    kind: str
    speed: float
    radii: tuple | None = None

    def filename(self) -> str:
        if self.kind == "grid":
            r1, r2 = self.radii
            return f"grid-{self.speed:.3f}-r1-{r1:.4f}-r2-{r2:.4f}.json"
        return f"{self.kind}-{self.speed:.3f}.json"

    def label(self) -> str:
        if self.kind == "grid":
            return f"r1 {self.radii[0]:.4f} m, r2 {self.radii[1]:.4f} m"
        return self.kind


@dataclass(frozen=True)
class MapSettings(campaign.Settings):
    """What shapes a map's numbers, recorded in its folder."""

    # 2: a robot without actuators has the catalog's default set (biped-gait/3)
    FORMAT = "biped-design-map/2"
    robot: Robot
    criterion: str
    safety: Safety
    speeds: tuple  # [m/s]
    r1: tuple  # [m] the grid's radii
    r2: tuple  # [m]
    upper: tuple  # [m] the design's upper bounds of (r1, r2)
    seed: int
    starts: int

    def problem(self, speed: float) -> DesignProblem:
        return DesignProblem(self.robot, speed, self.criterion, self.safety, upper=self.upper)


def radius_grid(robot: Robot, values, name: str) -> tuple:
    """Sorted distinct radii [m] of a grid, each within the design bounds, distinct at the
    files' 0.1 mm resolution; a clear error otherwise."""
    index = RADII.index(name)
    values = sorted(float(v) for v in values)
    if not values:
        raise BipedError(f"{name} grid is empty: allowed one radius or more")
    for value in values:
        radii = [0.0, 0.0]
        radii[index] = value
        check_radii(robot, radii)
    return tuple(distinct_values(values, name, "m", 4, "0.1 mm"))  # MapPoint.filename's


def read_point(folder: Path, point: MapPoint) -> dict | None:
    """The result saved for ``point``, or None if missing or unreadable (then run again)."""
    path = Path(folder) / point.filename()
    try:
        content = json.loads(path.read_text())
    except (OSError, ValueError, UnicodeDecodeError):
        return None
    if not isinstance(content, dict) or content.get("point") != _point_dict(point):
        return None
    return content


def _point_dict(point: MapPoint) -> dict:
    return {
        "kind": point.kind,
        "speed": point.speed,
        "radii": None if point.radii is None else list(point.radii),
    }


def _save(folder: Path, point: MapPoint, optimum, radii, report_seconds: float) -> dict:
    report = optimum.report
    content = {
        "point": _point_dict(point),
        "knee": optimum.knee,
        "radii": None if radii is None else list(radii),
        "value": optimum.value if np.isfinite(optimum.value) else None,
        "sthenic": optimum.evaluation.sthenic,
        "energy": optimum.evaluation.energy,
        "feasible": optimum.feasible,
        "status": report.status,
        "certified": optimum.certified,
        "starts": report.starts,
        "starts_at_best": report.starts_at_best,
        "seconds": report_seconds,
        "variables": dict(
            zip(VARIABLES, (v if np.isfinite(v) else None for v in optimum.variables), strict=True)
        ),
    }
    atomic_write_text(Path(folder) / point.filename(), json.dumps(content, indent=1))
    return content


def _line(point: MapPoint, content: dict, unit: str) -> str:
    """One optimization's line: its criterion on the check grid with its ``unit``, where,
    what it is, and the starts at its value."""
    status = campaign.failure(content["status"], content["feasible"]) or "certified"
    value = content["value"]
    radii = content["radii"]
    where = "" if radii is None else f" at r1 {radii[0]:.4f} m, r2 {radii[1]:.4f} m"
    return (
        f"[{point.kind:8} {point.speed:.3f} m/s] {point.label():30} "
        f"C = {value if value is not None else float('nan'):12.6f} {unit}{where}  {status}  "
        f"{content['starts_at_best']}/{content['starts']} starts at best  "
        f"{content['seconds']:5.1f} s"
    )


def solve_point(task: Task) -> str:
    """One optimization of a map (a ``campaign.Task``): writes its file and returns a line
    saying what it found."""
    settings, point, folder = task.settings, task.point, Path(task.folder)
    problem = settings.problem(point.speed)
    began = time.perf_counter()
    if point.kind == "design":
        given = []
        for content in _stage_one(folder, task.given):
            variables = campaign.variables(content["variables"])
            if variables is not None:
                given.append((variables, content["radii"] or problem.reference_radii))
        design = optimize_design(problem, seed=settings.seed, starts=settings.starts, given=given)
        optimum, radii = design.optimum, design.radii
    elif point.kind == "grid":  # one design graph per process serves every radius
        radii = point.radii
        optimum = optimize_at(problem, radii, seed=settings.seed, starts=settings.starts)
    else:  # the references, as 'biped optimize' finds them
        radii = problem.reference_radii if point.kind == "table1" else None
        knee = "rolling" if point.kind == "table1" else "revolute"
        gait = problem.gait_problem(problem.reference_radii, knee)
        optimum = optimize(gait, seed=settings.seed, starts=settings.starts)
    content = _save(folder, point, optimum, radii, time.perf_counter() - began)
    return _line(point, content, CRITERION_UNITS[problem.criterion])


def _stage_one(folder: Path, given) -> list[dict]:
    """The first-stage results that start the design (``given``: the first stage's points at
    its speed, ``first_stage``): the best certified grid point, the Table 1 and revolute
    gaits."""
    found = []
    grid = [read_point(folder, p) for p in given if p.kind == "grid"]
    certified = [c for c in grid if c is not None and c["certified"]]
    if certified:
        found.append(min(certified, key=lambda c: c["value"]))
    references = {p.kind: p for p in given if p.kind != "grid"}
    for kind in ("table1", "revolute"):
        content = read_point(folder, references[kind])
        if content is not None and content["certified"]:
            found.append(content)
    return found


def first_stage(settings: MapSettings, speed: float) -> tuple[MapPoint, ...]:
    """The first stage's points at ``speed``: the revolute and Table 1 references, the grid."""
    grid = tuple(MapPoint("grid", speed, (r1, r2)) for r1 in settings.r1 for r2 in settings.r2)
    return (MapPoint("revolute", speed), MapPoint("table1", speed), *grid)


def map_points(settings: MapSettings) -> tuple[list[MapPoint], list[MapPoint]]:
    """(first stage, second stage) points of a map."""
    first = [p for speed in settings.speeds for p in first_stage(settings, speed)]
    return first, [MapPoint("design", speed) for speed in settings.speeds]


def map_stages(folder: Path, settings: MapSettings) -> list[list[Task]]:
    """The tasks still to run, in waves (``staging.schedule``): the references and the grid,
    then the design at each speed, started from the first stage's results at its speed."""
    first, second = map_points(settings)
    plan = [
        staging.Stage("first", solve_point, str(folder), tuple(first)),
        staging.Stage(
            "design",
            solve_point,
            str(folder),
            tuple(second),
            given=staging.Seed("first", lambda p: first_stage(settings, p.speed)),
        ),
    ]
    return staging.schedule(plan, settings, lambda _, p: read_point(folder, p) is not None)


def run_design_map(
    folder,
    robot: Robot,
    speeds,
    r1=None,
    r2=None,
    criterion: str = "sthenic",
    safety: Safety = PAPER_SAFETY,
    upper=None,
    seed: int = 0,
    starts: int = DEFAULT_STARTS,
    **where,
) -> MapSettings:
    """Every optimization of the map not yet in ``folder``; returns its settings.

    Args:
        speeds: walking speeds [m/s].
        r1, r2: the grid's radii [m] (default ``DEFAULT_GRID`` from 0 to the upper bound).
        upper: the design's upper bounds of (r1, r2) [m] (default ``radius_limits``).
        where: where the map runs (``jobs``, ``dask``, ``stream``, ``progress``), as
            ``campaign.Campaign.run`` says.
    """
    speeds = campaign.distinct_speeds(speeds)
    problem = DesignProblem(robot, speeds[0], criterion, safety, upper=upper)
    for speed in speeds[1:]:
        problem = dataclasses.replace(problem, speed=speed)  # each speed checked
    upper = problem.upper
    r1 = radius_grid(robot, np.linspace(0.0, upper[0], DEFAULT_GRID) if r1 is None else r1, "r1")
    r2 = radius_grid(robot, np.linspace(0.0, upper[1], DEFAULT_GRID) if r2 is None else r2, "r2")
    upper, seed, starts = tuple(upper), int(seed), int(starts)
    settings = MapSettings(robot, criterion, safety, tuple(speeds), r1, r2, upper, seed, starts)
    with claimed(folder):  # one run at a time on the folder
        folder = MAP.claim(folder, settings)  # checked before the folder is made
        stages = map_stages(folder, settings)
        total, remaining = sum(map(len, map_points(settings))), sum(map(len, stages))
        plan = (
            f"design map: {total} optimizations in {folder}, {total - remaining} already done, "
            f"{remaining} to run"
        )
        MAP.run(plan, stages, lambda: summarize(folder, settings), **where)
    return settings


def load(folder) -> tuple[MapSettings, dict]:
    """The settings of the map in ``folder`` and its results {MapPoint: content}."""
    folder = Path(folder)
    try:
        settings = MapSettings.from_dict(json.loads((folder / MANIFEST).read_text()))
    except (OSError, ValueError, UnicodeDecodeError, KeyError, TypeError, BipedError) as error:
        raise BipedError(
            f"{folder / MANIFEST}: no design map there ({error}): run 'biped design-map'"
        ) from None
    first, second = map_points(settings)
    contents = {point: read_point(folder, point) for point in first + second}
    return settings, {point: c for point, c in contents.items() if c is not None}


def summarize(folder, settings: MapSettings) -> str:
    """How many optimizations are certified, and which are not."""
    first, second = map_points(settings)

    def why_not(point):
        content = read_point(Path(folder), point)
        if content is None:
            return "missing"
        return campaign.failure(content["status"], content["feasible"])

    counted = "optimizations certified (converged and feasible)"
    return campaign.tally(first + second, why_not, counted, most=5)


@dataclass(frozen=True)
class SpeedSummary:
    """The map's answer at one speed: optimal radii and criteria (None where the
    optimization was not certified)."""

    speed: float
    radii: tuple | None
    design: float | None
    table1: float | None
    revolute: float | None
    best_grid: float | None

    def gain(self, value: float | None) -> float | None:
        """[%] Change of ``value`` against the revolute knee
        (``biped.optimization.comparison.relative_change``: negative, ``value`` is the smaller)."""
        if value is None or self.revolute is None:
            return None
        return relative_change(value, self.revolute)


def speed_summaries(settings: MapSettings, results: dict) -> list[SpeedSummary]:
    def value(point):
        content = results.get(point)
        return content["value"] if content is not None and content["certified"] else None

    summaries = []
    for speed in settings.speeds:
        design = results.get(MapPoint("design", speed))
        radii = tuple(design["radii"]) if design is not None and design["certified"] else None
        grid = [value(MapPoint("grid", speed, (a, b))) for a in settings.r1 for b in settings.r2]
        best = min((v for v in grid if v is not None), default=None)
        values = {kind: value(MapPoint(kind, speed)) for kind in ("design", "table1", "revolute")}
        summaries.append(SpeedSummary(speed, radii, **values, best_grid=best))
    return summaries


def summary_csv(settings: MapSettings, results: dict) -> str:
    criterion = settings.criterion
    lines = [
        f"speed [m/s],r1 [m],r2 [m],{criterion} design,{criterion} table1,{criterion} revolute,"
        f"best grid,design vs revolute [%],table1 vs revolute [%]"
    ]

    def text(value, digits=6):
        return "" if value is None else f"{value:.{digits}f}"

    for s in speed_summaries(settings, results):
        r1, r2 = s.radii if s.radii is not None else (None, None)
        cells = [s.speed, r1, r2, s.design, s.table1, s.revolute, s.best_grid]
        cells += [s.gain(s.design), s.gain(s.table1)]
        digits = (3, 4, 4, 6, 6, 6, 6, 3, 3)
        lines.append(",".join(text(v, d) for v, d in zip(cells, digits, strict=True)))
    return "\n".join(lines) + "\n"
