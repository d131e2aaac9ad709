"""The double support phase of a two-phase gait file (``biped optimize --double-support``):
the ``DoubleSupport`` record a ``Gait`` holds in its ``double_support`` block, each field with
its unit, and how it follows from the gait's parameters (``biped.model.two_phase``).

A two-phase gait file is a gait file (``biped.records.gait_file``) whose ``parameters`` are the
two-phase step's (``biped.model.two_phase.parameter_names(landing)``), whose ``samples``,
``costs``, ``constraints``, ``walkability`` and ``knee_loads`` are its single support phase's
on the check grid (each integral divided by the whole step's length S = V (T + T_ds)), with no
``impact`` and no ``electrical`` block (the landing holds both feet: its impulses are here; the
drive's figures of a double support are not built), and with this block:

    landing         "impact" or "zero-speed" (``biped.model.two_phase``)
    duration        T_ds [s]; share T_ds / (T + T_ds), share_range the problem's
    sthenic         C_Γ over both phases [N²·m·s]: the single support on the check grid, the
                    double support on the solver's samples (what the optimizer minimised)
    energy          C_E over both phases [J per step]: the joints' work ∫ Σ |Γ_i θ̇_i| dt, the
                    single support's (``costs.energy``) and the double support's on ``samples``
                    (trapezoids: the integrand has kinks where a joint's power changes sign);
                    energy_per_metre the same over the step length [J/m]. Files written
                    before these two have none (read, and left so)
    front_wrench    the front foot's ground wrench [Fx, Fz, Cy] at the solver's n + 1 samples
                    of the phase (the load split the optimizer chose: an input, like the
                    parameters); between them it is linear in time (the rule this file states)
    coefficients    the cubic c0 + c1 t + c2 t² + c3 t³ of x_H, z_H, q5 (t from the landing)
    landing_impulse the ground's impulse at the landing on the rear then the front foot
    foot_margins    each foot's worst Ψ (``FOOT_CONSTRAINTS``) on the check grid below, the
                    front wrench linear between the solver's samples: the constraints must
                    hold between the samples too (a foot's ZMP that leaves its sole there
                    tips it), and ``feasible`` is false when one does not; not where the
                    foot hands its load over (the rear foot at lift-off, the front foot at
                    a zero-speed landing): there it carries nothing and has no ZMP
    handover        each foot's wrench where it hands its load over [N, N, N·m]: zero within
                    ``HANDOVER_TOLERANCE`` (``biped.model.double_support``) after a
                    zero-speed landing or the gait is not ``feasible``; after an impact
                    reported, not judged (the impact landing jumps the loads)
    samples         the phase on ``CHECK_PER_INTERVAL`` times the solver's grid: q, q̇, q̈, the
                    torques and both feet's wrenches (the front one as stated above)

Everything here but ``front_wrench``, ``landing`` and ``share_range`` follows from the
parameters; ``Gait.check_consistency`` recomputes it. Numpy only: read without CasADi.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

import numpy as np

from biped.errors import BipedError
from biped.model import double_support as ds
from biped.model.criteria import StepEvaluation
from biped.model.dynamics import JOINTS, Biped
from biped.model.kinematics import COORDINATES
from biped.model.two_phase import (
    TwoPhaseStep,
    build_two_phase,
    landing_margins,
    parameter_names,
)
from biped.model.units import PURE, per_coordinate, unit_field

# The unit of a two-phase parameter or solver variable, from its name (the first part found).
_UNITS = (
    ("accel", "rad/s²"),
    ("rate_x_hip", "m/s"),
    ("rate_z_hip", "m/s"),
    ("rate", "rad/s"),
    ("bend", "rad"),
    ("trunk", "rad"),
    ("x_hip", "m"),
    ("z_hip", "m"),
    ("period", "s"),
    ("double_support", "s"),
    ("front_cy", "N·m"),
    ("front_f", "N"),
)
# Samples of the phase's check grid per interval of the solver's (``samples``).
CHECK_PER_INTERVAL = ds.FINE_PER_INTERVAL
WRENCH = ["N", "N", "N·m"]
IMPULSE = ["N·s", "N·s", "N·m·s"]  # a wrench integrated over the impact
WRENCH_COLUMNS = ("Fx", "Fz", "Cy")
FEET = ("rear", "front")
CUBIC = {
    "x_hip": ["m", "m/s", "m/s²", "m/s³"],
    "z_hip": ["m", "m/s", "m/s²", "m/s³"],
    "trunk": ["rad", "rad/s", "rad/s²", "rad/s³"],
}
FOOT_UNITS = ["N", "N", "N", "m", "m"]  # ``biped.model.double_support.FOOT_CONSTRAINTS``


def unit_of(name: str) -> str:
    """The unit of the two-phase parameter or solver variable ``name``."""
    for part, unit in _UNITS:
        if part in name:
            return unit
    raise KeyError(name)


@dataclass(frozen=True, eq=False)
class PhaseSamples:
    """The double support phase on its check grid, from the landing (t = 0) to lift-off."""

    t: np.ndarray = unit_field("s")
    q: np.ndarray = unit_field(per_coordinate("rad", "m"), COORDINATES)
    qd: np.ndarray = unit_field(per_coordinate("rad/s", "m/s"), COORDINATES)
    qdd: np.ndarray = unit_field(per_coordinate("rad/s²", "m/s²"), COORDINATES)
    torques: np.ndarray = unit_field("N·m", JOINTS)
    rear_wrench: np.ndarray = unit_field(WRENCH, WRENCH_COLUMNS)
    front_wrench: np.ndarray = unit_field(WRENCH, WRENCH_COLUMNS)

    def to_dict(self) -> dict:
        return {f.name: getattr(self, f.name).tolist() for f in dataclasses.fields(self)}

    @classmethod
    def from_content(cls, content, bad) -> PhaseSamples:
        """The samples of a file's ``double_support.samples``, each of its declared width."""
        if not isinstance(content, dict):
            raise bad("double_support.samples missing")
        arrays = {}
        for f in dataclasses.fields(cls):
            columns = f.metadata["columns"]
            try:
                array = np.asarray(content[f.name], dtype=float)
            except (KeyError, TypeError, ValueError):
                raise bad(f"double_support.samples.{f.name} is not an array of numbers") from None
            width = () if columns is None else (len(columns),)
            if array.shape[1:] != width or not np.all(np.isfinite(array)):
                raise bad(
                    f"double_support.samples.{f.name} is not (N, {len(columns or ())}) finite"
                )
            arrays[f.name] = array
        if len({len(a) for a in arrays.values()}) != 1 or len(arrays["t"]) < 2:
            raise bad("double_support.samples do not have one row count of 2 or more")
        return cls(**arrays)


@dataclass(frozen=True, eq=False)
class DoubleSupport:
    """A two-phase gait's double support phase (see the module)."""

    landing: str
    duration: float = unit_field("s")
    share: float = unit_field(PURE)
    share_range: list = unit_field(PURE)
    sthenic: float = unit_field("N²·m·s")
    front_wrench: list = unit_field(WRENCH, WRENCH_COLUMNS)
    coefficients: dict = unit_field(CUBIC)
    landing_impulse: list = unit_field(IMPULSE + IMPULSE)
    foot_margins: dict = unit_field({foot: FOOT_UNITS for foot in FEET})
    # each foot's wrench where it hands its load over (``biped.model.double_support.HANDOVERS``:
    # the rear foot's at lift-off, the front foot's at the landing), zero within
    # ``HANDOVER_TOLERANCE`` after a zero-speed landing (after an impact: reported)
    handover: dict = unit_field({name: WRENCH for name in ds.HANDOVERS})
    # both feet's constraints on the check grid (``samples``: the front wrench linear between
    # the solver's samples); at the landing both feet pushed within the friction cone
    # (``biped.model.two_phase.landing_margins``)
    feasible: bool
    samples: PhaseSamples = unit_field(PhaseSamples)
    # the joints' work over both phases, per step and per metre (see the module); None in a
    # file written before them
    energy: float | None = unit_field("J", default=None)
    energy_per_metre: float | None = unit_field("J/m", default=None)

    def to_dict(self) -> dict:
        values = {f.name: getattr(self, f.name) for f in dataclasses.fields(self)}
        values["samples"] = self.samples.to_dict()
        return values

    @classmethod
    def from_content(cls, content, bad) -> DoubleSupport:
        """The record of a file's ``double_support`` object, its numbers checked finite."""
        if not isinstance(content, dict):
            raise bad("double_support is not an object")
        names = [f.name for f in dataclasses.fields(cls)]
        optional = {"energy", "energy_per_metre"}  # added later: absent from older files
        missing = [name for name in names if name not in content and name not in optional]
        if missing:
            raise bad(f"double_support.{missing[0]} missing")
        front = np.asarray(content["front_wrench"], dtype=float)
        if front.ndim != 2 or front.shape[1] != 3 or len(front) < 3 or (len(front) - 1) % 2:
            raise bad(
                f"double_support.front_wrench has shape {front.shape}: allowed (n + 1, 3), n even"
            )
        if not np.all(np.isfinite(front)):
            raise bad("double_support.front_wrench is not finite: allowed finite numbers")
        fields = {name: content.get(name) for name in names}
        fields["samples"] = PhaseSamples.from_content(content["samples"], bad)
        return cls(**fields)

    @property
    def front_wrench_array(self) -> np.ndarray:
        """(n + 1, 3) [N, N, N·m] at the solver's samples."""
        return np.asarray(self.front_wrench, dtype=float)


def two_phase_step(model: Biped, speed: float, parameters: dict, landing: str) -> TwoPhaseStep:
    """The step of a two-phase gait file's ``parameters`` (by name)."""
    names = parameter_names(landing)
    return build_two_phase(model, speed, np.array([parameters[n] for n in names]), landing)


def _simpson(n: int) -> np.ndarray:
    """Simpson's weights on n + 1 equally spaced samples of [0, 1] (n even)."""
    w = np.ones(n + 1)
    w[1:-1:2], w[2:-1:2] = 4.0, 2.0
    return w / (3.0 * n)


def phase_samples(model: Biped, step: TwoPhaseStep, front) -> PhaseSamples:
    """The double support of ``step`` on its check grid, the front foot's wrench ``front``
    (n + 1, 3) at the solver's samples, linear between them (``ds.sample_split``)."""
    fine = ds.sample_split(model, step.double, front, CHECK_PER_INTERVAL)
    return PhaseSamples(
        fine.time, fine.q, fine.qd, fine.qdd, fine.torques, fine.stance_wrench, fine.swing_wrench
    )


def double_support_of(
    model: Biped,
    step: TwoPhaseStep,
    evaluation: StepEvaluation,
    front,
    share_range,
) -> DoubleSupport:
    """The record of ``step``'s double support, the single support's ``evaluation`` on the
    check grid (its part of C_Γ), the front foot's wrench ``front`` at the solver's samples."""
    front = np.asarray(front, dtype=float)
    if front.ndim != 2 or front.shape[1] != 3 or (len(front) - 1) % 2 or len(front) < 3:
        raise BipedError(f"front wrench of shape {front.shape}: allowed (n + 1, 3), n even")
    samples = phase_samples(model, step, front)
    at_solver = slice(None, None, CHECK_PER_INTERVAL)
    torques = samples.torques[at_solver]
    double = step.double.duration * float(_simpson(len(front) - 1) @ (torques**2).sum(-1))
    zero_speed = step.landing == "zero-speed"
    fine = ds.DoubleSupportSamples(  # the file's rule between samples
        samples.t, samples.q, samples.qd, samples.qdd, samples.torques,
        samples.rear_wrench, samples.front_wrench,
    )  # fmt: skip
    judged = fine.margins(model.robot, zero_speed=True if zero_speed else None).min(axis=0)
    margins = {foot: judged[k].tolist() for k, foot in enumerate(FEET)}
    handover = fine.handover(zero_speed)
    loads = ds.handover_loads(handover, zero_speed)
    landing = np.min(landing_margins(step.impulse))  # 0 for a zero-speed landing
    feasible = bool(
        landing >= 0.0
        and all(min(m) >= 0.0 for m in margins.values())
        and all(load <= ds.HANDOVER_TOLERANCE for load in loads.values())
    )
    dwell = step.double.duration
    energy = evaluation.energy + phase_work(model, samples)
    return DoubleSupport(
        landing=step.landing,
        duration=dwell,
        share=dwell / step.duration,
        share_range=[float(x) for x in share_range],
        sthenic=evaluation.sthenic + double / step.step_length,
        front_wrench=front.tolist(),
        coefficients={
            name: row.tolist() for name, row in zip(CUBIC, step.double.coefficients, strict=True)
        },
        landing_impulse=np.asarray(step.impulse, dtype=float).tolist(),
        foot_margins=margins,
        handover={name: wrench.tolist() for name, wrench in handover.items()},
        feasible=feasible,
        samples=samples,
        energy=energy,
        energy_per_metre=energy / step.step_length,
    )


def phase_work(model: Biped, samples: PhaseSamples) -> float:
    """[J] the joints' work over the double support, ∫ Σ |Γ_i θ̇_i| dt on its check grid
    (trapezoids)."""
    power = np.abs(model.joint_angles(samples.qd) * samples.torques).sum(-1)
    return float(np.trapezoid(power, samples.t))
