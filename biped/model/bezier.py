"""The Bézier gait family, one the paper names for its future work (§6): each free angle
over the whole step a single Bézier curve of degree n in normalised time t_n = t / T,

    f(t_n) = Σ_i P_i B_i,n(t_n),    B_i,n(t) = C(n, i) t^i (1 − t)^(n − i),   i = 0..n,

its control points P_i (6 angles, n + 1 points each) built from the parameters.

The ends are those of the spline families (``biped.model.gait.step_ends``: flat feet, the
end posture the start's with the legs swapped, the start rates the impact map of the end
rates), met exactly by fixing the two control points at each end: a Bézier curve starts at
P_0 with slope n (P_1 − P_0) and ends at P_n with slope n (P_n − P_(n−1)), so

    P_0 = q(0),  P_1 = q(0) + T q̇(0⁺) / n,    P_(n−1) = q(T) − T q̇(T⁻) / n,  P_n = q(T).

Parameters (``biped.model.gait.parameter_names(Bezier(n))``): the hip, the trunk and the
five end rates as the paper's (8), the interior control points P_2..P_(n−2) of each angle
[rad] (6 (n − 3)), the period T [s]: 9 + 6 (n − 3), for n from ``MIN_DEGREE`` (a single
cubic, its ends alone) to ``MAX_DEGREE``. This module holds the curves' mathematics and the
family's name (``Bezier``); ``biped.model.gait`` builds, evaluates and samples its steps as it
does the splines' (a ``Step`` of one piece, its coefficients the control points).

What the family holds. A curve of degree n is a polynomial of degree n over the whole step,
with no knot: it does not hold the paper's spline (two cubics joined C¹ at t_n = 0.5, its
second derivative jumping there), nor any K-knot family's members beyond the single cubic
(n = 3 holds nothing else). It holds every curve of lower degree: a curve of degree n is
the curve of degree n + 1 of the elevated control points (``elevate``), the same motion,
its ends' points still those above (so ``raised`` gives a degree n's gait as parameters
of any higher degree), and the degrees 3, 4, 5, ... are a nested ladder whose optima can
only improve.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass

import numpy as np

from biped.errors import BipedError

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


@dataclass(frozen=True)
class Bezier:
    """The Bézier family of ``degree`` n: a gait family as ``biped.model.gait`` names them
    (beside a spline's number of interior knots)."""

    degree: int

    def __post_init__(self):
        object.__setattr__(self, "degree", check_degree(self.degree))

    def __str__(self) -> str:
        return f"Bézier of degree {self.degree}"

    @property
    def label(self) -> str:
        """How a ladder's rung names it: "n = 7" (a spline's: "K = 3")."""
        return f"n = {self.degree}"

    def to_dict(self) -> dict:
        """As files write it: {"bezier": degree} (a spline's family: its knots K)."""
        return {"bezier": self.degree}

    @property
    def interior(self) -> int:
        """The free control points of each angle, n − 3."""
        return self.degree - 3


def control_points(degree, period, start_angles, start_rates, end_angles, end_rates, interior):
    """The control points (n + 1, 6) of each free angle: the ends' two each from the angles
    [rad] and rates [rad/s] there, ``interior`` (n − 3, 6) between them (arrays or CasADi
    expressions alike, row by row)."""
    first = [start_angles, start_angles + period * start_rates / degree]
    last = [end_angles - period * end_rates / degree, end_angles]
    return first + list(interior) + last


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
        term = np.full_like(t, math.comb(degree, i), dtype=float)
        for _ in range(i):
            term = term * t
        for _ in range(degree - i):
            term = term * (1.0 - t)
        columns.append(term)
    return np.hstack(columns)


def _difference(degree: int) -> np.ndarray:
    """(n, n + 1): the forward differences P_(i+1) − P_i of n + 1 points."""
    return np.eye(degree, degree + 1, k=1) - np.eye(degree, degree + 1)


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


def elevate(control: np.ndarray) -> np.ndarray:
    """The control points (n + 2, 6) of the same curve at degree n + 1:
    P'_i = i / (n + 1) P_(i−1) + (1 − i / (n + 1)) P_i."""
    control = np.asarray(control, dtype=float)
    n = control.shape[0] - 1
    share = (np.arange(n + 2) / (n + 1))[:, None]
    padded = np.vstack([np.zeros((1, control.shape[1])), control])  # P_(i−1), i = 0..n+1
    upper = np.vstack([control, np.zeros((1, control.shape[1]))])  # P_i
    return share * padded + (1.0 - share) * upper


def raised(control: np.ndarray, degree: int) -> np.ndarray:
    """The control points (``degree`` + 1, 6) of the same curve as ``control`` (n + 1, 6) at
    ``degree`` >= n (``elevate`` repeated)."""
    degree = check_degree(degree)
    control = np.asarray(control, dtype=float)
    if degree < control.shape[0] - 1:
        raise BipedError(
            f"degree = {degree}: a curve of degree {control.shape[0] - 1} is held by degrees "
            f"{control.shape[0] - 1} to {MAX_DEGREE} only"
        )
    while control.shape[0] - 1 < degree:
        control = elevate(control)
    return control


__all__ = [
    "DEGREES",
    "MAX_DEGREE",
    "MIN_DEGREE",
    "Bezier",
    "bernstein",
    "bezier_basis",
    "check_degree",
    "control_points",
    "elevate",
    "raised",
]
