"""A sweep with double support (``biped sweep --double-support LOW:HIGH``): at each speed and
knee the two-phase optimum (single then double support, sthenic criterion,
``biped.optimization.two_phase.optimize_two_phase``) started from the sweep's certified
single-support optimum of the same point, beside it.

On the campaign mechanism (``campaign``): the sweep's folder holds the single-support optima
(``biped.studies.sweep``); its ``double-support/`` folder (``FOLDER``) holds this campaign's
record (``two_phase.json``: robot, safety, speeds, seed, starts, share range, landing,
versions; a resume with any of them changed is refused), a file per point (the two-phase
gait file, or a failure record saying why there is none: its single support not certified,
or no start converged to an optimum feasible on the numeric model) and ``summary.json``
(``biped.records.two_phase_sweep``: per point C_Γ over the step, the double support's share,
the step length and cadence of both optima; per speed the knees' difference with and
without the phase). The points run in parallel (``--jobs``, Dask), each written whole, so a
run stopped at any moment and run again ends with the files of an uninterrupted one.
"""

from __future__ import annotations

import json
from dataclasses import dataclass
from pathlib import Path

from biped.errors import BipedError
from biped.model.criteria import Safety
from biped.model.dynamics import Biped
from biped.model.robot import Robot
from biped.model.two_phase import check_landing
from biped.optimization.comparison import relative_change
from biped.optimization.problem import GaitProblem
from biped.optimization.solver import one_blas_thread
from biped.optimization.two_phase import TwoPhaseProblem, TwoPhaseSolver, optimize_two_phase
from biped.records import gait_file, two_phase_file
from biped.records.gait_file import Gait
from biped.records.two_phase_sweep import KneeDifference, Phases, PointSummary
from biped.records.two_phase_sweep import TwoPhaseSweepSummary as Summary
from biped.runtime.claims import claimed
from biped.runtime.files import atomic_write_text
from biped.studies import campaign, sweep
from biped.studies.campaign import Task

FOLDER = "double-support"
RECORD = "two_phase.json"
SUMMARY = "summary.json"
FIGURE = "double_support.png"
FAILURE = "biped-two-phase-failure/1"  # a point's file when it has no two-phase optimum
CRITERION = "sthenic"  # the only criterion the two-phase problem has
TWO_PHASE = campaign.Campaign(
    "double support",
    RECORD,
    "two-phase sweep record",
    "this folder's two-phase sweep was",
    "a two-phase sweep's",
    "two-phase gait files",
)


@dataclass(frozen=True)
class Point:
    knee: str
    speed: float  # [m/s]

    def filename(self) -> str:
        return f"{self.knee}-{CRITERION}-{self.speed:.3f}.json"

    def single(self) -> sweep.Point:
        """The sweep's point of the same knee and speed."""
        return sweep.Point(self.knee, CRITERION, self.speed)


@dataclass(frozen=True)
class Settings(campaign.Settings):
    """What shapes the two-phase optima, recorded in ``FOLDER``."""

    FORMAT = "biped-two-phase-sweep/1"
    robot: Robot
    safety: Safety
    speeds: tuple  # [m/s], sorted
    seed: int  # of every optimization's perturbed starts
    starts: int  # each point's starts (the single-support optimum, then perturbations)
    share: tuple  # (least, largest) T_ds / (T + T_ds) [1]
    landing: str  # "impact" or "zero-speed" (``biped.model.two_phase.LANDINGS``)


def two_phase_settings(sweep_settings: sweep.Settings, share, landing: str) -> Settings:
    """The two-phase settings of a sweep's (its robot, safety, speeds, seed, starts); the
    problem's refusals (another gait family, walkable constraints) raised before any work."""
    s = sweep_settings
    settings = Settings(
        s.robot, s.safety, s.speeds, s.seed, s.starts, tuple(map(float, share)), landing
    )
    check_landing(landing)
    if s.knots != 1:
        raise BipedError(f"--double-support with the family {s.knots!r}: allowed --knots 1")
    _problem(settings, Point("revolute", s.speeds[0]))  # its refusals, by name
    return settings


def _problem(settings: Settings, point: Point) -> TwoPhaseProblem:
    single = GaitProblem(Biped(settings.robot, point.knee), point.speed, CRITERION, settings.safety)
    return TwoPhaseProblem(single, settings.share, landing=settings.landing)


def check_two_phase(sweep_folder, settings: Settings) -> None:
    """Raise the BipedError ``run_two_phase`` would raise on the folder's record."""
    TWO_PHASE.check(Path(sweep_folder) / FOLDER, settings.to_dict())


def _single(folder: Path, point: Point) -> Gait | None:
    """The sweep's single-support gait of ``point`` (``folder``: the sweep's), None if missing."""
    path = folder / point.single().filename()
    return gait_file.read(path) if path.exists() else None


def solve_two_phase(task: Task) -> str:
    """A point's two-phase optimum from its certified single-support optimum, written as a
    gait file; a failure record where there is none (``solve_from_single``)."""
    settings, point = task.settings, task.point
    single = _single(Path(task.folder).parent, point)
    return solve_from_single(
        single,
        lambda: _problem(settings, point),
        settings,
        task.path,
        f"{point.knee:8} {point.speed:.3f} m/s",
        {"knee": point.knee, "speed": point.speed},
    )


def solve_from_single(
    single: Gait | None, problem, settings, path: Path, label: str, identity: dict
) -> str:
    """The two-phase optimum of ``problem()`` (built only when ``single`` is a certified
    single-support optimum) from ``single``, ``settings.starts`` starts seeded by
    ``settings.seed``, written as the gait file ``path``; else a failure record there
    (``identity``, the point's fields, and why). Returns the point's line (``label``)."""
    why = "single support missing" if single is None else None
    if single is not None:
        why = campaign.failure(single.optimizer.status, single.feasible)
        why = None if why is None else f"single support {why}"
    if why is None:
        # MUMPS on one thread, as every single-support solve runs it: a resumed run's
        # process, which solved no single support, gives the same bits (else 4e-14 of C_Γ)
        one_blas_thread()
        built = problem()
        variables = campaign.variables(single.optimizer.variables)
        result = optimize_two_phase(
            TwoPhaseSolver(built), variables, single.costs.sthenic, settings.starts, settings.seed
        )
        if result.best is None:
            why = (
                f"NOT CONVERGED or INFEASIBLE: {result.converged} of {result.starts} starts "
                f"converged, {result.feasible} feasible ({'; '.join(result.outcomes)})"
            )
        else:
            gait = two_phase_file.gait_of(built, result, settings.seed)
            gait.write(path)
            double = gait.double_support
            return (
                f"[two phases] {label}  C = {double.sthenic:12.6f} "
                f"N²·m·s over the step, share {double.share:.4f} (single support alone "
                f"{single.costs.sthenic:.6f}); {result.at_best}/{result.starts} starts at best"
            )
    record = {"format": FAILURE, **identity, "why": why}
    atomic_write_text(path, json.dumps(record, indent=1))
    return f"[two phases] {label}  NO OPTIMUM: {why}"


def read_two_phase(path: Path) -> tuple[Gait | None, str]:
    """A point's two-phase gait file (None: none) and why not ("" when there is one;
    "missing" when the file is)."""
    if not path.exists():
        return None, "missing"
    try:
        content = json.loads(path.read_text())
    except (OSError, ValueError) as error:
        raise BipedError(f"{path}: unreadable ({error}): allowed a two-phase gait file") from None
    if isinstance(content, dict) and content.get("format") == FAILURE:
        return None, str(content["why"])
    return Gait.read(path, two_phase=True), ""


def _two_phase(folder: Path, point: Point) -> tuple[Gait | None, str]:
    """A point's two-phase gait (None: none) and why not ("" when there is one)."""
    return read_two_phase(folder / point.filename())


def run_two_phase(sweep_folder, settings: Settings, knees, **where) -> Summary:
    """The two-phase optimum of every knee and speed of ``settings`` not yet in the sweep's
    ``FOLDER``, from the sweep's single-support optima (run first); ``where`` as
    ``campaign.Campaign.run`` says. Writes and returns the summary."""
    points = [Point(k, s) for k in knees for s in settings.speeds]
    return run_points(
        Path(sweep_folder) / FOLDER,
        TWO_PHASE,
        settings,
        points,
        solve_two_phase,
        lambda: summarize(Path(sweep_folder), settings, points),
        **where,
    )


def run_points(folder: Path, kind, settings, points, solve, summary, **where):
    """The double support's campaign (``kind``, a ``campaign.Campaign``) in ``folder``: the
    two-phase optimum of every point of ``points`` (each with ``filename()``) whose file is
    not there yet, each a task of ``solve``; then ``summary()`` (a record with ``write``)
    written as ``SUMMARY`` there and returned. One run of it at a time (``claimed``);
    ``where`` as ``campaign.Campaign.run`` says."""
    with claimed(folder):
        folder = kind.claim(folder, settings)
        todo = [p for p in points if not (folder / p.filename()).exists()]
        tasks = [Task(solve, settings, p, str(folder)) for p in todo]
        plan = (
            f"double support: {len(points)} two-phase optimizations in {folder}, "
            f"{len(points) - len(todo)} already done, {len(todo)} to run"
        )

        def tally() -> str:
            return campaign.tally(
                points,
                lambda p: read_two_phase(folder / p.filename())[1] or None,
                "points with a two-phase optimum (converged, feasible on the numeric model)",
            )

        kind.run(plan, [tasks] if tasks else [], tally, **where)
        written = summary()
        written.write(folder / SUMMARY)
    return written


def phases_of(gait: Gait | None, two_phase: bool) -> Phases | None:
    """The step of a gait (``Phases``), single support alone or ``two_phase``; None for
    None."""
    if gait is None:
        return None
    if not two_phase:
        costs = gait.costs
        return Phases(
            costs.sthenic, 0.0, gait.step_length, 60.0 / gait.period, costs.energy_per_metre
        )
    double = gait.double_support
    step = gait.period + double.duration
    return Phases(
        double.sthenic, double.share, gait.step_length, 60.0 / step, double.energy_per_metre
    )


def summarize(sweep_folder: Path, settings: Settings, points) -> Summary:
    """The summary of the points' optima, both supports (``biped.records.two_phase_sweep``)."""
    rows = []
    for point in points:
        single = _single(sweep_folder, point)
        if single is not None and campaign.failure(single.optimizer.status, single.feasible):
            single = None
        double, why = _two_phase(sweep_folder / FOLDER, point)
        rows.append(
            PointSummary(
                point.knee,
                point.speed,
                phases_of(single, False),
                phases_of(double, True),
                why,
            )
        )
    return Summary(settings.share, settings.landing, tuple(rows), differences(rows))


def differences(rows) -> tuple:
    """Per speed with both knees, (rolling − revolute) / revolute of C_Γ [%] with and without
    double support (None where either is unknown)."""
    by = {(row.knee, row.speed): row for row in rows}
    speeds = sorted({row.speed for row in rows})
    found = []
    for speed in speeds:
        rolling, revolute = by.get(("rolling", speed)), by.get(("revolute", speed))
        if rolling is None or revolute is None:
            continue

        found.append(
            KneeDifference(
                speed,
                *(_change(rolling, revolute, phase) for phase in ("single", "double")),
                *(_change(rolling, revolute, p, "energy_per_metre") for p in ("single", "double")),
            )
        )
    return tuple(found)


def _change(
    rolling: PointSummary, revolute: PointSummary, phase: str, figure: str = "sthenic"
) -> float | None:
    """[%] (rolling − revolute) / revolute of one ``phase``'s ``figure``; None if either is
    unknown."""
    a, b = getattr(rolling, phase), getattr(revolute, phase)
    a, b = (None if x is None else getattr(x, figure) for x in (a, b))
    return None if a is None or b is None else relative_change(a, b)
