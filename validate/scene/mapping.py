"""Names and coordinate maps between the paper's model and the MuJoCo models.

The paper's coordinates q = [qp1, qp2, q1, q2, q3, q4, q5, xH, zH] name the legs by role
(stance, swing); the MJCF names them by side (left, right). With the ``stance`` side given,
MuJoCo's qpos is a constant linear map of q (all angles relative, parent to child):

    rootx = xH, rootz = zH, rooty = q5
    <stance>_hip = q2 - q5, <stance>_knee = q1 - q2, <stance>_ankle = qp1 - q1
    <swing>_hip  = q3 - q5, <swing>_knee  = q4 - q3, <swing>_ankle  = qp2 - q4

and for the rolling knee the flexion q_shank - q_thigh splits into knee_upper = r1/l and
knee_lower = r2/l of it. Velocities and accelerations map the same way.

A profiled knee (``validate.scene.profile_mjcf``) is not linear: its four joints are functions of
the flexion θ = q_thigh − q_shank (knee_upper = −ψ2, knee_lower = −ψ1, knee_slide = Σ − r1 − r2,
knee_arc = S2(ψ2), ``biped.model.profile``), read with the profile from the model's own
equalities; ``Mapping.qvel`` and ``qacc`` carry their first and second derivatives in θ.
Back from MuJoCo, upper + lower = −θ exactly, so ``Mapping.to_paper`` is linear for both.
"""

from __future__ import annotations

from dataclasses import dataclass

import mujoco
import numpy as np

from biped.model.kinematics import NQ, Q1, Q2, Q3, Q4, Q5, QP1, QP2, XH, ZH
from biped.model.profile import KneeProfile, rolling
from validate.scene.mjcf import SIDES
from validate.scene.model import JOINT_ORDER
from validate.scene.profile_mjcf import model_profile

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


# A profiled knee's joints, in the order of ``knee_joints``' rows.
PROFILE_JOINTS = ("upper", "lower", "slide", "arc")


@dataclass(frozen=True)
class Mapping:
    """Maps between the paper's q and MuJoCo's qpos for one stance side: linear (the matrix
    ``qpos_from_q``) but for a profiled knee's joints (``knees``)."""

    qpos_from_q: np.ndarray  # (nq, 9)
    actuator_order: np.ndarray  # index of the actuator carrying Γ1..Γ6
    stance: str
    columns: np.ndarray = None  # index in ``validate.scene.model.JOINT_ORDER`` of Γ1..Γ6's joint
    # (thigh, shank, qpos addresses of ``PROFILE_JOINTS``) of each profiled knee
    knees: tuple = ()
    profile: KneeProfile | None = None
    to_paper: np.ndarray = None  # (9, nq): q (or q̇) from qpos (or qvel)

    def qpos(self, q):
        """qpos (..., nq) of q (..., 9)."""
        qpos = np.asarray(q) @ self.qpos_from_q.T
        return self._knees(qpos, q, None, None) if self.knees else qpos

    def qvel(self, q, qd):
        """qvel (..., nv) of q̇ at q."""
        qvel = np.asarray(qd) @ self.qpos_from_q.T
        return self._knees(qvel, q, qd, None) if self.knees else qvel

    def qacc(self, q, qd, qdd):
        """qacc (..., nv) of q̈ at q, q̇."""
        qacc = np.asarray(qdd) @ self.qpos_from_q.T
        return self._knees(qacc, q, qd, qdd) if self.knees else qacc

    def _knees(self, out, q, qd, qdd):
        """``out`` with the profiled knees' joints: their values, or with q̇ their rates, or
        with q̈ too their accelerations."""
        out = np.array(out, dtype=float)
        q = np.asarray(q, dtype=float)
        for thigh, shank, addresses in self.knees:
            joints = knee_joints(self.profile, q[..., thigh] - q[..., shank])
            if qd is None:
                values = joints[0]
            else:
                rate = np.asarray(qd)[..., thigh] - np.asarray(qd)[..., shank]
                values = [first * rate for first in joints[1]]
                if qdd is not None:
                    accel = np.asarray(qdd)[..., thigh] - np.asarray(qdd)[..., shank]
                    values = [
                        first * accel + second * rate * rate
                        for first, second in zip(joints[1], joints[2], strict=True)
                    ]
            for address, value in zip(addresses, values, strict=True):
                out[..., address] = value
        return out


def knee_joints(profile: KneeProfile, theta):
    """The profiled knee's joints (``PROFILE_JOINTS``) at flexion θ and their first and
    second derivatives in θ: (values, d/dθ, d²/dθ²), each a list of four arrays."""
    r1, r2, k1, k2 = profile.vector
    roll = rolling(profile, theta)
    rho1, rho2 = r1 + k1 * roll.psi1, r2 + k2 * roll.psi2
    rate2 = 1.0 - roll.rate  # ψ2'
    values = [
        -roll.psi2,
        -roll.psi1,
        roll.total - r1 - r2,
        r2 * roll.psi2 + 0.5 * k2 * roll.psi2**2,
    ]
    first = [-rate2, -roll.rate, (k1 * rho2 + k2 * rho1) / roll.total, rho2 * rate2]
    second = [
        roll.curvature,
        -roll.curvature,
        (k1 - k2) * roll.curvature,
        k2 * rate2 * rate2 - rho2 * roll.curvature,
    ]
    return values, first, second


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
    profile = model_profile(model)
    knees, halves = [], []  # a profiled knee's joints, and its hinges' rows that invert it
    for side, thigh, shank, foot in ((stance, Q2, Q1, QP1), (swing, Q3, Q4, QP2)):
        r = row(f"{side}_hip")
        r[thigh], r[Q5] = 1.0, -1.0
        flexion = np.zeros(NQ)
        flexion[shank], flexion[thigh] = 1.0, -1.0
        r1, r2 = radii
        if profile is not None:  # nonlinear (``Mapping._knees``); upper + lower = flexion
            names = [f"{side}_knee_{part}" for part in PROFILE_JOINTS]
            knees.append((thigh, shank, tuple(model.joint(n).qposadr[0] for n in names)))
            for part in ("upper", "lower"):
                halves.append((model.joint(f"{side}_knee_{part}").qposadr[0], 0.5 * flexion))
        elif r1 + r2 > 0.0:
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
    inverted = matrix.copy()  # a profiled knee's hinges as halves of its flexion
    for address, half in halves:
        inverted[address] = half
    to_paper = np.linalg.pinv(inverted)
    return Mapping(
        qpos_from_q=matrix,
        actuator_order=order,
        stance=stance,
        columns=columns,
        knees=tuple(knees),
        profile=profile,
        to_paper=to_paper,
    )


def rotor_torques(mapped: Mapping, layout, q, qd, qdd) -> np.ndarray:
    """(..., 6) The torques the drives' rotors (MuJoCo's armature) take along q, q̇, q̈, per
    joint of ``JOINT_ORDER`` in MuJoCo's sign: Σ_j a_j s_j q̈_j over each joint's MuJoCo
    joints j (armature a_j, rate s_j per unit of the joint's angle), virtual work exactly.
    The circles' rates are constant: ``Layout.rotor_inertia`` times the joint angles'
    accelerations; a profiled knee's vary with its flexion (``knee_joints``)."""
    qacc = mapped.qacc(q, qd, qdd)
    torques = layout.rotor_inertia * layout.joint_angles(qacc)
    if not mapped.knees:
        return torques
    q = np.asarray(q, dtype=float)
    armature = layout.model.dof_armature
    sides = (mapped.stance, other(mapped.stance))
    for side, (thigh, shank, addresses) in zip(sides, mapped.knees, strict=True):
        _, rates, _ = knee_joints(mapped.profile, q[..., thigh] - q[..., shank])
        row = JOINT_ORDER.index(f"{side}_knee")
        # per unit of MuJoCo's knee angle, −θ: s_j = −dq_j/dθ
        torques[..., row] = sum(
            armature[address] * -rate * qacc[..., address]
            for address, rate in zip(addresses, rates, strict=True)
        )
    return torques
