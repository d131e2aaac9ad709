"""The joints' actuators: an electric motor behind a gear at each joint, and what it takes
electrically to drive a gait.

Each of the six relative joints of eq. (32) is driven by the actuator of its kind (``KINDS``:
ankle, knee, hip; a leg's joint is the same motor whether the leg stands or swings). One
``Actuator`` holds a motor, its gear and the joint's friction; ``Actuators`` one per kind.

The drive, for the joint torque Γ [N·m], rate θ̇ [rad/s] and acceleration θ̈ [rad/s²]
(``drive``; numpy arrays or CasADi expressions alike)::

    Γ_f = b θ̇ + c tanh(θ̇ / ω_c)                 friction at the joint (viscous b, Coulomb c)
    Γ_m = (Γ + Γ_f) / (N η) + J_r N θ̈           motor torque: gear ratio N, efficiency η,
                                                  the rotor J_r accelerated
    i   = Γ_m / k_t                              motor current, torque constant k_t
    u   = R i + k_t N θ̇                          voltage: winding resistance R, back-EMF
    P   = u i = R i² + θ̇ (Γ + Γ_f) / η + J_r N² θ̇ θ̈    electrical power

Convention (smooth, simple, stated here): the gear's loss is a share 1 − η of the torque it
carries, always added to the motor's torque, driving or braking. So the copper losses are
R (Γ / (k_t N η))² for a frictionless, rotor-less joint, whatever the sign of Γθ̇; when
braking, the gear appears to return Γθ̇ / η, more than the joint gives (η < 1): the figure
"with regeneration" is then an upper bound of what a regenerating drive recovers. Coulomb
friction is smoothed over ω_c = ``COULOMB_SMOOTHING`` (its loss c θ̇ tanh(θ̇/ω_c) is c |θ̇|
to within c ω_c). Copper losses R i², friction losses b θ̇² + c θ̇ tanh(θ̇ / ω_c).

A gait's electrical energy (``electrical``): without regeneration the negative power of a
joint is lost, E = ∫ Σ_i max(P_i, 0) dt; with regeneration E_r = ∫ Σ_i P_i dt. A lossless
actuator (R = 0, b = c = 0, J_r = 0, η = 1) has P_i = Γ_i θ̇_i, so that E is the joints'
positive work and 2 E − E_r = ∫ Σ |Γ_i θ̇_i| dt, the paper's energy criterion C_E (eq. 31).

The default set (``Actuators.default``) is the CubeMars AK80-64 at every joint, an integrated
actuator (motor, 64:1 planetary gear, drive) whose figures are its datasheet's, read from the
package's catalog (``catalog.json``, each entry cited; ``Actuator.from_datasheet``): 48 N·m
rated and 120 N·m peak at the joint, sized for the 70 kg robot of Table 1 (its knee holds
72 N·m standing on one leg, ``biped demo``). What no datasheet gives is assumed and named in
the catalog: the gear's efficiency and the viscous friction.
"""

from __future__ import annotations

import dataclasses
import functools
import math
from dataclasses import dataclass
from importlib import resources

import numpy as np

from biped.errors import BipedError, ParameterError
from biped.model import datasheets

# The kinds of joint, each driven by one actuator model; the kind of each joint of eq. (32),
# in the order of ``biped.model.dynamics.JOINTS`` (which imports the robot, hence this module:
# a test holds the two orders equal).
KINDS = ("ankle", "knee", "hip")
JOINT_KINDS = ("ankle", "knee", "hip", "hip", "knee", "ankle")
# [rad/s] Rate over which the Coulomb friction's sign is smoothed (tanh(θ̇ / ω_c)).
COULOMB_SMOOTHING = 1e-2

# The package's catalog of actuators (``biped.model.sizing``, ``biped.model.datasheets``), of
# which the default actuator.
CATALOG = "catalog.json"
DEFAULT_ACTUATOR = "AK80-64 KV80"

# The T-Motor AK80-6 motor (before its 6:1 transmission), from the DFKI underactuated lab's
# documentation of the actuator (https://dfki-ric-underactuated-lab.github.io/double_pendulum/
# hardware.motors.tmotors.html, "Physical Parameters of the Actuator"): torque constant
# 0.091 N·m/A, phase-to-phase resistance 0.170 Ω, rotor inertia 6.0719e-5 kg·m², rated
# 1.092 N·m and peak 2.184 N·m at the motor, 2400 rpm (251.2 rad/s) at 24 V, 485 g with its
# 6:1 gear. The resistance is taken as the one the current i = Γ_m / k_t flows through.
AK80_MOTOR = {
    "torque_constant": 0.091,
    "resistance": 0.170,
    "rotor_inertia": 6.0719e-5,
    "motor_continuous_torque": 1.092,
    "motor_peak_torque": 2.184,
    "motor_max_speed": 251.2,
    "supply_voltage": 24.0,
}
# The default set before the catalog's datasheets (``Actuator.legacy``: what a gait file of
# format biped-gait/2 without actuators was computed with): the AK80-6's motor behind a
# modelled 64:1 gear of three stages of efficiency 0.9, 850 g, with assumed friction.
LEGACY_GEAR_RATIO = 64.0
LEGACY_GEAR_EFFICIENCY = 0.9**3
LEGACY_MASS = 0.85
LEGACY_VISCOUS = 0.1  # [N·m·s/rad]
LEGACY_COULOMB = 0.5  # [N·m]

_POSITIVE = (
    "torque_constant",
    "gear_ratio",
    "gear_efficiency",
    "continuous_torque",
    "peak_torque",
    "max_speed",
    "supply_voltage",
)


@dataclass(frozen=True)
class Actuator:
    """One joint's motor, gear and friction; torques, speeds and frictions at the joint."""

    torque_constant: float
    """[N·m/A] Motor torque per ampere (k_t); also its back-EMF constant [V·s/rad]."""
    resistance: float
    """[Ω] Winding resistance the motor current flows through (R); 0 or more."""
    rotor_inertia: float
    """[kg·m²] Moment of inertia of the motor's rotor (J_r); 0 or more."""
    gear_ratio: float
    """[1] Motor turns per joint turn (N); > 0."""
    gear_efficiency: float
    """[1] Share of the torque the gear passes on (η); 0 < η <= 1."""
    viscous_friction: float
    """[N·m·s/rad] Viscous friction at the joint (b); 0 or more."""
    coulomb_friction: float
    """[N·m] Coulomb friction at the joint (c); 0 or more."""
    continuous_torque: float
    """[N·m] Torque the actuator holds continuously at the joint (its RMS limit); > 0."""
    peak_torque: float
    """[N·m] Largest torque at the joint; >= continuous_torque."""
    max_speed: float
    """[rad/s] Largest joint speed; > 0."""
    supply_voltage: float
    """[V] Voltage of the supply, the largest |u| the drive applies; > 0."""
    mass: float
    """[kg] Mass of motor and gear; 0 or more."""

    def __post_init__(self):
        for f in dataclasses.fields(self):
            value = getattr(self, f.name)
            if isinstance(value, bool) or not isinstance(value, (int, float)):
                raise ParameterError(f"actuator.{f.name}", value, "a real number")
            if not math.isfinite(value):
                raise ParameterError(f"actuator.{f.name}", value, "a finite number")
            object.__setattr__(self, f.name, float(value))
            if f.name in _POSITIVE and value <= 0.0:
                raise ParameterError(f"actuator.{f.name}", value, "> 0")
            if value < 0.0:
                raise ParameterError(f"actuator.{f.name}", value, ">= 0")
        if self.gear_efficiency > 1.0:
            raise ParameterError("actuator.gear_efficiency", self.gear_efficiency, "0 < η <= 1")
        if self.peak_torque < self.continuous_torque:
            raise ParameterError(
                "actuator.peak_torque",
                self.peak_torque,
                f">= continuous_torque = {self.continuous_torque!r} N·m",
            )

    @classmethod
    def geared(cls, motor: dict, ratio: float, efficiency: float, mass: float, **friction):
        """The actuator of a ``motor`` (``AK80_MOTOR``'s keys) behind a gear: its joint
        torques N η × the motor's, its speed the motor's / N."""
        return cls(
            torque_constant=motor["torque_constant"],
            resistance=motor["resistance"],
            rotor_inertia=motor["rotor_inertia"],
            gear_ratio=ratio,
            gear_efficiency=efficiency,
            viscous_friction=friction.get("viscous_friction", LEGACY_VISCOUS),
            coulomb_friction=friction.get("coulomb_friction", LEGACY_COULOMB),
            continuous_torque=ratio * efficiency * motor["motor_continuous_torque"],
            peak_torque=ratio * efficiency * motor["motor_peak_torque"],
            max_speed=motor["motor_max_speed"] / ratio,
            supply_voltage=motor["supply_voltage"],
            mass=mass,
        )

    @classmethod
    def default(cls) -> Actuator:
        """The AK80-64 of the package's catalog (``DEFAULT_ACTUATOR``, see the module)."""
        return package_catalog()[DEFAULT_ACTUATOR]

    @classmethod
    def legacy(cls) -> Actuator:
        """The default actuator before the catalog's datasheets: the AK80-6's motor behind a
        modelled 64:1 gear (``LEGACY_GEAR_RATIO``), for the gait files written with it."""
        return cls.geared(AK80_MOTOR, LEGACY_GEAR_RATIO, LEGACY_GEAR_EFFICIENCY, LEGACY_MASS)

    @classmethod
    def from_datasheet(cls, entry: dict, source: str = "catalog") -> Actuator:
        """The actuator of a catalog entry (``biped.model.datasheets``): its datasheet's
        figures in SI units and its assumed fields; a BipedError naming the figure as the
        file has it when one is not allowed."""
        names = [f.name for f in dataclasses.fields(cls)]
        values, origins = datasheets.fields_of(entry, names, _POSITIVE, source)
        try:
            return cls(**values)
        except ParameterError as error:  # a rule between fields: named as the file has them
            field = error.field.rsplit(".", 1)[-1]
            raise BipedError(
                f"{source}: {origins[field]} is invalid: allowed {error.allowed}"
            ) from None

    @classmethod
    def lossless(cls, **changes) -> Actuator:
        """The default actuator without losses: R = 0, b = c = 0, J_r = 0, η = 1."""
        values = dataclasses.asdict(cls.default())
        values.update(
            resistance=0.0,
            rotor_inertia=0.0,
            gear_efficiency=1.0,
            viscous_friction=0.0,
            coulomb_friction=0.0,
        )
        return cls(**{**values, **changes})

    @classmethod
    def from_mapping(cls, values, base: Actuator | None = None, source: str = "actuator"):
        """An actuator from a mapping of field names; missing fields take ``base``'s (the
        default actuator's)."""
        if not isinstance(values, dict):
            raise ParameterError(source, type(values).__name__, "a table of field = value")
        known = [f.name for f in dataclasses.fields(cls)]
        unknown = sorted(set(values) - set(known))
        if unknown:
            raise ParameterError(f"{source}.{unknown[0]}", values[unknown[0]], f"one of {known}")
        try:
            return dataclasses.replace(base or cls.default(), **values)
        except ParameterError as error:  # named as the file names it
            name = error.field.split(".", 1)[1]
            raise ParameterError(f"{source}.{name}", error.value, error.allowed) from None


# Where the package's catalog is, as messages name it.
CATALOG_SOURCE = f"biped/model/{CATALOG}"


@functools.cache
def package_catalog_text() -> str:
    """The package's catalog (``CATALOG``), as its file holds it (read once)."""
    return resources.files("biped.model").joinpath(CATALOG).read_text(encoding="utf-8")


@functools.cache
def package_catalog() -> dict[str, Actuator]:
    """The actuators of the package's catalog by name (read once)."""
    content = datasheets.loads(package_catalog_text(), CATALOG_SOURCE)
    return catalog_actuators(content, CATALOG_SOURCE)


def catalog_actuators(content, source: str) -> dict[str, Actuator]:
    """The actuators of a catalog's JSON content (``biped.model.datasheets.CATALOG_FORMAT``)
    by name."""
    return {
        entry["name"]: Actuator.from_datasheet(entry, f"catalog {source!r} {entry['name']!r}")
        for entry in datasheets.entries(content, source)
    }


UNITS = {
    "torque_constant": "N·m/A",
    "resistance": "Ω",
    "rotor_inertia": "kg·m²",
    "gear_ratio": "1",
    "gear_efficiency": "1",
    "viscous_friction": "N·m·s/rad",
    "coulomb_friction": "N·m",
    "continuous_torque": "N·m",
    "peak_torque": "N·m",
    "max_speed": "rad/s",
    "supply_voltage": "V",
    "mass": "kg",
}


@dataclass(frozen=True)
class Actuators:
    """The actuator of each kind of joint (``KINDS``); ``Actuators.default()`` the same
    default actuator at every joint."""

    ankle: Actuator
    knee: Actuator
    hip: Actuator

    @classmethod
    def default(cls) -> Actuators:
        return cls.same(Actuator.default())

    @classmethod
    def legacy(cls) -> Actuators:
        """``Actuator.legacy`` at every joint: the set of gait files of format biped-gait/2
        written without actuators."""
        return cls.same(Actuator.legacy())

    @classmethod
    def same(cls, actuator: Actuator) -> Actuators:
        """One actuator at every joint."""
        return cls(actuator, actuator, actuator)

    @classmethod
    def from_mapping(cls, common=None, per_kind=None) -> Actuators:
        """From a robot file's tables: ``common`` (``[actuator]``: every joint) and
        ``per_kind`` (``[actuators.knee]`` ...: one kind, over ``common``); fields left out
        take the default actuator's."""
        base = Actuator.from_mapping(common if common is not None else {}, source="actuator")
        per_kind = {} if per_kind is None else per_kind
        if not isinstance(per_kind, dict):
            raise ParameterError("actuators", type(per_kind).__name__, f"a table of {KINDS}")
        unknown = sorted(set(per_kind) - set(KINDS))
        if unknown:
            raise ParameterError(f"actuators.{unknown[0]}", per_kind[unknown[0]], f"one of {KINDS}")
        return cls(
            **{
                kind: Actuator.from_mapping(per_kind.get(kind, {}), base, f"actuators.{kind}")
                for kind in KINDS
            }
        )

    def to_dict(self) -> dict:
        """Each kind's fields, for JSON (read back by ``from_mapping(None, ...)``)."""
        return {kind: dataclasses.asdict(getattr(self, kind)) for kind in KINDS}

    def per_joint(self) -> tuple:
        """The actuator of each joint of ``biped.model.dynamics.JOINTS``."""
        return tuple(getattr(self, kind) for kind in JOINT_KINDS)

    def constants(self) -> dict:
        """Each field as an array (6,) over the joints (``JOINTS``), read-only (built once
        per set: every evaluation of a step asks for them)."""
        return _constants(self)


@functools.cache
def _constants(actuators: Actuators) -> dict:
    joints = actuators.per_joint()
    arrays = {
        f.name: np.array([getattr(a, f.name) for a in joints]) for f in dataclasses.fields(Actuator)
    }
    for array in arrays.values():
        array.setflags(write=False)
    return arrays


@dataclass(frozen=True)
class Drive:
    """The motors' state at each sample and joint (arrays (..., 6) or CasADi expressions)."""

    current: object  # [A] i
    voltage: object  # [V] u
    copper: object  # [W] R i²
    friction: object  # [W] b θ̇² + c θ̇ tanh(θ̇ / ω_c)
    power: object  # [W] P = u i


def drive(constants: dict, torque, speed, acceleration, tanh=np.tanh) -> Drive:
    """The drive of the module's formulas for joint torques Γ, rates θ̇ and accelerations
    θ̈: numpy arrays (..., 6) with ``constants`` of ``Actuators.constants``, or CasADi
    expressions (6, 1) with the constants as CasADi columns and ``tanh=casadi.tanh``."""
    k = constants
    smooth = tanh(speed / COULOMB_SMOOTHING)
    friction_torque = k["viscous_friction"] * speed + k["coulomb_friction"] * smooth
    ratio = k["gear_ratio"]
    motor = (torque + friction_torque) / (ratio * k["gear_efficiency"])
    motor = motor + k["rotor_inertia"] * ratio * acceleration
    current = motor / k["torque_constant"]
    voltage = k["resistance"] * current + k["torque_constant"] * ratio * speed
    return Drive(
        current=current,
        voltage=voltage,
        copper=k["resistance"] * current * current,
        friction=k["viscous_friction"] * speed * speed + k["coulomb_friction"] * speed * smooth,
        power=voltage * current,
    )


def limit_margins(constants: dict, torque, speed, voltage) -> list:
    """The actuator limits as margins >= 0 when met, each divided by its limit (a share):
    1 ∓ Γ / Γ_peak, 1 ∓ θ̇ / θ̇_max, 1 ∓ u / u_supply, in that order (numpy or CasADi,
    elementwise)."""
    k = constants
    margins = []
    for value, limit in (
        (torque, k["peak_torque"]),
        (speed, k["max_speed"]),
        (voltage, k["supply_voltage"]),
    ):
        margins += [1.0 - value / limit, 1.0 + value / limit]
    return margins


LIMITS = ("peak_torque", "max_speed", "supply_voltage")
