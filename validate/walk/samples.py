"""The gait as a gait file stores it: its samples as functions of time.

What MuJoCo plays is the file, not the parameters it came from: the torques Γ(t), the motion
q(t) and the start state are read from ``samples`` (``biped.records.gait_file``), interpolated
on each spline piece separately (the accelerations and torques jump at the knots, t = T/2 for
the paper's spline, where the file holds both limits):

    q(t), q̇(t)     cubic Hermite through (q, q̇), resp. (q̇, q̈), at the samples: the file holds
                  the derivatives, so the interpolation is exact to O(h⁴) between samples
    q̈(t), Γ(t)     linear between samples

A time outside [0, T] is taken modulo T: the gait repeats every step.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from biped.errors import BipedError
from biped.model.bezier import Bezier
from biped.records.gait_file import Gait

FIELDS = ("q", "qd", "qdd", "torques", "wrench", "zmp")


@dataclass(frozen=True)
class GaitSamples:
    """A gait file's samples (``biped.records.gait_file``) over one step.

    Attributes:
        period: T [s].
        step_length: S [m], the hip's advance over the step.
        t: (N,) sample times from 0 to T, T/2 twice (left and right limits) [s].
        q, qd, qdd: (N, 9) coordinates, velocities, accelerations (paper's order).
        torques: (N, 6) Γ1..Γ6 [N·m].
        wrench: (N, 3) ground wrench on the stance foot [Fx, Fz, Cy] [N, N, N·m].
        zmp: (N, 1) x of the ZMP from the stance ankle [m].
        one_piece: the gait is one polynomial over the step (a Bézier family's), its times
            each once; a spline's hold each knot's time twice.
    """

    period: float
    step_length: float
    t: np.ndarray
    q: np.ndarray
    qd: np.ndarray
    qdd: np.ndarray
    torques: np.ndarray
    wrench: np.ndarray
    zmp: np.ndarray
    one_piece: bool = False

    @classmethod
    def from_gait(cls, gait: Gait) -> GaitSamples:
        """The samples of a gait."""
        arrays = {key: np.asarray(getattr(gait.samples, key), float) for key in ("t", *FIELDS)}
        arrays["zmp"] = arrays["zmp"].reshape(-1, 1)
        one_piece = isinstance(gait.knots, Bezier)
        return cls(float(gait.period), float(gait.step_length), **arrays, one_piece=one_piece)

    def pieces(self) -> list[tuple[slice, float, float]]:
        """(rows, start [s], end [s]) of each spline piece: the samples between two knots,
        where the file holds a time twice (the left and right limits at the knot; the
        paper's spline has one, at T/2)."""
        knots = np.flatnonzero(np.diff(self.t) == 0.0)
        if self.one_piece:
            if len(knots):
                raise BipedError("samples.t of one curve holds a time twice: allowed each once")
            return [(slice(0, len(self.t)), self.t[0], self.t[-1])]
        if len(knots) == 0:
            raise BipedError("samples.t has no knot: allowed each knot's time twice (T/2 once)")
        firsts = [0, *(k + 1 for k in knots)]
        lasts = [*(k + 1 for k in knots), len(self.t)]
        return [(slice(a, b), self.t[a], self.t[b - 1]) for a, b in zip(firsts, lasts, strict=True)]

    def at(self, name: str, t) -> np.ndarray:
        """One field (``FIELDS``) at times ``t`` (M,): (M, width)."""
        t = np.atleast_1d(np.asarray(t, dtype=float))
        outside = (t < 0.0) | (t > self.period)
        t = np.where(outside, np.mod(t, self.period), t)
        values = getattr(self, name)
        out = np.empty((len(t), values.shape[1]))
        pieces = self.pieces()
        ends = [begin for _, begin, _ in pieces[1:]] + [np.inf]
        for (rows, begin, _), end in zip(pieces, ends, strict=True):
            mask = (t >= begin) & (t < end)
            if not mask.any():
                continue
            times = self.t[rows]
            if name in ("q", "qd"):
                slope = self.qd if name == "q" else self.qdd
                out[mask] = _hermite(times, values[rows], slope[rows], t[mask])
            else:
                for column in range(values.shape[1]):
                    out[mask, column] = np.interp(t[mask], times, values[rows, column])
        return out

    def start(self) -> tuple[np.ndarray, np.ndarray]:
        """(q, q̇) at t = 0: the state just after the landing that starts the step."""
        return self.q[0].copy(), self.qd[0].copy()

    def end(self) -> tuple[np.ndarray, np.ndarray]:
        """(q, q̇⁻) at t = T: the state just before the landing that ends the step."""
        return self.q[-1].copy(), self.qd[-1].copy()


def _hermite(times, values, slopes, t) -> np.ndarray:
    """Cubic Hermite interpolation (M, width) through values and slopes at ``times``."""
    k = np.clip(np.searchsorted(times, t, side="right") - 1, 0, len(times) - 2)
    h = (times[k + 1] - times[k])[:, None]
    s = ((t - times[k])[:, None]) / h
    h00 = (1 + 2 * s) * (1 - s) ** 2
    h10 = s * (1 - s) ** 2
    h01 = s**2 * (3 - 2 * s)
    h11 = s**2 * (s - 1)
    return h00 * values[k] + h10 * h * slopes[k] + h01 * values[k + 1] + h11 * h * slopes[k + 1]
