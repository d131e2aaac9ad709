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

Richer families (``knots`` = K interior knots, at t_n = k / (K + 1)): a C¹ cubic spline per
angle on K + 1 pieces, each piece the cubic Hermite polynomial of the values and rates at its
ends; the parameters replace the 12 accelerations by the six angles and their rates at each
interior knot (``parameter_names``): 21 + 12 (K − 1) parameters, with the same conditions at
both ends (flat feet, leg swap, impact map), for K from 1 to ``MAX_KNOTS``. A family holds
another when its knots include the other's (every odd K holds the paper's, t_n = 0.5; the
ladder K = 1, 3, 7, 15, ... (``ladder``) halves the pieces at each rung, each rung holding
the one below): a spline smooth on each of its pieces is the Hermite spline of its own
values and rates at the richer family's knots (``embedded``), the same motion, so a richer
family's optimum is never worse.

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
from biped.model.bezier import Bezier, bernstein, bezier_basis, control_points, raised
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
# Most interior knots of a gait family: 31 is the ladder's fifth rung (``ladder``), 381
# parameters.
MAX_KNOTS = 31
# Interior knots of the gait families: the paper's spline (1) and richer ones.
KNOTS = tuple(range(1, MAX_KNOTS + 1))


def check_knots(knots) -> int | Bezier:
    """``knots`` if it names a family (``KNOTS``, or a ``Bezier`` family), else a clear
    error."""
    if isinstance(knots, Bezier):
        return knots
    integer = isinstance(knots, (int, np.integer)) and not isinstance(knots, bool)
    if not integer or knots not in KNOTS:
        raise BipedError(
            f"knots = {knots!r}: allowed an integer from 1 to {MAX_KNOTS} interior knots (1: the "
            "paper's spline)"
        )
    return int(knots)


def ladder(rungs: int) -> tuple:
    """The nested families K = 2^(k+1) − 1 (1, 3, 7, 15, ...) of ``rungs`` rungs: each halves
    the pieces of the one below, so holds it (``check_embedding``)."""
    return tuple(2 ** (k + 1) - 1 for k in range(rungs))


@functools.cache
def parameter_names(knots: int = 1) -> tuple:
    """The parameters of the family of ``knots`` interior knots, in order: the paper's 21
    (``PARAMETERS``) for 1; for more, the accelerations replaced by each knot's angles [rad]
    and rates [rad/s]."""
    if check_knots(knots) == 1:
        return PARAMETERS
    if isinstance(knots, Bezier):
        interior = tuple(f"control{i}_{a}" for i in range(2, knots.degree - 1) for a in FREE_ANGLES)
        return PARAMETERS[:8] + interior + ("period",)
    at_knots = tuple(
        f"knot{k}_{kind}{a}"
        for k in range(1, knots + 1)
        for kind in ("", "rate_")
        for a in FREE_ANGLES
    )
    return PARAMETERS[:8] + at_knots + ("period",)


def family_label(knots) -> str:
    """How a ladder's rung names a family: "K = 3" (interior knots) or "n = 7" (a Bézier's
    degree)."""
    return check_knots(knots).label if isinstance(knots, Bezier) else f"K = {knots}"


def family_words(knots) -> str:
    """A family in a sentence: "the paper's spline (21 parameters)", "cubic splines of 3
    interior knots (45 parameters)", "Bézier curves of degree 11 (57 parameters)"."""
    size = f"({len(parameter_names(knots))} parameters)"
    if isinstance(check_knots(knots), Bezier):
        return f"Bézier curves of degree {knots.degree} {size}"
    return (
        "the paper's spline " + size
        if knots == 1
        else f"cubic splines of {knots} interior knots {size}"
    )


def family_json(knots):
    """A family as files write it: K, or {"bezier": degree}."""
    return check_knots(knots).to_dict() if isinstance(knots, Bezier) else knots


def pieces(knots: int = 1) -> int:
    """The pieces of a family: K + 1 for a spline of K interior knots, 1 for a Bézier."""
    return 1 if isinstance(check_knots(knots), Bezier) else knots + 1


def breakpoints(knots: int = 1) -> np.ndarray:
    """Normalised times [0, knots..., 1] of the pieces' ends ([0, 1] for a Bézier)."""
    return np.linspace(0.0, 1.0, pieces(knots) + 1)


# The leg swap (``biped.model.kinematics.LEG_SWAP``) of the free angles: the end posture is
# start[FREE_SWAP] (qp2 -> qp2, q1 <-> q4, q2 <-> q3, q5 -> q5), the swing foot flat at both
# ends; free angle i is q[i + 1].
FREE_SWAP = [0] + [LEG_SWAP[i] - 1 for i in range(Q1, Q5 + 1)]


@dataclass(frozen=True)
class Step:
    """One step built from the parameters: spline coefficients and boundary states.

    Attributes:
        pieces: (K + 1, 6, 4) coefficients of each piece's cubic per free angle, in the
            piece's normalised time (``piece_variable``): for the paper's spline the
            coefficients a, b of eqs. (25), (26).
        knots: interior knots K of the family.
        period: T [s].
        step_length: S [m].
        start: q, q̇ (9,) just after the impact at t = 0 (stance foot fixed).
        end: q, q̇⁻ (9,) just before the impact at t = T.
        impulse: I_R (3,) of the landing at t = T [N·s, N·s, N·m·s].
    """

    pieces: np.ndarray
    knots: int
    period: float
    step_length: float
    start: tuple
    end: tuple
    impulse: np.ndarray

    @property
    def a(self) -> np.ndarray:
        """(6, 4) coefficients of eq. (25) (the paper's spline)."""
        return self.pieces[0]

    @property
    def b(self) -> np.ndarray:
        """(6, 4) coefficients of eq. (26) (the paper's spline)."""
        return self.pieces[1]

    @property
    def coefficients(self) -> np.ndarray:
        """The pieces' coefficients stacked (4 (K + 1), 6): [a0..a3, b0..b3] for the paper's."""
        return np.concatenate(list(self.pieces), axis=1).T


def piece_variable(knots: int, piece: int) -> tuple[float, float]:
    """(origin, sign) of a piece's normalised time u = sign (t_n − origin): the paper's
    second piece runs backwards from t_n = 1 (eq. 26), every other forwards from its start."""
    if knots == 1 and piece == 1:
        return 1.0, -1.0
    return float(breakpoints(knots)[piece]), 1.0


class StepBuildError(BipedError):
    """The parameters give no posture (hip out of reach, non-positive period)."""

    def __init__(self, message: str, excess: float):
        super().__init__(message)
        self.excess = excess  # how far outside the allowed set, for a graded penalty


@dataclass(frozen=True)
class StepEnds:
    """The ends of one step fixed by the parameters every family shares (the hip, the trunk,
    the end rates and the period): the conditions of §3.2 (flat feet, leg swap, impact map).

    Attributes:
        period: T [s].
        step_length: S = V T [m].
        start_angles, start_rates: the six free angles [rad] and their rates [rad/s] just
            after the impact at t = 0.
        end_angles, end_rates: the same just before the impact at t = T.
        start: q, q̇ (9,) at t = 0; end: q, q̇⁻ (9,) at t = T.
        impulse: I_R (3,) of the landing at t = T [N·s, N·s, N·m·s].
    """

    period: float
    step_length: float
    start_angles: np.ndarray
    start_rates: np.ndarray
    end_angles: np.ndarray
    end_rates: np.ndarray
    start: tuple
    end: tuple
    impulse: np.ndarray

    @property
    def conditions(self) -> tuple:
        """(start angles, start rates, end angles, end rates), each (6,)."""
        return (self.start_angles, self.start_rates, self.end_angles, self.end_rates)


def step_ends(model: Biped, speed: float, p, size: int) -> StepEnds:
    """The ends of the step of the parameters ``p`` (``size`` of them: the hip, the trunk
    and the five end rates first, the period last) at walking speed ``speed``."""
    p = np.asarray(p, dtype=float)
    if p.shape != (size,):
        raise BipedError(f"gait parameters have shape {p.shape}: allowed ({size},)")
    if not np.all(np.isfinite(p)):
        raise StepBuildError("gait parameters are not all finite", excess=1.0)
    x_hip, z_hip, trunk = p[0:3]
    end_rates = np.concatenate([[0.0], p[3:8]])
    period = p[-1]
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
    return StepEnds(
        period=float(period),
        step_length=float(length),
        start_angles=start_angles,
        start_rates=qd_start[1:7],
        end_angles=end_angles,
        end_rates=end_rates,
        start=(q_start, qd_start),
        end=(q_end, qd_end),
        impulse=impulse,
    )


def build_step(model: Biped, speed: float, p, knots: int = 1) -> Step:
    """Spline coefficients of one step from the parameters (``parameter_names(knots)``; the
    paper's 21 for 1 knot) at walking speed ``speed``; a Bézier family's control points as
    its one piece's coefficients."""
    p = np.asarray(p, dtype=float)
    ends = step_ends(model, speed, p, len(parameter_names(knots)))
    period = ends.period
    if isinstance(knots, Bezier):
        interior = p[8:-1].reshape(knots.interior, 6)
        control = control_points(knots.degree, period, *ends.conditions, interior)
        found = np.array(control).T[None]  # one piece, its coefficients the control points
    elif knots == 1:
        found = paper_pieces(period, *ends.conditions, p[8:14], p[14:20])
    else:
        found = _hermite_pieces(period, *ends.conditions, p[8:-1].reshape(knots, 2, 6))
    return Step(
        pieces=found,
        knots=knots,
        period=period,
        step_length=ends.step_length,
        start=ends.start,
        end=ends.end,
        impulse=ends.impulse,
    )


def paper_pieces(period, start_angles, start_rates, end_angles, end_rates, acc0, acc1):
    """The coefficients a, b (2, 6, 4) of eqs. (25)-(26): the ends' angles, rates and
    accelerations, C⁰ and C¹ at t_n = 0.5."""
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
    return np.stack([a, b])


def hermite(h, y0, m0, y1, m1):
    """Coefficients [c0, c1, c2, c3] of the cubic c0 + c1 u + c2 u² + c3 u³ on [0, h] with
    value ``y0`` and slope ``m0`` at u = 0, ``y1`` and ``m1`` at u = h (arrays or CasADi
    expressions alike)."""
    rise = (y1 - y0) / h
    return [y0, m0, (3 * rise - 2 * m0 - m1) / h, (m0 + m1 - 2 * rise) / h**2]


def _hermite_pieces(period, start_angles, start_rates, end_angles, end_rates, at_knots):
    """The pieces (K + 1, 6, 4) of the Hermite spline through the ends' and the knots'
    angles and rates (``at_knots`` (K, 2, 6)), slopes in normalised time (T × rate)."""
    values = [start_angles, *at_knots[:, 0], end_angles]
    slopes = [period * start_rates, *(period * at_knots[:, 1]), period * end_rates]
    h = 1.0 / (len(values) - 1)
    return np.stack(
        [
            np.column_stack(hermite(h, values[j], slopes[j], values[j + 1], slopes[j + 1]))
            for j in range(len(values) - 1)
        ]
    )


def half_grid(samples_per_half: int):
    """Normalised times of the two spline pieces, each closed: (t_left, t_right)."""
    return piece_grid(samples_per_half, 1)


def piece_grid(samples_per_piece: int, knots: int = 1) -> tuple:
    """Normalised times of each piece of the family of ``knots`` interior knots, each closed
    (``samples_per_piece`` + 1 times)."""
    ends = breakpoints(knots)
    t = np.linspace(0.0, ends[1], samples_per_piece + 1)
    return tuple(t + origin for origin in ends[:-1])


def evaluate(step: Step, t_n, piece):
    """Angles, rates, accelerations (..., 6) of the free angles at normalised times t_n.

    Args:
        piece: the piece's index (0 to K), or for the paper's spline ``"left"`` for eq. (25)
            (t_n in [0, 0.5]) and ``"right"`` for eq. (26).
    Derivatives are with respect to physical time [rad/s, rad/s²].
    """
    if isinstance(step.knots, Bezier):
        return _evaluate_bezier(step, t_n, piece)
    t_n = np.asarray(t_n, dtype=float)[..., None]
    index = {"left": 0, "right": 1}.get(piece, piece) if step.knots == 1 else piece
    if isinstance(index, str) or not (isinstance(index, int) and 0 <= index <= step.knots):
        allowed = "'left', 'right'" if step.knots == 1 else f"0 to {step.knots}"
        raise BipedError(f"piece = {piece!r}: allowed {allowed}")
    c = step.pieces[index]
    origin, sign = piece_variable(step.knots, index)
    u = sign * (t_n - origin)
    period = step.period
    value = c[:, 0] + u * (c[:, 1] + u * (c[:, 2] + u * c[:, 3]))
    rate = sign * (c[:, 1] + u * (2 * c[:, 2] + 3 * u * c[:, 3])) / period
    accel = (2 * c[:, 2] + 6 * u * c[:, 3]) / period**2
    return value, rate, accel


def _evaluate_bezier(step: Step, t_n, piece):
    """``evaluate`` of a Bézier family's step (one piece, 0)."""
    if piece != 0 or isinstance(piece, bool):
        raise BipedError(f"piece = {piece!r}: allowed 0 (a Bézier curve is one piece)")
    t_n = np.asarray(t_n, dtype=float)
    values, rates, accels = (
        m @ step.coefficients for m in bernstein(step.knots.degree, t_n.ravel())
    )
    shape = t_n.shape + (6,)
    period = step.period
    rates, accels = rates / period, accels / period**2
    return values.reshape(shape), rates.reshape(shape), accels.reshape(shape)


@functools.cache
def spline_basis(samples_per_piece: int, knots: int = 1):
    """The normalised times of every piece of ``piece_grid`` ((K + 1) (n + 1),) and the
    matrices [-] mapping the stacked coefficients (``Step.coefficients``, 4 (K + 1) x 6) to
    the values and the first and second derivatives in normalised time there:
    (t_n, (values, rates, accels)).

    A piece's polynomial is in u = sign (t_n − origin) (``piece_variable``), so d/dt_n =
    sign d/du there (the paper's second piece: u = 1 − t_n). A Bézier family's: its one
    piece's Bernstein matrices (``biped.model.bezier.bezier_basis``) on its control points.
    """
    if isinstance(knots, Bezier):
        return bezier_basis(samples_per_piece, knots.degree)
    grids = piece_grid(samples_per_piece, knots)
    n, pieces = len(grids[0]), len(grids)
    bases = [np.zeros((pieces * n, 4 * pieces)) for _ in range(3)]
    for j, t in enumerate(grids):
        origin, sign = piece_variable(knots, j)
        u = (sign * (t - origin))[:, None]
        zero, one = np.zeros_like(u), np.ones_like(u)
        # u * u * u, not u**3: numpy's power has other kernels on other CPUs (AVX-512 or
        # not) that differ in the last bit, and these matrices are the solver's constants.
        square = u * u
        value = np.hstack([one, u, square, square * u])
        rate = np.hstack([zero, one, 2 * u, 3 * square])
        accel = np.hstack([zero, zero, 2 * one, 6 * u])
        for block, matrix, scale in zip(bases, (value, rate, accel), (1.0, sign, 1.0), strict=True):
            block[j * n : (j + 1) * n, 4 * j : 4 * j + 4] = scale * matrix
    for block in bases:
        block.setflags(write=False)
    return np.concatenate(grids), bases


def sample(model: Biped, step: Step, samples_per_half: int, points=()):
    """Motion and inverse dynamics on every piece; each knot appears twice (both sides).

    Returns:
        t [s] (N,), q, q̇, q̈ (N, 9), torques (N, 6), wrench (N, 3), positions of ``points``
        (N, P, 2), N = (K + 1) (n + 1).
    """
    t_n, (values, rates, accels) = spline_basis(samples_per_half, step.knots)
    coefficients = step.coefficients
    period = step.period
    return (t_n * period,) + model.single_support(
        values @ coefficients,
        (rates @ coefficients) / period,
        (accels @ coefficients) / period**2,
        points,
    )


def embedded(step: Step, knots: int) -> np.ndarray:
    """The knots' angles and rates (``knots``, 2, 6) of ``step``'s spline: the parameters
    beyond the ends' of the family of ``knots`` interior knots that holds it (its knots
    include ``step``'s: ``check_embedding``), the same motion; for a Bézier family holding
    ``step``'s curve, its interior control points (n − 3, 6) raised to that degree."""
    check_embedding(step.knots, knots)
    return at_knots(step, knots)


def at_knots(step: Step, knots: int) -> np.ndarray:
    """``step``'s angles and rates (``knots``, 2, 6) at the interior knots of the family of
    ``knots``: its embedding where that family holds it (``embedded``), otherwise the
    Hermite spline through them, an approximation of it (a first guess). For a Bézier
    family, the interior control points (n − 3, 6): ``step``'s raised where it is a Bézier
    curve of lower degree, else the least-squares fit of ``step``'s angles (``fitted``)."""
    check_knots(knots)
    if isinstance(knots, Bezier):
        return fitted(step, knots)
    times = breakpoints(knots)[1:-1]
    ends = breakpoints(step.knots)
    last = pieces(step.knots) - 1
    rows = []
    for t in times:
        piece = min(int(np.searchsorted(ends, t, side="right")) - 1, last)
        angles, rates, _ = evaluate(step, t, piece)
        rows.append([angles, rates])
    return np.array(rows)


# Samples per step of the least-squares fit of a gait by a Bézier curve (``fitted``).
FIT_SAMPLES = 400


def fitted(step: Step, family: Bezier) -> np.ndarray:
    """The interior control points (n − 3, 6) of the Bézier curve of ``family`` with
    ``step``'s ends (angles and rates) closest to ``step``'s angles in least squares over
    the step: ``step``'s own curve raised where ``step`` is of that family's degree or
    lower (the same motion)."""
    if isinstance(step.knots, Bezier) and step.knots.degree <= family.degree:
        return raised(step.coefficients, family.degree)[2:-2]
    t, angles = [], []
    ends = breakpoints(step.knots)
    for j in range(pieces(step.knots)):
        grid = np.linspace(ends[j], ends[j + 1], FIT_SAMPLES // pieces(step.knots) + 1)
        t.append(grid)
        angles.append(evaluate(step, grid, j)[0])
    t, angles = np.concatenate(t), np.concatenate(angles)
    basis = bernstein(family.degree, t)[0]
    start, start_rate, _ = evaluate(step, 0.0, 0)
    end, end_rate, _ = evaluate(step, 1.0, pieces(step.knots) - 1)
    fixed = control_points(family.degree, step.period, start, start_rate, end, end_rate, [])
    fixed_part = basis[:, [0, 1]] @ np.array(fixed[:2]) + basis[:, [-2, -1]] @ np.array(fixed[2:])
    interior, *_ = np.linalg.lstsq(basis[:, 2:-2], angles - fixed_part, rcond=None)
    return interior


def check_embedding(knots: int, richer: int) -> None:
    """Raise unless the family of ``richer`` interior knots holds that of ``knots``: a
    spline's knots include the other's; a Bézier of a degree no lower (a Bézier curve has
    no knot: it holds no spline but a single cubic, and is held by no spline family but as
    a single cubic)."""
    if isinstance(knots, Bezier) or isinstance(richer, Bezier):
        holds = (
            isinstance(knots, Bezier)
            and isinstance(richer, Bezier)
            and knots.degree <= richer.degree
        ) or (knots == Bezier(3) and not isinstance(richer, Bezier))
        if not holds:
            raise BipedError(
                f"the {_family_name(richer)} does not hold the {_family_name(knots)}: "
                "allowed a Bézier of no lower degree"
            )
        return
    small, large = breakpoints(knots)[1:-1], breakpoints(richer)[1:-1]
    if not all(np.any(np.isclose(t, large, rtol=0.0, atol=1e-12)) for t in small):
        raise BipedError(
            f"knots = {richer}: its knots do not include those of {knots} knot(s), so its "
            "family does not hold the other's"
        )


def _family_name(knots) -> str:
    return str(knots) if isinstance(knots, Bezier) else f"spline of {knots} knot(s)"
