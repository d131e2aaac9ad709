"""Gait parametrisation: one cubic spline per angle, §3 of the paper (eqs. 25-26).

The six free angles [qp2, q1, q2, q3, q4, q5] of one step (single support, stance foot flat at
x = 0) are functions of the normalised time t_n = t / T with one knot at t_n = 0.5:

    f(t_n)  = a0 + a1 t_n + a2 t_n² + a3 t_n³                 0   <= t_n <= 0.5   (25)
    f'(t_n) = b0 + b1 (1 - t_n) + b2 (1 - t_n)² + b3 (1 - t_n)³  0.5 <= t_n <= 1   (26)

Conditions of §3.2, all exact by construction:

- both feet flat on the ground at t = 0 and t = T (double support at the impacts), the
  swing foot at rest in rotation at the end (qp2(T) = 0, q̇p2(T) = 0);
- the end posture is the start posture with the legs swapped (thighs and shanks 2T-periodic,
  trunk and feet T-periodic): q2(T) = q3(0), q3(T) = q2(0), q1(T) = q4(0), q4(T) = q1(0);
- C¹ at t_n = 0.5;
- the start velocities are the impact map (eq. 23) of the end velocities, legs swapped.

Parameters (21, the paper's vector p; physical units):

    x_H(0), z_H(0)                hip at the start, from the stance ankle's ground point [m]
    q5(0)                         trunk angle at the start [rad]
    q̇1..q̇5 (T)                    end velocities (q̇p2(T) = 0 is imposed) [rad/s]
    q̈p2, q̈1..q̈5 (0)               start accelerations [rad/s²]
    q̈p2, q̈1..q̈5 (T)               end accelerations [rad/s²]
    T                             duration of the step [s]

Step length and speed ("d" of the paper): the walking speed V is given; the hip advances by
the step length S = V T in one step, which is the distance between the two ankles in double
support (swing ankle at x = -S at the start, +S at the end). The swing foot thus travels
d = 2 S in one step, the reading under which 2 / d in eq. (30) normalises per metre walked.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass

import numpy as np

from biped.errors import BipedError
from biped.model.dynamics import Biped
from biped.model.kinematics import LEG_SWAP, Q1, Q5, swap_legs

# Names of the 21 parameters, in order.
PARAMETERS = (
    ("x_hip", "z_hip", "trunk")
    + tuple(f"end_rate_{a}" for a in ("q1", "q2", "q3", "q4", "q5"))
    + tuple(f"start_accel_{a}" for a in ("qp2", "q1", "q2", "q3", "q4", "q5"))
    + tuple(f"end_accel_{a}" for a in ("qp2", "q1", "q2", "q3", "q4", "q5"))
    + ("period",)
)
N_PARAMETERS = len(PARAMETERS)  # 21
FREE_ANGLES = ("qp2", "q1", "q2", "q3", "q4", "q5")

# The leg swap (``biped.model.kinematics.LEG_SWAP``) of the free angles: the end posture is
# start[FREE_SWAP] (qp2 -> qp2, q1 <-> q4, q2 <-> q3, q5 -> q5), the swing foot flat at both
# ends; free angle i is q[i + 1].
FREE_SWAP = [0] + [LEG_SWAP[i] - 1 for i in range(Q1, Q5 + 1)]


@dataclass(frozen=True)
class Step:
    """One step built from the parameters: spline coefficients and boundary states.

    Attributes:
        a, b: (6, 4) coefficients of eqs. (25), (26) per free angle (normalised time).
        period: T [s].
        step_length: S [m].
        start: q, q̇ (9,) just after the impact at t = 0 (stance foot fixed).
        end: q, q̇⁻ (9,) just before the impact at t = T.
        impulse: I_R (3,) of the landing at t = T [N·s, N·s, N·m·s].
    """

    a: np.ndarray
    b: np.ndarray
    period: float
    step_length: float
    start: tuple
    end: tuple
    impulse: np.ndarray


class StepBuildError(BipedError):
    """The parameters give no posture (hip out of reach, non-positive period)."""

    def __init__(self, message: str, excess: float):
        super().__init__(message)
        self.excess = excess  # how far outside the allowed set, for a graded penalty


def build_step(model: Biped, speed: float, p) -> Step:
    """Spline coefficients of one step from the 21 parameters at walking speed ``speed``."""
    p = np.asarray(p, dtype=float)
    if p.shape != (N_PARAMETERS,):
        raise BipedError(f"gait parameters have shape {p.shape}: allowed ({N_PARAMETERS},)")
    if not np.all(np.isfinite(p)):
        raise StepBuildError("gait parameters are not all finite", excess=1.0)
    x_hip, z_hip, trunk = p[0:3]
    end_rates = np.concatenate([[0.0], p[3:8]])
    acc0, acc1 = p[8:14], p[14:20]
    period = p[20]
    if not period > 0.0:
        raise StepBuildError(f"period = {period!r} s: allowed > 0", excess=-period + 1.0)
    length = speed * period
    hp = model.robot.ankle_height
    hips = np.array([[x_hip, z_hip - hp], [x_hip + length, z_hip - hp]])
    low, high = model.leg_reach()
    distance = np.linalg.norm(hips, axis=-1)
    excess = float(np.maximum(distance - high, 0.0).sum() + np.maximum(low - distance, 0.0).sum())
    if excess > 0.0 or z_hip <= hp:
        raise StepBuildError("hip out of the legs' reach", excess=excess + max(hp - z_hip, 0.0))
    (q1, q2), (q4, q3) = model.leg_angles(hips)
    start_angles = np.array([0.0, q1, q2, q3, q4, trunk])
    end_angles = start_angles[FREE_SWAP]
    q_end, qd_end, _ = model.stance_state(end_angles, end_rates)
    qd_plus, impulse = model.impact(q_end, qd_end)
    q_start, qd_start = swap_legs(model, q_end, qd_plus)
    start_rates = qd_start[1:7]

    a = np.empty((6, 4))
    b = np.empty((6, 4))
    a[:, 0] = start_angles
    a[:, 1] = period * start_rates
    a[:, 2] = 0.5 * period**2 * acc0
    b[:, 0] = end_angles
    b[:, 1] = -period * end_rates
    b[:, 2] = 0.5 * period**2 * acc1
    # C⁰ and C¹ at t_n = 0.5 fix a3 and b3:
    #   a3/8 - b3/8 = R1,  3/4 (a3 + b3) = R2
    r1 = b[:, 0] + b[:, 1] / 2 + b[:, 2] / 4 - a[:, 0] - a[:, 1] / 2 - a[:, 2] / 4
    r2 = -(b[:, 1] + b[:, 2]) - a[:, 1] - a[:, 2]
    a[:, 3] = 4 * r1 + 2 * r2 / 3
    b[:, 3] = 2 * r2 / 3 - 4 * r1
    return Step(
        a=a,
        b=b,
        period=float(period),
        step_length=float(length),
        start=(q_start, qd_start),
        end=(q_end, qd_end),
        impulse=impulse,
    )


def half_grid(samples_per_half: int):
    """Normalised times of the two spline pieces, each closed: (t_left, t_right)."""
    t = np.linspace(0.0, 0.5, samples_per_half + 1)
    return t, t + 0.5


def evaluate(step: Step, t_n, piece: str):
    """Angles, rates, accelerations (..., 6) of the free angles at normalised times t_n.

    Args:
        piece: ``"left"`` for eq. (25) (t_n in [0, 0.5]), ``"right"`` for eq. (26).
    Derivatives are with respect to physical time [rad/s, rad/s²].
    """
    t_n = np.asarray(t_n, dtype=float)[..., None]
    period = step.period
    if piece == "left":
        c = step.a
        u, sign = t_n, 1.0
    elif piece == "right":
        c = step.b
        u, sign = 1.0 - t_n, -1.0
    else:
        raise BipedError(f"piece = {piece!r}: allowed 'left', 'right'")
    value = c[:, 0] + u * (c[:, 1] + u * (c[:, 2] + u * c[:, 3]))
    rate = sign * (c[:, 1] + u * (2 * c[:, 2] + 3 * u * c[:, 3])) / period
    accel = (2 * c[:, 2] + 6 * u * c[:, 3]) / period**2
    return value, rate, accel


@functools.cache
def spline_basis(samples_per_half: int):
    """The normalised times of both pieces of ``half_grid`` (2 (n + 1),) and the matrices [-]
    mapping the stacked coefficients [a0..a3, b0..b3] (8, 6) to the values and the first and
    second derivatives in normalised time there: (t_n, (values, rates, accels)).

    Piece (26) is a polynomial in u = 1 - t_n, so d/dt_n = -d/du there.
    """
    left, right = half_grid(samples_per_half)
    n = len(left)
    u = np.concatenate([left, 1.0 - right])[:, None]
    zero, one = np.zeros_like(u), np.ones_like(u)
    value = np.hstack([one, u, u**2, u**3])
    rate = np.hstack([zero, one, 2 * u, 3 * u**2])
    accel = np.hstack([zero, zero, 2 * one, 6 * u])
    bases = []
    for matrix, sign in ((value, 1.0), (rate, -1.0), (accel, 1.0)):
        block = np.zeros((2 * n, 8))
        block[:n, :4] = matrix[:n]
        block[n:, 4:] = sign * matrix[n:]
        block.setflags(write=False)
        bases.append(block)
    return np.concatenate([left, right]), bases


def sample(model: Biped, step: Step, samples_per_half: int, points=()):
    """Motion and inverse dynamics on both pieces; t = T/2 appears twice (both sides).

    Returns:
        t [s] (N,), q, q̇, q̈ (N, 9), torques (N, 6), wrench (N, 3), positions of ``points``
        (N, P, 2), N = 2 (n + 1).
    """
    t_n, (values, rates, accels) = spline_basis(samples_per_half)
    coefficients = np.concatenate([step.a, step.b], axis=1).T  # (8, 6)
    period = step.period
    return (t_n * period,) + model.single_support(
        values @ coefficients,
        (rates @ coefficients) / period,
        (accels @ coefficients) / period**2,
        points,
    )


def angles_at(step: Step, t_n):
    """Angles, rates, accelerations (..., 6) at normalised times t_n in [0, 1], the left
    piece up to t_n = 0.5 inclusive, the right piece after."""
    t_n = np.asarray(t_n, dtype=float)
    left = evaluate(step, np.minimum(t_n, 0.5), "left")
    right = evaluate(step, np.maximum(t_n, 0.5), "right")
    first = (t_n <= 0.5)[..., None]
    return tuple(np.where(first, a, b) for a, b in zip(left, right, strict=True))
