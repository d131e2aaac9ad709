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

import dataclasses
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from biped.errors import BipedError
from biped.model.units import PURE, unit_field
from biped.records.gait_file import Gait
from biped.runtime.runner import ProgressBar, run_tasks
from validate.checks.orbit import NOMINAL, Orbit, Steps, notes, orbit, orbit_figures
from validate.checks.units import FIGURE_UNITS, OrbitFigures
from validate.scene.model import model_spec
from validate.walk.simulate import Walker, WalkSettings, quiet_mujoco

# Knob -> (the WalkSettings field it sets, what it scales, in words).
KNOBS = {
    "kp": ("kp_scale", "the servos' stiffness KP"),
    "kv": ("kv_scale", "the servos' damping KV"),
    "speed": ("speed_scale", "the speed loop's gain SPEED_GAIN"),
}
# Largest scale of a gain (a walk's physics at 1 ms resolves stiffer servos poorly).
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


@dataclass(frozen=True)
class StudiedOrbit:
    """One orbit of a study: the knob's scale it was found at (None: the validation's
    controller), the orbit check's figures (``OrbitFigures``, each with its unit) and what
    the check says of it (``validate.checks.orbit.notes``)."""

    value: float | None = unit_field(PURE)
    figures: OrbitFigures = unit_field(OrbitFigures, default=None)
    notes: tuple[str, ...] = ()

    @property
    def found(self) -> bool:
        """Whether the orbit was found (a walk that falls has none: no spectral radius)."""
        return self.figures.spectral_radius is not None

    def to_dict(self) -> dict:
        """The orbit as a study's JSON holds it: the value, the figures, the notes."""
        return {"value": self.value, **self.figures.to_dict(), "notes": list(self.notes)}

    @classmethod
    def from_dict(cls, content: dict) -> StudiedOrbit:
        names = {f.name for f in dataclasses.fields(OrbitFigures)}
        figures = OrbitFigures(**{k: v for k, v in content.items() if k in names})
        return cls(content["value"], figures, tuple(content["notes"]))


@dataclass(frozen=True)
class Boundary:
    """Where the verdict changes between two neighbouring scales of the knob: both scales,
    both verdicts, and where ρ crosses 1 between them (linear between the two radii; None
    where it does not, or a walk falls)."""

    between: tuple[float, float] = unit_field(PURE)
    verdicts: tuple[str, str] = unit_field(None)
    radius_crosses_1_at: float | None = unit_field(PURE, default=None)

    def to_dict(self) -> dict:
        return {
            "between": list(self.between),
            "verdicts": list(self.verdicts),
            "radius_crosses_1_at": self.radius_crosses_1_at,
        }

    @classmethod
    def from_dict(cls, content: dict) -> Boundary:
        return cls(
            tuple(content["between"]), tuple(content["verdicts"]), content["radius_crosses_1_at"]
        )


@dataclass(frozen=True)
class OrbitStudy:
    """A gait's orbits over the scales of one knob (``knob`` None: the validation's
    controller alone, one orbit), and the boundaries between them. ``to_dict`` is its JSON
    with its ``units`` map (no time or host in it); ``from_dict`` reads it back."""

    gait: str  # the gait file, as given
    knee: str
    criterion: str
    speed: float = unit_field("m/s")
    knob: str | None = None
    values: tuple[float | None, ...] = unit_field(PURE, default=(None,))
    orbits: tuple[StudiedOrbit, ...] = unit_field([StudiedOrbit], default=())
    boundaries: tuple[Boundary, ...] = unit_field([Boundary], default=())

    @classmethod
    def of(
        cls, path: str | Path, gait: Gait, knob: str | None, values, orbits: list[StudiedOrbit]
    ) -> OrbitStudy:
        """The study of the gait file ``path`` (``gait``) over ``values`` of ``knob``."""
        values = tuple(None if v is None else float(v) for v in values)
        return cls(
            str(path),
            gait.knee,
            gait.criterion,
            gait.speed,
            knob,
            values,
            tuple(orbits),
            () if knob is None else tuple(boundaries(values, orbits)),
        )

    def to_dict(self) -> dict:
        body = {
            "gait": self.gait,
            "knee": self.knee,
            "criterion": self.criterion,
            "speed": self.speed,
            "knob": "none" if self.knob is None else self.knob,
            "scales": "the validation's controller" if self.knob is None else KNOBS[self.knob][1],
            "values": list(self.values),
            "orbits": [orbit.to_dict() for orbit in self.orbits],
            "boundaries": [boundary.to_dict() for boundary in self.boundaries],
        }
        units = {"speed": "m/s", "values": PURE}
        for name, unit in FIGURE_UNITS["orbit"].items():
            units[f"orbits[].{name}"] = unit
        units["orbits[].value"] = PURE
        units["boundaries[].between"] = PURE
        units["boundaries[].radius_crosses_1_at"] = PURE
        body["units"] = units
        return body

    @classmethod
    def from_dict(cls, content: dict) -> OrbitStudy:
        knob = None if content["knob"] == "none" else content["knob"]
        return cls(
            content["gait"],
            content["knee"],
            content["criterion"],
            content["speed"],
            knob,
            tuple(content["values"]),
            tuple(StudiedOrbit.from_dict(o) for o in content["orbits"]),
            tuple(Boundary.from_dict(b) for b in content["boundaries"]),
        )


def orbit_of(task: Task) -> tuple[int, StudiedOrbit]:
    """The task's index and its orbit (a task of ``run_tasks``)."""
    walker = Walker(task.gait, model_spec(task.gait.biped, task.model))
    with quiet_mujoco():
        result: Orbit = orbit(walker, settings_at(task.knob, task.value), task.steps)
    return task.index, StudiedOrbit(task.value, orbit_figures(result), tuple(notes(result)))


def boundaries(values, orbits: list[StudiedOrbit]) -> list[Boundary]:
    """Where the verdict changes between neighbouring values (in the order given): both
    values, both verdicts, and where ρ crosses 1 between them (None if it does not)."""
    found = []
    for i in range(len(values) - 1):
        (a, b), (left, right) = values[i : i + 2], orbits[i : i + 2]
        verdicts = left.figures.verdict, right.figures.verdict
        if (verdicts[0] == "stable") == (verdicts[1] == "stable"):
            continue
        if left.found and right.found:
            ra, rb = left.figures.spectral_radius, right.figures.spectral_radius
            crosses = (ra - 1.0) * (rb - 1.0) <= 0.0 and ra != rb
            crossing = a + (1.0 - ra) * (b - a) / (rb - ra) if crosses else None
        else:  # a walk falls (no orbit): no radius to cross 1
            crossing = None
        at = None if crossing is None else float(crossing)
        found.append(Boundary((float(a), float(b)), verdicts, at))
    return found


def study(
    gaits: list[Gait],
    knob: str | None = None,
    values=(None,),
    model: str | None = None,
    steps: Steps | None = None,
    jobs: int = 1,
    progress: ProgressBar | None = None,
) -> list[list[StudiedOrbit]]:
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
