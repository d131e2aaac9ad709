"""Motor sizing: what a gait asks of each joint's actuator, and the lightest combination of a
catalog's motors and gears that gives it with a margin.

A leg's joint is one motor whether the leg stands or swings, so each kind of joint
(``biped.model.actuators.KINDS``) must drive both of its joints of eq. (32) (the stance
joint in one step, the swing joint in the next). Over a step of period T, with Γ_s, Γ_w the
stance and swing joint's torques and θ̇ their rates (``Requirement.of``):

    peak torque  max |Γ|                     RMS torque  √((∫ Γ_s² dt + ∫ Γ_w² dt) / 2T)
    peak speed   max |θ̇|                    peak power  max |Γ θ̇|

A candidate (``Candidate``: a motor behind a gear, ``biped.model.actuators.Actuator``)
meets a requirement with the margin m when peak torque × (1 + m) <= its peak torque, RMS
torque × (1 + m) <= its continuous torque, peak speed × (1 + m) <= its top speed and the
largest voltage of its drive over the gait (``biped.model.actuators.drive``) × (1 + m) <= its
supply voltage. The catalog (``biped/model/catalog.json``, format ``CATALOG_FORMAT``: integrated
actuators, each with its datasheet's figures and its source, what no datasheet gives assumed and
named) ships with the package; ``load_catalog`` reads another, or one of the earlier format
``MOTORS_AND_GEARS_FORMAT`` (every motor behind every gear).
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from biped.errors import BipedError
from biped.model import datasheets
from biped.model.actuators import (
    CATALOG_SOURCE,
    JOINT_KINDS,
    KINDS,
    Actuator,
    catalog_actuators,
    drive,
    package_catalog_text,
)

CATALOG_FORMAT = datasheets.CATALOG_FORMAT
# The earlier catalogs' format: motors and gears, every motor behind every gear.
MOTORS_AND_GEARS_FORMAT = "biped-actuator-catalog/1"
# The default margin on every requirement: 20 %.
DEFAULT_MARGIN = 0.2
# The limits a combination must meet, in order: (name, unit) as printed.
CHECKS = (
    ("peak torque", "N·m"),
    ("RMS torque", "N·m"),
    ("peak speed", "rad/s"),
    ("peak voltage", "V"),
)
_MOTOR_FIELDS = (
    "torque_constant",
    "resistance",
    "rotor_inertia",
    "motor_continuous_torque",
    "motor_peak_torque",
    "motor_max_speed",
    "supply_voltage",
)


@dataclass(frozen=True)
class Requirement:
    """What a gait asks of one kind of joint's actuator."""

    kind: str
    peak_torque: float  # [N·m]
    rms_torque: float  # [N·m]
    peak_speed: float  # [rad/s]
    peak_power: float  # [W] mechanical, |Γ θ̇|
    torques: np.ndarray  # [N·m] (N, 2) the stance and swing joint's, for the drive
    rates: np.ndarray  # [rad/s] (N, 2)
    accels: np.ndarray  # [rad/s²] (N, 2)

    @classmethod
    def of(cls, kind: str, torques, rates, accels, weights, period) -> Requirement:
        """The requirement of ``kind`` from the gait's samples (N, 6) on its time grid and
        the Simpson weights (N,) [s] of that grid (∫ f dt = weights @ f)."""
        joints = [j for j, k in enumerate(JOINT_KINDS) if k == kind]
        tau, rate = np.asarray(torques)[:, joints], np.asarray(rates)[:, joints]
        return cls(
            kind=kind,
            peak_torque=float(np.abs(tau).max()),
            rms_torque=float(np.sqrt((weights @ tau**2).sum() / (2 * period))),
            peak_speed=float(np.abs(rate).max()),
            peak_power=float(np.abs(tau * rate).max()),
            torques=tau,
            rates=rate,
            accels=np.asarray(accels)[:, joints],
        )

    def figures(self, actuator: Actuator) -> dict:
        """The figures of ``CHECKS`` with ``actuator`` driving, and its limits: {name: (asked,
        allowed)}."""
        constants = {name: np.full(2, value) for name, value in vars(actuator).items()}
        state = drive(constants, self.torques, self.rates, self.accels)
        return {
            "peak torque": (self.peak_torque, actuator.peak_torque),
            "RMS torque": (self.rms_torque, actuator.continuous_torque),
            "peak speed": (self.peak_speed, actuator.max_speed),
            "peak voltage": (float(np.abs(state.voltage).max()), actuator.supply_voltage),
        }

    def failures(self, actuator: Actuator, margin: float) -> list[str]:
        """The limits of ``CHECKS`` that ``actuator`` does not meet with ``margin``."""
        return [
            name
            for name, (asked, allowed) in self.figures(actuator).items()
            if asked * (1.0 + margin) > allowed
        ]


@dataclass(frozen=True)
class Candidate:
    """One actuator of the catalog: a motor behind a gear."""

    name: str
    actuator: Actuator
    source: str

    @property
    def mass(self) -> float:
        """[kg] Motor and gear."""
        return self.actuator.mass


@dataclass(frozen=True)
class Choice:
    """The lightest candidate meeting a requirement, or None with the reason."""

    requirement: Requirement
    candidate: Candidate | None
    reason: str = ""


def load_catalog(path: str | Path | None = None) -> list[Candidate]:
    """The candidates of a catalog file (default: the package's): its actuators, or
    every motor behind every gear of a catalog of ``MOTORS_AND_GEARS_FORMAT``."""
    if path is None:
        text, source = package_catalog_text(), CATALOG_SOURCE
    else:
        source = str(path)
        try:
            text = Path(path).read_text(encoding="utf-8")
        except (OSError, UnicodeDecodeError) as error:
            raise BipedError(f"catalog {source!r} cannot be read ({error})") from None
    content = datasheets.loads(text, source)
    found = content.get("format") if isinstance(content, dict) else None
    if found == CATALOG_FORMAT:
        actuators = catalog_actuators(content, source)
        sources = {entry["name"]: entry["source"] for entry in content["actuators"]}
        return [Candidate(name, a, sources[name]) for name, a in actuators.items()]
    if found != MOTORS_AND_GEARS_FORMAT:
        raise BipedError(
            f"catalog {source!r}: allowed a JSON file of format {CATALOG_FORMAT!r} (or the "
            f"earlier {MOTORS_AND_GEARS_FORMAT!r})"
        )
    try:
        motors, gears = dict(content["motors"]), list(content["gears"])
        candidates = [_candidate(n, motor, gear) for n, motor in motors.items() for gear in gears]
        if not candidates:
            raise ValueError("no motor or no gear")
    except (KeyError, TypeError, ValueError, OverflowError, BipedError) as error:
        raise BipedError(
            f"catalog {source!r} is corrupt ({error}): allowed motors with "
            f"{', '.join(_MOTOR_FIELDS)} and gears with name, ratio, efficiency, mass"
        ) from None
    return candidates


def _candidate(name: str, motor: dict, gear: dict) -> Candidate:
    actuator = Actuator.geared(
        {key: float(motor[key]) for key in _MOTOR_FIELDS},
        float(gear["ratio"]),
        float(gear["efficiency"]),
        float(gear["mass"]),
    )
    return Candidate(f"{name} {gear['name']}", actuator, str(motor.get("source", "")))


def choose(requirement: Requirement, catalog: list[Candidate], margin: float) -> Choice:
    """The lightest candidate of ``catalog`` that meets ``requirement`` with ``margin``
    (the first of equal masses); if none, the reason: the limits no candidate meets, each
    with what is asked and the most the catalog gives."""
    meeting = [c for c in catalog if not requirement.failures(c.actuator, margin)]
    if meeting:
        return Choice(requirement, min(meeting, key=lambda c: c.mass))
    figures = [requirement.figures(c.actuator) for c in catalog]
    reasons = []
    for name, unit in CHECKS:
        asked = figures[0][name][0] if name != "peak voltage" else None
        best = max(f[name][1] / max(f[name][0], 1e-300) for f in figures)
        if best < 1.0 + margin:  # no candidate meets this limit alone
            if asked is None:
                reasons.append(f"{name} above every supply voltage with the margin")
            else:
                most = max(f[name][1] for f in figures)
                reasons.append(
                    f"{name} {asked:.4g} {unit} x {1 + margin:g} > {most:.4g} {unit}, the "
                    "catalog's most"
                )
    if not reasons:
        reasons.append("no single combination meets every limit at once")
    return Choice(requirement, None, "; ".join(reasons))


def size(torques, rates, accels, weights, period, catalog, margin=DEFAULT_MARGIN) -> list:
    """The ``Choice`` of each kind of joint (``KINDS``) for a gait's samples."""
    if not (isinstance(margin, (int, float)) and 0.0 <= margin <= 10.0):
        raise BipedError(f"margin = {margin!r}: allowed 0 to 10 (a share: 0.2 is 20 %)")
    return [
        choose(Requirement.of(kind, torques, rates, accels, weights, period), catalog, margin)
        for kind in KINDS
    ]
