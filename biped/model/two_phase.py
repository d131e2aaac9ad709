"""One step of two phases: single support (the paper's spline, §3) then double support
(``biped.model.double_support``), closing on itself after the leg swap.

    lift-off ──single support (T)──► landing ──double support (T_ds)──► lift-off, legs swapped

The single support phase starts at the lift-off of the rear foot with both feet at rest (the
double support's end state, legs swapped, no impact) and ends when its swing foot lands flat at
x = S. The landing is either

- ``"impact"``: the flat-foot impact of eqs. (21)-(24) with both feet held after it
  (``biped.model.impact.both_feet_impact``), each foot's impulse pushing it and within the
  floor's friction cone (``landing_margins``, the caller's constraint); or
- ``"zero-speed"``: the swing foot arrives at rest, its velocity already that of the closed
  chain, so nothing jumps.

Parameters (``parameter_names(landing)``; physical units):

    x_hip, z_hip, trunk               posture at lift-off, the hip from the single support's
                                      stance ankle's ground point [m], the trunk [rad]
    lift_rate_x_hip, _z_hip, _trunk   their rates at lift-off [m/s, m/s, rad/s]
    landing_x_hip, _z_hip, _trunk     the posture at landing, the hip from the rear ankle's
                                      ground point [m], the trunk [rad]
    end_rate_q1..q5                   (impact) rates before the landing (q̇p2 = 0) [rad/s], or
    landing_rate_x_hip, _z_hip, _trunk (zero-speed) the closed chain's rates [m/s, rad/s]
    start_accel_*, end_accel_*        the single support's accelerations at both ends [rad/s²]
    period                            T, the single support's duration [s]
    double_support                    T_ds, the double support's duration [s]

The step length is S = V (T + T_ds): the hip advances S in one step of both phases.

What this family holds. The single support phase of this family starts with both feet at rest
and, with the impact landing, loses the energy of an impact that stops both feet; the paper's
step (``biped.model.gait``) starts with the rear foot lifting at the speed its one-foot impact
leaves. A double support of zero duration therefore is not the paper's step: this family does
not contain the single-support family, and the comparison of their optima is a measurement,
not a consequence of nesting.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass

import numpy as np

from biped.errors import BipedError
from biped.model.double_support import (
    DoubleSupportPhase,
    build_phase,
    chain_posture,
    chain_state,
    check_model,
)
from biped.model.dynamics import Biped
from biped.model.gait import Step, paper_pieces
from biped.model.impact import both_feet_impact
from biped.model.kinematics import swap_legs
from biped.model.robot import FOOT_FRICTION
from biped.model.walkable import impact_friction_margins

LANDINGS = ("impact", "zero-speed")
# The feet at the landing, in the order of ``TwoPhaseStep.impulse``, and each foot's landing
# constraints (``landing_margins``): the impulse into the floor, the friction cone's two sides.
FEET = ("rear", "front")
LANDING_CONSTRAINTS = ("normal_impulse", "impact_friction_forward", "impact_friction_backward")
_ANGLES = ("qp2", "q1", "q2", "q3", "q4", "q5")
_POSTURE = ("x_hip", "z_hip", "trunk")


def check_landing(landing: str) -> str:
    """``landing`` if it names a landing (``LANDINGS``), else a clear error."""
    if landing not in LANDINGS:
        raise BipedError(f"landing = {landing!r}: allowed {', '.join(map(repr, LANDINGS))}")
    return landing


@functools.cache
def parameter_names(landing: str = "impact") -> tuple:
    """The parameters of the two-phase step with ``landing``, in order (module docstring)."""
    if check_landing(landing) == "impact":
        before = tuple(f"end_rate_{a}" for a in _ANGLES[1:])
    else:
        before = tuple(f"landing_rate_{a}" for a in _POSTURE)
    return (
        _POSTURE
        + tuple(f"lift_rate_{a}" for a in _POSTURE)
        + tuple(f"landing_{a}" for a in _POSTURE)
        + before
        + tuple(f"start_accel_{a}" for a in _ANGLES)
        + tuple(f"end_accel_{a}" for a in _ANGLES)
        + ("period", "double_support")
    )


@dataclass(frozen=True)
class TwoPhaseStep:
    """One step of both phases built from the parameters.

    Attributes:
        single: the single support phase (``biped.model.gait.Step``, the paper's spline);
            its ``impulse`` is the landing foot's part of ``impulse``.
        double: the double support phase, in the single support's labels.
        speed: V [m/s].
        landing: ``"impact"`` or ``"zero-speed"``.
        impulse: (6,) [N·s, N·s, N·m·s] of the ground at the landing on the rear foot, then
            the landing foot (zero for a zero-speed landing).
    """

    single: Step
    double: DoubleSupportPhase
    speed: float
    landing: str
    impulse: np.ndarray

    @property
    def duration(self) -> float:
        """T + T_ds [s]."""
        return self.single.period + self.double.duration

    @property
    def step_length(self) -> float:
        """S [m]."""
        return self.single.step_length


def landing_margins(impulse, friction: float = FOOT_FRICTION, solver: bool = False) -> list:
    """Each foot's landing constraints (``FEET`` by ``LANDING_CONSTRAINTS``, >= 0 when met)
    [N·s] from the impulse (6,) of ``TwoPhaseStep.impulse``: I_z, μ I_z − I_x, μ I_z + I_x,
    the floor pushing the foot within its friction cone (μ = ``FOOT_FRICTION``, the MuJoCo
    floor's, as in double support). The cone is the single-support problem's impact
    friction (``biped.model.walkable.impact_friction_margins``); ``solver``: with its margin
    (``RELATIVE_MARGIN`` of μ). Sums and products only: numbers or CasADi's symbols. A
    zero-speed landing has no impulse, every margin 0 (met): nothing to constrain."""
    margins = []
    for at in (0, 3):
        foot = impulse[at : at + 3]
        margins.append([foot[1], *impact_friction_margins(foot, friction, solver)])
    return margins


def build_two_phase(model: Biped, speed: float, p, landing: str = "impact") -> TwoPhaseStep:
    """The two-phase step at walking speed ``speed`` [m/s] from the parameters ``p``.

    Raises:
        BipedError: parameters of the wrong shape, not finite or non-positive durations;
            UnreachableError: a posture out of the legs' reach.
    """
    check_model(model)
    names = parameter_names(landing)
    p = np.asarray(p, dtype=float)
    if p.shape != (len(names),):
        raise BipedError(f"two-phase parameters have shape {p.shape}: allowed ({len(names)},)")
    if not np.all(np.isfinite(p)):
        raise BipedError("two-phase parameters are not all finite")
    value = dict(zip(names, p, strict=True))
    period, dwell = value["period"], value["double_support"]
    for name, duration in (("period", period), ("double_support", dwell)):
        if not duration > 0.0:
            raise BipedError(f"{name} = {float(duration):g} s: allowed > 0")
    length = speed * (period + dwell)

    # Lift-off in the double support's labels: the hip S ahead of the rear ankle's x_hip.
    lift = np.array([value["x_hip"] + length, value["z_hip"], value["trunk"]])
    lift_rates = np.array([value[f"lift_rate_{a}"] for a in _POSTURE])
    q_lift, qd_lift, _ = chain_state(model, length, lift, lift_rates)
    q_start, qd_start = swap_legs(model, q_lift, qd_lift)

    touch = np.array([value[f"landing_{a}"] for a in _POSTURE])
    if landing == "impact":
        end_angles = chain_posture(model, length, touch)[1:7]
        end_rates = np.concatenate([[0.0], [value[f"end_rate_{a}"] for a in _ANGLES[1:]]])
        q_end, qd_end, _ = model.stance_state(end_angles, end_rates)
        qd_landed, impulse = both_feet_impact(model, q_end, qd_end)
    else:
        touch_rates = np.array([value[f"landing_rate_{a}"] for a in _POSTURE])
        q_end, qd_end, _ = chain_state(model, length, touch, touch_rates)
        end_angles, end_rates = q_end[1:7], qd_end[1:7]
        qd_landed, impulse = qd_end, np.zeros(6)

    accelerations = [
        np.array([value[f"{kind}_accel_{a}"] for a in _ANGLES]) for kind in ("start", "end")
    ]
    pieces = paper_pieces(
        period, q_start[1:7], qd_start[1:7], end_angles, end_rates, *accelerations
    )
    single = Step(
        pieces=pieces,
        knots=1,
        period=float(period),
        step_length=float(length),
        start=(q_start, qd_start),
        end=(q_end, qd_end),
        impulse=impulse[3:],
    )
    double = build_phase(model, length, dwell, (q_end, qd_landed), (q_lift, qd_lift))
    return TwoPhaseStep(single, double, float(speed), landing, impulse)
