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
from biped.model.actuators import LIMITS, Actuators, Drive, drive, limit_margins
from biped.model.dynamics import JOINTS, Biped, zmp_from
from biped.model.gait import Step, breakpoints, piece_grid, sample
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


@functools.cache
def margin_profile(samples_per_half: int, knots: int = 1) -> np.ndarray:
    """δ (N, 7) on the time grid of ``biped.model.gait.sample``."""
    t_n = np.concatenate(piece_grid(samples_per_half, knots))
    ramp = np.clip(np.minimum(t_n, 1.0 - t_n) / FOOT_MARGIN_RAMP, 0.0, 1.0)
    profile = np.tile(MARGINS, (len(t_n), 1))
    profile[:, 5:] *= ramp[:, None]
    profile.setflags(write=False)
    return profile


# The swing foot's required clearance (``Safety.clearance``, 0 in the paper) ramps up over
# this fraction of the step at each end, where the foot leaves and reaches the ground.
CLEARANCE_RAMP = 0.3
CLEARANCE_DELAY = 0.03
# Largest safety margins accepted [m].
MAX_CLEARANCE = 0.2
MAX_ZMP_MARGIN = 0.05
# Largest least bend of the stance knee asked [rad].
MAX_KNEE_BEND = 1.0


@dataclass(frozen=True)
class Safety:
    """Margins of ours on top of the paper's constraints, for gaits that stand a physics
    engine's contact model and tracking errors. ``Safety()`` is the paper's problem.

    Attributes:
        clearance: [m] height the swing foot keeps off the ground away from the ends of the
            step (``clearance_profile``); Ψ6, Ψ7 become the heights above it.
        zmp_margin: [m] distance the ZMP keeps inside the sole's heel and toe (Ψ2, Ψ3).
        knee_bend: [rad] least flexion of the stance knee over the step (Ψ4 becomes the
            flexion beyond it): the two knee kinematics differ only where the knee bends.
        actuator_limits: every joint's torque, speed and voltage within its motor's
            (``biped.model.actuators.limit_margins``) at every sample: a gait the motors
            cannot follow is not feasible.
    """

    clearance: float = field(default=0.0, metadata={"unit": "m"})
    zmp_margin: float = field(default=0.0, metadata={"unit": "m"})
    knee_bend: float = field(default=0.0, metadata={"unit": "rad"})
    actuator_limits: bool = field(default=False, metadata={"unit": None})

    def __post_init__(self):
        if not isinstance(self.actuator_limits, bool):
            raise BipedError(f"actuator_limits = {self.actuator_limits!r}: allowed true or false")
        limits = (
            ("clearance", MAX_CLEARANCE, "m"),
            ("zmp_margin", MAX_ZMP_MARGIN, "m"),
            ("knee_bend", MAX_KNEE_BEND, "rad"),
        )
        for name, high, unit in limits:
            value = getattr(self, name)
            if isinstance(value, bool) or not isinstance(value, (int, float)):
                what = "metres" if unit == "m" else "radians"
                raise BipedError(f"{name} = {value!r}: allowed a number of {what}")
            if not (math.isfinite(value) and 0.0 <= value <= high):
                raise BipedError(f"{name} = {value!r} {unit}: allowed 0 to {high} {unit}")
            object.__setattr__(self, name, float(value))


PAPER_SAFETY = Safety()  # the paper's constraints, no margin of ours


def safety_dict(safety: Safety) -> dict:
    """The margins as a file writes them: a least knee bend and the actuator limits only
    when asked (a file of the paper's problem is as it was before they existed)."""
    values = dataclasses.asdict(safety)
    if not values["knee_bend"]:
        del values["knee_bend"]
    if not values["actuator_limits"]:
        del values["actuator_limits"]
    return values


@functools.cache
def clearance_profile(samples_per_half: int, clearance: float, knots: int = 1) -> np.ndarray:
    """Required height (N,) [m] of the swing heel and toe: none for the first and last
    ``CLEARANCE_DELAY`` of the step (lift-off and touchdown), then ``clearance`` reached
    linearly at ``CLEARANCE_RAMP``."""
    t_n = np.concatenate(piece_grid(samples_per_half, knots))
    x = (np.minimum(t_n, 1.0 - t_n) - CLEARANCE_DELAY) / (CLEARANCE_RAMP - CLEARANCE_DELAY)
    profile = clearance * np.clip(x, 0.0, 1.0)
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
    weights = np.concatenate([piece] * (knots + 1))
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
    mask = np.ones(((knots + 1) * (samples_per_half + 1), len(CONSTRAINTS)), dtype=bool)
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
        feet_z = feet_z - clearance_profile(samples_per_half, safety.clearance, knots)[:, None]
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
    )
