"""Gait files: one optimal gait as a ``Gait`` record, written as JSON atomically (SI units,
the paper's coordinate order; ground at z = 0, stance ankle at x = 0), read back with checks.

``Gait`` and its inner records (``Costs``, ``Constraints``, ``Impact``, ``Electrical``,
``KneeLoads``, ``Optimizer``, ``Samples``) are declared once, each field with its unit as
metadata: the file holds their fields in their order, ``format`` first and ``units``
(``Gait.units``: the unit of every number, see ``biped.model.units``) before ``samples``.
``costs`` are on the check grid of 202 samples per step (what the comparisons, tables and
figures use); ``optimizer.value`` is the criterion on the solver's 52 samples per step, which
ranked the starts. ``constraints`` hold the worst Ψ_i on the samples less the safety margins
(>= 0 when met); ``impact.consistent``: Iz > 0 and the trailing foot lifts (the flat-foot
impact model holds); ``knee_loads``: the force of the thigh on the lower leg through each knee
on the check grid, along and across the rolling knee's line of centres, and the ligament load
it needs; ``provenance``: what produced the file (``biped.records.provenance``). The samples
run from t = 0 to t = T inclusive on both spline pieces; t = T/2 appears twice, left and right
limits, because the accelerations (and torques) jump at the knot.

``Gait.read`` checks the format and names the bad field; with ``consistent=True`` it also
recomputes what the parameters determine (``Gait.check_consistency``) and refuses a file
whose figures are not those of its parameters, naming the field: every command that reads a
gait file a user gives reads it so.
"""

from __future__ import annotations

import dataclasses
import functools
import json
import math
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from biped.errors import BipedError
from biped.model import walkable
from biped.model.actuators import KINDS, Actuators
from biped.model.actuators import UNITS as ACTUATOR_UNITS
from biped.model.bezier import Bezier
from biped.model.criteria import (
    ALL_CRITERIA,
    CONSTRAINTS,
    CRITERIA,
    CRITERION_UNITS,
    PAPER_SAFETY,
    Safety,
    evaluate_step,
    safety_dict,
)
from biped.model.dynamics import JOINTS, Biped
from biped.model.gait import PARAMETERS, build_step, check_knots, parameter_names
from biped.model.impact import trailing_foot_lift
from biped.model.kinematics import COORDINATES, KNEES, XH
from biped.model.knee_loads import KNEE_SIDES, knee_forces
from biped.model.robot import Robot
from biped.model.two_phase import LANDINGS
from biped.model.two_phase import parameter_names as two_phase_parameter_names
from biped.model.units import (
    CONSTRAINT_UNITS,
    PERCENT,
    PURE,
    declared_units,
    parameter_unit,
    per_coordinate,
    robot_unit,
    unit_field,
)
from biped.optimization.comparison import GAINS, PROFILE_DESIGN_UNITS, RADII
from biped.optimization.problem import (
    CHECK_SAMPLES,
    VARIABLES,
    GaitProblem,
    check_speed,
    variable_names,
)
from biped.optimization.report import Report
from biped.records.provenance import provenance as make_provenance
from biped.records.two_phase_gait import (
    DoubleSupport,
    double_support_of,
    two_phase_step,
    unit_of,
)
from biped.records.validation_report import is_report
from biped.runtime.files import atomic_write_text

if TYPE_CHECKING:  # reading a gait file needs no solver (CasADi)
    from biped.optimization.optimize import Optimum

# 2: safety margins recorded; 3: a robot without actuators has the catalog's default set
# (``biped.model.actuators.Actuators.default``).
FORMAT = "biped-gait/3"
# Earlier formats read: a file of format 2 whose robot names no actuators was computed with
# the default set of its time (``Actuators.legacy``), which it is read with.
EARLIER_FORMATS = ("biped-gait/2",)
# A block added to a format (``electrical``, ``knee_loads``) changes none of its other figures
# and leaves the format as it is: a file written before the block reads with None there.
READ_FORMATS = (FORMAT, *EARLIER_FORMATS)
# Shortest step a gait file may hold [m]: shorter is no walk (a speed near 0).
MIN_STEP_LENGTH = 1e-3
# What a gait file is and who writes it, for a message refusing another file.
GAIT_FILE = f"a gait file (format {FORMAT!r}) that biped optimize, sweep, design or pipeline writes"
# The project's other JSON files with a "format", by its prefix (the version follows "/"):
# what each is, and the command that writes it.
OTHER_FORMATS = {
    "biped-sweep/": "a sweep's record (which biped sweep writes, as sweep.json)",
    "biped-design-map/": (
        "a design map's record (which biped design-map writes, as design-map.json)"
    ),
    "biped-paper-method/": (
        "the record of the paper's method's runs (which biped sweep --paper-seeds writes, as "
        "paper-method/settings.json)"
    ),
    "biped-atlas/": "an atlas's record (which biped atlas writes, as atlas.json)",
    "biped-optima-table/": (
        "a table of optima (which biped table writes; the package ships one, "
        "biped/optimization/optima.json)"
    ),
    "biped-actuator-catalog/": "a catalog of actuators (which biped size --catalog reads)",
}
# The project's other JSON files without a "format", by the keys that only they hold.
OTHER_KEYS = (
    ({"nominal", "limits", "ranges"}, "a robustness map (which biped robustness writes)"),
    ({"orbits", "knob", "boundaries"}, "an orbit study (which biped orbit writes)"),
    (
        {"status", "certified", "next_optimum", "variables"},
        "one optimization of an atlas (which biped atlas writes)",
    ),
)
# A recording's owner record (``validate.outputs.outputs``) holds these keys and no other.
OWNER_RECORD = (
    {"gait", "sha256"},
    "a recording's owner record (which biped validate and biped pipeline write beside it)",
)
# Consistency: the derived fields of a gait file against those recomputed from its parameters.
# A file keeps every bit of its numbers (JSON), so only the rounding of another CPU or numpy
# build (1e-13 of a field's size or so) may separate them; an edited figure differs by far
# more. Allowed difference: CONSISTENCY_RTOL × the field's largest magnitude (at least 1 in
# its unit, so fields near zero are not held to nothing).
CONSISTENCY_RTOL = 1e-9


RATES = per_coordinate("rad/s", "m/s")
# Units of a designed knee's block, ``design`` (``biped.optimization.design.Comparison``): the
# radii and their bounds, each knee compared (the revolute knee's radii null), the changes.
DESIGN_UNITS = {
    **{f"design.{group}.{name}": "m" for group in ("radii", "lower", "upper") for name in RADII},
    "design.compared[].radii": "m",
    **{f"design.compared[].radii.{name}": "m" for name in RADII},
    "design.compared[].sthenic": CRITERION_UNITS["sthenic"],
    "design.compared[].energy": CRITERION_UNITS["energy"],
    **{f"design.gains_percent.{name}": PERCENT for name in GAINS},
}


@dataclass(frozen=True, eq=False)
class Samples:
    """The gait on the check grid (N samples from t = 0 to T, T/2 twice), as numpy arrays."""

    t: np.ndarray = unit_field("s")
    q: np.ndarray = unit_field(per_coordinate("rad", "m"), COORDINATES)
    qd: np.ndarray = unit_field(RATES, COORDINATES)
    qdd: np.ndarray = unit_field(per_coordinate("rad/s²", "m/s²"), COORDINATES)
    torques: np.ndarray = unit_field("N·m", JOINTS)
    wrench: np.ndarray = unit_field(["N", "N", "N·m"], ("Fx", "Fz", "Cy"))
    zmp: np.ndarray = unit_field("m")

    def to_dict(self) -> dict:
        return {f.name: getattr(self, f.name).tolist() for f in dataclasses.fields(self)}


class _Record:
    """A gait's object of named values (costs, constraints, impact), declared with units."""

    def to_dict(self) -> dict:
        """The fields in order (one the file lacked left out, as it was)."""
        values = {f.name: getattr(self, f.name) for f in dataclasses.fields(self)}
        return {name: value for name, value in values.items() if value is not None}

    @classmethod
    def from_content(cls, content, name: str, bad):
        """The record of a file's object ``name`` as it holds it (None for none; a field it
        lacks None, named by ``Gait.check_consistency``); ``bad`` if it is not an object."""
        if content is None:
            return None
        if not isinstance(content, dict):
            raise bad(f"{name} = {content!r}, allowed an object")
        return cls(**{f.name: content.get(f.name) for f in dataclasses.fields(cls)})


def _cost(unit: str, label: str, of):
    """A field of ``Costs``: its unit, its label on a page, and ``of(model, step, evaluation)``,
    its value for the gait's model, step and evaluation on the check grid."""
    return unit_field(unit, metadata={"label": label, "of": of})


@dataclass(frozen=True, eq=False)
class Costs(_Record):
    """The gait's criteria on the check grid (no penalty), which the comparisons use; each
    field says its unit, its label and how it follows from the gait, so that a new cost is
    one declaration here (its file entry, unit, consistency check and page row follow)."""

    sthenic: float = _cost(
        CRITERION_UNITS["sthenic"],
        "sthenic criterion C_Γ (per metre walked)",
        lambda model, step, ev: ev.sthenic,
    )
    energy: float = _cost(
        CRITERION_UNITS["energy"],
        "energy criterion C_E (per step)",
        lambda model, step, ev: ev.energy,
    )
    energy_per_metre: float = _cost(
        "J/m", "energy per metre walked", lambda model, step, ev: ev.energy / step.step_length
    )
    # Added after the per-metre criteria: a file written before has none (read, and left so).
    cost_of_transport: float | None = unit_field(
        PURE,
        metadata={
            "label": "cost of transport C_E / (m g S)",
            "of": lambda model, step, ev: ev.energy / (step.step_length * model.robot.weight),
            "optional": True,
        },
        default=None,
    )
    # Added with the actuators: a file written before has none (read, and left so).
    electrical: float | None = unit_field(
        CRITERION_UNITS["electrical"],
        metadata={
            "label": "electrical energy per metre walked (no regeneration)",
            "of": lambda model, step, ev: ev.electrical / step.step_length,
            "optional": True,
        },
        default=None,
    )

    @classmethod
    def of(cls, model: Biped, step, evaluation) -> Costs:
        """The costs of a gait's step and its evaluation on the check grid."""
        fields = dataclasses.fields(cls)
        return cls(**{f.name: f.metadata["of"](model, step, evaluation) for f in fields})

    def criterion(self, name: str) -> float:
        """The value of the criterion ``name`` (``biped.model.criteria.ALL_CRITERIA``)."""
        return getattr(self, name.replace("-", "_"))

    def labelled(self) -> list[tuple]:
        """(name, label, value, unit) of each cost the gait has, in order."""
        fields = [(f, getattr(self, f.name)) for f in dataclasses.fields(self)]
        return [
            (f.name, f.metadata["label"], value, f.metadata["unit"])
            for f, value in fields
            if value is not None
        ]


def _per_joint(unit: str, label: str):
    """A field of ``Electrical`` per joint (``JOINTS``): its unit and what it is."""
    return unit_field(unit, JOINTS, metadata={"label": label})


def _total(unit: str, label: str):
    """A field of ``Electrical`` for the whole gait: its unit and what it is."""
    return unit_field(unit, metadata={"label": label})


@dataclass(frozen=True, eq=False)
class Electrical(_Record):
    """What the motors draw to walk the gait (``biped.model.actuators``: current i, voltage
    u, power P = u i at each joint), on the check grid; energies per step unless per metre.
    Without regeneration a joint's negative power is lost (∫ max(P, 0) dt), with it it is
    recovered (∫ P dt). The cost of transport is the energy per metre over the weight m g."""

    current_peak: list = _per_joint("A", "largest current")
    current_rms: list = _per_joint("A", "RMS current over the step")
    voltage_peak: list = _per_joint("V", "largest voltage")
    copper: list = _per_joint("J", "copper losses R i² over the step")
    friction: list = _per_joint("J", "friction losses over the step")
    energy: list = _per_joint("J", "electrical energy over the step, no regeneration")
    energy_regenerated: list = _per_joint("J", "electrical energy over the step, regeneration")
    energy_per_step: float = _total("J", "energy drawn per step, no regeneration")
    energy_per_metre: float = _total("J/m", "energy drawn per metre, no regeneration")
    cost_of_transport: float = _total(PURE, "cost of transport, no regeneration")
    regenerated_energy_per_step: float = _total("J", "energy drawn per step, with regeneration")
    regenerated_energy_per_metre: float = _total("J/m", "energy drawn per metre, with regeneration")
    regenerated_cost_of_transport: float = _total(PURE, "cost of transport, with regeneration")

    @classmethod
    def of(cls, model: Biped, step, ev) -> Electrical:
        """The electrical figures of a gait's step and its evaluation on the check grid."""
        weights, drive, length = ev.weights, ev.drive, step.step_length
        weight = model.robot.weight

        def integral(rate) -> list:
            return [float(v) for v in weights @ rate]

        return cls(
            current_peak=np.abs(drive.current).max(axis=0).tolist(),
            current_rms=np.sqrt(np.array(integral(drive.current**2)) / step.period).tolist(),
            voltage_peak=np.abs(drive.voltage).max(axis=0).tolist(),
            copper=integral(drive.copper),
            friction=integral(drive.friction),
            energy=integral(np.maximum(drive.power, 0.0)),
            energy_regenerated=integral(drive.power),
            energy_per_step=ev.electrical,
            energy_per_metre=ev.electrical / length,
            cost_of_transport=ev.electrical / (length * weight),
            regenerated_energy_per_step=ev.electrical_net,
            regenerated_energy_per_metre=ev.electrical_net / length,
            regenerated_cost_of_transport=ev.electrical_net / (length * weight),
        )


# The knees of ``KneeLoads``: the stance leg's, in stance, and the swing leg's, in swing (each
# leg's knee through its stance, resp. its swing, over the two steps of a stride).
KNEE_COLUMNS = tuple(f"{side}_knee" for side in KNEE_SIDES)


def _per_knee(unit: str, label: str):
    """A field of ``KneeLoads`` per knee (``KNEE_COLUMNS``): its unit and what it is."""
    return unit_field(unit, KNEE_COLUMNS, metadata={"label": label})


@dataclass(frozen=True, eq=False)
class KneeLoads(_Record):
    """The force of the thigh on the lower leg through each knee on the check grid
    (``biped.model.knee_loads``), one column per knee (``KNEE_COLUMNS``): its normal part N
    along the rolling knee's line of centres, from the thigh's circle's centre C2 to the
    shank's C1 (the revolute knee's shank, knee to ankle), > 0 compression, < 0 tension, and
    its tangential part T across it. Two surfaces in contact carry no tension: a rolling knee
    with N < 0 anywhere needs ligaments, which carry the largest tension; a revolute knee's
    pin carries it. |T| / N where N > 0 is the friction coefficient rolling without slip
    needs (None: a knee never compressed)."""

    normal: list = _per_knee("N", "normal force N along the line of centres (> 0 compression)")
    tangential: list = _per_knee("N", "tangential force T across the line of centres")
    max_tension: list = _per_knee("N", "largest tension max(-N), the ligament load needed")
    max_compression: list = _per_knee("N", "largest compression max(N)")
    max_slip_ratio: list = _per_knee(PURE, "largest |T| / N where N > 0")
    needs_ligaments: bool  # a rolling knee in tension (N < 0) at some sample

    @classmethod
    def of(cls, model: Biped, evaluation) -> KneeLoads:
        """The knee loads of a step's evaluation on the check grid (with its ground wrench)."""
        ev = evaluation
        loads = knee_forces(model, ev.q, ev.qd, ev.qdd, ev.wrench)
        ratio = np.max(np.nan_to_num(loads.slip_ratio, nan=-1.0), axis=0)
        tension = loads.tension.max(axis=0)
        return cls(
            normal=loads.normal.tolist(),
            tangential=loads.tangential.tolist(),
            max_tension=tension.tolist(),
            max_compression=loads.compression.max(axis=0).tolist(),
            max_slip_ratio=[float(r) if r >= 0.0 else None for r in ratio],
            needs_ligaments=bool(sum(model.radii) > 0.0 and tension.max() > 0.0),
        )


# The worst Ψ_i of each constraint on the check grid less its safety margin (>= 0 when met),
# by name (``biped.model.criteria.CONSTRAINTS``).
Constraints = dataclasses.make_dataclass(
    "Constraints",
    [(name, float, unit_field(unit)) for name, unit in CONSTRAINT_UNITS.items()],
    bases=(_Record,),
    frozen=True,
    eq=False,
    namespace={"__module__": __name__, "__doc__": "Ψ_i − margin, worst on the check grid."},
)


def _margin(unit, label: str):
    """A field of ``Walkability``: the tightest margin of one walkable constraint, written
    only where the gait's ``safety`` asks for the constraint."""
    return unit_field(unit, metadata={"label": label, "optional": True}, default=None)


def _added(unit, label: str):
    """A field added to a record after format 3's first files: a file written before has
    none (read, and left so; ``_Record.to_dict`` leaves it out)."""
    return unit_field(unit, metadata={"label": label, "optional": True}, default=None)


@dataclass(frozen=True, eq=False)
class Impact(_Record):
    """The flat-foot impact that ends the step (eqs. 21-24): the impulse on the landing foot
    [Fx, Fz, Cy], the trailing foot's lift velocities (heel, toe), whether the flat-foot model
    holds (Iz > 0 and the trailing foot lifts, or no impact: the sole lands at rest), the
    velocities just before and after it; the sole's velocity (vx, vz) and speed at touchdown
    (every point of the flat, not turning sole moves as the ankle,
    ``biped.model.walkable.touchdown_velocity``) and the impulse's |Ix| / Iz, the friction
    the landing needs."""

    impulse: list = unit_field(["N·s", "N·s", "N·m·s"])
    trailing_foot_lift: list = unit_field("m/s")
    consistent: bool
    qd_minus: list = unit_field(RATES)
    qd_plus: list = unit_field(RATES)
    touchdown_velocity: list | None = _added("m/s", "the sole's velocity at touchdown")
    touchdown_speed: float | None = _added("m/s", "the sole's speed at touchdown")
    friction_needed: float | None = _added(PURE, "the landing's |Ix| / Iz")

    @classmethod
    def of(cls, model: Biped, step) -> Impact:
        """The impact at the end of a gait's step."""
        qd_plus, _ = model.impact(*step.end)
        lift = trailing_foot_lift(model, step.end[0], qd_plus)
        velocity = walkable.touchdown_velocity(model, *step.end)
        speed = float(np.linalg.norm(velocity))
        pushed = step.impulse[1] > 0 and np.all(lift >= 0)
        tolerance = walkable.LANDING_TOLERANCE
        at_rest = bool(speed <= tolerance and np.all(lift >= -tolerance))
        return cls(
            impulse=step.impulse.tolist(),
            trailing_foot_lift=lift.tolist(),
            consistent=bool(pushed or at_rest),
            qd_minus=step.end[1].tolist(),
            qd_plus=step.start[1].tolist(),
            touchdown_velocity=velocity.tolist(),
            touchdown_speed=speed,
            friction_needed=_landing_friction(step.impulse, at_rest),
        )


def _landing_friction(impulse, at_rest: bool) -> float | None:
    """|Ix| / Iz of the landing's impulse: the friction it needs; 0 for a landing at rest
    (no impulse), None (unknown) for an impulse that pulls the sole (Iz <= 0)."""
    if impulse[1] > 0:
        return float(abs(impulse[0]) / impulse[1])
    return 0.0 if at_rest else None


@dataclass(frozen=True, eq=False)
class Walkability(_Record):
    """What walking the gait asks of the floor, the joints and the hip, on the check grid
    (``biped.model.walkable``): the stance foot's largest |Fx| / Fz, the least distance of a hip
    or ankle to its stop (``biped.model.robot.JOINT_STOPS``), the hip's least forward speed;
    and the tightest margin of each walkable constraint the gait's ``safety`` asks (>= 0 when
    met; None where not asked), each in its unit."""

    friction_needed: float = unit_field(PURE, metadata={"label": "the stance foot's |Fx| / Fz"})
    joint_stop_distance: float = unit_field(
        "rad", metadata={"label": "a hip's or an ankle's least distance to its stop"}
    )
    least_hip_speed: float = unit_field("m/s", metadata={"label": "the hip's least speed"})
    landing: float | None = _margin("m/s", "landing speed")
    impact_friction: float | None = _margin("N·s", "the landing's friction cone")
    friction: float | None = _margin("N", "the stance foot's friction cone")
    joint_stops: float | None = _margin("rad", "the joints' stops")
    progress: float | None = _margin("m/s", "the hip's least speed")

    @classmethod
    def of(cls, model: Biped, evaluation) -> Walkability:
        """The figures of a gait's evaluation on the check grid."""
        wrench = evaluation.wrench
        distances = walkable.joint_stop_margins(model.joint_angles(evaluation.q).T, 0.0)
        margins = {name: float(m.min()) for name, m in evaluation.walkable.items()}
        return cls(
            friction_needed=float(np.max(np.abs(wrench[:, 0]) / wrench[:, 1])),
            joint_stop_distance=float(np.min(distances)),
            least_hip_speed=float(evaluation.qd[:, XH].min()),
            **margins,
        )


@dataclass(frozen=True, eq=False)
class Optimizer(Report):
    """How the gait was found (``biped.optimization.optimize.Report``) and the solver's
    variables at its optimum (None where not finite: a Nelder-Mead point beyond their reach)."""

    variables: dict = unit_field({name: parameter_unit(name) for name in VARIABLES}, kw_only=True)

    @classmethod
    def of(cls, report: Report, variables, names=VARIABLES) -> Optimizer:
        """The record of ``report`` and ``variables`` named ``names`` (the paper's spline's
        21 by default)."""
        fields = {f.name: getattr(report, f.name) for f in dataclasses.fields(Report)}
        named = dict(zip(names, map(_finite_or_none, variables), strict=True))
        return cls(**fields, variables=named)

    def report(self) -> Report:
        """The optimizer's ``Report`` alone."""
        return Report(**{f.name: getattr(self, f.name) for f in dataclasses.fields(Report)})


@dataclass(frozen=True, eq=False)
class Gait:
    """One optimal gait, as its file holds it (see the module); built by ``from_optimum`` or
    ``read``. Its ``biped``, ``problem`` and ``parameter_vector`` follow from it."""

    knee: str
    criterion: str
    speed: float = unit_field("m/s")
    period: float = unit_field("s")
    step_length: float = unit_field("m")
    safety: Safety = unit_field(Safety)  # margins beyond the paper's constraints
    feasible: bool  # every constraint holds on the check grid
    costs: Costs = unit_field(Costs)
    robot: Robot = unit_field({f.name: robot_unit(f.name) for f in Robot.body_fields()})
    parameters: dict = unit_field({name: parameter_unit(name) for name in PARAMETERS})
    constraints: Constraints | None = unit_field(Constraints)  # None: a file without them
    impact: Impact | None = unit_field(Impact)  # None: a file without it
    walkability: Walkability | None = unit_field(Walkability)  # None: a file without it
    electrical: Electrical | None = unit_field(Electrical)  # None: a file without it
    knee_loads: KneeLoads | None = unit_field(KneeLoads)  # None: a file without them
    optimizer: Optimizer = unit_field(Optimizer)
    provenance: dict
    samples: Samples = unit_field(Samples)
    design: dict | None = None  # a designed knee's (``biped design``)
    # The gait family: interior knots of a spline (1: the paper's; written if not), or a
    # Bézier family, written {"bezier": degree} (``family_of``).
    knots: int | Bezier = 1
    # A two-phase gait's double support phase (``biped.records.two_phase_gait``); None (not
    # written): a gait of single support only.
    double_support: DoubleSupport | None = unit_field(DoubleSupport, default=None)

    @classmethod
    def from_optimum(cls, optimum: Optimum, robot: Robot, provenance: dict | None = None) -> Gait:
        """The gait of an optimum of ``robot``; ``provenance``: what produced it (default:
        ``biped.records.provenance.provenance()`` now)."""
        ev, step, knots = optimum.evaluation, optimum.step, optimum.problem.knots
        names = parameter_names(knots)
        return cls(
            knee=optimum.knee,
            criterion=optimum.criterion,
            speed=optimum.speed,
            safety=optimum.safety,
            feasible=optimum.feasible,
            robot=robot,
            parameters=dict(zip(names, map(float, optimum.parameters), strict=True)),
            optimizer=Optimizer.of(optimum.report, optimum.variables, variable_names(knots)),
            provenance=dict(provenance) if provenance is not None else make_provenance(),
            knots=knots,
            **_derived(Biped(robot, optimum.knee), step, ev),
        )

    @classmethod
    def from_design(cls, comparison) -> Gait:
        """The gait of a knee design (``biped.optimization.design.Comparison``): the designed
        robot's gait, the comparison as its ``design``."""
        design = comparison.design
        gait = cls.from_optimum(design.optimum, design.robot)
        return dataclasses.replace(gait, design=comparison.to_dict())

    @classmethod
    def from_profile_design(cls, comparison) -> Gait:
        """The gait of a knee profile's design
        (``biped.optimization.profile_design.ProfileComparison``): the designed robot's gait
        (the circles', when no profile did better), the comparison as its ``design``."""
        design = comparison.profile
        gait = cls.from_optimum(design.optimum, design.robot)
        return dataclasses.replace(gait, design=comparison.to_dict())

    @classmethod
    def from_two_phase(
        cls,
        robot: Robot,
        knee: str,
        speed: float,
        parameters,
        landing: str,
        front_wrench,
        share_range,
        optimizer: Optimizer,
        safety: Safety = PAPER_SAFETY,
        provenance: dict | None = None,
    ) -> Gait:
        """The two-phase gait (sthenic criterion) of the two-phase step's ``parameters``
        (``biped.model.two_phase.parameter_names(landing)`` order), the front foot's wrench
        at the double support's solver samples ``front_wrench`` (n + 1, 3) [N, N, N·m], the
        problem's ``share_range`` and the solver's record ``optimizer``."""
        model = Biped(robot, knee)
        names = two_phase_parameter_names(landing)
        named = dict(zip(names, map(float, parameters), strict=True))
        step = two_phase_step(model, speed, named, landing)
        evaluation = evaluate_step(model, step.single, CHECK_SAMPLES[1], safety=safety)
        double = double_support_of(model, step, evaluation, front_wrench, share_range)
        derived = _derived(model, step.single, evaluation, two_phase=True)
        return cls(
            knee=knee,
            criterion="sthenic",
            speed=float(speed),
            safety=safety,
            feasible=bool(evaluation.feasible and double.feasible),
            robot=robot,
            parameters=named,
            optimizer=optimizer,
            provenance=dict(provenance) if provenance is not None else make_provenance(),
            double_support=double,
            **derived,
        )

    @property
    def two_phase(self) -> bool:
        """A gait of single then double support (``double_support`` holds the second)."""
        return self.double_support is not None

    @classmethod
    def read(
        cls,
        path: str | Path,
        allowed: str = GAIT_FILE,
        consistent: bool = False,
        two_phase: bool = False,
    ) -> Gait:
        """Read a gait file. Raises BipedError if it is not one, saying what it is if it is
        another of this project's files and what is ``allowed`` (default a gait file: what
        the command takes); with ``consistent``, if its figures are not its parameters';
        without ``two_phase``, if it is a two-phase gait (what reads one says so: only
        ``biped validate`` so far)."""
        path = Path(path)
        try:
            content = json.loads(path.read_text())
        except OSError as error:
            raise BipedError(f"gait file {str(path)!r} cannot be read: {error.strerror}") from None
        except (ValueError, RecursionError) as error:  # JSONDecodeError, UnicodeDecodeError
            reason = "nested too deeply" if isinstance(error, RecursionError) else error
            raise BipedError(
                f"gait file {str(path)!r} is not valid JSON ({reason}): allowed {allowed}"
            ) from None
        kind = other_kind(content)
        if kind is not None:  # a valid file of another kind is not corrupt
            raise BipedError(f"{str(path)!r} is {kind}, not a gait file: allowed {allowed}")
        found = content.get("format") if isinstance(content, dict) else None
        if isinstance(found, str) and found.startswith("biped-gait/") and found not in READ_FORMATS:
            raise BipedError(
                f"gait file {str(path)!r} has format {found!r}, another version's: "
                f"allowed {allowed}"
            )
        gait = cls.from_content(content, f"gait file {str(path)!r}")
        if gait.two_phase and not two_phase:
            raise BipedError(
                f"gait file {str(path)!r} is of two phases (single then double support), which "
                f"this command does not take yet: allowed a gait of single support (biped "
                f"validate takes both)"
            )
        if consistent:
            gait.check_consistency(f"gait file {str(path)!r}")
        return gait

    @classmethod
    def from_content(cls, content, source: str = "gait") -> Gait:
        """The gait of a file's JSON content (``to_dict``); a BipedError naming ``source`` and
        the first bad field if it is not a gait's."""

        def bad(what):
            return BipedError(f"{source} is corrupt: {what}")

        if not isinstance(content, dict) or content.get("format") not in READ_FORMATS:
            raise bad(f"format is not {FORMAT!r}")
        _check_scalars(content, bad)
        try:
            safety = Safety(**content["safety"])
        except (KeyError, TypeError, BipedError) as error:
            raise bad(f"safety {content.get('safety')!r}: {error}") from None
        _check_kinds(content, bad)
        try:
            knots = family_of(content.get("knots", 1))
            robot = _robot(content)
            names = set(content["parameters"])
        except (KeyError, TypeError) as error:
            raise bad(f"robot or parameters missing ({error})") from None
        except BipedError as error:
            raise bad(str(error)) from None
        double = content.get("double_support")
        if double is not None:
            landing = double.get("landing") if isinstance(double, dict) else None
            if landing not in LANDINGS:
                raise bad(f"double_support.landing = {landing!r}, allowed {', '.join(LANDINGS)}")
            expected = two_phase_parameter_names(landing)
        else:
            expected = parameter_names(knots)
        if (
            not isinstance(content["parameters"], dict)
            or names != set(expected)
            or not all(map(_finite_number, content["parameters"].values()))
        ):
            raise bad(f"parameters are not the {len(expected)} finite numbers of the gait")
        try:
            check_speed(Biped(robot, content["knee"]), content["speed"])
        except BipedError as error:
            raise bad(str(error)) from None
        double = None if double is None else DoubleSupport.from_content(double, bad)
        _check_step(content, bad, 0.0 if double is None else double.duration)
        optimizer = _optimizer(content.get("optimizer"), bad)
        fields = {f.name: content.get(f.name) for f in dataclasses.fields(cls)}
        records = {
            name: record.from_content(content.get(name), name, bad)
            for name, record in (
                ("costs", Costs),
                ("constraints", Constraints),
                ("impact", Impact),
                ("walkability", Walkability),
                ("electrical", Electrical),
                ("knee_loads", KneeLoads),
            )
        }
        parsed = {"safety": safety, "robot": robot, "optimizer": optimizer, "knots": knots}
        parsed["double_support"] = double
        return cls(**{**fields, **records, **parsed, "samples": _samples(content, bad)})

    @staticmethod
    def units(
        criterion: str,
        knots: int = 1,
        safety: Safety = PAPER_SAFETY,
        actuators: bool = False,
        design: bool = False,
        profile: bool = False,
        profile_design: bool = False,
        two_phase: bool = False,
    ) -> dict:
        """The ``units`` map of a gait file optimised for ``criterion`` in the family of
        ``knots`` interior knots, under the margins ``safety`` (the paper's by default), with
        the robot's actuators if ``actuators`` (a robot file's, not the default set), with a
        designed knee's block if ``design`` (``DESIGN_UNITS``), with the knee profile's rates
        k1, k2 if ``profile`` (a robot whose knee surfaces are not circles), with a profile
        design's block if ``profile_design`` (``PROFILE_DESIGN_UNITS`` beside
        ``DESIGN_UNITS``), with the double support's block if ``two_phase`` (its parameters'
        and variables' units are the file's, ``_units``), from the fields' declarations:
        ``{"costs.sthenic": "N²·m·s", ...}``."""
        units = declared_units(Gait, "", criterion)
        if not two_phase:
            units = {k: v for k, v in units.items() if not k.startswith("double_support.")}
        if not profile:  # circles: k1 = k2 = 0 are not written (``Robot.to_dict``)
            units.pop("robot.k1")
            units.pop("robot.k2")
        written = safety_dict(safety)  # a setting left at its default is not written
        for name in [f.name for f in dataclasses.fields(Safety) if f.name not in written]:
            units.pop(f"safety.{name}", None)
        for name in walkable.SCALES:  # the margins of the walkable constraints asked only
            if name not in safety.walkable:
                units.pop(f"walkability.{name}", None)
        if design or profile_design:
            units.update(DESIGN_UNITS)
        if profile_design:
            units.update(PROFILE_DESIGN_UNITS)
        if actuators:
            for kind in KINDS:
                for name, unit in ACTUATOR_UNITS.items():
                    units[f"robot.actuators.{kind}.{name}"] = unit
        if knots == 1:
            return units
        units["knots.bezier" if isinstance(knots, Bezier) else "knots"] = PURE
        for prefix, names in (
            ("parameters.", parameter_names(knots)),
            ("optimizer.variables.", variable_names(knots)),
        ):
            units = {key: value for key, value in units.items() if not key.startswith(prefix)}
            units.update({prefix + name: parameter_unit(name) for name in names})
        return units

    def _units(self) -> dict:
        units = self.units(
            self.criterion,
            self.knots,
            self.safety,
            self.robot.actuators is not None,
            self.design is not None,
            self.robot.profiled,
            isinstance(self.design, dict) and "profile" in self.design,
            self.two_phase,
        )
        for group in ("impact", "walkability"):  # a figure not written has no unit
            record = getattr(self, group)
            for f in dataclasses.fields(record) if record is not None else ():
                if getattr(record, f.name) is None:
                    units.pop(f"{group}.{f.name}", None)
        if not self.two_phase:
            return units
        # Two phases: no impact or electrical block; the two-phase step's parameters and the
        # two-phase solver's variables.
        dropped = ("impact.", "electrical.", "parameters.", "optimizer.variables.")
        units = {k: v for k, v in units.items() if not k.startswith(dropped)}
        for prefix, names in (
            ("parameters.", self.parameters),
            ("optimizer.variables.", self.optimizer.variables),
        ):
            units.update({prefix + name: unit_of(name) for name in names})
        return units

    def to_dict(self) -> dict:
        """The JSON-ready content of the gait's file."""
        content = {"format": FORMAT}
        for f in dataclasses.fields(self):
            if f.name == "samples":
                content["units"] = self._units()
            value = getattr(self, f.name)
            unwritten = (("design", None), ("knots", 1), ("double_support", None))
            if self.two_phase:  # no impact of one foot, no drive's figures
                unwritten += (("impact", None), ("electrical", None))
            if (f.name, value) in unwritten:  # the paper's, a single support: unwritten
                continue
            if hasattr(value, "to_dict"):  # the samples, records, robot, a Bézier family
                value = value.to_dict()
            elif dataclasses.is_dataclass(value):  # the safety margins, a knee bend if asked
                value = safety_dict(value)
            content[f.name] = value
        return content

    def write(self, path: str | Path) -> Path:
        """Write the gait's file at ``path`` (``write_json``); returns the path."""
        return write_json(path, self.to_dict())

    @functools.cached_property
    def biped(self) -> Biped:
        """The analytical robot of the gait."""
        return Biped(self.robot, self.knee)

    @property
    def problem(self) -> GaitProblem:
        """The problem the gait solves."""
        return GaitProblem(self.biped, self.speed, self.criterion, self.safety, knots=self.knots)

    @property
    def parameter_vector(self) -> np.ndarray:
        """The parameters in ``biped.model.gait.parameter_names(knots)`` order (the paper's
        21 for its spline); of a two-phase gait, ``biped.model.two_phase.parameter_names``'."""
        if self.two_phase:
            names = two_phase_parameter_names(self.double_support.landing)
        else:
            names = parameter_names(self.knots)
        return np.array([self.parameters[name] for name in names])

    def two_phase_step(self):
        """The two-phase step of a two-phase gait's parameters (``biped.model.two_phase``)."""
        if not self.two_phase:
            raise BipedError("a gait of single support has no two-phase step")
        return two_phase_step(self.biped, self.speed, self.parameters, self.double_support.landing)

    def check_consistency(self, source: str = "gait") -> None:
        """Raise a ``BipedError`` naming the first field that does not belong to the gait's
        parameters, recomputed as ``from_optimum`` computes them (no MuJoCo): period and step
        length, the samples on the check grid, the costs, the constraints, ``feasible`` and
        the impact. ``source`` names the file in the message."""

        def bad(what):
            return BipedError(f"{source} is inconsistent: {what}")

        try:
            if self.two_phase:
                both = self.two_phase_step()
                step = both.single
            else:
                step = build_step(self.biped, self.speed, self.parameter_vector, self.knots)
        except BipedError as error:
            raise bad(f"its parameters build no step ({error})") from None
        samples = CHECK_SAMPLES[self.knots]
        evaluation = evaluate_step(self.biped, step, samples, safety=self.safety)
        expected = _derived(self.biped, step, evaluation, two_phase=self.two_phase)
        feasible = evaluation.feasible
        if self.two_phase:
            double = self.double_support
            try:
                wanted = double_support_of(
                    self.biped, both, evaluation, double.front_wrench_array, double.share_range
                )
            except BipedError as error:
                raise bad(str(error)) from None
            _check_double_support(double, wanted, bad)
            feasible = evaluation.feasible and wanted.feasible
        units = self._units()
        for key in ("period", "step_length"):
            if _mismatch(getattr(self, key), expected[key]):
                raise bad(
                    f"{key} = {getattr(self, key)!r}{_shown(units, key)}, its parameters give "
                    f"{expected[key]!r}"
                )
        _check_samples(self.samples, expected["samples"], units, bad)
        for group in ("costs", "constraints"):
            _check_group(getattr(self, group), group, expected[group], units, bad)
        if self.feasible != feasible:
            violated = evaluation.violations_line()
            raise bad(
                f"feasible = {str(self.feasible).lower()}, its parameters give "
                f"{str(feasible).lower()}" + (f" (Ψ < 0: {violated})" if violated else "")
            )
        if self.impact is not None:
            _check_impact(self.impact, expected["impact"], bad)
        if self.walkability is not None:  # a file written before the walkable constraints
            _check_group(self.walkability, "walkability", expected["walkability"], units, bad)
        if self.electrical is not None:  # a file written before the actuators has none
            _check_group(self.electrical, "electrical", expected["electrical"], units, bad)
        if self.knee_loads is not None:  # a file written before the knee loads has none
            _check_knee_loads(self.knee_loads, expected["knee_loads"], units, bad)


def _robot(content: dict) -> Robot:
    """The robot of a gait file's content; one of an earlier format without actuators has the
    default set of its time (``EARLIER_FORMATS``)."""
    robot = Robot.from_mapping(content["robot"], source="robot")
    if content["format"] in EARLIER_FORMATS and robot.actuators is None:
        return dataclasses.replace(robot, actuators=Actuators.legacy())
    return robot


def _derived(model: Biped, step, evaluation, two_phase: bool = False) -> dict:
    """The fields of a gait that its parameters determine, from its step and its evaluation
    on the check grid; of a two-phase gait's single support (``two_phase``) no impact (its
    landing is in ``double_support``) and no electrical figures (not built for both phases)."""
    derived = {
        "period": step.period,
        "step_length": step.step_length,
        "costs": Costs.of(model, step, evaluation),
        "constraints": Constraints(
            **dict(zip(CONSTRAINTS, map(float, evaluation.worst), strict=True))
        ),
        "impact": Impact.of(model, step),
        "walkability": Walkability.of(model, evaluation),
        "electrical": Electrical.of(model, step, evaluation),
        "knee_loads": KneeLoads.of(model, evaluation),
        "samples": Samples(
            **{f.name: getattr(evaluation, f.name) for f in dataclasses.fields(Samples)}
        ),
    }
    if two_phase:
        derived["impact"] = derived["electrical"] = None
    return derived


def write_json(path: str | Path, content: dict) -> Path:
    """Write JSON whole or not at all (``biped.runtime.files``), creating the folder; returns the
    path."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    return atomic_write_text(path, json.dumps(content, indent=1, allow_nan=False))


read = Gait.read  # the format checked; read_consistent: the figures its parameters' too
read_consistent = functools.partial(Gait.read, consistent=True)


def _finite_number(value) -> bool:
    """A JSON number other than a boolean, finite as a float (integers beyond floats are not)."""
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        return False
    try:
        return math.isfinite(float(value))
    except OverflowError:
        return False


def _finite_numbers(value) -> bool:
    """A finite JSON number, or a list of them (a figure per joint)."""
    if isinstance(value, list):
        return bool(value) and all(map(_finite_number, value))
    return _finite_number(value)


def _finite_or_none(value):
    return float(value) if math.isfinite(value) else None


def other_kind(content) -> str | None:
    """What a JSON file of this project other than a gait file is, and which command writes
    it ("a robustness map (which biped robustness writes)"), or None if it is none of them
    (a gait file, of any version, or something else)."""
    if not isinstance(content, dict):
        return None
    found = content.get("format")
    for prefix, kind in OTHER_FORMATS.items():
        if isinstance(found, str) and found.startswith(prefix):
            return kind
    for keys, kind in OTHER_KEYS:
        if keys <= content.keys():
            return kind
    if content.keys() == OWNER_RECORD[0]:
        return OWNER_RECORD[1]
    if _validation_report(content):
        return "a validation report (which biped validate --json and biped pipeline write)"
    if content and all(_validation_report(value) for value in content.values()):
        return "the validation reports of several gait files (which biped validate --json writes)"
    if isinstance(content.get("point"), dict) and "certified" in content:
        return "one optimization of a design map (which biped design-map writes)"
    return None


def _validation_report(content) -> bool:
    """Whether ``content`` is a validation report (``biped.records.validation_report``)."""
    return is_report(content) and isinstance(content.get("inverse_dynamics"), dict)


def _check_scalars(content: dict, bad) -> None:
    """The scalar fields present; the speed, period and step length numbers > 0."""
    for key in ("knee", "criterion", "speed", "period", "step_length", "feasible", "costs"):
        if key not in content:
            raise bad(f"missing {key!r}")
    for key in ("speed", "period", "step_length"):
        value = content[key]
        if not (_finite_number(value) and value > 0):
            raise bad(f"{key} = {value!r}, allowed a number > 0")


def family_of(written) -> int | Bezier:
    """The gait family of a file's ``knots``: a number of interior knots, or {"bezier":
    degree}."""
    if isinstance(written, dict):
        if set(written) != {"bezier"}:
            raise BipedError(f"knots = {written!r}: allowed K or {{'bezier': degree}}")
        return Bezier(written["bezier"])
    return check_knots(written)


def _check_kinds(content: dict, bad) -> None:
    """The knee, the criterion, ``feasible`` and the costs of their kinds."""
    if content["knee"] not in KNEES:
        raise bad(f"knee = {content['knee']!r}, allowed {', '.join(KNEES)}")
    if content["criterion"] not in ALL_CRITERIA:
        raise bad(f"criterion = {content['criterion']!r}, allowed {', '.join(ALL_CRITERIA)}")
    if not isinstance(content["feasible"], bool):
        raise bad(f"feasible = {content['feasible']!r}, allowed true or false")
    costs = content["costs"]
    if not isinstance(costs, dict) or not all(_finite_number(costs.get(name)) for name in CRITERIA):
        raise bad(f"costs = {costs!r}, allowed finite numbers for {', '.join(CRITERIA)}")


def _check_step(content: dict, bad, dwell: float = 0.0) -> None:
    """A step length of a walk, the speed times the period (and the double support's
    duration ``dwell`` [s] of a two-phase gait)."""
    speed, period, length = content["speed"], content["period"], content["step_length"]
    if length < MIN_STEP_LENGTH:
        raise bad(f"step_length = {length!r} m, allowed {MIN_STEP_LENGTH} m or more")
    if not (_finite_number(dwell) and dwell >= 0.0):
        raise bad(f"double_support.duration = {dwell!r} s, allowed a number > 0")
    if not math.isclose(length, speed * (period + dwell), rel_tol=1e-6):
        both = " + double_support.duration" if dwell else ""
        raise bad(
            f"step_length = {length!r} m, allowed speed × (period{both}) = "
            f"{speed * (period + dwell)!r} m (speed {speed!r} m/s, period {period!r} s)"
        )


def _optimizer(content, bad) -> Optimizer:
    """The optimizer record of a file's content, or ``bad`` naming the field it lacks."""
    if not isinstance(content, dict):
        raise bad("missing 'optimizer'" if content is None else "optimizer is not an object")
    try:
        return Optimizer.from_dict(content)
    except KeyError as error:
        raise bad(f"optimizer.{error.args[0]} missing") from None
    except (TypeError, ValueError, AttributeError) as error:
        raise bad(f"optimizer is not a solver's report ({error})") from None


def _samples(content: dict, bad) -> Samples:
    """The samples of a file's content, as arrays of the declared widths with one row count,
    times rising from 0 to the period."""
    samples = content.get("samples")
    if not isinstance(samples, dict):
        raise bad("missing samples")
    arrays = {}
    for f in dataclasses.fields(Samples):
        key, columns = f.name, f.metadata["columns"]
        if key not in samples:
            raise bad(f"samples.{key} missing")
        try:
            array = np.asarray(samples[key], dtype=float)
        except (TypeError, ValueError, OverflowError):
            raise bad(f"samples.{key} is not an array of numbers") from None
        shape = "(N,)" if columns is None else f"(N, {len(columns)})"
        if array.ndim != (1 if columns is None else 2) or (
            columns is not None and array.shape[1] != len(columns)
        ):
            raise bad(f"samples.{key} has shape {array.shape}, allowed {shape}")
        if not np.all(np.isfinite(array)):
            where = tuple(int(i) for i in np.argwhere(~np.isfinite(array))[0])
            raise bad(
                f"samples.{key}{list(where)} = {array[where]} is not finite: allowed finite numbers"
            )
        arrays[key] = array
    rows = {key: len(array) for key, array in arrays.items()}
    counts = list(rows.values())
    common = max(counts, key=counts.count)  # the odd one out is to blame
    for key, count in rows.items():
        if count != common:
            raise bad(f"samples.{key} has {count} rows, the other samples {common}")
    t, period = arrays["t"], content["period"]
    if common < 2 or t[0] != 0.0 or np.any(np.diff(t) < 0.0):
        raise bad("samples.t does not rise from 0: allowed 2 or more times from 0 to period")
    if not math.isclose(t[-1], period, rel_tol=1e-6):
        raise bad(f"samples.t ends at {t[-1]!r} s, allowed the period {period!r} s")
    return Samples(**arrays)


def _shown(units: dict, field: str, column: int | None = None) -> str:
    """A field's unit as printed after its value ("" for a pure number)."""
    unit = units.get(field, "")
    if isinstance(unit, list):
        unit = unit[column] if column is not None else ""
    return f" {unit}" if unit and unit != PURE else ""


def _mismatch(found, expected) -> tuple[int, float] | None:
    """The flat index and size of the largest difference beyond the tolerance, or None."""
    found, expected = np.asarray(found, dtype=float), np.asarray(expected, dtype=float)
    tolerance = CONSISTENCY_RTOL * max(float(np.max(np.abs(expected), initial=0.0)), 1.0)
    difference = np.abs(found - expected).ravel()
    worst = int(np.argmax(difference))
    return (worst, float(difference[worst])) if difference[worst] > tolerance else None


def _check_samples(samples: Samples, expected: Samples, units: dict, bad) -> None:
    """Each sample array against the parameters' (its largest difference named with its time
    and column)."""
    for f in dataclasses.fields(Samples):
        key, columns, path = f.name, f.metadata["columns"], f"samples.{f.name}"
        found, wanted = getattr(samples, key), getattr(expected, key)
        if found.shape != wanted.shape:
            raise bad(
                f"{path} has shape {found.shape}, the parameters' samples "
                f"{wanted.shape}: {path} do not belong to the parameters"
            )
        mismatch = _mismatch(found, wanted)
        if mismatch:
            index, size = mismatch
            row, column = divmod(index, wanted.shape[1]) if wanted.ndim == 2 else (index, None)
            where = f"t = {expected.t[row]:.4f} s" + (
                f", {columns[column]}" if column is not None else ""
            )
            raise bad(
                f"{path} do not belong to the parameters (off by {size:.3g}"
                f"{_shown(units, path, column)} at {where})"
            )


def _check_group(stored, group: str, expected, units: dict, bad) -> None:
    """The costs or the constraints (records) against the parameters'."""
    if stored is None:
        raise bad(f"{group} missing")
    optional = {f.name for f in dataclasses.fields(stored) if f.metadata.get("optional")}
    for name, wanted in expected.to_dict().items():
        path = f"{group}.{name}"
        value = getattr(stored, name)
        if value is None and name in optional:  # a figure added since the file was written
            continue
        if not _finite_numbers(value) or _mismatch(value, wanted):
            raise bad(
                f"{path} = {value!r}{_shown(units, path)}, its parameters give "
                f"{wanted!r}{_shown(units, path)}"
            )


def _check_knee_loads(stored: KneeLoads, expected: KneeLoads, units: dict, bad) -> None:
    """The knee loads against the parameters': each figure a knee's (a ratio None where the
    knee is never compressed), ``needs_ligaments`` last."""
    for name, wanted in expected.to_dict().items():
        path, value = f"knee_loads.{name}", getattr(stored, name)
        if name == "needs_ligaments":
            if value is not wanted:
                raise bad(f"{path} = {value!r}, its parameters give {str(wanted).lower()}")
            continue
        wanted_array = np.array(wanted, dtype=float)  # None: NaN
        try:
            found = np.array(value, dtype=float)
        except (TypeError, ValueError):
            found = None
        if found is None or found.shape != wanted_array.shape:
            raise bad(f"{path} is not the {wanted_array.shape} numbers it should be")
        missing = np.isnan(found)  # where a ratio is None (an infinity differs by inf)
        if not np.array_equal(missing, np.isnan(wanted_array)):
            raise bad(f"{path} has None where its parameters give a number, or the reverse")
        off = _mismatch(np.where(missing, 0.0, found), np.nan_to_num(wanted_array))
        if off:
            raise bad(
                f"{path} do not belong to the parameters (off by {off[1]:.3g}{_shown(units, path)})"
            )


def _check_impact(impact: Impact, expected: Impact, bad) -> None:
    """The impact record against the parameters' (its ``consistent`` flag last; a figure
    added since the file was written, absent from it, is not checked)."""
    added = ("touchdown_velocity", "touchdown_speed", "friction_needed")
    for name in ("impulse", "qd_minus", "qd_plus", "trailing_foot_lift", *added):
        path, value, wanted = f"impact.{name}", getattr(impact, name), getattr(expected, name)
        if name in added and value is None and impact.touchdown_speed is None:
            continue
        try:
            if value is None or wanted is None:
                if value is None and wanted is None:
                    continue
                raise TypeError(name)
            found = _mismatch(value, wanted)
        except (TypeError, ValueError):
            raise bad(f"{path} is not the {np.shape(wanted)} numbers it should be") from None
        if found:
            raise bad(f"{path} does not belong to the parameters (off by {found[1]:.3g})")
    if impact.consistent is not expected.consistent:
        raise bad(
            f"impact.consistent = {impact.consistent!r}, its parameters give "
            f"{str(expected.consistent).lower()}"
        )


def _check_double_support(stored: DoubleSupport, expected: DoubleSupport, bad) -> None:
    """A two-phase gait's ``double_support`` against the one its parameters and its front
    foot's wrench give: every number, its samples, ``feasible``."""
    for f in dataclasses.fields(DoubleSupport):
        path, found, wanted = f"double_support.{f.name}", getattr(stored, f.name), None
        wanted = getattr(expected, f.name)
        if found is None and f.default is None:  # a field added later, absent from the file
            continue
        if f.name in ("landing", "feasible"):
            if found != wanted:
                raise bad(f"{path} = {found!r}, its parameters give {wanted!r}")
            continue
        if f.name == "samples":
            for g in dataclasses.fields(wanted):
                a, b = getattr(found, g.name), getattr(wanted, g.name)
                if a.shape != b.shape or _mismatch(a, b):
                    raise bad(f"{path}.{g.name} do not belong to the parameters")
            continue
        if isinstance(wanted, dict):
            pairs = [(f"{path}.{k}", found.get(k) if isinstance(found, dict) else None, v)
                     for k, v in wanted.items()]  # fmt: skip
        else:
            pairs = [(path, found, wanted)]
        for where, value, target in pairs:
            try:
                off = np.shape(value) != np.shape(target) or _mismatch(value, target)
            except (TypeError, ValueError):
                off = True
            if off:
                raise bad(f"{where} = {value!r}, its parameters give {target!r}")
