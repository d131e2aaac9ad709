"""The Bézier gait family, one the paper names for its future work (§6): each free angle
over the whole step a single Bézier curve of degree n in normalised time t_n = t / T,

    f(t_n) = Σ_i P_i B_i,n(t_n),    B_i,n(t) = C(n, i) t^i (1 − t)^(n − i),   i = 0..n,

its control points P_i (6 angles, n + 1 points each) built from the parameters.

The ends are those of the spline families (``biped.model.gait.step_ends``: flat feet, the
end posture the start's with the legs swapped, the start rates the impact map of the end
rates), met exactly by fixing the two control points at each end: a Bézier curve starts at
P_0 with slope n (P_1 − P_0) and ends at P_n with slope n (P_n − P_(n−1)), so

    P_0 = q(0),  P_1 = q(0) + T q̇(0⁺) / n,    P_(n−1) = q(T) − T q̇(T⁻) / n,  P_n = q(T).

Parameters (``parameter_names``): the hip, the trunk and the five end rates as the paper's
(8), the interior control points P_2..P_(n−2) of each angle [rad] (6 (n − 3)), the period
T [s]: 9 + 6 (n − 3), for n from ``MIN_DEGREE`` (a single cubic, its ends alone) to
``MAX_DEGREE``.

What the family holds. A curve of degree n is a polynomial of degree n over the whole step,
with no knot: it does not hold the paper's spline (two cubics joined C¹ at t_n = 0.5, its
second derivative jumping there), nor any K-knot family's members beyond the single cubic
(n = 3 holds nothing else). It holds every curve of lower degree: a curve of degree n is
the curve of degree n + 1 of the elevated control points (``elevate``), the same motion,
its ends' points still those above (so ``embedded`` gives a degree n's gait as parameters
of any higher degree), and the degrees 3, 4, 5, ... are a nested ladder whose optima can
only improve.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass

import numpy as np
from scipy.special import comb

from biped.errors import BipedError
from biped.model.dynamics import Biped
from biped.model.gait import FREE_ANGLES, PARAMETERS, step_ends

# The least degree: the two end points and the two beside them fixed by the ends' angles
# and rates, no free control point (a single cubic).
MIN_DEGREE = 3
# The highest degree offered: 20 gives 111 parameters, as many as 15 knots' 189 in order.
MAX_DEGREE = 20
DEGREES = tuple(range(MIN_DEGREE, MAX_DEGREE + 1))


def check_degree(degree) -> int:
    """``degree`` if it names a family (``DEGREES``), else a clear error."""
    integer = isinstance(degree, (int, np.integer)) and not isinstance(degree, bool)
    if not integer or degree not in DEGREES:
        raise BipedError(
            f"degree = {degree!r}: allowed an integer from {MIN_DEGREE} to {MAX_DEGREE} "
            f"({MIN_DEGREE}: a single cubic)"
        )
    return int(degree)


@functools.cache
def parameter_names(degree: int) -> tuple:
    """The parameters of the family of ``degree``, in order: the paper's first 8 (hip, trunk,
    end rates), the interior control points ``control{i}_{angle}`` [rad], the period [s]."""
    interior = tuple(
        f"control{i}_{a}" for i in range(2, check_degree(degree) - 1) for a in FREE_ANGLES
    )
    return PARAMETERS[:8] + interior + ("period",)


def control_points(degree, period, start_angles, start_rates, end_angles, end_rates, interior):
    """The control points (n + 1, 6) of each free angle: the ends' two each from the angles
    [rad] and rates [rad/s] there, ``interior`` (n − 3, 6) between them (arrays or CasADi
    expressions alike, row by row)."""
    first = [start_angles, start_angles + period * start_rates / degree]
    last = [end_angles - period * end_rates / degree, end_angles]
    return first + list(interior) + last


@dataclass(frozen=True)
class BezierStep:
    """One step of the Bézier family built from the parameters.

    Attributes:
        control: (n + 1, 6) control points of each free angle [rad].
        degree: n.
        period: T [s].
        step_length: S [m].
        start: q, q̇ (9,) just after the impact at t = 0 (stance foot fixed).
        end: q, q̇⁻ (9,) just before the impact at t = T.
        impulse: I_R (3,) of the landing at t = T [N·s, N·s, N·m·s].
    """

    control: np.ndarray
    degree: int
    period: float
    step_length: float
    start: tuple
    end: tuple
    impulse: np.ndarray


def build_bezier_step(model: Biped, speed: float, p, degree: int) -> BezierStep:
    """The step of the parameters ``p`` (``parameter_names(degree)``) at walking speed
    ``speed``: its ends as the spline families' (``step_ends``), its control points
    (``control_points``)."""
    degree = check_degree(degree)
    p = np.asarray(p, dtype=float)
    ends = step_ends(model, speed, p, len(parameter_names(degree)))
    interior = p[8:-1].reshape(degree - 3, 6)
    control = np.array(control_points(degree, ends.period, *ends.conditions, interior))
    control.setflags(write=False)
    return BezierStep(
        control=control,
        degree=degree,
        period=ends.period,
        step_length=ends.step_length,
        start=ends.start,
        end=ends.end,
        impulse=ends.impulse,
    )


def bernstein(degree: int, t_n) -> tuple:
    """The matrices (N, n + 1) [-] mapping the control points to the values and the first
    and second derivatives in normalised time at the times ``t_n`` (N,): the derivative of a
    curve of degree n is n Σ (P_(i+1) − P_i) B_i,n−1, whence the differences below."""
    t = np.asarray(t_n, dtype=float)[:, None]
    values = _basis(degree, t)
    rates = degree * (_basis(degree - 1, t) @ _difference(degree))
    accels = degree * (degree - 1) * (_basis(degree - 2, t) @ _difference(degree - 1))
    accels = accels @ _difference(degree)
    return values, rates, accels


def _basis(degree: int, t: np.ndarray) -> np.ndarray:
    """B_i,n(t) (N, n + 1); t (N, 1). Products of powers by repeated multiplication, not
    numpy's power (whose kernels differ in the last bit between CPUs)."""
    columns = []
    for i in range(degree + 1):
        term = np.full_like(t, comb(degree, i, exact=True), dtype=float)
        for _ in range(i):
            term = term * t
        for _ in range(degree - i):
            term = term * (1.0 - t)
        columns.append(term)
    return np.hstack(columns)


def _difference(degree: int) -> np.ndarray:
    """(n, n + 1): the forward differences P_(i+1) − P_i of n + 1 points."""
    return np.eye(degree, degree + 1, k=1) - np.eye(degree, degree + 1)


def evaluate(step: BezierStep, t_n):
    """Angles, rates, accelerations (N, 6) of the free angles at normalised times t_n (N,),
    derivatives with respect to physical time [rad, rad/s, rad/s²]."""
    values, rates, accels = bernstein(step.degree, np.atleast_1d(t_n))
    period = step.period
    control = step.control
    return values @ control, (rates @ control) / period, (accels @ control) / period**2


@functools.cache
def bezier_basis(samples: int, degree: int):
    """The normalised times of ``samples`` + 1 samples over the step (one piece, closed) and
    the matrices (``bernstein``) there: (t_n, (values, rates, accels)), read-only."""
    t_n = np.linspace(0.0, 1.0, samples + 1)
    bases = bernstein(check_degree(degree), t_n)
    for block in bases:
        block.setflags(write=False)
    t_n.setflags(write=False)
    return t_n, bases


def sample(model: Biped, step: BezierStep, samples: int, points=()):
    """Motion and inverse dynamics at ``samples`` + 1 times over the step.

    Returns:
        t [s] (N,), q, q̇, q̈ (N, 9), torques (N, 6), wrench (N, 3), positions of ``points``
        (N, P, 2).
    """
    t_n, (values, rates, accels) = bezier_basis(samples, step.degree)
    period, control = step.period, step.control
    return (t_n * period,) + model.single_support(
        values @ control, (rates @ control) / period, (accels @ control) / period**2, points
    )


def elevate(control: np.ndarray) -> np.ndarray:
    """The control points (n + 2, 6) of the same curve at degree n + 1:
    P'_i = i / (n + 1) P_(i−1) + (1 − i / (n + 1)) P_i."""
    control = np.asarray(control, dtype=float)
    n = control.shape[0] - 1
    share = (np.arange(n + 2) / (n + 1))[:, None]
    padded = np.vstack([np.zeros((1, control.shape[1])), control])  # P_(i−1), i = 0..n+1
    upper = np.vstack([control, np.zeros((1, control.shape[1]))])  # P_i
    return share * padded + (1.0 - share) * upper


def embedded(step: BezierStep, degree: int) -> np.ndarray:
    """The interior control points (n' − 3, 6) of ``step``'s curve raised to ``degree`` n' >=
    its own (``elevate``): with ``step``'s other parameters, the parameters of the same
    motion in the family of ``degree``."""
    degree = check_degree(degree)
    if degree < step.degree:
        raise BipedError(
            f"degree = {degree}: a curve of degree {step.degree} is held by degrees "
            f"{step.degree} to {MAX_DEGREE} only"
        )
    control = step.control
    for _ in range(degree - step.degree):
        control = elevate(control)
    return control[2:-2]


def embedded_parameters(step: BezierStep, parameters, degree: int) -> np.ndarray:
    """``parameters`` of ``step`` (its family's) as parameters of the family of ``degree``:
    the same hip, trunk, end rates and period, the elevated interior points."""
    p = np.asarray(parameters, dtype=float)
    return np.concatenate([p[:8], embedded(step, degree).ravel(), p[-1:]])


__all__ = [
    "DEGREES",
    "MAX_DEGREE",
    "MIN_DEGREE",
    "BezierStep",
    "bernstein",
    "bezier_basis",
    "build_bezier_step",
    "check_degree",
    "control_points",
    "elevate",
    "embedded",
    "embedded_parameters",
    "evaluate",
    "parameter_names",
    "sample",
]
