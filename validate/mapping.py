"""Names and coordinate maps between the paper's model and the MuJoCo models.

The paper's coordinates q = [qp1, qp2, q1, q2, q3, q4, q5, xH, zH] name the legs by role
(stance, swing); the MJCF names them by side (left, right). With the ``stance`` side given,
MuJoCo's qpos is a constant linear map of q (all angles relative, parent to child):

    rootx = xH, rootz = zH, rooty = q5
    <stance>_hip = q2 - q5, <stance>_knee = q1 - q2, <stance>_ankle = qp1 - q1
    <swing>_hip  = q3 - q5, <swing>_knee  = q4 - q3, <swing>_ankle  = qp2 - q4

and for the rolling knee the flexion q_shank - q_thigh splits into knee_upper = r1/l and
knee_lower = r2/l of it. Velocities and accelerations map the same way.
"""

from __future__ import annotations

from dataclasses import dataclass

import mujoco
import numpy as np

from biped.model.kinematics import NQ, Q1, Q2, Q3, Q4, Q5, QP1, QP2, XH, ZH
from validate.mjcf import SIDES
from validate.model import JOINT_ORDER

# Paper torque order Γ1..Γ6 as (role, joint).
TORQUES = (
    ("stance", "ankle"),
    ("stance", "knee"),
    ("stance", "hip"),
    ("swing", "hip"),
    ("swing", "knee"),
    ("swing", "ankle"),
)


def other(side: str) -> str:
    return SIDES[1 - SIDES.index(side)]


@dataclass(frozen=True)
class Mapping:
    """Linear maps between the paper's q and MuJoCo's qpos for one stance side."""

    qpos_from_q: np.ndarray  # (nq, 9)
    actuator_order: np.ndarray  # index of the actuator carrying Γ1..Γ6
    stance: str
    columns: np.ndarray = None  # index in ``validate.model.JOINT_ORDER`` of Γ1..Γ6's joint

    def qpos(self, q):
        return np.asarray(q) @ self.qpos_from_q.T


def mapping(model: mujoco.MjModel, stance: str, radii=(0.0, 0.0)) -> Mapping:
    """The map for ``stance`` in {'left', 'right'}; ``radii`` (r1, r2) of a rolling knee."""
    if stance not in SIDES:
        raise ValueError(f"stance = {stance!r}: allowed one of {SIDES}")
    swing = other(stance)
    matrix = np.zeros((model.nq, NQ))

    def row(joint: str):
        return matrix[model.joint(joint).qposadr[0]]

    row("rootx")[XH] = 1.0
    row("rootz")[ZH] = 1.0
    row("rooty")[Q5] = 1.0
    for side, thigh, shank, foot in ((stance, Q2, Q1, QP1), (swing, Q3, Q4, QP2)):
        r = row(f"{side}_hip")
        r[thigh], r[Q5] = 1.0, -1.0
        flexion = np.zeros(NQ)
        flexion[shank], flexion[thigh] = 1.0, -1.0
        r1, r2 = radii
        if r1 + r2 > 0.0:
            row(f"{side}_knee_upper")[:] = r1 / (r1 + r2) * flexion
            row(f"{side}_knee_lower")[:] = r2 / (r1 + r2) * flexion
        else:
            row(f"{side}_knee")[:] = flexion
        r = row(f"{side}_ankle")
        r[foot], r[shank] = 1.0, -1.0
    roles = {"stance": stance, "swing": swing}
    names = [f"{roles[role]}_{joint}" for role, joint in TORQUES]
    order = np.array([model.actuator(name).id for name in names])
    columns = np.array([JOINT_ORDER.index(name) for name in names])
    return Mapping(qpos_from_q=matrix, actuator_order=order, stance=stance, columns=columns)
