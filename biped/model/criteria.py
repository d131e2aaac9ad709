"""Constraints Ψ1-Ψ7 (eq. 28) and the sthenic and energy criteria (eqs. 30-31).

    Ψ1 = Fz                    the ground pushes (unilateral contact)
    Ψ2 = x_ZMP + l_p           ZMP in front of the heel
    Ψ3 = -x_ZMP + (L_p - l_p)  ZMP behind the toe
    Ψ4 = q2 - q1               stance knee not inverted
    Ψ5 = q3 - q4               swing knee not inverted
    Ψ6 = z of the swing heel   swing foot above the ground
    Ψ7 = z of the swing toe

    C_Γ = (2/d) ∫₀ᵀ (ΓᵀΓ + k Σ (e^(|Ψ_i| - Ψ_i) - 1)) dt + Err              (30)
    C_E =       ∫₀ᵀ (Σ |Γ_i θ̇_i| + k Σ (e^(|Ψ_i| - Ψ_i) - 1)) dt + Err      (31)

with k = 10⁶ and d = 2 S (see ``biped.model.gait``). Integrals use Simpson's rule on each spline
piece separately: the accelerations, hence the torques, jump at the knot t = T/2.
Ψ6 and Ψ7 vanish by construction at t = 0 and t = T (both feet on the ground); they are
checked at the interior samples only.

The electrical criterion (ours, ``biped.model.actuators``): the electrical energy the motors
draw per metre walked without regeneration, E / S = (1/S) ∫₀ᵀ Σ_i max(P_i, 0) dt [J/m], P_i
= u_i i_i the electrical power of joint i's motor.
"""

from __future__ import annotations

import dataclasses
import functools
import math
from dataclasses import dataclass, field

import numpy as np

from biped.errors import BipedError
from biped.model import walkable
from biped.model.actuators import LIMITS, Actuators, Drive, drive, limit_margins
from biped.model.dynamics import JOINTS, Biped, zmp_from
from biped.model.gait import Step, breakpoints, piece_grid, pieces, sample
from biped.model.kinematics import Q1, Q2, Q3, Q4

CONSTRAINTS = (
    "normal_force",
    "zmp_heel",
    "zmp_toe",
    "stance_knee",
    "swing_knee",
    "swing_heel",
    "swing_toe",
)
# The paper's criteria (its comparison, a sweep's by default), and all, with ours: the energy
# per metre walked, C_E / S, which ranks gaits of different step lengths (at a given speed C_E
# per step rewards short fast steps).
CRITERIA = ("sthenic", "energy")
# And ours of the actuators: the electrical energy per metre walked, without regeneration.
ALL_CRITERIA = (*CRITERIA, "energy-per-metre", "electrical")
# The criteria counting the joints' work |Γ_i θ̇_i| or the motors' power max(P_i, 0) (exact
# through slack variables).
WORK_CRITERIA = ("energy", "energy-per-metre", "electrical")
# Unit of each criterion's value: C_Γ per metre walked, C_E per step, C_E / S per metre, the
# electrical energy per metre.
CRITERION_UNITS = {
    "sthenic": "N²·m·s",
    "energy": "J",
    "energy-per-metre": "J/m",
    "electrical": "J/m",
}
PENALTY_WEIGHT = 1e6  # k of eqs. (30)-(31)
# Err of eqs. (30)-(31) when the parameters give no posture: a large cost growing with the
# distance [m] by which the hip is out of reach, so that the simplex is led back.
BUILD_ERROR_COST = 1e12
BUILD_ERROR_SLOPE = 1e13  # per metre out of reach


# Constraints are divided by these in the solvers so that all are of order one
# [N, m, m, rad, rad, m, m].
CONSTRAINT_SCALES = np.array([1000.0, 0.1, 0.1, 1.0, 1.0, 0.1, 0.1])
# Margins δ_i the optimiser keeps from each constraint [N, m, m, rad, rad, m, m]. With an
# exponential penalty of finite weight, the minimum of the penalised criterion violates an
# active constraint slightly; asking for Ψ_i >= δ_i there leaves Ψ_i >= 0 with room to spare.
# The swing-foot margins ramp up from zero over the first and last tenth of the step, where
# the foot leaves and reaches the ground.
MARGINS = np.array([1.0, 1e-3, 1e-3, 1e-3, 1e-3, 1e-3, 1e-3])
FOOT_MARGIN_RAMP = 0.1  # fraction of the step
# Margin δ the optimiser keeps from each actuator limit (``Safety.actuator_limits``), a share
# of the limit: between the solver's samples a torque, speed or voltage may rise above them.
ACTUATOR_MARGIN = 0.01


def foot_margin(t_n) -> np.ndarray:
    """δ of Ψ6, Ψ7 (the swing heel's and toe's) at the normalised times ``t_n``."""
    t_n = np.asarray(t_n, dtype=float)
    ramp = np.clip(np.minimum(t_n, 1.0 - t_n) / FOOT_MARGIN_RAMP, 0.0, 1.0)
    return MARGINS[5] * ramp


@functools.cache
def margin_profile(samples_per_half: int, knots: int = 1) -> np.ndarray:
    """δ (N, 7) on the time grid of ``biped.model.gait.sample``."""
    t_n = np.concatenate(piece_grid(samples_per_half, knots))
    profile = np.tile(MARGINS, (len(t_n), 1))
    profile[:, 5:] = foot_margin(t_n)[:, None]
    profile.setflags(write=False)
    return profile


# The swing sole's clearance (``Safety.clearance`` C, 0 in the paper) is an envelope over the
# step (``clearance_envelope``): nothing in the lift-off and touchdown windows (a fraction W
# of the step at each end, ``Safety.clearance_window``), at least ``CLEARANCE_FLOOR`` of C
# from them on, rising linearly to the whole of C at ``CLEARANCE_FULL`` of the step from
# each end (30 % to 70 % of it). A full clearance from 10 % of the step is often infeasible
# (at 0.2 m/s with 3 cm); the optima keep a third of it from there.
CLEARANCE_WINDOW = 0.1  # W by default [T]
CLEARANCE_FULL = 0.3  # [T]
CLEARANCE_FLOOR = 1.0 / 3.0
MAX_CLEARANCE_WINDOW = 0.45  # [T]: the swing between the windows at least a tenth of the step
# Largest safety margins accepted [m].
MAX_CLEARANCE = 0.2
MAX_ZMP_MARGIN = 0.05
# Largest least bend of the stance knee asked [rad].
MAX_KNEE_BEND = 1.0
# Ranges of the walkable constraints' settings (``biped.model.walkable``): the landing speed
# [m/s], the friction coefficient, the joints' margin to their stops [rad], the hip's least
# forward speed as a share of the walking speed.
MAX_LANDING_SPEED = 10.0
MAX_LANDING_SHARE = 5.0
FRICTION_RANGE = (0.05, 2.0)
MAX_JOINT_MARGIN = 0.5
MAX_HIP_PROGRESS = 1.0
# The walkable constraints' settings that may be None (not asked).
OPTIONAL = ("landing_speed", "landing_share", "friction", "joint_margin", "hip_progress")


@dataclass(frozen=True)
class Safety:
    """Margins of ours on top of the paper's constraints, for gaits that stand a physics
    engine's contact model and tracking errors. ``Safety()`` is the paper's problem.

    Attributes:
        clearance: [m] height the swing sole keeps off the ground between its lift-off and
            touchdown windows (``clearance_envelope``), on the check grid's every sample;
            Ψ6, Ψ7 become the heights above it.
        zmp_margin: [m] distance the ZMP keeps inside the sole's heel and toe (Ψ2, Ψ3).
        knee_bend: [rad] least flexion of the stance knee over the step (Ψ4 becomes the
            flexion beyond it): the two knee kinematics differ only where the knee bends.
        actuator_limits: every joint's torque, speed and voltage within its motor's
            (``biped.model.actuators.limit_margins``) at every sample: a gait the motors
            cannot follow is not feasible.
        clearance_window: [T] the lift-off and touchdown windows of the clearance, a
            fraction of the step at each end.
        landing_speed: [m/s] largest speed of the swing sole at touchdown (0: a landing
            without impact); None: unbounded (the paper's).
        landing_share: the same bound as a share of the walking speed V (the sole lands at
            ``landing_share`` V at most); one of the two at most.
        friction: μ, the stance foot's |F_x| <= μ F_z at every sample and the landing's
            impulse within the same cone; None: unbounded.
        joint_margin: [rad] least distance of every hip and ankle to its stops
            (``biped.model.robot.JOINT_STOPS``); None: the stops are not constrained.
        hip_progress: the hip's least forward speed, a share of the walking speed; None:
            not constrained.
    """

    clearance: float = field(default=0.0, metadata={"unit": "m"})
    zmp_margin: float = field(default=0.0, metadata={"unit": "m"})
    knee_bend: float = field(default=0.0, metadata={"unit": "rad"})
    actuator_limits: bool = field(default=False, metadata={"unit": None})
    clearance_window: float = field(default=CLEARANCE_WINDOW, metadata={"unit": "T"})
    landing_speed: float | None = field(default=None, metadata={"unit": "m/s"})
    landing_share: float | None = field(default=None, metadata={"unit": "1"})
    friction: float | None = field(default=None, metadata={"unit": "1"})
    joint_margin: float | None = field(default=None, metadata={"unit": "rad"})
    hip_progress: float | None = field(default=None, metadata={"unit": "1"})

    def __post_init__(self):
        if not isinstance(self.actuator_limits, bool):
            raise BipedError(f"actuator_limits = {self.actuator_limits!r}: allowed true or false")
        limits = (
            ("clearance", 0.0, MAX_CLEARANCE, "m"),
            ("zmp_margin", 0.0, MAX_ZMP_MARGIN, "m"),
            ("knee_bend", 0.0, MAX_KNEE_BEND, "rad"),
            ("clearance_window", 0.0, MAX_CLEARANCE_WINDOW, "T"),
            ("landing_speed", 0.0, MAX_LANDING_SPEED, "m/s"),
            ("landing_share", 0.0, MAX_LANDING_SHARE, "of the walking speed"),
            ("friction", *FRICTION_RANGE, ""),
            ("joint_margin", 0.0, MAX_JOINT_MARGIN, "rad"),
            ("hip_progress", 0.0, MAX_HIP_PROGRESS, "of the walking speed"),
        )
        for name, low, high, unit in limits:
            value = getattr(self, name)
            if value is None and name in OPTIONAL:
                continue
            allowed = f"{low:g} to {high:g} {unit}".rstrip()
            if isinstance(value, bool) or not isinstance(value, (int, float)):
                raise BipedError(f"{name} = {value!r}: allowed a number {allowed}")
            if not (math.isfinite(value) and low <= value <= high):
                raise BipedError(f"{f'{name} = {value!r} {unit}'.rstrip()}: allowed {allowed}")
            object.__setattr__(self, name, float(value))
        if self.landing_speed is not None and self.landing_share is not None:
            raise BipedError(
                f"landing_speed = {self.landing_speed!r} m/s and landing_share = "
                f"{self.landing_share!r}: allowed one of the two"
            )

    @property
    def walkable(self) -> tuple:
        """The walkable constraints asked (``biped.model.walkable``), by name, in the order of
        the solver's rows: "landing", "impact_friction", "friction", "joint_stops",
        "progress"."""
        asked = []
        if self.landing_speed is not None or self.landing_share is not None:
            asked.append("landing")
        if self.friction is not None:
            asked += ["impact_friction", "friction"]
        if self.joint_margin is not None:
            asked.append("joint_stops")
        if self.hip_progress is not None:
            asked.append("progress")
        return tuple(asked)


PAPER_SAFETY = Safety()  # the paper's constraints, no margin of ours
# The walkable preset (``--walkable``): the margins at which MuJoCo's walk of the optimal gaits
# follows the model (``validate.studies.margins_study``, docs/margins-*.png: the servos add at
# most a fifth of the joint torque, MuJoCo spends within 5 % of the model's energy per step, every
# check passes). The landing share is the study's choice: the loosest at which every point of
# 0.2-0.6 m/s meets the targets (at 1 V the rolling knee's servos add 0.2003 at 0.3 m/s; no
# share makes the 1 m/s optima walk). Clearance and ZMP margin move neither figure
# systematically from 0 to 2 cm (the servos' share by < 0.04, the energy by < 3 points); the
# only verdicts they change are the 0.6 m/s orbits at the edge of stability (ρ + 2 spreads
# 1.00), one way or the other: 5 mm each keeps the swing sole beyond MuJoCo's scuff margin
# (1 mm) and the centre of pressure off the sole's edge.
WALKABLE = Safety(
    clearance=0.005,
    zmp_margin=0.005,
    landing_share=0.75,
    friction=0.6,
    joint_margin=0.05,
    hip_progress=0.2,
)
_LEFT_OUT = {
    "knee_bend": 0.0,
    "actuator_limits": False,
    "clearance_window": CLEARANCE_WINDOW,
    **dict.fromkeys(OPTIONAL),
}


def safety_dict(safety: Safety, kept: tuple = ()) -> dict:
    """The margins as a file writes them: those beyond the clearance and the ZMP margin only
    when asked (``_LEFT_OUT``), but for those ``kept`` (a campaign's record keeps the knee
    bend, which it wrote before the others existed)."""
    values = dataclasses.asdict(safety)
    for name, default in _LEFT_OUT.items():
        at_default = values[name] == default and type(values[name]) is type(default)
        if at_default and name not in kept:
            del values[name]
    return values


def clearance_envelope(t_n, clearance: float, window: float = CLEARANCE_WINDOW) -> np.ndarray:
    """Least height [m] of the swing sole at the normalised times ``t_n``: 0 within ``window``
    of either end of the step, else ``CLEARANCE_FLOOR`` of ``clearance`` rising linearly to
    all of it at ``CLEARANCE_FULL`` of the step from the nearer end."""
    end = np.minimum(np.asarray(t_n, dtype=float), 1.0 - np.asarray(t_n, dtype=float))
    if window < CLEARANCE_FULL:
        rise = np.clip((end - window) / (CLEARANCE_FULL - window), 0.0, 1.0)
    else:
        rise = np.ones_like(end)
    share = CLEARANCE_FLOOR + (1.0 - CLEARANCE_FLOOR) * rise
    return np.where(end >= window, clearance * share, 0.0)


@functools.cache
def clearance_profile(
    samples_per_half: int, clearance: float, knots: int = 1, window: float = CLEARANCE_WINDOW
) -> np.ndarray:
    """``clearance_envelope`` (N,) [m] on the time grid of ``biped.model.gait.sample``."""
    t_n = np.concatenate(piece_grid(samples_per_half, knots))
    profile = clearance_envelope(t_n, clearance, window)
    profile.setflags(write=False)
    return profile


@functools.cache
def simpson_weights(samples_per_half: int, knots: int = 1) -> np.ndarray:
    """Weights w with Σ w f(t_n) = Simpson's rule on every piece of the normalised grid.

    On each piece of n = samples + 1 evenly spaced samples h apart: h/3 (1, 4, 2, ..., 4, 1)
    for an odd n; for an even n the same on the first n - 1 and Cartwright's parabola
    through the last three on the last interval, h (-1, 8, 5)/12: the rule of
    ``scipy.integrate.simpson`` (``tests/test_criteria.py`` holds them equal), written out
    because importing scipy's integrators costs every process 0.6 s.
    """
    if samples_per_half < 1:
        raise BipedError(f"samples per half = {samples_per_half}: allowed 1 or more")
    n = samples_per_half + 1
    h = breakpoints(knots)[1] / samples_per_half
    piece = np.zeros(n)
    if n == 2:
        piece[:] = h / 2
    else:
        odd = n if n % 2 else n - 1  # samples of the composite rule
        piece[:odd] += np.array([1.0] + [4.0, 2.0] * ((odd - 3) // 2) + [4.0, 1.0]) * h / 3
        if odd < n:
            piece[-3:] += np.array([-1.0, 8.0, 5.0]) * h / 12
    weights = np.concatenate([piece] * pieces(knots))
    weights.setflags(write=False)  # cached: shared by every caller
    return weights


@dataclass(frozen=True)
class StepEvaluation:
    """Everything computed on one step's time grid."""

    t: np.ndarray  # [s] (N,), T/2 twice
    q: np.ndarray
    qd: np.ndarray
    qdd: np.ndarray
    torques: np.ndarray  # [N·m] (N, 6)
    wrench: np.ndarray  # (N, 3)
    zmp: np.ndarray  # [m] (N,)
    constraints: np.ndarray  # (N, 7) Ψ1..Ψ7, NaN where not checked (swing foot at 0 and T)
    sthenic: float  # (2/d) ∫ ΓᵀΓ dt [N²·m·s]
    energy: float  # ∫ Σ |Γ θ̇| dt [J]
    penalty: float  # ∫ k Σ (e^(|Ψ|-Ψ) - 1) dt [s]; inf if any value is not finite
    # What the motors' figures (``drive``, ``electrical``, computed when first asked) follow
    # from: the joints' rates θ̇ and accelerations θ̈ (N, 6), the actuators, the weights
    # [s] (N,) of Simpson's rule on the grid.
    joint_rates: np.ndarray
    joint_accels: np.ndarray
    actuators: Actuators
    weights: np.ndarray
    # Under ``Safety.actuator_limits``: the margins of ``limit_margins`` (N, 6, 6): sample,
    # limit (``LIMITS`` each twice, − then +), joint; else None.
    actuator_margins: np.ndarray | None = None
    # The margins of the walkable constraints asked (``biped.model.walkable.step_margins``),
    # by name, in each one's unit: once a step (k,) or at each sample (N, k).
    walkable: dict = field(default_factory=dict)

    @functools.cached_property
    def drive(self) -> Drive:
        """The motors at each sample, arrays (N, 6) (``biped.model.actuators.drive``)."""
        return drive(self.actuators.constants(), self.torques, self.joint_rates, self.joint_accels)

    @functools.cached_property
    def electrical(self) -> float:
        """[J] ∫ Σ max(P_i, 0) dt: the motors' energy over the step, without regeneration."""
        return float(self.weights @ np.maximum(self.drive.power, 0.0).sum(-1))

    @functools.cached_property
    def electrical_net(self) -> float:
        """[J] ∫ Σ P_i dt: the motors' energy over the step, with regeneration."""
        return float(self.weights @ self.drive.power.sum(-1))

    def value(self, criterion: str, step_length: float) -> float:
        """The criterion ``criterion`` without the penalty: C_Γ, C_E, C_E / S or E / S."""
        if criterion == "sthenic":
            return self.sthenic
        if criterion == "energy":
            return self.energy
        work = self.electrical if criterion == "electrical" else self.energy
        return work / step_length

    def cost(self, criterion: str, step_length: float) -> float:
        """C_Γ, C_E, C_E / S or E / S with the penalty (Err = 0: the step was built)."""
        if criterion == "sthenic":
            return self.sthenic + self.penalty / step_length
        if criterion == "energy-per-metre":
            return (self.energy + self.penalty) / step_length
        if criterion == "electrical":
            return (self.electrical + self.penalty) / step_length
        return self.energy + self.penalty

    @property
    def feasible(self) -> bool:
        """Every constraint holds on the samples: no violation, zero penalty."""
        return self.penalty == 0.0 and not self.violations()

    @property
    def worst(self) -> np.ndarray:
        """Smallest value of each Ψ_i over the checked samples (7,)."""
        return np.nanmin(self.constraints, axis=0)

    def violations(self) -> dict:
        """Worst value of each violated constraint (Ψ_i < 0), by name; under the actuator
        limits also each joint's limit exceeded ("swing_knee max_speed": its margin, a share
        of the limit)."""
        found = {name: float(w) for name, w in zip(CONSTRAINTS, self.worst, strict=True) if w < 0.0}
        for name, margins in self.walkable.items():
            if margins.min() < 0.0:
                found[name] = float(margins.min())
        if self.actuator_margins is not None:
            worst = self.actuator_margins.min(axis=0).reshape(len(LIMITS), 2, -1).min(axis=1)
            for limit, row in zip(LIMITS, worst, strict=True):
                for joint, margin in zip(JOINTS, row, strict=True):
                    if margin < 0.0:
                        found[f"{joint} {limit}"] = float(margin)
        return found

    def violations_line(self) -> str:
        """The violated constraints and worst values, as printed: 'zmp_toe = -0.0012, ...'."""
        return ", ".join(f"{k} = {v:.3g}" for k, v in self.violations().items())


def constraints(robot, q, torques, wrench, swing_feet_z) -> np.ndarray:
    """Ψ1..Ψ7 (N, 7) of eq. (28) from the samples.

    Args:
        robot: the parameters (foot geometry).
        q: (N, 9); torques: (N, 6); wrench: (N, 3).
        swing_feet_z: (N, 2) heights of the swing heel and toe [m].
    """
    zmp = zmp_from(torques, wrench, robot.ankle_height)
    return np.column_stack(
        [
            wrench[:, 1],
            zmp + robot.foot_heel,
            robot.foot_length - robot.foot_heel - zmp,
            q[:, Q2] - q[:, Q1],
            q[:, Q3] - q[:, Q4],
            swing_feet_z,
        ]
    )


def penalty_rate(psi, checked) -> np.ndarray:
    """k Σ_i (e^(|Ψ_i| - Ψ_i) - 1) per sample (N,), over the ``checked`` entries only."""
    return PENALTY_WEIGHT * np.where(checked, np.expm1(np.abs(psi) - psi), 0.0).sum(axis=1)


@functools.cache
def checked_mask(samples_per_half: int, knots: int = 1) -> np.ndarray:
    """Which Ψ_i are checked at which sample (N, 7): all but the swing foot at t = 0, T."""
    mask = np.ones((pieces(knots) * (samples_per_half + 1), len(CONSTRAINTS)), dtype=bool)
    mask[[0, -1], 5:] = False  # both feet on the ground by construction
    mask.setflags(write=False)
    return mask


def evaluate_step(
    model: Biped,
    step: Step,
    samples_per_half: int,
    margins: bool = False,
    safety: Safety = PAPER_SAFETY,
) -> StepEvaluation:
    """Torques, wrench, ZMP, constraints and criteria of one step.

    Args:
        margins: penalise Ψ_i - δ_i instead of Ψ_i (``MARGINS``), as the optimiser does.
        safety: margins of ours on the constraints (``Safety``); the paper's by default.
    """
    t, q, qd, qdd, torques, wrench, feet = sample(
        model, step, samples_per_half, ("swing_heel", "swing_toe")
    )
    robot = model.robot
    feet_z = feet[..., 1]
    knots = step.knots
    if safety.clearance:
        window = safety.clearance_window
        required = clearance_profile(samples_per_half, safety.clearance, knots, window)
        feet_z = feet_z - required[:, None]
    psi = constraints(robot, q, torques, wrench, feet_z)
    psi[:, 1:3] -= safety.zmp_margin
    if safety.knee_bend:
        psi[:, 3] -= safety.knee_bend
    checked = checked_mask(samples_per_half, knots)
    seen = psi - margin_profile(samples_per_half, knots) if margins else psi
    rates = model.joint_angles(qd)
    power = np.abs(rates * torques).sum(-1)
    squared = (torques**2).sum(-1)
    weights = step.period * simpson_weights(samples_per_half, knots)
    actuators, accels = robot.drive_actuators, model.joint_angles(qdd)
    limits = None
    penalty = penalty_rate(seen, checked)
    walk = walkable.step_margins(model, step, q, qd, wrench, safety, solver=margins)
    penalty = penalty + _walkable_penalty(walk, step.period)
    if safety.actuator_limits:
        constants = actuators.constants()
        voltage = drive(constants, torques, rates, accels).voltage
        limits = np.stack(limit_margins(constants, torques, rates, voltage), axis=1)
        penalty = penalty + penalty_rate(limits.reshape(len(t), -1), True)
    finite = bool(np.all(np.isfinite(psi[checked])) and np.all(np.isfinite(squared)))
    return StepEvaluation(
        t=t,
        q=q,
        qd=qd,
        qdd=qdd,
        torques=torques,
        wrench=wrench,
        zmp=zmp_from(torques, wrench, robot.ankle_height),
        constraints=np.where(checked, psi, np.nan),
        sthenic=float(weights @ squared) / step.step_length,
        energy=float(weights @ power),
        penalty=float(weights @ penalty) if finite else float("inf"),
        joint_rates=rates,
        joint_accels=accels,
        actuators=actuators,
        weights=weights,
        actuator_margins=limits,
        walkable=walk,
    )


def _walkable_penalty(margins: dict, period: float) -> np.ndarray | float:
    """The penalty rate of the walkable constraints' ``margins`` (``penalty_rate``, each in
    its solver's scale), per sample; a once-a-step margin's spread over the step (the
    penalised criteria of the paper's method, ``biped.optimization.penalty``)."""
    rate = 0.0
    for name, values in margins.items():
        scaled = np.atleast_2d(values / walkable.SCALES[name])
        term = penalty_rate(scaled, True)
        rate = rate + (term.sum() / period if values.ndim == 1 else term)
    return rate
