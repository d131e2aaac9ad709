"""Sweeps of certified optimal gaits over walking speed, both knees and both criteria.

Every point (knee, criterion, speed) is solved twice:

1. independent: IPOPT from the point's own starts (``biped.optimization.optimize.optimize``);
   the result is kept in the hidden folder ``.independent/``. The energy criterion also starts from
   the sthenic optimum of its problem: the sthenic point's independent optimum, read from
   there (the same numbers as computed again);
2. neighbours: IPOPT again from the independent optima of the neighbouring speeds of the
   same series and of the other knee at the same speed; the best of both is the point's
   gait file.

The solves run in three waves (``biped.studies.staging``), each task of a wave independent of
the others, so they run in parallel (``biped.runtime.runner``: on all cores, or on the
workers of a Dask cluster): the sthenic independent optima; the energy independent optima
with the sthenic neighbours' solves; the energy neighbours' solves. Each result depends only
on files of the waves before, which are written whole (``biped.runtime.files``), so a sweep
stopped at any moment and run again ends with exactly the files of an uninterrupted sweep.
The folder's ``sweep.json`` records what shapes the numbers (robot, safety, speeds, seed,
starts, gait family, method, versions); resuming with any of them changed is refused. Points
whose solver did not converge, or whose optimum is infeasible, are saved with their status
and counted in the summary; they are not optimised again.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from biped.errors import BipedError
from biped.model.bezier import Bezier
from biped.model.criteria import (
    ALL_CRITERIA,
    CRITERIA,
    CRITERION_UNITS,
    PAPER_SAFETY,
    Safety,
)
from biped.model.dynamics import Biped
from biped.model.gait import check_knots, family_label
from biped.model.kinematics import KNEES
from biped.model.robot import Robot
from biped.optimization import table
from biped.optimization.comparison import SINGLE_START
from biped.optimization.optimize import (
    DEFAULT_STARTS,
    Optimum,
    apart_from_table,
    best_of,
    checked,
    confirm,
    optimize,
    single_start_note,
)
from biped.optimization.problem import GaitProblem, check_speed
from biped.records import gait_file
from biped.runtime.claims import claimed
from biped.studies import campaign, staging
from biped.studies.campaign import Task

DEFAULT_SPEEDS = np.round(np.linspace(0.15, 0.45, 13), 6)  # [m/s], every 0.025 m/s
MANIFEST = "sweep.json"
SWEEP = campaign.Campaign(
    "sweep", MANIFEST, "sweep record", "this folder's sweep was", "a sweep's", "gait files"
)
INDEPENDENT = ".independent"


@dataclass(frozen=True)
class Point:
    knee: str
    criterion: str
    speed: float

    def filename(self) -> str:
        return f"{self.knee}-{self.criterion}-{self.speed:.3f}.json"


@dataclass(frozen=True)
class Settings(campaign.Settings):
    """What shapes a sweep's numbers, recorded in its folder."""

    # 3: a robot without actuators has the catalog's default set (biped-gait/3)
    FORMAT = "biped-sweep/3"
    robot: Robot
    safety: Safety
    speeds: tuple  # [m/s], sorted
    seed: int  # of every optimization's perturbed starts
    starts: int  # every point's own starts
    # the gaits' family (``biped.model.gait``): a spline's interior knots, or a ``Bezier``
    knots: int | Bezier = 1


def _problem(settings: Settings, point: Point) -> GaitProblem:
    model = Biped(settings.robot, point.knee)
    return GaitProblem(model, point.speed, point.criterion, settings.safety, knots=settings.knots)


def _read_gait(path: Path, point: Point, settings: Settings):
    """The gait saved at ``path`` or None if missing or unreadable."""
    try:
        gait = gait_file.read(path)
    except BipedError:
        return None
    found = (gait.knee, gait.criterion, gait.speed)
    same = gait.robot == settings.robot and gait.safety == settings.safety
    same = same and gait.knots == settings.knots
    if found != (point.knee, point.criterion, point.speed) or not same:
        raise BipedError(
            f"{path} holds a gait of another robot, safety or point ({found[0]}, "
            f"{found[1]}, {found[2]} m/s): allowed only this sweep's, choose another --out folder"
        )
    return gait


def _optimum_of(gait: gait_file.Gait, settings: Settings, point: Point) -> Optimum:
    """The ``Optimum`` stored in a gait file (same numbers: JSON keeps every bit)."""
    variables = campaign.variables(gait.optimizer.variables)
    return checked(_problem(settings, point), variables, gait.optimizer.report())


def solve_independent(task: Task) -> str:
    """A point's own starts, in ``INDEPENDENT`` (``task.folder``); the energy criterion's also
    from the sthenic optimum of its problem (``task.given``), solved."""
    settings, point = task.settings, task.point
    sthenic = None
    for twin in task.given:
        gait = gait_file.read(Path(task.folder) / twin.filename())
        if campaign.variables(gait.optimizer.variables) is not None:  # else computed again
            sthenic = _optimum_of(gait, settings, twin)
    problem = _problem(settings, point)
    optimum = optimize(problem, seed=settings.seed, starts=settings.starts, sthenic=sthenic)
    gait_file.Gait.from_optimum(optimum, settings.robot).write(task.path)
    return _line("independent", point, optimum)


def _solve_with_neighbours(task: Task) -> str:
    """A point's final optimum: its own, or better from its neighbours' (``task.given``)."""
    settings, point, stage = task.settings, task.point, Path(task.folder) / INDEPENDENT
    own = _optimum_of(gait_file.read(stage / point.filename()), settings, point)
    given = [
        campaign.variables(gait_file.read(stage / p.filename()).optimizer.variables)
        for p in task.given
    ]
    problem = _problem(settings, point)
    # the table's starts were among the point's own (stage 1): a given one of them is that start
    given = apart_from_table(problem, [v for v in given if v is not None])
    optimum = own
    if given:
        again = optimize(problem, seed=settings.seed, starts=0, given=given)
        optimum = best_of(problem, [own, again])
    optimum = confirm(problem, optimum, given)  # a best reached by one start tried again
    gait_file.Gait.from_optimum(optimum, settings.robot).write(task.path)
    return _line("final", point, optimum)


# What each stage's line calls its result: only the final stage's optimum is a point's
# answer, so only it may be called certified (``biped.optimization.comparison.CERTIFIED``).
STAGES = {"independent": "own starts, stage 1/2", "final": "final, stage 2/2"}


def _line(stage: str, point: Point, optimum: Optimum) -> str:
    """One optimization's line: its stage, the criterion on the check grid with its unit,
    what the result is (only a final one is "certified") and the starts at its value."""
    report = optimum.report
    status = campaign.failure(report.status, optimum.feasible)
    if stage == "final":
        single = f" ({SINGLE_START})" if report.starts_at_best < 2 else ""
        status = "certified" + single if status is None else "NOT CERTIFIED, " + status
    elif status is None:
        status = "converged, feasible, not final"
    return (
        f"[{STAGES[stage]:21}] {point.knee:8} {point.criterion:7} {point.speed:.3f} m/s  "
        f"C = {optimum.value:12.6f} {CRITERION_UNITS[point.criterion]:6} on the check grid: "
        f"{status}; {report.starts_at_best}/{report.starts} starts at best  "
        f"{report.seconds:5.1f} s"
    )


def sweep_settings(
    robot: Robot,
    speeds=DEFAULT_SPEEDS,
    seed: int = 0,
    starts: int = DEFAULT_STARTS,
    safety: Safety = PAPER_SAFETY,
    knots: int | Bezier = 1,
) -> Settings:
    """The settings of a sweep (``run_sweep``), its speeds sorted, each walkable by either knee
    and with its own file name; a clear error if not. ``seed`` and ``starts`` go to
    ``biped.optimization.optimize.optimize``."""
    speeds = sorted(float(s) for s in speeds)
    for knee in KNEES:
        model = Biped(robot, knee)
        for speed in speeds:
            check_speed(model, speed)
    speeds = campaign.distinct_speeds(speeds)
    return Settings(robot, safety, tuple(speeds), int(seed), int(starts), check_knots(knots))


def check_sweep(folder, settings: Settings) -> None:
    """Raise the BipedError ``run_sweep`` would raise on the folder's record, writing
    nothing: a command checks the sweep before what follows from it."""
    SWEEP.check(folder, settings.to_dict())


def run_sweep(folder: Path, settings: Settings, knees=KNEES, criteria=CRITERIA, **where):
    """Certified optima of every (knee, criterion, speed) of ``settings`` (``sweep_settings``)
    not yet in ``folder``; returns all points. ``where`` the sweep runs (``jobs``, ``dask``,
    ``stream`` of a line per optimization, ``progress`` over the optimizations of all stages)
    as ``campaign.Campaign.run`` says."""
    if len(set(knees)) != len(knees) or len(set(criteria)) != len(criteria):
        raise BipedError(f"knees {list(knees)}, criteria {list(criteria)}: allowed each once")
    with claimed(folder):  # one run at a time on the folder
        folder = SWEEP.claim(folder, settings, INDEPENDENT)  # checked before anything is written
        points = [Point(k, c, s) for c in criteria for k in knees for s in settings.speeds]
        final = [p for p in points if _read_gait(folder / p.filename(), p, settings) is None]
        saved = {p for p in points if _read_gait(folder / INDEPENDENT / p.filename(), p, settings)}
        stages = sweep_stages(folder, settings, points, final, knees, saved)
        plan = _plan(folder, points, final, stages, saved)
        SWEEP.run(plan, stages, lambda: summarize(folder, points, settings), **where)
    return points


def _plan(folder: Path, points, final, stages, saved: set) -> str:
    """What the sweep will do, counted in optimizations as its progress bar counts them: two
    per point, in the stages of its lines (``STAGES``: own starts, then final), those of
    each stage already in the folder (``saved``: the points with an independent optimum),
    and those to run (the bar's total)."""
    done = {"independent": len(saved), "final": len(points) - len(final)}
    to_run = sum(len(tasks) for tasks in stages)
    unneeded = 2 * len(points) - sum(done.values()) - to_run  # stage 1 of finished points
    text = (
        f"sweep: {2 * len(points)} optimizations for {len(points)} "
        f"point{'' if len(points) == 1 else 's'} in {folder}, in 2 "
        f"stages (own starts, final): {sum(done.values())} already done "
        f"({done['independent']} of stage 1, {done['final']} of stage 2), {to_run} to run"
    )
    if unneeded:
        text += f", {unneeded} of stage 1 not needed (their points are final)"
    return text


def sweep_stages(folder: Path, settings: Settings, points, final, knees, saved: set) -> list:
    """The tasks still to run, in waves (``staging.schedule``) whose tasks are independent of
    each other and depend only on the files of the waves before: the sthenic independent
    optima; the energy ones (each started from the sthenic optimum of its problem, when the
    sweep has that criterion) with the sthenic finals; the energy finals. ``final``: the
    points without a final optimum; ``saved``: those whose independent optimum is in the
    folder. An independent optimum is solved only where a final still to run reads it."""
    criteria = sorted({p.criterion for p in points})
    own = staging.Seed(INDEPENDENT, lambda p: (p,))
    stages = [
        staging.Stage(
            INDEPENDENT,
            solve_independent,
            str(folder / INDEPENDENT),
            tuple(points),
            given=staging.Seed(INDEPENDENT, staging.sthenic_twin(criteria)),
            needed_only=True,
        ),
        staging.Stage(
            "final",
            _solve_with_neighbours,
            str(folder),
            tuple(points),
            given=staging.Seed(INDEPENDENT, neighbourhood(settings.speeds, knees).of),
            reads=own,
        ),
    ]
    pending = set(final)

    def done(stage: staging.Stage, point: Point) -> bool:
        return point in saved if stage.name == INDEPENDENT else point not in pending

    return staging.schedule(stages, settings, done)


def neighbourhood(speeds, knees) -> staging.Neighbours:
    """The neighbours of a point whose independent optima start its second solve: the
    neighbouring speeds of its series, and the same speed with the other knees (the
    variables mean the same for both knees)."""
    return staging.Neighbours(
        steps=(staging.Axis("speed", tuple(speeds)),), across=(staging.Axis("knee", tuple(knees)),)
    )


def neighbours(point: Point, speeds, knees) -> list[Point]:
    """The points whose independent optima start ``point``'s second solve
    (``neighbourhood``)."""
    return neighbourhood(speeds, knees).of(point)


def optima_table(folder) -> dict:
    """The table of optima (``biped.optimization.table``) of the sweep in ``folder``: its
    final optima that are certified, by knee and criterion."""
    folder = Path(folder)
    found = SWEEP.read(folder)
    if found is None:
        raise BipedError(f"{folder} has no {MANIFEST}: allowed a folder biped sweep wrote")
    if found.get("format") != Settings.FORMAT:
        raise BipedError(
            f"{folder / MANIFEST} has format {found.get('format')!r}, another version's: "
            f"allowed a sweep of format {Settings.FORMAT!r} (run biped sweep again)"
        )
    settings = Settings.from_dict(found)
    if settings.knots != 1:
        raise BipedError(
            f"{folder / MANIFEST}: a sweep of the family {family_label(settings.knots)}: allowed "
            "a sweep of the paper's spline (knots 1), whose variables the table holds"
        )
    series: dict = {}
    for criterion in ALL_CRITERIA:
        for knee in KNEES:
            for speed in settings.speeds:
                point = Point(knee, criterion, speed)
                gait = _read_gait(folder / point.filename(), point, settings)
                if gait is None or campaign.failure(gait.optimizer.status, gait.feasible):
                    continue
                optimum = campaign.variables(gait.optimizer.variables)
                series.setdefault((knee, criterion), []).append((speed, optimum))
    source = f"the certified final optima of the sweep in {folder.name}/ ({MANIFEST})"
    return table.content(series, settings.robot, settings.safety, source)


def _why_not(folder: Path, points, settings: Settings):
    """The points' final gait files (None: missing) and why a point is not certified (None:
    it is)."""
    gaits = {p: _read_gait(Path(folder) / p.filename(), p, settings) for p in points}

    def why_not(p):
        gait = gaits[p]
        if gait is None:
            return "missing"
        return campaign.failure(gait.optimizer.status, gait.feasible)

    return gaits, why_not


def uncertified(folder: Path, points, settings: Settings) -> list[Point]:
    """The points whose final optimum is missing, did not converge or is infeasible."""
    _, why_not = _why_not(folder, points, settings)
    return [p for p in points if why_not(p) is not None]


def summarize(folder: Path, points, settings: Settings) -> str:
    """How many points are certified, and which are not."""
    gaits, why_not = _why_not(folder, points, settings)

    single = [
        f"{p.filename()} ({single_start_note(gaits[p].optimizer.report())})"
        for p in points
        if why_not(p) is None and gaits[p].optimizer.starts_at_best < 2
    ]
    note = f"; {len(single)} of them {SINGLE_START}: " + ", ".join(single) if single else ""
    counted = "points certified (final optima, solver converged, feasible on the check grid)"
    return campaign.tally(points, why_not, counted, note)
