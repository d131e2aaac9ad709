"""The gait as a gait file stores it: its samples as functions of time.

What MuJoCo plays is the file, not the parameters it came from: the torques Γ(t), the motion
q(t) and the start state are read from ``samples`` (``biped.records.gait_file``), interpolated
on each spline piece separately (the accelerations and torques jump at the knots, t = T/2 for
the paper's spline, where the file holds both limits):

    q(t), q̇(t)     cubic Hermite through (q, q̇), resp. (q̇, q̈), at the samples: the file holds
                  the derivatives, so the interpolation is exact to O(h⁴) between samples
    q̈(t), Γ(t)     linear between samples

A time outside [0, T] is taken modulo T: the gait repeats every step.

A two-phase gait's samples (``biped.records.two_phase_gait``) cover both phases: the single
support from 0 to T, then the double support from T to T + T_ds (the landing's time T held
twice: q̇ before the landing, then after it), the period T + T_ds; ``swing_wrench`` holds the
front foot's ground wrench (zero in single support), ``wrench`` and ``zmp`` the rear
(stance) foot's. ``single_support`` and ``double_support`` give each phase alone.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from biped.errors import BipedError
from biped.model.bezier import Bezier
from biped.model.double_support import zmp
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
        swing_wrench: (N, 3) the ground wrench on the swing (front) foot [N, N, N·m], zero
            in single support; None: a gait of single support only.
        landing: the time of the landing that starts the double support [s] (T); None: a
            gait of single support only.
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
    swing_wrench: np.ndarray | None = None
    landing: float | None = None

    @property
    def two_phase(self) -> bool:
        return self.landing is not None

    @property
    def landing_time(self) -> float:
        """[s] the swing foot's landing: T, a two-phase gait's single support (its
        ``landing``), the ``period`` of a gait of single support."""
        return self.period if self.landing is None else self.landing

    @classmethod
    def from_gait(cls, gait: Gait) -> GaitSamples:
        """The samples of a gait (of both phases, a two-phase gait's)."""
        single = cls.single_support_of(gait)
        if not gait.two_phase:
            return single
        double = cls.double_support_of(gait)
        arrays = {
            key: np.concatenate([getattr(single, key), getattr(double, key)]) for key in FIELDS
        }
        arrays["swing_wrench"] = np.concatenate([np.zeros_like(single.wrench), double.swing_wrench])
        t = np.concatenate([single.t, single.period + double.t])
        period = single.period + double.period
        return cls(period, single.step_length, t, **arrays, landing=single.period)

    @classmethod
    def single_support_of(cls, gait: Gait) -> GaitSamples:
        """The samples of a gait's single support phase (the whole step of a gait of one)."""
        arrays = {key: np.asarray(getattr(gait.samples, key), float) for key in ("t", *FIELDS)}
        arrays["zmp"] = arrays["zmp"].reshape(-1, 1)
        one_piece = isinstance(gait.knots, Bezier)
        return cls(float(gait.period), float(gait.step_length), **arrays, one_piece=one_piece)

    @classmethod
    def double_support_of(cls, gait: Gait) -> GaitSamples:
        """The samples of a two-phase gait's double support alone, from its landing (t = 0,
        after the impact) to lift-off, one piece: both feet's wrenches, the rear foot's ZMP."""
        phase = gait.double_support.samples
        rear = np.asarray(phase.rear_wrench, float)
        return cls(
            float(gait.double_support.duration),
            float(gait.step_length),
            np.asarray(phase.t, float),
            *(np.asarray(getattr(phase, key), float) for key in ("q", "qd", "qdd", "torques")),
            wrench=rear,
            zmp=zmp(rear, gait.robot.ankle_height).reshape(-1, 1),
            one_piece=True,
            swing_wrench=np.asarray(phase.front_wrench, float),
        )

    def single_support(self) -> GaitSamples:
        """The samples of the single support phase alone (all of them, a single support's)."""
        if not self.two_phase:
            return self
        rows = self.t <= self.landing
        rows[np.flatnonzero(self.t == self.landing)[1:]] = False  # the landing's left limit
        arrays = {key: getattr(self, key)[rows] for key in ("t", *FIELDS)}
        return GaitSamples(self.landing, self.step_length, **arrays)

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

    def double_support(self) -> GaitSamples:
        """The samples of a two-phase gait's double support alone, from its landing (t = 0,
        after the impact) to lift-off, as ``double_support_of`` gives them."""
        if not self.two_phase:
            raise BipedError("a gait of single support has no double support phase")
        first = np.flatnonzero(self.t == self.landing)[-1]  # the landing's right limit
        arrays = {key: getattr(self, key)[first:] for key in (*FIELDS, "swing_wrench")}
        t = self.t[first:] - self.landing
        return GaitSamples(
            self.period - self.landing, self.step_length, t, **arrays, one_piece=True
        )

    def at(self, name: str, t) -> np.ndarray:
        """One field (``FIELDS``) at times ``t`` (M,): (M, width)."""
        t = np.atleast_1d(np.asarray(t, dtype=float))
        outside = (t < 0.0) | (t > self.period)
        t = np.where(outside, np.mod(t, self.period), t)
        values = getattr(self, name)
        if values is None:
            raise BipedError(f"samples.{name}: a gait of single support has none")
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
