"""Every certified optimum of an atlas walked in MuJoCo: a resumable stage after its
optimizations (``biped.studies.atlas``), run on the campaign's machinery
(``biped.studies.campaign``: ``--jobs`` processes or Dask, one record per walk written
whole, Ctrl-C and SIGTERM as every campaign's).

Each certified final optimum (every criterion, cell and knee) is walked from its gait file:
the forward walk with contact of ``STEPS`` steps (``validate.checks.checks.check_forward``) and the
feedforward replay (``check_feedforward``) everywhere; every check of
``validate.checks.validation.validate`` (the gains and the orbit included) at the corners of speed x
clearance and at each criterion's best pay-off (``biped.studies.atlas.fully_checked``). A
gait walks when every check run on it passes: an orbit only 'undecided' fails the orbit
check, and is not a walk.

The record of a walk, ``walks/<knee>-<criterion>-<cell>.json`` (read by
``biped.studies.atlas.read_walk``): each check's verdict, its cause (the note that says why it
failed) and its notes, and the key figures with
their units (steps walked, fell, the stance foot's slip, the servos' share of the torque in
the walk and in the replay, MuJoCo's energy per step and the model's, the orbit's spectral
radius and verdict where checked), a figure not measured null. A walk that raised is recorded
with its error, neither walking nor failing, and walked again by the next run; a run walks
the optima without a record of the checks they are asked.
"""

from __future__ import annotations

import json
import math
import time
from dataclasses import dataclass
from pathlib import Path

from biped.model.kinematics import KNEES
from biped.model.units import PURE
from biped.records.gait_file import Gait
from biped.runtime.claims import claimed
from biped.runtime.files import atomic_write_text
from biped.studies import atlas, campaign
from biped.studies.campaign import Task
from validate import DEFAULT_STEPS

STEPS = DEFAULT_STEPS
# The walks' lines and their closing line, in the atlas's folder.
CAMPAIGN = campaign.Campaign(
    "atlas walks", atlas.MANIFEST, "atlas record", "this folder's atlas was", "an atlas's"
)
# The checks of a walk away from the corners and the best pay-off.
LIGHT = ("feedforward", "forward")
# The key figures of a record: (check, figure in its report, name in the record, unit).
FIGURES = (
    ("forward", "steps", "steps", PURE),
    ("forward", "fell", "fell", None),
    ("forward", "max_slip", "max_slip", "m"),
    ("forward", "swing_clearance", "swing_clearance", "m"),
    ("forward", "feedback_share", "feedback_share", PURE),
    ("feedforward", "max_feedback_share", "replay_feedback_share", PURE),
    ("forward", "energy_per_step", "energy_per_step", "J"),
    ("forward", "analytic_energy_per_step", "model_energy_per_step", "J"),
    ("gains", "kp_scale_range", "kp_scale_range", PURE),
    ("orbit", "spectral_radius", "spectral_radius", PURE),
    ("orbit", "verdict", "orbit_verdict", None),
)


@dataclass(frozen=True)
class WalkPoint:
    """One walk: the final optimum of ``point`` (a ``biped.studies.atlas.Point``), with every
    check or the light ones (``LIGHT``)."""

    point: atlas.Point
    every_check: bool

    def filename(self) -> str:
        return self.point.at(atlas.WALKS).filename()


def _clean(value):
    """A figure as JSON holds it: NaN (not measured) is null, numpy's scalars Python's."""
    if isinstance(value, (list, tuple)):
        return [_clean(v) for v in value]
    if isinstance(value, bool) or value is None or isinstance(value, str):
        return value
    if hasattr(value, "item"):
        value = value.item()
    if isinstance(value, float) and not math.isfinite(value):
        return None
    return value


def _checks(gait: Gait, every_check: bool) -> list:
    """The checks of ``gait`` in MuJoCo: every check of ``validate``, or the light ones."""
    from validate.checks import checks as c
    from validate.checks.validation import validate
    from validate.scene.model import model_spec
    from validate.walk.samples import GaitSamples
    from validate.walk.simulate import Walker

    if every_check:
        return validate(gait, STEPS).checks
    spec = model_spec(gait.biped)
    replay = c.check_feedforward(spec, gait.biped, GaitSamples.from_gait(gait))
    forward, _, _ = c.check_forward(Walker(gait, spec), STEPS, gait.costs.energy)
    return [replay, forward]


def content(walk: WalkPoint, checks: list | None, error: str | None = None) -> dict:
    """The record of a walk: its checks (None if it raised ``error``), their key figures."""
    point = walk.point
    by_name = {check.name: check for check in checks or ()}
    figures, units = {}, {}
    for check, figure, name, unit in FIGURES:
        if check in by_name:
            figures[name] = _clean(by_name[check].figures.get(figure, math.nan))
            if unit is not None:
                units[f"figures.{name}"] = unit
    energies = figures.get("energy_per_step"), figures.get("model_energy_per_step")
    if None not in energies and "forward" in by_name and energies[1] != 0:
        figures["energy_error"] = energies[0] / energies[1] - 1.0
        units["figures.energy_error"] = PURE
    checked = {
        name: atlas.WalkCheck(bool(check.passed), _cause(check), tuple(map(str, check.notes)))
        for name, check in by_name.items()
    }
    walks = None if error is not None or not checked else all(c.passed for c in checked.values())
    cell = point.cell
    return {
        "format": atlas.WALK_FORMAT,
        "gait": point.gait_filename(),
        "knee": point.knee,
        "criterion": point.criterion,
        "cell": {"speed": cell.speed, "clearance": cell.clearance, "knee_bend": cell.knee_bend},
        "every_check": walk.every_check,
        "steps_asked": STEPS,
        "walks": walks,
        "error": error,
        "checks": {name: check.to_dict() for name, check in checked.items()},
        "figures": figures,
        "units": {
            "cell.speed": "m/s",
            "cell.clearance": "m",
            "cell.knee_bend": "rad",
            "steps_asked": PURE,
            **units,
        },
    }


def _cause(check) -> str:
    """Why a check failed, in one note ("" if it passed): the orbit's verdict (its last
    note), another check's first note."""
    if check.passed:
        return ""
    if not check.notes:
        return "failed"
    return str(check.notes[-1] if check.name == "orbit" else check.notes[0])


def _walk(task: Task) -> str:
    """Walk one final optimum, write its record whole; its line."""
    from validate.walk.simulate import quiet_mujoco

    walk, began = task.point, time.perf_counter()
    path = Path(task.folder) / walk.point.gait_filename()
    try:
        with quiet_mujoco():  # a walk counts MuJoCo's warnings itself
            record = content(walk, _checks(Gait.read(path, consistent=True), walk.every_check))
    except Exception as error:  # a walk not measured: recorded, walked again by a rerun
        record = content(walk, None, f"{type(error).__name__}: {' '.join(str(error).split())}")
    record["seconds"] = time.perf_counter() - began
    record["units"]["seconds"] = "s"
    atomic_write_text(task.path, json.dumps(record, indent=1, allow_nan=False))
    return _line(walk, atlas.Walk.from_dict(record), record["seconds"])


def _line(walk: WalkPoint, result: atlas.Walk, seconds: float) -> str:
    point = walk.point
    checked = "every check" if walk.every_check else "walk, replay"
    if result.walks is None:
        verdict = "NOT MEASURED: " + (result.error or "no check")
    else:
        verdict = "walks" if result.walks else "DOES NOT WALK: " + result.causes()
    return (
        f"[walk  ] {point.knee:8} {point.criterion:16} {point.cell.speed:.3f} m/s clearance "
        f"{100 * point.cell.clearance:4.1f} cm bend {point.cell.knee_bend:.3f} rad  "
        f"({checked}) {verdict}  {seconds:5.1f} s"
    )


def certified(folder, settings: atlas.Settings) -> list[atlas.Point]:
    """The final optima of the atlas that are certified (each criterion, cell, knee)."""
    found = []
    for criterion in settings.criteria:
        for cell in settings.cells():
            for knee in KNEES:
                point = atlas.Point("final", knee, criterion, cell)
                record = atlas.read(folder, point)
                if record is not None and record.certified:
                    found.append(point)
    return found


def walks(folder, settings: atlas.Settings) -> list[WalkPoint]:
    """Every walk of the atlas's certified optima, those with every check first (the
    longest, so that none starts last)."""
    full = {c: set(atlas.fully_checked(folder, settings, c)) for c in settings.criteria}
    chosen = [WalkPoint(p, p.cell in full[p.criterion]) for p in certified(folder, settings)]
    return sorted(chosen, key=lambda walk: not walk.every_check)


def _done(folder, walk: WalkPoint) -> bool:
    """Whether ``walk`` has a record of the checks it is asked, measured."""
    found = atlas.read_walk(folder, walk.point)
    return found is not None and found.walks is not None and found.every_check == walk.every_check


def run_walks(folder, settings: atlas.Settings, **where) -> list[WalkPoint]:
    """Walk every certified optimum of the atlas in ``folder`` without a record yet (its
    optimizations done: ``biped.studies.atlas.run_atlas``); returns the walks asked.
    ``where``: ``jobs``, ``dask``, ``stream``, ``progress``, as ``campaign.Campaign.run``."""
    with claimed(folder):  # one run at a time on the folder
        atlas.check_folder(folder, settings)
        folder = atlas.ATLAS.claim(folder, settings, atlas.WALKS)
        asked = walks(folder, settings)
        tasks = [Task(_walk, settings, w, str(folder)) for w in asked if not _done(folder, w)]
        full = sum(w.every_check for w in asked)
        plan = (
            f"atlas walks: {len(asked)} certified optima walked in MuJoCo ({STEPS}-step forward "
            f"walk with contact and feedforward replay; every check for {full} of them, at the "
            f"corners and each criterion's best pay-off): {len(asked) - len(tasks)} already "
            f"walked, {len(tasks)} to walk"
        )
        CAMPAIGN.run(plan, [tasks], lambda: summarize(folder, asked), **where)
    return asked


def summarize(folder, asked: list[WalkPoint]) -> str:
    """How many of the optima walked walk (every check run passes), which do not and why."""

    def why_not(walk):
        found = atlas.read_walk(folder, walk.point)
        if found is None:
            return "not walked"
        return None if found.walks else found.causes()

    counted = "certified optima walk in MuJoCo (every check run passes)"
    points = [w.point.at(atlas.WALKS) for w in asked]
    by_point = dict(zip(points, asked, strict=True))
    return campaign.tally(points, lambda p: why_not(by_point[p]), counted, most=8)


def unmeasured(folder, settings: atlas.Settings) -> list[str]:
    """The walks of the atlas that measured nothing (no record, or one of an error)."""
    found = []
    for walk in walks(folder, settings):
        result = atlas.read_walk(folder, walk.point)
        if result is None or result.walks is None:
            why = "no record" if result is None else result.error
            found.append(f"{walk.filename()} ({why})")
    return found
