"""The double support's references closed on the feet where they landed.

A two-phase gait's double support is a closed chain: rear ankle at x = 0, front ankle at
x = S, both feet flat (``biped.model.double_support``). MuJoCo's front foot lands a few
millimetres off S (the walk's speed varies from step to step); the five servos' references
of the file then describe a chain that does not close, and the servos strain the legs
against each other (the rear foot sliding back, the feet's forces chattering:
docs/gaits.md). Once the foot has landed, the front leg's references are therefore
re-anchored on it, for the rest of the step:

    front ankle  a_w = (S_m, h_p),  S_m the landed foot's ankle from the rear ankle, once flat
    (q4, q3) = leg_angles(hip(τ) − a_w),  q_p2 = 0                (the inverse geometric model)

the hip (x_H, z_H), the trunk q5 and the rear leg (q1, q2) those of the file at each phase
τ, their rates the file's; the front leg's rates are the derivatives of its re-anchored
angles along τ. The feedforward torques (the file's, and its rotors') are kept: only the
servos' references and reference rates change, so the servos' torque, read from the logged
references (``Simulation.feedback``), is measured against the chain that closes.

When: once per step, at the end of the first reading period (``RESYNC``, 20 ms) after the
touchdown that reaches the file's landing τ = T, where the file's foot comes to rest. Not at
the touchdown itself: the foot touches at 0.9-1.0 T still moving forward, and references
re-anchored there brake it where it grazed the floor (the rolling knee's walk then slips
4-10 mm from its fifth step and falls at its eighth, measured).

S_m: the sole touches the floor first at one end, and a foot set down flat turns about that
end; the landed ankle is that end's x plus its offset along the flat sole (l_p from the
heel, L_p − l_p from the toe). A hip out of the re-anchored leg's reach (a foot landed
beyond the straight leg) is brought back to the reach along its direction: that leg is then
straight, and the chain closes to the distance said by ``Anchoring.reach_gap``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from biped.model.dynamics import Biped
from biped.model.kinematics import Q3, Q4, QP2, XH, ZH
from validate.scene.layout import Layout
from validate.scene.mapping import mapping, other
from validate.scene.mjcf import SIDES

__all__ = ["Anchoring", "ChainAnchor", "landed_step_length"]

# The front leg's paper coordinates that the re-anchoring recomputes: its foot, thigh, shank.
FRONT_LEG = [QP2, Q3, Q4]


def landed_step_length(layout: Layout, biped: Biped, sensors: np.ndarray, stance: str) -> float:
    """[m] S_m: the front (swing) foot's ankle, set down flat about the end of its sole that
    touched (the lower one), from the rear (stance) ankle, read from one row of sensors."""
    robot = biped.robot
    heel, toe = layout.heel(sensors, other(stance)), layout.toe(sensors, other(stance))
    if heel[2] <= toe[2]:
        front = heel[0] + robot.foot_heel
    else:
        front = toe[0] - (robot.foot_length - robot.foot_heel)
    return float(front - layout.ankle(sensors, stance)[0])


@dataclass(frozen=True)
class Anchoring:
    """The front leg re-anchored over the table's points from ``start`` on.

    Attributes:
        start: the table's first re-anchored point (its row).
        step_length: S_m [m], the front ankle from the rear one.
        q: (N - start, 9) the chain's coordinates at those points (paper's, rad and m).
        qd: (N - start, 9) their rates along the gait's time τ [rad/s, m/s].
        reach_gap: [m] the largest distance by which the hip was beyond the re-anchored
            leg's reach (0: the chain closes at every point).
    """

    start: int
    step_length: float
    q: np.ndarray
    qd: np.ndarray
    reach_gap: float


class ChainAnchor:
    """Re-anchors a two-phase gait's phase table (``PhaseTable.motion``: the file's q, q̇
    at its points) on the landed front foot."""

    def __init__(self, table, layout: Layout, biped: Biped):
        self.table, self.layout, self.biped = table, layout, biped
        self.mappings = {side: mapping(layout.model, side, biped.radii) for side in SIDES}

    def anchoring(self, start: int, step_length: float) -> Anchoring:
        """The chain of the table's points from ``start`` on, its front ankle at
        (``step_length``, h_p)."""
        q_file, qd_file = self.table.motion
        q, qd = q_file[start:].copy(), qd_file[start:].copy()
        ankle = np.array([step_length, self.biped.robot.ankle_height])
        hip_from_ankle = q[:, [XH, ZH]] - ankle
        distance = np.linalg.norm(hip_from_ankle, axis=1)
        reach = self.biped.leg_reach()[1]
        beyond = np.maximum(distance - reach, 0.0)
        hip_from_ankle *= (np.minimum(distance, reach) / distance)[:, None]
        angles = self.biped.leg_angles(hip_from_ankle)  # (shank, thigh)
        q[:, Q4], q[:, Q3], q[:, QP2] = angles[:, 0], angles[:, 1], 0.0
        tau = self.table.tau[start:]
        if len(tau) > 1:
            qd[:, FRONT_LEG] = np.gradient(q[:, FRONT_LEG], tau, axis=0)
        else:
            qd[:, FRONT_LEG] = 0.0
        return Anchoring(start, float(step_length), q, qd, float(beyond.max(initial=0.0)))

    def servo_commands(self, stance: str, anchoring: Anchoring) -> tuple[np.ndarray, np.ndarray]:
        """(N - start, 6) each: the servos' references [rad] and reference rates [rad/s]
        (MuJoCo's joint angles, ``JOINT_ORDER``) of ``anchoring``'s points, ``stance`` the
        rear leg."""
        mapped, layout = self.mappings[stance], self.layout
        references = layout.joint_angles(mapped.qpos(anchoring.q))
        return references, layout.joint_angles(mapped.qvel(anchoring.q, anchoring.qd))
