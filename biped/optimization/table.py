"""A table of certified optima over speed, shipped with the package: one more start.

``optima.json`` beside this module holds, for each knee and criterion of one robot and safety
(the paper's by default), the solvers' variables (``biped.optimization.problem.VARIABLES``) of
the certified optima of a sweep at its speeds. ``biped table`` writes one from a sweep's
folder (``biped.studies.sweep.optima_table``); the shipped file is made in the source
tree by

    biped sweep && biped table --out biped/optimization/optima.json

(from an earlier version's sweep, its ``source`` says). Every optimization reads the
installed package's file (``SHIPPED``), no other: the source tree's only under an editable
install, which ``biped table`` says when it writes elsewhere. It stays fixed: made again from
today's sweep, the starts move, and with them some of the energy criterion's optima among
its close local minima.

An optimization starts from the table's optima at the neighbouring speeds (``start``): the
optima interpolated linearly in speed between the nearest tabled speeds below and above, the
speed itself left out, so a tabled optimum never starts its own point: the start is the
neighbours', a start independent of the point's own, reaching the point's basin where the
optima change smoothly with speed (the energy criterion's basins follow the step period).
Beyond the table's speeds, the nearest tabled optimum. The table's fingerprint (``digest``)
is recorded by the campaigns whose numbers it shapes. The table ``covers`` a problem of its
robot, safety, knee and criterion within its speeds: its starts then lie near the optima.
"""

from __future__ import annotations

import dataclasses
import functools
import hashlib
import json
from pathlib import Path

import numpy as np

from biped.errors import BipedError
from biped.optimization.problem import VARIABLES, GaitProblem

FORMAT = "biped-optima-table/1"
SHIPPED = Path(__file__).with_name("optima.json")
TABLE_START = "optima table at neighbouring speeds"
OTHER_KNEE_START = "optima table, other knee"
# Two speeds [m/s] are the same point of the table when closer than this.
SAME_SPEED = 1e-9


@dataclasses.dataclass(frozen=True)
class _Table:
    """A table file as read: its series {(knee, criterion): (speeds (K,) [m/s], variables
    (K, 21))} and what they were made for: the robot's body fields and the margins [m]."""

    series: dict
    robot: dict
    clearance: float
    zmp_margin: float


_NO_TABLE = _Table({}, {}, float("nan"), float("nan"))


@functools.cache
def _read(path: str) -> _Table:
    """The table at ``path`` (``_NO_TABLE`` when the file is missing); a BipedError naming
    the file when it is not a table."""
    file = Path(path)
    if not file.exists():
        return _NO_TABLE
    try:
        content = json.loads(file.read_text())
        if content.get("format") != FORMAT or content.get("variables") != list(VARIABLES):
            raise ValueError(f"format is not {FORMAT!r} with the solvers' variables")
        series = {}
        for entry in content["series"]:
            speeds = np.array(entry["speeds"], dtype=float)
            optima = np.array(entry["optima"], dtype=float).reshape(len(speeds), len(VARIABLES))
            order = np.argsort(speeds)
            series[(entry["knee"], entry["criterion"])] = (speeds[order], optima[order])
        robot = {k: v for k, v in content["robot"].items() if k != "actuators"}
        safety = content["safety"]
        return _Table(series, robot, safety["clearance"], safety["zmp_margin"])
    except (OSError, ValueError, KeyError, TypeError, AttributeError) as error:
        raise BipedError(f"{file}: not a table of optima ({error})") from None


def covers(problem: GaitProblem, path: Path = SHIPPED) -> bool:
    """Whether the table holds optima of ``problem``'s robot (its body), safety, knee and
    criterion at speeds on both sides of its own or at it, and the other knee's, of the
    paper's spline on the solvers' default grid: its starts (``start``,
    ``other_knee_start``) then lie near the problem's optima. (The table records the
    clearance and ZMP margin of its sweep, not a knee bend or actuator limits: it covers
    problems without those.)"""
    made = _read(str(path))
    series = made.series.get((problem.knee, problem.criterion))
    if series is None or problem.knots != 1 or not problem.on_default_grid:
        return False
    if start(problem, path) is None or other_knee_start(problem, path) is None:
        return False
    safety = problem.safety
    own = {k: v for k, v in problem.model.robot.to_dict().items() if k != "actuators"}
    margins = (safety.clearance, safety.zmp_margin) == (made.clearance, made.zmp_margin)
    same = own == made.robot and margins
    same = same and safety.knee_bend == 0.0 and not safety.actuator_limits
    speeds = series[0]
    return same and speeds[0] - SAME_SPEED <= problem.speed <= speeds[-1] + SAME_SPEED


def digest(path: Path = SHIPPED) -> str | None:
    """The first 16 hex digits of the table's SHA-256, None without a table."""
    path = Path(path)
    return hashlib.sha256(path.read_bytes()).hexdigest()[:16] if path.exists() else None


def start(problem: GaitProblem, path: Path = SHIPPED) -> np.ndarray | None:
    """The table's start of ``problem`` (variables (21,)): its knee's and criterion's optima
    at the tabled speeds other than its own, interpolated at its speed (the nearest beyond
    them); None when the table has no such series (or only the speed itself)."""
    return _interpolated(
        _read(str(path)).series.get((problem.knee, problem.criterion)), problem, True
    )


def other_knee_start(problem: GaitProblem, path: Path = SHIPPED) -> np.ndarray | None:
    """The table's optimum of the other knee for ``problem``'s criterion at its speed
    (interpolated between tabled speeds): the variables mean the same for both knees. None
    when the table has no such series."""
    others = [
        entry
        for (knee, criterion), entry in _read(str(path)).series.items()
        if knee != problem.knee and criterion == problem.criterion
    ]
    return _interpolated(others[0] if others else None, problem, False)


def _interpolated(entry, problem: GaitProblem, others_only: bool) -> np.ndarray | None:
    """The optima of ``entry`` (speeds, variables) interpolated linearly at the problem's
    speed, the nearest beyond the tabled speeds; with ``others_only``, the problem's own
    speed left out."""
    if entry is None:
        return None
    speeds, optima = entry
    if others_only:
        keep = np.abs(speeds - problem.speed) > SAME_SPEED
        speeds, optima = speeds[keep], optima[keep]
    if len(speeds) == 0:
        return None
    exact = np.abs(speeds - problem.speed) <= SAME_SPEED
    if np.any(exact):
        return optima[int(np.argmax(exact))].copy()
    above = int(np.searchsorted(speeds, problem.speed))
    if above == 0 or above == len(speeds):
        return optima[min(above, len(speeds) - 1)].copy()
    low, high = speeds[above - 1], speeds[above]
    share = (problem.speed - low) / (high - low)
    return (1.0 - share) * optima[above - 1] + share * optima[above]


def content(series: dict, robot, safety, source: str) -> dict:
    """A table's JSON content: ``series`` {(knee, criterion): [(speed, variables (21,)), ...]}
    of ``robot`` and ``safety``, made from ``source``."""
    return {
        "format": FORMAT,
        "source": source,
        "robot": robot.to_dict(),
        "safety": {"clearance": safety.clearance, "zmp_margin": safety.zmp_margin},
        "variables": list(VARIABLES),
        "series": [
            {
                "knee": knee,
                "criterion": criterion,
                "speeds": [float(speed) for speed, _ in points],
                "optima": [[float(v) for v in variables] for _, variables in points],
            }
            for (knee, criterion), points in sorted(series.items())
        ],
    }
