"""Robot parameters: the single source of truth for masses, lengths and knee radii.

Conventions (used throughout the package, see also ``biped.model.kinematics``):

- Planar robot in the x-z plane, x forward, z up, ground at z = 0.
- Every angle is absolute, measured from the vertical, positive counter-clockwise in the
  x-z plane (from +x towards +z). A segment hanging down from P with angle a ends at
  P + L (sin a, -cos a); the trunk stands up from the hip and ends at P + L (-sin a, cos a).
- Centre-of-mass distances are measured from the proximal end of each segment: the hip for
  thigh and trunk, the knee for the shank, the ankle for the foot (straight below it when
  the foot is flat).
- Rolling knee (paper, Fig. 3): the shank ends in a circle of radius ``r1``, the thigh in a
  circle of radius ``r2``; the two roll without slip. The overall segment lengths ``l1``,
  ``l2`` include the radii, so both robots have the same height.
"""

from __future__ import annotations

import dataclasses
import json
import math
import tomllib
from pathlib import Path

from biped.errors import ParameterError
from biped.model.actuators import Actuators

# Standard gravity [m/s²].
STANDARD_GRAVITY = 9.81
# Coefficient of sliding friction μ between the soles and the floor, the one the MuJoCo models
# use (``validate.scene.mjcf``): a gait whose stance foot needs |Fx| / Fz above it would slip.
FOOT_FRICTION = 1.0
# Stops of the joints [rad], a human's anatomical range, each joint's angle taken as its child's
# absolute angle minus its parent's (hip q_thigh − q_trunk, knee q_shank − q_thigh, ankle
# q_foot − q_shank; the paper's θ of eq. (32) is minus that): the MJCF's joint ranges
# (``validate.scene.mjcf``) and the constraint that keeps a gait inside them
# (``biped.model.walkable``). Extension 29° and flexion 115° at the hip, flexion 138° and 3°
# past straight at the knee, plantar flexion 46° and dorsiflexion 34° at the ankle.
JOINT_STOPS = {"hip": (-0.5, 2.0), "knee": (-2.4, 0.05), "ankle": (-0.8, 0.6)}
# The two ends of a sole, heel first (``Robot.sole_edges``), by the names the MJCF's contact
# points and sites, the recording and the figures give them.
SOLE_EDGES = ("heel", "toe")

# Plausible ranges, wide enough for any walking robot from a toy to twice human size; beyond
# them the numbers are typos or overflow (a 1e308 kg trunk gives torques of inf and nan).
# Mass of one segment [kg].
MASS_RANGE = (1e-3, 1e3)
# Moments of inertia of one segment about its centre of mass [kg·m²].
INERTIA_RANGE = (1e-8, 1e4)
# Lengths and distances [m]: segment lengths, the sole, the ankle height are at least LENGTH_MIN;
# centres of mass and knee radii lie within their segment (checked against its length).
LENGTH_MIN = 1e-3
LENGTH_MAX = 10.0
# Gravitational acceleration [m/s²]: from a small moon's to a few times the Earth's.
GRAVITY_RANGE = (0.1, 100.0)

_MASSES = ("foot_mass", "shank_mass", "thigh_mass", "trunk_mass")
_INERTIAS = ("foot_inertia", "shank_inertia", "thigh_inertia", "trunk_inertia")
# The knee's surfaces: radii >= 0, the profile's rates of any sign (``biped.model.profile``).
PROFILE_FIELDS = ("r1", "r2", "k1", "k2")
_LENGTHS = ("foot_length", "ankle_height", "shank_length", "thigh_length", "trunk_length")


@dataclasses.dataclass(frozen=True)
class Robot:
    """Parameters of the seven-link planar biped (paper, Table 1), SI units.

    Symbols of the paper in brackets. Both legs are identical.
    """

    foot_length: float
    """[m] Length of the sole, heel to toe (L_p); plausible 0.001 to 10 m."""
    foot_heel: float
    """[m] Horizontal distance from the heel to the ankle (l_p)."""
    ankle_height: float
    """[m] Height of the ankle above the sole (h_p); plausible 0.001 to 10 m."""
    foot_mass: float
    """[kg] Mass of one foot (m_p); plausible 0.001 to 1000 kg."""
    foot_inertia: float
    """[kg·m²] Moment of inertia of one foot about its centre of mass (I_p).

    Plausible 1e-8 to 1e4 kg·m² (``INERTIA_RANGE``, as for every segment)."""
    foot_com: float
    """[m] Distance of the foot centre of mass below the ankle (s_p)."""

    shank_length: float
    """[m] Ankle to knee (l_1), the rolling-knee radius r1 included.

    Plausible 0.001 to 10 m (``LENGTH_MIN``, ``LENGTH_MAX``)."""
    shank_mass: float
    """[kg] (m_1); plausible 0.001 to 1000 kg."""
    shank_inertia: float
    """[kg·m²] About the shank centre of mass (I_1); plausible 1e-8 to 1e4 kg·m²."""
    shank_com: float
    """[m] Knee to shank centre of mass (s_1); s1 - r1 from the rolling circle centre C1."""

    thigh_length: float
    """[m] Knee to hip (l_2), the rolling-knee radius r2 included.

    Plausible 0.001 to 10 m (``LENGTH_MIN``, ``LENGTH_MAX``)."""
    thigh_mass: float
    """[kg] (m_2); plausible 0.001 to 1000 kg."""
    thigh_inertia: float
    """[kg·m²] About the thigh centre of mass (I_2); plausible 1e-8 to 1e4 kg·m²."""
    thigh_com: float
    """[m] Hip to thigh centre of mass (s_2)."""

    trunk_length: float
    """[m] Hip to top of the head-arms-trunk segment (l_3); plausible 0.001 to 10 m."""
    trunk_mass: float
    """[kg] (m_3); plausible 0.001 to 1000 kg."""
    trunk_inertia: float
    """[kg·m²] About the trunk centre of mass (I_3); plausible 1e-8 to 1e4 kg·m²."""
    trunk_com: float
    """[m] Hip to trunk centre of mass (s_3)."""

    r1: float = 0.05
    """[m] Radius of the shank's rolling surface (rolling knee only)."""
    r2: float = 0.05
    """[m] Radius of the thigh's rolling surface (rolling knee only)."""
    k1: float = 0.0
    """[m/rad] Rate of the shank's radius of curvature with its tangent angle (rolling knee
    only, ``biped.model.profile``): 0, the circle of radius r1; left out of the file when 0."""
    k2: float = 0.0
    """[m/rad] The thigh's, as ``k1``."""
    gravity: float = STANDARD_GRAVITY
    """[m/s²] Gravitational acceleration; plausible 0.1 to 100 m/s²."""
    actuators: Actuators | None = None
    """The joints' motors and gears (``biped.model.actuators``); None: the default set,
    ``Actuators.default()`` (what ``drive_actuators`` gives), left out of the file."""

    def __post_init__(self):
        if self.actuators is not None and not isinstance(self.actuators, Actuators):
            raise ParameterError("actuators", self.actuators, "a biped.model.actuators.Actuators")
        for field in self.body_fields():
            value = getattr(self, field.name)
            if isinstance(value, bool) or not isinstance(value, (int, float)):
                raise ParameterError(field.name, value, "a real number")
            try:
                number = float(value)
            except OverflowError:  # an integer beyond the floats
                number = math.inf
            if not math.isfinite(number):
                raise ParameterError(field.name, value, "a finite number")
            object.__setattr__(self, field.name, number)
        positive = [f.name for f in self.body_fields() if f.name not in PROFILE_FIELDS]
        for name in positive:
            if getattr(self, name) <= 0.0:
                raise ParameterError(name, getattr(self, name), "> 0")
        for name in ("r1", "r2"):
            if getattr(self, name) < 0.0:
                raise ParameterError(name, getattr(self, name), ">= 0")
        # After the signs, so that a negative mass is told "> 0" (the range's floor is arbitrary).
        for names, (low, high), unit in (
            (_MASSES, MASS_RANGE, "kg"),
            (_INERTIAS, INERTIA_RANGE, "kg·m²"),
            (_LENGTHS, (LENGTH_MIN, LENGTH_MAX), "m"),
            (("gravity",), GRAVITY_RANGE, "m/s²"),
        ):
            for name in names:
                if not low <= getattr(self, name) <= high:
                    raise ParameterError(
                        name, getattr(self, name), f"{low:g} to {high:g} {unit} (plausible range)"
                    )
        self._check_below("foot_heel", "foot_length", "0 < foot_heel < foot_length")
        self._check_below("foot_com", "ankle_height", "0 < foot_com <= ankle_height", strict=False)
        for segment in ("shank", "thigh", "trunk"):
            self._check_below(
                f"{segment}_com", f"{segment}_length", f"0 < {segment}_com < {segment}_length"
            )
        self._check_below("r1", "shank_length", "0 <= r1 < shank_length")
        self._check_below("r2", "thigh_length", "0 <= r2 < thigh_length")
        self._check_profile()

    def _check_profile(self):
        """Profiles (k1, k2 not 0): convex surfaces over the knee's range
        (``biped.model.profile.check_profile``)."""
        from biped.model.profile import PROFILE_RANGE, KneeProfile, check_profile

        try:
            check_profile(KneeProfile.of(self))
        except ValueError as broken:
            which = {"shank": "k1", "thigh": "k2"}.get(str(broken).split()[0], "k1, k2")
            value = {"k1": self.k1, "k2": self.k2}.get(which, (self.k1, self.k2))
            why = "the surfaces stop rolling" if str(broken) == "rolling" else f"{broken} fails"
            raise ParameterError(
                which,
                value,
                f"convex surfaces over the knee's flexion {PROFILE_RANGE[0]:g} to "
                f"{PROFILE_RANGE[1]:g} rad (radii of curvature r + k ψ > 0; here {why})",
            ) from None

    @classmethod
    def body_fields(cls) -> tuple:
        """The fields of the body parameters (numbers), all but ``actuators``."""
        return tuple(f for f in dataclasses.fields(cls) if f.name != "actuators")

    @property
    def drive_actuators(self) -> Actuators:
        """The actuators that drive the joints: ``actuators``, or the default set."""
        return self.actuators if self.actuators is not None else Actuators.default()

    def _check_below(self, name: str, bound: str, allowed: str, strict: bool = True):
        value, limit = getattr(self, name), getattr(self, bound)
        if value > limit or (strict and value == limit):
            raise ParameterError(name, value, f"{allowed} (here {bound} = {limit!r})")

    # ------------------------------------------------------------------ factories
    @classmethod
    def paper(cls) -> Robot:
        """Table 1 of the paper: 70 kg, 1.70 m, knee radii r1 = r2 = 0.05 m."""
        return cls(
            foot_length=0.2584,
            foot_heel=0.0935,
            ankle_height=0.0663,
            foot_mass=1.015,
            foot_inertia=0.001,
            foot_com=0.0331,
            shank_length=0.4182,
            shank_mass=3.2550,
            shank_inertia=0.0519,
            shank_com=0.1811,
            thigh_length=0.4165,
            thigh_mass=7.00,
            thigh_inertia=0.1267,
            thigh_com=0.1803,
            trunk_length=0.7990,
            trunk_mass=47.46,
            trunk_inertia=7.4539,
            trunk_com=0.5002,
            r1=0.05,
            r2=0.05,
        )

    @classmethod
    def from_mapping(cls, values: dict, source: str = "mapping") -> Robot:
        """A robot from a mapping of field names; missing fields take Table 1 values.

        Actuators (``biped.model.actuators``): a table ``actuator`` for every joint and a
        table ``actuators`` of the kinds (``ankle``, ``knee``, ``hip``) over it, each of
        ``Actuator``'s field names (SI units); fields left out take the default actuator's.
        A mapping with neither has the default set (``actuators`` None)."""
        if not isinstance(values, dict):
            raise ParameterError(source, type(values).__name__, "a table of field = value")
        values = dict(values)
        common, per_kind = values.pop("actuator", None), values.pop("actuators", None)
        known = {f.name for f in dataclasses.fields(cls)} | {"actuator"}
        unknown = sorted(set(values) - known)
        if unknown:
            raise ParameterError(unknown[0], values[unknown[0]], f"one of {sorted(known)}")
        if common is not None or per_kind is not None:
            values["actuators"] = Actuators.from_mapping(common, per_kind)
        return dataclasses.replace(cls.paper(), **values)

    @classmethod
    def from_file(cls, path: str | Path) -> Robot:
        """Load a robot from a ``.json`` or ``.toml`` file of field names (SI units).

        Fields left out take their Table 1 value, so ``r1 = 0.08`` alone is a valid file.
        """
        path = Path(path)
        suffix = path.suffix.lower()
        if suffix not in (".json", ".toml"):
            raise ParameterError("file", str(path), "a .json or .toml file")
        try:
            text = path.read_text(encoding="utf-8")
        except OSError as error:
            raise ParameterError("file", str(path), f"a readable file ({error.strerror})") from None
        except UnicodeDecodeError as error:
            raise ParameterError(
                "file", str(path), f"a UTF-8 text file (byte {error.start} is not UTF-8)"
            ) from None
        try:
            values = json.loads(text) if suffix == ".json" else tomllib.loads(text)
        except (json.JSONDecodeError, tomllib.TOMLDecodeError) as error:
            raise ParameterError(
                "file", str(path), f"valid {suffix[1:].upper()} ({error})"
            ) from None
        return cls.from_mapping(values, source=str(path))

    def to_dict(self) -> dict:
        """Field names to values, for JSON output; ``actuators`` (each kind's fields) only
        when given."""
        values = {f.name: getattr(self, f.name) for f in self.body_fields()}
        for name in ("k1", "k2"):  # circles: the files of before
            if values[name] == 0.0:
                del values[name]
        if self.actuators is not None:
            values["actuators"] = self.actuators.to_dict()
        return values

    # ------------------------------------------------------------------ derived values
    @property
    def profiled(self) -> bool:
        """The knee's surfaces are profiles (k1 or k2 not 0), not circles."""
        return self.k1 != 0.0 or self.k2 != 0.0

    @property
    def total_mass(self) -> float:
        """[kg] Mass of the whole robot (two feet, two shanks, two thighs, trunk)."""
        return 2 * (self.foot_mass + self.shank_mass + self.thigh_mass) + self.trunk_mass

    @property
    def weight(self) -> float:
        """[N] Weight of the whole robot, m g (what a cost of transport divides by, with the
        distance)."""
        return self.total_mass * self.gravity

    def sole_edges(self) -> dict[str, float]:
        """[m] x of the heel and the toe from the ankle, by name (``SOLE_EDGES``)."""
        return dict(
            zip(SOLE_EDGES, (-self.foot_heel, self.foot_length - self.foot_heel), strict=True)
        )

    @property
    def height(self) -> float:
        """[m] Standing height: ankle height + shank + thigh + trunk."""
        return self.ankle_height + self.shank_length + self.thigh_length + self.trunk_length
