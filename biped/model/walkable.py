"""Constraints of ours for gaits a robot walks as computed, beyond the paper's Ψ1-Ψ7: each asked
by a field of ``biped.model.criteria.Safety`` (none by default: the paper's problem), each a
margin >= 0 when met, written once for numbers and for CasADi's symbols (only sums and
products of their arguments), so that the numeric check and the solver's graph
(``biped.optimization.symbolic``) compute one formula.

- landing (``Safety.landing_speed`` L, or ``landing_share`` s with L = s V): the swing
  sole's speed at touchdown at most L. At touchdown the landing foot is flat and does not
  turn (its angle's rate is 0 by the gait's construction), so every point of the sole moves
  as the ankle. The speed is bounded through a regular octagon inscribed in the disc |v| <=
  L: |v · n_k| <= L cos(π/8) for the four directions n_k = (cos kπ/4, sin kπ/4) (linear in v,
  well posed at L = 0, an impactless landing, where the paper's impact map is then a no-op);
- impact friction (``Safety.friction`` μ): the landing's impulse within the friction cone,
  |I_x| <= μ I_z;
- friction: the stance foot's |F_x| <= μ F_z at every sample;
- joint stops (``Safety.joint_margin`` m): every hip and ankle at least m inside its stop
  (``biped.model.robot.JOINT_STOPS``; a knee's extension stop is the paper's Ψ4, Ψ5, its
  flexion stop far beyond any gait);
- progress (``Safety.hip_progress`` p): the hip moves forward at p V at least at every sample.

The margins are in each constraint's own unit (m/s, N·s, N, rad, m/s); ``SCALES`` divides
them for the solver.
"""

from __future__ import annotations

import math

import numpy as np

from biped.model.kinematics import XH
from biped.model.robot import JOINT_STOPS

# The joints whose stops are constrained (rows of eq. 32's θ, ``biped.model.dynamics.JOINTS``)
# and each one's kind in ``JOINT_STOPS``.
STOPPED = {0: "ankle", 2: "hip", 3: "hip", 5: "ankle"}
# The octagon's half-widths over its inscribed circle's radius: cos(π/8).
OCTAGON = math.cos(math.pi / 8)
# Directions n_k of the octagon's sides (4, 2).
DIRECTIONS = np.array([[math.cos(k * math.pi / 4), math.sin(k * math.pi / 4)] for k in range(4)])
# Each constraint's scale in the solver (its unit): a margin of order one.
SCALES = {
    "landing": 1.0,  # [m/s]
    "impact_friction": 10.0,  # [N·s]
    "friction": 1000.0,  # [N]
    "joint_stops": 1.0,  # [rad]
    "progress": 0.1,  # [m/s]
}
# The margins the solver keeps inside each constraint (``biped.model.criteria.MARGINS``' role):
# on its samples, so that the check grid's samples between them stay inside too.
RELATIVE_MARGIN = 0.01  # landing speed, friction coefficient: a share of the bound
JOINT_MARGIN = 5e-3  # [rad]: a fast gait's joint (1 m/s) goes 1.2 mrad beyond its samples
PROGRESS_MARGIN = 1e-3  # [m/s]
# The check's tolerance on a landing at speed 0: a sole touching down at 1 μm/s is at rest.
LANDING_TOLERANCE = 1e-6  # [m/s]


def landing_margins(velocity, limit: float, solver: bool = False) -> list:
    """The octagon's 8 margins [m/s] of the sole's velocity (vx, vz) at touchdown under the
    speed ``limit`` L: L cos(π/8) ∓ v · n_k. The solver keeps ``RELATIVE_MARGIN`` of L inside;
    the check allows ``LANDING_TOLERANCE``."""
    bound = limit * (1.0 - RELATIVE_MARGIN) if solver else limit + LANDING_TOLERANCE
    bound *= OCTAGON
    margins = []
    for nx, nz in DIRECTIONS:
        along = velocity[0] * nx + velocity[1] * nz
        margins += [bound - along, bound + along]
    return margins


def impact_friction_margins(impulse, mu: float, solver: bool = False) -> list:
    """μ I_z ∓ I_x [N·s] of the landing's impulse (I_x, I_z, C_y)."""
    mu = mu * (1.0 - RELATIVE_MARGIN) if solver else mu
    return [mu * impulse[1] - impulse[0], mu * impulse[1] + impulse[0]]


def friction_margins(fx, fz, mu: float, solver: bool = False) -> list:
    """μ F_z ∓ F_x [N] of the stance foot's ground force, at each sample."""
    mu = mu * (1.0 - RELATIVE_MARGIN) if solver else mu
    return [mu * fz - fx, mu * fz + fx]


def joint_stop_margins(theta, margin: float, solver: bool = False) -> list:
    """Each constrained joint's distance [rad] to its two stops less ``margin``, from the
    angles θ (6, ...) of eq. (32) (minus the stops' convention: θ = −(child − parent)), in
    ``STOPPED`` order, the lower stop first."""
    margin = margin + JOINT_MARGIN if solver else margin
    margins = []
    for row, kind in STOPPED.items():
        low, high = JOINT_STOPS[kind]
        angle = -theta[row]  # child − parent
        margins += [angle - low - margin, high - margin - angle]
    return margins


def progress_margins(hip_rate, share: float, speed, solver: bool = False) -> list:
    """ẋ_H − p V [m/s] at each sample."""
    least = share * speed + (PROGRESS_MARGIN if solver else 0.0)
    return [hip_rate - least]


def landing_bound(safety, speed):
    """[m/s] The sole's largest landing speed ``safety`` asks at walking speed ``speed`` V (a
    number or a symbol): ``landing_speed``, or ``landing_share`` V."""
    if safety.landing_speed is not None:
        return safety.landing_speed
    return safety.landing_share * speed


def touchdown_velocity(model, q, qd) -> np.ndarray:
    """(vx, vz) [m/s] of the swing ankle at the end of the step (the state before the impact),
    the velocity of every point of the landing sole (it does not turn then)."""
    return model.point_jacobian(q, "swing_ankle") @ qd


def step_margins(model, step, q, qd, wrench, safety, solver: bool = False) -> dict:
    """The margins of the walkable constraints ``safety`` (a ``Safety``) asks, by name
    (``Safety.walkable``): the landing's (8,) and the impact's friction (2,) once a step, the
    others (N, k) at each sample of ``q``, ``qd`` (N, 9) and ``wrench`` (N, 3). ``solver``:
    with the margins the solver keeps inside them."""
    found = {}
    speed = step.step_length / step.period
    if "landing" in safety.walkable:
        velocity = touchdown_velocity(model, *step.end)
        bound = landing_bound(safety, speed)
        found["landing"] = np.array(landing_margins(velocity, bound, solver))
    if safety.friction is not None:
        found["impact_friction"] = np.array(
            impact_friction_margins(step.impulse, safety.friction, solver)
        )
        friction = friction_margins(wrench[:, 0], wrench[:, 1], safety.friction, solver)
        found["friction"] = np.stack(friction, axis=-1)
    if safety.joint_margin is not None:
        theta = model.joint_angles(q).T
        found["joint_stops"] = np.stack(
            joint_stop_margins(theta, safety.joint_margin, solver), axis=-1
        )
    if safety.hip_progress is not None:
        hip_rate = qd[:, XH]
        found["progress"] = np.stack(
            progress_margins(hip_rate, safety.hip_progress, speed, solver), axis=-1
        )
    return found
