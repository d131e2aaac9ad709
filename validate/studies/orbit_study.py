"""The orbit of gaits under a range of one controller gain: where the walk stops being stable.

A knob (``KNOBS``) scales one gain of the walk's controller (``validate.walk.simulate``): ``kp``
the servos' stiffness ``KP``, ``kv`` their damping ``KV``, ``speed`` the speed loop's gain
``SPEED_GAIN`` (0: the speed loop off). At each value the orbit is found and its multipliers
computed (``validate.checks.orbit.orbit``); a walk that falls has no orbit and counts as unstable.
The boundaries are where the verdict changes between two neighbouring values, and where ρ
crosses 1 between them (linear between the two radii; none where a walk falls).

The orbits of a gait (or of several, one task each) are independent: they run on ``jobs``
processes (``biped.runtime.runner.run_tasks``); each is deterministic, so the content is the
same for any number of processes.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from biped.errors import BipedError
from biped.model.units import PURE
from biped.records.gait_file import Gait
from biped.runtime.runner import ProgressBar, run_tasks
from validate.checks.orbit import NOMINAL, Orbit, Steps, figures, notes, orbit
from validate.checks.units import FIGURE_UNITS
from validate.scene.model import model_spec
from validate.walk.simulate import Walker, WalkSettings, quiet_mujoco

# Knob -> (the WalkSettings field it sets, what it scales, in words).
KNOBS = {
    "kp": ("kp_scale", "the servos' stiffness KP"),
    "kv": ("kv_scale", "the servos' damping KV"),
    "speed": ("speed_scale", "the speed loop's gain SPEED_GAIN"),
}
# Largest scale of a gain (a walk's physics at 2 ms resolves stiffer servos poorly).
MAX_SCALE = 100.0


def settings_at(knob: str | None, value: float | None) -> WalkSettings:
    """The walk's settings with ``knob`` at ``value`` (None: the validation's)."""
    if knob is None:
        return NOMINAL
    if knob not in KNOBS:
        raise BipedError(f"knob {knob!r}: allowed one of {', '.join(KNOBS)}")
    if not (np.isfinite(value) and 0.0 <= value <= MAX_SCALE):
        raise BipedError(f"{knob} scale = {value!r}: allowed 0 to {MAX_SCALE:g}")
    return WalkSettings(**{KNOBS[knob][0]: float(value)})


@dataclass(frozen=True)
class Task:
    """One orbit of a study: its place in the study, the gait, its model (a path, None: the
    default), the knob and its value (None: the validation's controller), the central
    differences' steps."""

    index: int
    gait: Gait
    model: str | None
    knob: str | None
    value: float | None
    steps: Steps


def orbit_of(task: Task) -> tuple[int, dict]:
    """The task's index, and the orbit check's figures and notes of it (a task of
    ``run_tasks``)."""
    walker = Walker(task.gait, model_spec(task.gait.biped, task.model))
    with quiet_mujoco():
        result: Orbit = orbit(walker, settings_at(task.knob, task.value), task.steps)
    return task.index, {"value": task.value, **figures(result), "notes": notes(result)}


def boundaries(values, orbits: list[dict]) -> list[dict]:
    """Where the verdict changes between neighbouring values (in the order given): both
    values, both verdicts, and where ρ crosses 1 between them (None if it does not)."""
    found = []
    for i in range(len(values) - 1):
        (a, b), (left, right) = values[i : i + 2], orbits[i : i + 2]
        if (left["verdict"] == "stable") == (right["verdict"] == "stable"):
            continue
        ra, rb = (o.get("spectral_radius", np.inf) for o in (left, right))
        if np.isfinite(ra) and np.isfinite(rb):
            crosses = (ra - 1.0) * (rb - 1.0) <= 0.0 and ra != rb
            crossing = a + (1.0 - ra) * (b - a) / (rb - ra) if crosses else None
        else:  # a walk falls (no orbit): no radius to cross 1
            crossing = None
        found.append(
            {
                "between": [float(a), float(b)],
                "verdicts": [left["verdict"], right["verdict"]],
                "radius_crosses_1_at": None if crossing is None else float(crossing),
            }
        )
    return found


def study(
    gaits: list[Gait],
    knob: str | None = None,
    values=(None,),
    model: str | None = None,
    steps: Steps | None = None,
    jobs: int = 1,
    progress: ProgressBar | None = None,
) -> list[list[dict]]:
    """Per gait, the orbit at each value of ``knob`` (``orbit_of``), on ``jobs`` processes;
    ``steps``: the central differences' (None: ``Steps()``)."""
    steps = Steps() if steps is None else steps
    for value in values:
        settings_at(knob, value)  # refused before any work
    places = [(gait, value) for gait in gaits for value in values]
    tasks = [Task(i, gait, model, knob, value, steps) for i, (gait, value) in enumerate(places)]
    done = dict(run_tasks(orbit_of, tasks, jobs=jobs, stream=None, progress=progress))
    results = [done[i] for i in range(len(tasks))]  # in the tasks' order, whatever ended first
    n = len(values)
    return [results[i * n : (i + 1) * n] for i in range(len(gaits))]


def content(path: str | Path, gait: Gait, knob: str | None, values, orbits: list[dict]) -> dict:
    """A gait's study as JSON content with its ``units`` map (no time or host in it)."""
    body = {
        "gait": str(path),
        "knee": gait.knee,
        "criterion": gait.criterion,
        "speed": gait.speed,
        "knob": "none" if knob is None else knob,
        "scales": "the validation's controller" if knob is None else KNOBS[knob][1],
        "values": [None if v is None else float(v) for v in values],
        "orbits": orbits,
        "boundaries": [] if knob is None else boundaries(values, orbits),
    }
    units = {"speed": "m/s", "values": PURE}
    for name, unit in FIGURE_UNITS["orbit"].items():
        units[f"orbits[].{name}"] = unit
    units["orbits[].value"] = PURE
    units["boundaries[].between"] = PURE
    units["boundaries[].radius_crosses_1_at"] = PURE
    body["units"] = units
    return body
