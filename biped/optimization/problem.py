"""The gait optimisation problem shared by every solver, and its decision variables.

A ``GaitProblem`` is one question: the best gait of one robot and knee at one walking speed
for one criterion, under the paper's constraints and our safety margins, with the
constraints imposed at ``samples_per_half`` samples per spline piece.

Decision variables. The paper's 21 parameters start with the hip position (x_H, z_H) at the
start of the step. The knees' bends at double support follow from it through the inverse
geometric model, whose slope is unbounded at a straight knee, √(reach² − d²): the optimal
gaits keep the stance knee straight to the 1 mrad margin, about 1e-7 m from the edge of the
reach, where no derivative-based solver can work. The solvers therefore use the two knee
bends at the start of the step instead (``VARIABLES``):

    θ_s = q2(0) − q1(0) >= 0   stance knee flexion, θ_w = q3(0) − q4(0) >= 0   swing knee

Each bend gives a leg length d(θ), smooth and even in θ, and the hip is where the circles of
radii d_s about the stance ankle (x = 0) and d_w about the trailing ankle (x = −S) meet:

    x_H = (d_w² − d_s² − S²) / (2 S),    z_H = h_p + √(d_s² − x_H²)                     (*)

Every bend in its bounds is a posture of the leg; the two circles meet as long as
|d_s − d_w| < S < d_s + d_w, far from walking postures: the solvers keep the hip at least
``MIN_HIP_HEIGHT`` above the ankles (a smooth constraint). Gait files keep the paper's 21
parameters (``to_parameters``, ``from_parameters``).
"""

from __future__ import annotations

import dataclasses
import functools
import math
from dataclasses import dataclass

import numpy as np

from biped.errors import BipedError
from biped.model.bezier import DEGREES, Bezier
from biped.model.criteria import ALL_CRITERIA, PAPER_SAFETY, Safety
from biped.model.dynamics import Biped
from biped.model.gait import (
    KNOTS,
    N_PARAMETERS,
    PARAMETERS,
    at_knots,
    build_step,
    check_knots,
    embedded,
    parameter_names,
    pieces,
)

# Decision variables of the solvers: the paper's parameters with the hip replaced by the
# two knee bends at the start of the step.
VARIABLES = ("stance_knee_bend", "swing_knee_bend") + PARAMETERS[2:]
N_VARIABLES = len(VARIABLES)  # 21
_INDEX = {name: i for i, name in enumerate(VARIABLES)}

# Simple bounds of the variables [rad, rad/s, rad/s², s]. The paper sets none; these are
# wide enough never to bind at a walking gait, and a solver's report says when one does.
_LOWER = {"stance_knee_bend": 0.0, "swing_knee_bend": 0.0, "trunk": -0.6, "period": 0.15}
_UPPER = {"stance_knee_bend": 1.5, "swing_knee_bend": 1.5, "trunk": 0.6, "period": 3.0}
RATE_BOUND = 20.0  # [rad/s]
ACCEL_BOUND = 500.0  # [rad/s²]
# [m] Least height of the hip above the ankles at the start of the step, far below any
# walking posture: it keeps the two circles of (*) meeting.
MIN_HIP_HEIGHT = 0.3
# Slowest walking speed [m/s]: a step lasts a few seconds at most, so slower gaits take
# steps of a few centimetres down to nothing (1e-9 m/s: a 0.0000 m step), which is not
# walking. The fastest depends on the robot (``max_walking_speed``, √(g·leg length)).
MIN_SPEED = 0.01
# One unit of each variable in the solvers' scaled space (comparable changes of the gait).
SCALES = np.array([0.03, 0.03, 0.03] + [0.3] * 5 + [2.0] * 12 + [0.05])
# Duration of a step in the first guess [s].
FIRST_GUESS_PERIOD = 0.6
# Samples per spline piece where the solver imposes the constraints Ψ_i >= δ_i (each piece
# closed: 26 samples); feasibility is then checked on a finer grid (``CHECK_SAMPLES_PER_HALF``,
# 202 samples per step), where Ψ_i may dip below δ_i between them.
SOLVER_SAMPLES_PER_HALF = 25
CHECK_SAMPLES_PER_HALF = 100
# The same per piece of each family (``biped.model.gait.KNOTS``): about as many per step
# (``solver_samples``, ``check_samples``), and no fewer per piece than these, so that the
# solver's samples follow a piece's cubic and the check grid resolves it; the check grid's
# pieces of an even number of intervals, where Simpson's rule is the plain composite one. A
# gait embedded in a richer family (``biped.optimization.ladder``) has the same costs to
# round-off where the two check grids coincide (K = 1 and 3: 1/200 of the step apart), to the
# quadrature's error elsewhere (of the sthenic optima at 0.3 m/s, 1.5e-7 relative from K = 3
# to 7, 3e-6 from 7 to 15): a ladder compares a rung's optimum with the rung below's on the
# rung's own grid.
SOLVER_SAMPLES_PER_STEP = 2 * SOLVER_SAMPLES_PER_HALF
CHECK_SAMPLES_PER_STEP = 2 * CHECK_SAMPLES_PER_HALF
MIN_SOLVER_SAMPLES = 6
MIN_CHECK_SAMPLES = 26


def solver_samples(knots: int) -> int:
    """Samples per piece where the solvers impose the constraints in the family of ``knots``
    interior knots (25 for the paper's spline, 13 for 3 knots, 7 for 7, 6 for 15)."""
    return max(math.ceil(SOLVER_SAMPLES_PER_STEP / pieces(knots)), MIN_SOLVER_SAMPLES)


def check_samples(knots: int) -> int:
    """Samples per piece of the check grid of the family of ``knots`` interior knots, an even
    number (100 for the paper's spline, 50 for 3 knots, 34 for 5, 26 for 7 and more)."""
    per_piece = max(math.ceil(CHECK_SAMPLES_PER_STEP / pieces(knots)), MIN_CHECK_SAMPLES)
    return per_piece + per_piece % 2


# The gait families: the splines' (``KNOTS``) and the Bézier curves' (one piece, as many
# samples as the paper's spline's two, ``biped.model.bezier``).
FAMILIES = KNOTS + tuple(Bezier(degree) for degree in DEGREES)
SOLVER_SAMPLES = {knots: solver_samples(knots) for knots in FAMILIES}
CHECK_SAMPLES = {knots: check_samples(knots) for knots in FAMILIES}
# Scales and bounds of a richer family's knot angles [rad] and rates [rad/s].
KNOT_SCALES = {"": 0.03, "rate_": 0.3}
KNOT_ANGLE_BOUND = np.pi


@functools.cache
def variable_names(knots: int = 1) -> tuple:
    """The solvers' variables of the family of ``knots`` interior knots: its parameters
    (``biped.model.gait.parameter_names``) with the hip replaced by the two knee bends."""
    return ("stance_knee_bend", "swing_knee_bend") + parameter_names(knots)[2:]


# Families of more knots than this have their scales shrunk (``scales``).
SCALED_FROM_KNOTS = 5
# Exponents of the shrinking of the angles' (and the period's) and the rates' scales.
ANGLE_EXPONENT, RATE_EXPONENT = 3.0, 1.5


@functools.cache
def scales(knots: int = 1) -> np.ndarray:
    """``SCALES`` of the family: the paper's, the accelerations' replaced by the knots'.

    Beyond ``SCALED_FROM_KNOTS`` knots the pieces shorten, and the criterion's curvature in
    a variable grows as the pieces' accelerations do (the Hessian's diagonal at the optimum
    at 0.3 m/s, in these units: 0.1 to 1.5e5 for 3 knots, 6 to 8e6 for 15): IPOPT's dual
    infeasibility stalls at 1e-8 to 1e-7 where its tolerance asks 1e-9 (every start of 15
    knots at its acceptable level, a step of 1e-11). With f = (``SCALED_FROM_KNOTS`` + 1) /
    (K + 1), the angles' and the period's scales are multiplied by f^``ANGLE_EXPONENT``, the
    rates' by f^``RATE_EXPONENT``: the exponents at which every start of 15 knots converged
    (those of the curvature alone, 1.5 and 0.5, left it at 1e-8)."""
    if knots == 1:
        return SCALES
    if isinstance(knots, Bezier):
        return bezier_scales(knots)
    at_knots = [KNOT_SCALES[kind] for _ in range(knots) for kind in KNOT_SCALES for _ in range(6)]
    found = np.concatenate([SCALES[:8], at_knots, SCALES[-1:]])
    if knots <= SCALED_FROM_KNOTS:
        return found
    f = (SCALED_FROM_KNOTS + 1) / (knots + 1)
    rates = np.array(["rate" in name for name in variable_names(knots)])
    found = found * np.where(rates, f**RATE_EXPONENT, f**ANGLE_EXPONENT)
    found.setflags(write=False)
    return found


# Scale of a Bézier curve's interior control point [rad]: as a knot's angle.
CONTROL_SCALE = 0.03


@functools.cache
def bezier_scales(family: Bezier) -> np.ndarray:
    """``SCALES`` of a Bézier family: the paper's first 8 and period, ``CONTROL_SCALE`` for
    each interior control point."""
    found = np.concatenate([SCALES[:8], np.full(6 * family.interior, CONTROL_SCALE), SCALES[-1:]])
    found.setflags(write=False)
    return found


def bounds(knots: int = 1) -> tuple[np.ndarray, np.ndarray]:
    """Lower and upper bounds of the variables, in ``variable_names(knots)`` order."""
    names = variable_names(knots)
    lower = np.empty(len(names))
    upper = np.empty(len(names))
    for i, name in enumerate(names):
        if name.startswith("control"):
            lower[i], upper[i] = -KNOT_ANGLE_BOUND, KNOT_ANGLE_BOUND
        elif name.startswith("knot"):
            limit = RATE_BOUND if "_rate_" in name else KNOT_ANGLE_BOUND
            lower[i], upper[i] = -limit, limit
        elif name.startswith("end_rate"):
            lower[i], upper[i] = -RATE_BOUND, RATE_BOUND
        elif "accel" in name:
            lower[i], upper[i] = -ACCEL_BOUND, ACCEL_BOUND
        else:
            lower[i], upper[i] = _LOWER[name], _UPPER[name]
    return lower, upper


def index(name: str) -> int:
    """Position of a variable in ``VARIABLES``."""
    try:
        return _INDEX[name]
    except KeyError:
        raise BipedError(f"variable {name!r} is unknown: allowed {', '.join(VARIABLES)}") from None


def max_walking_speed(model: Biped) -> float:
    """[m/s] √(g L), L the leg length: above it (Froude number > 1) gravity cannot keep the
    stance foot on the ground as the hip vaults over it, whatever the gait."""
    leg = model.robot.shank_length + model.robot.thigh_length
    return float(np.sqrt(model.gravity * leg))


def check_speed(model: Biped, speed: float) -> float:
    """Return ``speed`` if walkable at all, raise a clear error otherwise."""
    high = max_walking_speed(model)
    if not (isinstance(speed, (int, float, np.floating)) and np.isfinite(speed)):
        raise BipedError(f"speed = {speed!r} m/s: allowed a finite number of m/s")
    if not MIN_SPEED <= speed <= high:
        raise BipedError(
            f"speed = {speed!r} m/s: allowed {MIN_SPEED:.3g} <= speed <= {high:.3g} m/s "
            f"(slower, a step of at most {_UPPER['period']:g} s is a few centimetres; faster "
            f"than √(g·leg length), the stance foot leaves the ground)"
        )
    return float(speed)


def check_criterion(criterion: str) -> str:
    if criterion not in ALL_CRITERIA:
        allowed = ", ".join(map(repr, ALL_CRITERIA))
        raise BipedError(f"criterion = {criterion!r}: allowed {allowed}")
    return criterion


def walkable_description(safety: Safety) -> str:
    """The walkable constraints ``safety`` asks, as a problem's line says them ("" for
    none)."""
    parts = []
    if safety.landing_speed is not None:
        parts.append(f"landing at {safety.landing_speed:g} m/s at most")
    if safety.landing_share is not None:
        parts.append(f"landing at {safety.landing_share:g} V at most")
    if safety.friction is not None:
        parts.append(f"friction {safety.friction:g}")
    if safety.joint_margin is not None:
        parts.append(f"joints {safety.joint_margin:g} rad from their stops")
    if safety.hip_progress is not None:
        parts.append(f"hip at {safety.hip_progress:g} V at least")
    if safety.clearance and safety.clearance_window != PAPER_SAFETY.clearance_window:
        parts.append(f"clearance windows {safety.clearance_window:g} T")
    return "".join(f", {part}" for part in parts)


@dataclass(frozen=True)
class GaitProblem:
    """Minimise ``criterion`` over the gaits of ``model`` at ``speed``.

    Attributes:
        model: the robot and its knee.
        speed: walking speed V [m/s]; the step length is V T.
        criterion: ``"sthenic"`` (eq. 30), ``"energy"`` (eq. 31), ``"energy-per-metre"``
            (eq. 31 divided by the step length) or ``"electrical"`` (the motors' energy per
            metre, ``biped.model.actuators``).
        safety: margins of ours beyond the paper's constraints (``Safety()``: the paper's).
        samples_per_half: samples per spline piece where the solvers impose the constraints.
    """

    model: Biped
    speed: float
    criterion: str = "sthenic"
    safety: Safety = PAPER_SAFETY
    samples_per_half: int | None = None
    knots: int = 1

    def __post_init__(self):
        object.__setattr__(self, "speed", check_speed(self.model, self.speed))
        check_criterion(self.criterion)
        if not isinstance(self.safety, Safety):
            raise BipedError(f"safety = {self.safety!r}: allowed a biped.model.criteria.Safety")
        check_knots(self.knots)
        if self.samples_per_half is None:
            object.__setattr__(self, "samples_per_half", SOLVER_SAMPLES[self.knots])
        n = self.samples_per_half
        if isinstance(n, bool) or not isinstance(n, int) or not 2 <= n <= 1000:
            raise BipedError(f"samples_per_half = {n!r}: allowed an integer from 2 to 1000")

    @property
    def knee(self) -> str:
        return self.model.knee

    @property
    def on_default_grid(self) -> bool:
        """Whether the solvers impose the constraints at the family's default samples
        (``SOLVER_SAMPLES``)."""
        return self.samples_per_half == SOLVER_SAMPLES[self.knots]

    @property
    def variables(self) -> tuple:
        """The names of the solvers' variables (``variable_names``)."""
        return variable_names(self.knots)

    def describe(self) -> str:
        margins = ""
        if self.safety != PAPER_SAFETY:
            margins = (
                f", clearance {self.safety.clearance:g} m, ZMP margin {self.safety.zmp_margin:g} m"
            )
            if self.safety.knee_bend:
                margins += f", stance knee bent {self.safety.knee_bend:g} rad at least"
            if self.safety.actuator_limits:
                margins += ", within the actuators' limits"
            margins += walkable_description(self.safety)
        family = f", {self.knots} knots" if self.knots != 1 else ""
        if isinstance(self.knots, Bezier):
            family = f", {self.knots}"
        return (
            f"{self.knee} knee, {self.criterion} criterion, {self.speed:.3f} m/s{margins}{family}"
        )

    # ------------------------------------------------------------------ variables <-> parameters
    def hip_start(self, stance_bend, swing_bend, period):
        """Hip (x_H, z_H) [m] at the start of the step from the knee bends, eq. (*)."""
        chain = self.model
        d_s2 = chain.reach_squared(stance_bend)
        d_w2 = chain.reach_squared(swing_bend)
        length = self.speed * period
        x = (d_w2 - d_s2 - length**2) / (2 * length)
        height2 = d_s2 - x**2
        if not height2 >= MIN_HIP_HEIGHT**2:
            raise BipedError(
                f"knee bends ({stance_bend:.6g}, {swing_bend:.6g}) rad with a step of "
                f"{length:.6g} m put the hip {math.sqrt(max(height2, 0.0)):.6g} m above the "
                f"ankles: allowed at least {MIN_HIP_HEIGHT} m"
            )
        return x, chain.robot.ankle_height + math.sqrt(height2)

    def to_parameters(self, variables) -> np.ndarray:
        """The parameters (``biped.model.gait.parameter_names``: the paper's 21 for its
        spline) of the solvers' variables."""
        z = np.asarray(variables, dtype=float)
        size = len(self.variables)
        if z.shape != (size,):
            raise BipedError(f"variables have shape {z.shape}: allowed ({size},)")
        x, height = self.hip_start(z[0], z[1], z[-1])
        return np.concatenate([[x, height], z[2:]])

    def from_parameters(self, parameters) -> np.ndarray:
        """The solvers' variables of the parameters (the knee bends at the start of the step
        from the inverse geometric model)."""
        p = np.asarray(parameters, dtype=float)
        size = len(parameter_names(self.knots))
        if p.shape != (size,):
            raise BipedError(f"gait parameters have shape {p.shape}: allowed ({size},)")
        x, height, period = p[0], p[1], p[-1]
        lift = height - self.model.robot.ankle_height
        hips = np.array([[x, lift], [x + self.speed * period, lift]])
        (q1, q2), (q4, q3) = self.model.leg_angles(hips)
        return np.concatenate([[q2 - q1, q3 - q4], p[2:]])

    def first_guess(self, period: float = FIRST_GUESS_PERIOD) -> np.ndarray:
        """A walkable first guess (variables): knees bent a little, the hip midway between
        the feet, legs turning as stiff pendulums; for a richer family, that gait of the
        paper's spline (``embedded``).

        Args:
            period: duration of the step T [s]; the step length is speed x T.
        """
        model = self.model
        leg = model.robot.shank_length + model.robot.thigh_length
        length = min(self.speed * period, leg)
        period = length / self.speed
        height = np.sqrt((0.97 * leg) ** 2 - (length / 2) ** 2) + model.robot.ankle_height
        p = np.zeros(N_PARAMETERS)
        p[0:3] = [-length / 2, height, 0.0]
        p[3:7] = -self.speed / leg  # q1..q4 turn backwards as the hip passes over the feet
        p[PARAMETERS.index("period")] = period
        paper = dataclasses.replace(self, knots=1, samples_per_half=None)
        return self.embedded(paper.from_parameters(p), exact=False)

    def embedded(self, variables, knots: int = 1, exact: bool = True) -> np.ndarray:
        """The variables of this problem's family for the gait of ``variables`` of the family
        of ``knots`` interior knots (the paper's spline's 21 by default): the same gait where
        this family holds that one (``biped.model.gait.embedded``), ``variables`` themselves
        in the same family. ``exact`` False: the Hermite spline through that gait's angles and
        rates at this family's knots where it does not hold it (``at_knots``; a first guess)."""
        z = np.asarray(variables, dtype=float)
        if knots == self.knots:
            return z
        if self.knots == 1:  # its variables are accelerations, not knots' angles and rates
            raise BipedError(f"a gait of {knots} knots: allowed in a family of knots only")
        below = dataclasses.replace(self, knots=knots, samples_per_half=None)
        step = build_step(self.model, self.speed, below.to_parameters(z), knots)
        inner = (embedded if exact else at_knots)(step, self.knots)
        return np.concatenate([z[:8], inner.ravel(), z[-1:]])

    def first_parameters(self) -> np.ndarray:
        """The parameters of ``first_guess``."""
        return self.to_parameters(self.first_guess())
