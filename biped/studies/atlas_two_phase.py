"""An atlas with double support (``biped atlas --double-support LOW:HIGH``): at every cell of
the atlas where the two-phase problem is built (sthenic criterion, the paper's spline, the
paper's constraints: ``biped.optimization.two_phase.TwoPhaseProblem`` refuses the rest by
name), each knee's two-phase optimum started from the cell's certified single-support optimum
(the sweep's solve, ``biped.studies.two_phase_sweep.solve_from_single``), beside it.

On the campaign mechanism (``campaign``): the atlas's folder holds its single-support optima
(``biped.studies.atlas``); its ``double-support/`` folder (``FOLDER``) holds this campaign's
record (``two_phase.json``: robot, margins, the cells, seed, starts, share range, landing,
versions; a resume with any of them changed is refused), a file per cell and knee (the
two-phase gait file, or a failure record saying why there is none) and ``summary.json``
(``biped.records.atlas_two_phase``: per cell the knees' step with and without the phase, the
rolling knee's difference and what the phase does to it, the cells not built and why). The
points run in parallel (``--jobs``, Dask), each written whole, so a run stopped at any moment
and run again ends with the files of an uninterrupted one.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from biped.errors import BipedError
from biped.model.criteria import Safety
from biped.model.kinematics import KNEES
from biped.model.robot import Robot
from biped.model.two_phase import check_landing
from biped.optimization.two_phase import TwoPhaseProblem
from biped.records import gait_file
from biped.records.atlas_two_phase import AtlasTwoPhaseSummary as Summary
from biped.records.atlas_two_phase import CellDifference, CellPoint, NotBuilt
from biped.records.two_phase_sweep import PointSummary
from biped.studies import atlas, campaign, two_phase_sweep
from biped.studies.campaign import Task

FOLDER = two_phase_sweep.FOLDER
RECORD = two_phase_sweep.RECORD
SUMMARY = two_phase_sweep.SUMMARY
FIGURE = two_phase_sweep.FIGURE
CRITERION = two_phase_sweep.CRITERION
TWO_PHASE = campaign.Campaign(
    "double support",
    RECORD,
    "atlas two-phase record",
    "this folder's atlas double support was",
    "an atlas double support's",
    "two-phase gait files",
)


@dataclass(frozen=True)
class Point:
    """A knee's two-phase optimum at a cell of the atlas."""

    knee: str
    cell: atlas.Cell

    def filename(self) -> str:
        return f"{self.knee}-{CRITERION}-{self.cell.name()}.json"

    def single(self) -> atlas.Point:
        """The atlas's final single-support optimum of the same knee and cell."""
        return atlas.Point("final", self.knee, CRITERION, self.cell)


@dataclass(frozen=True)
class Settings(campaign.Settings):
    """What shapes the two-phase optima, recorded in ``FOLDER``: the atlas's robot, base
    margins, cells, seed and starts (``of_atlas``), the share range and landing."""

    FORMAT = "biped-atlas-two-phase/1"
    robot: Robot
    safety: Safety  # the atlas's base margins, each cell's clearance and bend replacing its
    speeds: tuple  # [m/s]
    clearances: tuple  # [m]
    knee_bends: tuple  # [rad]
    seed: int
    starts: int
    share: tuple  # (least, largest) T_ds / (T + T_ds) [1]
    landing: str  # "impact" or "zero-speed" (``biped.model.two_phase.LANDINGS``)

    def atlas_settings(self) -> atlas.Settings:
        """The atlas's settings of its sthenic cells (what ``problem`` builds on)."""
        return atlas.Settings(
            self.robot,
            self.speeds,
            self.clearances,
            self.knee_bends,
            (CRITERION,),
            1,
            self.seed,
            self.starts,
            safety=self.safety,
        )

    def problem(self, point: Point, criterion: str = CRITERION) -> TwoPhaseProblem:
        """The two-phase problem at ``point``'s cell (a BipedError where it is not built)."""
        single = self.atlas_settings().problem(
            atlas.Point("final", point.knee, criterion, point.cell)
        )
        return TwoPhaseProblem(single, self.share, landing=self.landing)


def of_atlas(settings: atlas.Settings, share, landing: str) -> Settings:
    """The two-phase settings of an atlas's; a BipedError, before any work, where no cell of
    it builds the two-phase problem (``not_built`` says why for each)."""
    check_landing(landing)
    s = settings
    ours = Settings(
        s.robot,
        s.safety,
        s.speeds,
        s.clearances,
        s.knee_bends,
        s.seed,
        s.starts,
        tuple(map(float, share)),
        landing,
    )
    if not built_cells(settings, ours):
        whys = sorted({n.why for n in not_built(settings, ours)})
        raise BipedError(f"--double-support: no cell of the atlas builds it ({'; '.join(whys)})")
    return ours


def _why_not(settings: atlas.Settings, ours: Settings, criterion: str, cell) -> str | None:
    """Why the two-phase problem is not built at a cell and criterion (None: it is)."""
    if settings.knots != 1:
        return f"the gait family {settings.knots!r} (allowed the paper's spline, knots 1)"
    if settings.actuator_limits:
        return "actuator limits (allowed none)"
    try:
        single = settings.problem(atlas.Point("final", KNEES[0], criterion, cell))
        TwoPhaseProblem(single, ours.share, landing=ours.landing)
    except BipedError as error:
        return str(error)
    return None


def not_built(settings: atlas.Settings, ours: Settings) -> list[NotBuilt]:
    """Each criterion and cell of the atlas without a two-phase problem, and why."""
    found = []
    for criterion in settings.criteria:
        for cell in settings.cells():
            why = _why_not(settings, ours, criterion, cell)
            if why is not None:
                found.append(NotBuilt(criterion, cell.speed, cell.clearance, cell.knee_bend, why))
    return found


def built_cells(settings: atlas.Settings, ours: Settings) -> list[atlas.Cell]:
    """The atlas's cells whose two-phase problem is built (its sthenic ones, if any)."""
    if CRITERION not in settings.criteria:
        return []
    return [c for c in settings.cells() if _why_not(settings, ours, CRITERION, c) is None]


def check_two_phase(atlas_folder, settings: Settings) -> None:
    """Raise the BipedError ``run_two_phase`` would raise on the folder's record."""
    TWO_PHASE.check(Path(atlas_folder) / FOLDER, settings.to_dict())


def _single(atlas_folder: Path, point: Point) -> gait_file.Gait | None:
    """The atlas's single-support gait of ``point``, None if missing."""
    path = atlas_folder / point.single().gait_filename()
    return gait_file.read(path) if path.exists() else None


def solve_two_phase(task: Task) -> str:
    """A knee's two-phase optimum at a cell from the atlas's certified single-support optimum
    there, written as a gait file; a failure record where there is none."""
    settings, point, cell = task.settings, task.point, task.point.cell
    return two_phase_sweep.solve_from_single(
        _single(Path(task.folder).parent, point),
        lambda: settings.problem(point),
        settings,
        task.path,
        f"{point.knee:8} {cell.speed:.3f} m/s clearance {100 * cell.clearance:4.1f} cm "
        f"bend {cell.knee_bend:.3f} rad",
        {
            "knee": point.knee,
            "speed": cell.speed,
            "clearance": cell.clearance,
            "knee_bend": cell.knee_bend,
        },
    )


def run_two_phase(atlas_folder, atlas_settings: atlas.Settings, settings: Settings, **where):
    """The two-phase optimum of both knees at every built cell of the atlas not yet in its
    ``FOLDER``, from the atlas's single-support optima (run first); ``where`` as
    ``campaign.Campaign.run`` says. Writes and returns the summary."""
    cells = built_cells(atlas_settings, settings)
    return two_phase_sweep.run_points(
        Path(atlas_folder) / FOLDER,
        TWO_PHASE,
        settings,
        [Point(k, c) for c in cells for k in KNEES],
        solve_two_phase,
        lambda: summarize(Path(atlas_folder), settings, cells, not_built(atlas_settings, settings)),
        **where,
    )


def summarize(atlas_folder: Path, settings: Settings, cells, missing) -> Summary:
    """The summary of the cells' optima, both supports, and of the cells ``missing`` (not
    built)."""
    points, differences = [], []
    for cell in cells:
        rows = [_row(atlas_folder, Point(knee, cell)) for knee in KNEES]
        points += [CellPoint(cell.clearance, cell.knee_bend, row) for row in rows]
        differences += [
            CellDifference(cell.clearance, cell.knee_bend, d)
            for d in two_phase_sweep.differences(rows)
        ]
    return Summary(
        settings.share, settings.landing, tuple(points), tuple(differences), tuple(missing)
    )


def _row(atlas_folder: Path, point: Point) -> PointSummary:
    """A knee at a cell, both supports (an optimum not certified: None, with why)."""
    single = _single(atlas_folder, point)
    if single is not None and campaign.failure(single.optimizer.status, single.feasible):
        single = None
    path = atlas_folder / FOLDER / point.filename()
    double, why = two_phase_sweep.read_two_phase(path)
    return PointSummary(
        point.knee,
        point.cell.speed,
        two_phase_sweep.phases_of(single, False),
        two_phase_sweep.phases_of(double, True),
        why,
    )
