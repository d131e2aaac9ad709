"""The double support phase: both feet flat on the ground, a closed chain of three degrees of
freedom, its motion, and the split of the load between the motors and the two feet.

Labelling. The phase runs from the landing of the swing foot to the lift-off of the stance
foot, in the labels of the single support phase that ends with the landing: the *stance*
(rear) ankle at x = 0, the *swing* (front) ankle at x = S, S the step length, both at
z = h_p, both feet flat (q_p1 = q_p2 = 0). The legs are swapped (``swap_legs``) at lift-off.

Closed chain. Holding both feet is six constraints A q̇ = 0 on the nine coordinates, A the
rows of both feet's contact Jacobians (eqs. 13-15 twice); the free coordinates are

    s = (x_H, z_H, q5)     the hip [m] and the trunk's angle [rad]

and each leg's shank and thigh angles follow from the hip's position relative to its ankle
through the inverse geometric model (``Chain.leg_angles``: revolute and rolling knees alike).
Velocities and accelerations of the six others solve A q̇ = 0 and A q̈ + H_c = 0 (eq. 16 for
both feet) with ṡ, s̈ given.

Motion. Each of x_H, z_H, q5 is one cubic in time on [0, T_ds] (cubic Hermite): its value and
rate at the landing (after the impact, or at zero foot speed: no impact) and at lift-off, so
the motion is continuous in position and velocity with the single support phase at both ends;
the duration T_ds is a parameter.

Load split (the actuation redundancy). Eq. (19) with both feet held,

    D q̈ + H + Q = B Γ + A_sᵀ F_s + A_wᵀ F_w                                   (19')

is nine equations in twelve unknowns: the six motor torques Γ and the two ground wrenches
F_s, F_w = [Fx, Fz, Cy] (moment about each foot's own ankle). A first rule: at each instant
the split of least squared torque, min ΓᵀΓ subject to (19'), the integrand of the sthenic
criterion (eq. 30), unconstrained. Its optimality conditions (a linear system, ``split_load``):

    Γ = Bᵀλ,   A_s λ = 0 and A_w λ = 0 stacked (Aλ = 0),   B Γ + Aᵀ F = D q̈ + H + Q

That rule does not look at the feet's constraints, and it pulls on the ground: at the
landing of a walking step it asks the rear foot for −570 N (internal forces between the feet
cost no torque). The split of the optimizer is therefore the other stated rule: the swing
(front) foot's wrench is free at each instant (``split_with_swing_wrench``: the three numbers
of the redundancy, the rest from eq. (19')) and the optimizer chooses it, so that with the
sthenic criterion each instant's split is the least squared torque *within* the feet's
constraints (``foot_margins``): each foot's normal force Fz > 0, its friction cone
|Fx| <= μ Fz, and its ZMP inside its sole, x_ZMP = (Cy − h_p Fx) / Fz from its ankle (a flat
foot at rest whose centre of mass lies below its ankle: its moment balance gives Cy = its
ankle's torque, Γ1 for the stance foot, Γ6 for the swing foot).

Only the knees of circles (revolute, and rolling on two circles): a profiled rolling knee
(``Robot.profiled``) is refused.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from biped.errors import BipedError
from biped.model.dynamics import JOINT_MATRIX, Biped
from biped.model.gait import hermite
from biped.model.kinematics import NQ, Q1, Q2, Q3, Q4, Q5, QP1, QP2, XH, ZH
from biped.model.robot import FOOT_FRICTION, Robot

# The free coordinates of the closed chain, their indices in q, and their units.
CHAIN_COORDINATES = ("xH", "zH", "q5")
CHAIN_UNITS = ("m", "m", "rad")
FREE = [XH, ZH, Q5]
# The six coordinates that the two feet's constraints fix once the free ones are given.
BOUND = [QP1, QP2, Q1, Q2, Q3, Q4]
FEET = ("stance", "swing")
# Each foot's constraints Ψ >= 0 in double support [N, N, N, m, m].
FOOT_CONSTRAINTS = ("normal_force", "friction_forward", "friction_backward", "zmp_heel", "zmp_toe")
# Samples of the phase's fine grid per interval of the solver's: the front foot's wrench, a
# variable at the solver's samples, is linear in time between them (the gait file's rule), and
# both feet's constraints are judged, by the solver and by the file, on this grid.
FINE_PER_INTERVAL = 10
# With the zero-speed landing, where a foot meets the air it hands its load over: the rear
# foot at lift-off and the front foot at its landing (the impact landing jumps the loads as
# it jumps the velocities, at both ends: the paper's idealisation). There its wrench is
# zero: a flat foot leaves the floor when the floor stops pushing it, and a load that jumps
# from one foot to the other is one that no servo on a closed chain and no compliant sole
# can pass on (MuJoCo's walk of the gaits that allowed it: the rear foot still carried 90 N
# of a 690 N weight 16 ms after its lift-off).
# HANDOVER_TOLERANCE [N, N·m]: the largest component of such a wrench accepted (1 mN of a
# 690 N weight); there the foot's constraints Ψ are not judged (no load, no ZMP).
HANDOVERS = ("rear_at_lift_off", "front_at_landing")
HANDOVER_TOLERANCE = 1e-3
# Distance [m] from the chain's feet at which ``DoubleSupportPhase`` refuses an end state, and
# the residual foot speed [m/s, rad/s] it accepts there.
END_TOLERANCE = 1e-9


def check_model(model: Biped) -> Biped:
    """``model`` if double support is built for it (knees of circles), else a clear error."""
    if model.robot.profiled:
        raise BipedError(
            "double support of a profiled rolling knee (k1, k2 not 0) is not built: allowed "
            "the revolute knee and the rolling knee of circles"
        )
    return model


def contact_rows(model: Biped, q) -> np.ndarray:
    """A (..., 6, 9): the stance foot's three contact rows, then the swing foot's."""
    return np.concatenate([model.contact_jacobian(q, foot) for foot in FEET], axis=-2)


def ankles(model: Biped, step_length: float) -> np.ndarray:
    """(2, 2) [m]: the stance (rear) and swing (front) ankles in double support."""
    hp = model.robot.ankle_height
    return np.array([[0.0, hp], [step_length, hp]])


def chain_posture(model: Biped, step_length: float, coordinates) -> np.ndarray:
    """q (..., 9) of the closed chain at s = (x_H, z_H, q5) (..., 3) [m, m, rad].

    Raises:
        UnreachableError: the hip is out of one leg's reach.
    """
    check_model(model)
    s = np.asarray(coordinates, dtype=float)
    hip = s[..., :2]
    rear, front = ankles(model, step_length)
    stance = model.leg_angles(hip - rear)  # (q1, q2)
    swing = model.leg_angles(hip - front)  # (q4, q3): shank, thigh
    q = np.zeros(s.shape[:-1] + (NQ,))
    q[..., Q1], q[..., Q2] = stance[..., 0], stance[..., 1]
    q[..., Q4], q[..., Q3] = swing[..., 0], swing[..., 1]
    q[..., Q5] = s[..., 2]
    q[..., XH], q[..., ZH] = hip[..., 0], hip[..., 1]
    return q


def chain_state(model: Biped, step_length: float, coordinates, rates=None, accelerations=None):
    """q, q̇, q̈ (..., 9) of the closed chain from s, ṡ, s̈ (..., 3) [m, rad; /s; /s²].

    q̇ solves A q̇ = 0 and q̈ solves A q̈ + H_c = 0 (both feet at rest) for the six bound
    coordinates, ṡ and s̈ given.
    """
    q = chain_posture(model, step_length, coordinates)
    zeros = np.zeros(q.shape[:-1] + (3,))
    rates = zeros if rates is None else np.asarray(rates, dtype=float)
    accelerations = zeros if accelerations is None else np.asarray(accelerations, dtype=float)
    rows = contact_rows(model, q)
    bound, free = rows[..., BOUND], rows[..., FREE]
    qd = np.zeros_like(q)
    qd[..., FREE] = rates
    qd[..., BOUND] = -np.linalg.solve(bound, (free @ rates[..., None]))[..., 0]
    bias = np.concatenate([model.contact_bias(q, qd, foot) for foot in FEET], axis=-1)
    qdd = np.zeros_like(q)
    qdd[..., FREE] = accelerations
    qdd[..., BOUND] = -np.linalg.solve(bound, free @ accelerations[..., None] + bias[..., None])[
        ..., 0
    ]
    return q, qd, qdd


def split_load(model: Biped, q, qd, qdd):
    """Motor torques Γ (..., 6) [N·m] and the ground wrenches on the stance and the swing
    foot (..., 3) each [N, N, N·m], the split of least squared torque (module docstring).

    q, q̇, q̈ must hold both feet (``chain_state``): the split solves eq. (19') exactly.
    """
    check_model(model)
    tau = model.generalized_forces(q, qd, qdd)
    rows = contact_rows(model, q)
    shape = tau.shape[:-1]
    b = np.broadcast_to(JOINT_MATRIX.T, shape + (NQ, 6))
    rows_t = np.swapaxes(rows, -1, -2)  # Aᵀ (..., 9, 6)
    # Unknowns (Γ, F, λ): Γ − Bᵀλ = 0, −Aλ = 0, BΓ + AᵀF = τ.
    kkt = np.zeros(shape + (21, 21))
    kkt[..., :6, :6] = np.eye(6)
    kkt[..., :6, 12:] = -np.swapaxes(b, -1, -2)
    kkt[..., 6:12, 12:] = -rows
    kkt[..., 12:, :6] = b
    kkt[..., 12:, 6:12] = rows_t
    rhs = np.zeros(shape + (21,))
    rhs[..., 12:] = tau
    solution = np.linalg.solve(kkt, rhs[..., None])[..., 0]
    return solution[..., :6], solution[..., 6:9], solution[..., 9:12]


# The rows q1..q5 of B = JOINT_MATRIXᵀ: the five joints Γ1..Γ5 (a triangular, invertible
# 5 x 5 block) and the swing ankle's Γ6.
JOINTS5 = [Q1, Q2, Q3, Q4, Q5]
B5_SWING = JOINT_MATRIX.T[JOINTS5, 5]
B5_INVERSE = np.linalg.inv(JOINT_MATRIX.T[JOINTS5, :5])


def split_with_swing_wrench(model: Biped, q, qd, qdd, swing_wrench):
    """Motor torques Γ (..., 6) [N·m] and the stance foot's wrench (..., 3) [N, N, N·m] when
    the swing (front) foot's wrench is ``swing_wrench`` (..., 3): the redundancy's three
    numbers given, eq. (19') fixes the rest.

    The swing foot's angle row gives Γ6 = C_y,w − τ_qp2, the hip rows F_s = τ_H − F_w (x, z),
    the rows q1..q5 the five other torques (a constant invertible 5 x 5 block of B), the
    stance foot's angle row C_y,s = τ_qp1 + Γ1. The optimizer chooses the swing foot's wrench
    (``biped.optimization.two_phase``); ``split_load`` is this split at the least squared
    torque.
    """
    check_model(model)
    tau = model.generalized_forces(q, qd, qdd)
    rows = contact_rows(model, q)
    front = np.asarray(swing_wrench, dtype=float)
    g6 = front[..., 2] - tau[..., QP2]
    rear_xz = tau[..., [XH, ZH]] - front[..., :2]
    contact = np.einsum("...ij,...i->...j", rows[..., 0:2, JOINTS5], rear_xz) + np.einsum(
        "...ij,...i->...j", rows[..., 3:5, JOINTS5], front[..., :2]
    )
    rest = tau[..., JOINTS5] - contact - B5_SWING * g6[..., None]
    torques = np.concatenate([rest @ B5_INVERSE.T, g6[..., None]], axis=-1)
    stance = np.concatenate([rear_xz, (tau[..., QP1] + torques[..., 0])[..., None]], axis=-1)
    return torques, stance


def zmp(wrench, ankle_height: float):
    """x of a flat foot's zero-moment point from its ankle [m]: (Cy − h_p Fx) / Fz."""
    return (wrench[..., 2] - ankle_height * wrench[..., 0]) / wrench[..., 1]


def foot_margins(robot: Robot, wrench, friction: float = FOOT_FRICTION, loaded=None) -> np.ndarray:
    """Ψ (..., 5) of one foot, ``FOOT_CONSTRAINTS`` [N, N, N, m, m]: Fz, μ Fz − Fx,
    μ Fz + Fx, x_ZMP + l_p, L_p − l_p − x_ZMP; all >= 0 for a foot that holds. ``loaded``
    (a mask of the wrenches, default all): where it is False the foot hands its load over,
    its Ψ +inf (not judged)."""
    wrench = np.asarray(wrench, dtype=float)
    if loaded is not None:
        loaded = np.asarray(loaded, dtype=bool)
        wrench = np.where(loaded[..., None], wrench, [0.0, 1.0, 0.0])  # a load for the ZMP
    fx, fz = wrench[..., 0], wrench[..., 1]
    x = zmp(wrench, robot.ankle_height)
    margins = np.stack(
        [
            fz,
            friction * fz - fx,
            friction * fz + fx,
            x + robot.foot_heel,
            robot.foot_length - robot.foot_heel - x,
        ],
        axis=-1,
    )
    return margins if loaded is None else np.where(loaded[..., None], margins, np.inf)


def held_feet_residual(model: Biped, step_length: float, q, qd=None) -> float:
    """Largest distance [m] of the four sole corners from their places in double support
    (rear sole from x = −l_p, front sole from x = S − l_p, both on z = 0) and, with q̇, the
    largest foot speed (A q̇) [m/s, rad/s]: 0 on the closed chain."""
    r = model.robot
    names = ("stance_heel", "stance_toe", "swing_heel", "swing_toe")
    edges = np.array([-r.foot_heel, r.foot_length - r.foot_heel])
    places = np.array([[x, 0.0] for x in np.concatenate([edges, edges + step_length])])
    worst = float(np.max(np.abs(model.points(q, names) - places)))
    if qd is not None:
        speed = (contact_rows(model, q) @ np.asarray(qd, dtype=float)[..., None])[..., 0]
        worst = max(worst, float(np.max(np.abs(speed))))
    return worst


@dataclass(frozen=True)
class DoubleSupportPhase:
    """The double support phase: its duration and the cubic of each free coordinate.

    Attributes:
        step_length: S [m], the front ankle's x (the rear ankle at x = 0).
        duration: T_ds [s].
        coefficients: (3, 4) [m, m/s, m/s², m/s³ for x_H, z_H; rad... for q5]: the cubic
            c0 + c1 t + c2 t² + c3 t³ of each of ``CHAIN_COORDINATES``, t in [0, T_ds] [s].
        start: q, q̇ (9,) at the landing, both feet at rest (after the impact, if any).
        end: q, q̇ (9,) at the stance foot's lift-off, still in this phase's labels.
    """

    step_length: float
    duration: float
    coefficients: np.ndarray
    start: tuple
    end: tuple


def build_phase(model: Biped, step_length: float, duration: float, start, end):
    """The phase from ``start`` to ``end`` (each q, q̇ (9,) on the closed chain), in
    ``duration`` [s]: position and velocity continuous at both ends by construction.

    Raises:
        BipedError: a non-positive duration, or an end state off the closed chain (a foot
            away from its place or moving, by more than ``END_TOLERANCE``).
    """
    check_model(model)
    if not duration > 0.0:
        raise BipedError(f"double support duration = {float(duration):g} s: allowed > 0")
    for name, (q, qd) in (("start", start), ("end", end)):
        off = held_feet_residual(model, step_length, q, qd)
        if not off <= END_TOLERANCE:
            raise BipedError(
                f"double support {name} state is off the closed chain by {off:.3g} (feet away "
                f"from their places or moving): allowed {END_TOLERANCE:g}"
            )
    coefficients = np.array(
        hermite(
            duration,
            np.asarray(start[0])[FREE],
            np.asarray(start[1])[FREE],
            np.asarray(end[0])[FREE],
            np.asarray(end[1])[FREE],
        )
    ).T
    return DoubleSupportPhase(
        step_length=float(step_length),
        duration=float(duration),
        coefficients=coefficients,
        start=tuple(np.asarray(x, dtype=float) for x in start),
        end=tuple(np.asarray(x, dtype=float) for x in end),
    )


def phase_coordinates(phase: DoubleSupportPhase, t):
    """s, ṡ, s̈ (..., 3) at times t [s] from the landing (0 <= t <= T_ds)."""
    t = np.asarray(t, dtype=float)[..., None]
    c = phase.coefficients
    value = c[:, 0] + t * (c[:, 1] + t * (c[:, 2] + t * c[:, 3]))
    rate = c[:, 1] + t * (2 * c[:, 2] + 3 * t * c[:, 3])
    accel = 2 * c[:, 2] + 6 * t * c[:, 3]
    return value, rate, accel


@dataclass(frozen=True)
class DoubleSupportSamples:
    """The phase sampled: motion, torques and both feet's ground wrenches.

    Attributes:
        time: (N,) [s] from the landing.
        q, qd, qdd: (N, 9) [rad, m; /s; /s²].
        torques: (N, 6) [N·m], Γ of eq. (32): the split of least squared torque
            (``sample_phase``) or the one of a given front wrench (``sample_split``).
        stance_wrench, swing_wrench: (N, 3) [N, N, N·m] of the ground on the rear and the
            front foot, moment about each foot's ankle.
    """

    time: np.ndarray
    q: np.ndarray
    qd: np.ndarray
    qdd: np.ndarray
    torques: np.ndarray
    stance_wrench: np.ndarray
    swing_wrench: np.ndarray

    def margins(
        self, robot: Robot, friction: float = FOOT_FRICTION, zero_speed: bool | None = None
    ) -> np.ndarray:
        """Ψ (N, 2, 5) of both feet (stance, swing), ``FOOT_CONSTRAINTS``; with
        ``zero_speed`` True (a zero-speed landing) the feet's handover points
        (``handover_rows``) +inf: not judged, the foot carries nothing there."""
        handed = handover_rows(len(self.time), bool(zero_speed))
        feet = []
        for foot, wrench in zip(FEET, (self.stance_wrench, self.swing_wrench), strict=True):
            loaded = np.ones(len(self.time), dtype=bool)
            loaded[handed[foot]] = False
            feet.append(foot_margins(robot, wrench, friction, loaded=loaded))
        return np.stack(feet, axis=-2)

    def handover(self, zero_speed: bool) -> dict:
        """``HANDOVERS`` -> the wrench (3,) [N, N, N·m] of the rear foot at lift-off and of
        the front foot at the landing (judged after a zero-speed landing only:
        ``handover_loads``)."""
        return {
            "rear_at_lift_off": self.stance_wrench[-1].copy(),
            "front_at_landing": self.swing_wrench[0].copy(),
        }


def handover_rows(count: int, zero_speed: bool) -> dict:
    """Each foot's (``FEET``) rows of a phase sampled ``count`` times where it hands its load
    over (``HANDOVERS``): with a zero-speed landing the stance (rear) foot's last and the
    swing (front) foot's first; none after an impact (its loads jump, as its velocities)."""
    if not zero_speed:
        return {"stance": [], "swing": []}
    return {"stance": [count - 1], "swing": [0]}


def handover_loads(handover: dict, zero_speed: bool) -> dict:
    """``HANDOVERS`` judged (those of a zero-speed landing; none after an impact) -> the
    largest component of the foot's wrench there [N or N·m]: at most ``HANDOVER_TOLERANCE``
    when met."""
    judged = HANDOVERS if zero_speed else ()
    return {name: float(np.max(np.abs(handover[name]))) for name in judged}


def sample_phase(model: Biped, phase: DoubleSupportPhase, samples: int) -> DoubleSupportSamples:
    """The phase at ``samples`` + 1 equally spaced times from the landing to lift-off."""
    time = np.linspace(0.0, phase.duration, samples + 1)
    q, qd, qdd = chain_state(model, phase.step_length, *phase_coordinates(phase, time))
    torques, stance, swing = split_load(model, q, qd, qdd)
    return DoubleSupportSamples(time, q, qd, qdd, torques, stance, swing)


def front_wrench_at(front, duration: float, t) -> np.ndarray:
    """The front foot's wrench (M, 3) [N, N, N·m] at times t [s] from the landing: linear in
    time between the solver's samples ``front`` (n + 1, 3), equally spaced over
    ``duration`` [s]."""
    front = np.asarray(front, dtype=float)
    grid = np.linspace(0.0, duration, len(front))
    return np.column_stack([np.interp(t, grid, front[:, k]) for k in range(3)])


def sample_split(
    model: Biped, phase: DoubleSupportPhase, front, per_interval: int = FINE_PER_INTERVAL
) -> DoubleSupportSamples:
    """The phase on the fine grid, ``per_interval`` samples per interval of the solver's
    ``front`` (n + 1, 3) [N, N, N·m]: the front foot's wrench linear in time between those,
    the torques and the rear foot's wrench from eq. (19') (``split_with_swing_wrench``).
    Both feet's ``margins`` on it are what a gait's double support must hold everywhere."""
    front = np.asarray(front, dtype=float)
    time = np.linspace(0.0, phase.duration, (len(front) - 1) * per_interval + 1)
    q, qd, qdd = chain_state(model, phase.step_length, *phase_coordinates(phase, time))
    swing = front_wrench_at(front, phase.duration, time)
    torques, stance = split_with_swing_wrench(model, q, qd, qdd, swing)
    return DoubleSupportSamples(time, q, qd, qdd, torques, stance, swing)
