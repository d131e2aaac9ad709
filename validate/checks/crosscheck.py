"""Cross-checks of the analytical model against MuJoCo's dynamics of the MJCF.

Inverse dynamics. For each sample (q, q̇, q̈) of a gait, MuJoCo's recursive Newton-Euler
(``mj_rne``, no constraint forces) gives the generalized forces τ = M q̈ + c of its model.
In single support they are produced by the six motors, the ground wrench on the stance foot
and, for the rolling knee, the forces holding the two knee equalities:

    τ = Bᵀ u + J_cᵀ λ + J_eqᵀ μ

with B the actuator moments, J_c the stance ankle's Jacobian (x, z rows; rotation about -y,
the paper's positive sense) and J_eq the equality rows. The system is square (9 x 9 for the
revolute knee, 11 x 11 for the rolling knee), so u, λ = [Fx, Fz, Cy] and μ follow uniquely
and are compared with the analytical Γ and F_e. Both are exact rigid-body models of the same
robot, so they agree to rounding.

Knee forces. The force the thigh exerts on the lower leg through a knee is the translational
part of MuJoCo's ``cfrc_int`` of the body below the knee (the rolling knee's link, whose
subtree is link, shank and foot; the revolute knee's shank), world frame, which
``mj_rnePostConstraint`` computes from the accelerations by the same recursion, with the
ground's force from the inverse dynamics applied to the stance foot. The motors' torques and
the knee equalities' forces act about the hinges: they do not enter its translational part.

The MJCF carries two things the analytical model does not: armature on the rolling-knee
hinges (it enters MuJoCo's joint-space mass matrix, though not ``mj_rne``'s body recursion)
and a near-massless knee link. The cross-check zeroes both in a copy of the model;
``knee_link_effect`` reports what the link's mass changes.
"""

from __future__ import annotations

import copy
from dataclasses import dataclass

import mujoco
import numpy as np

from biped.model.dynamics import Biped
from validate.scene.mapping import Mapping, mapping, other
from validate.scene.mjcf import SIDES, robot_xml
from validate.scene.model import JOINT_ORDER, ModelError
from validate.scene.profile_mjcf import model_profile


def load_model(biped: Biped, exact: bool = False) -> mujoco.MjModel:
    """Compile the MJCF of ``biped.robot``; ``exact`` zeroes armature and knee-link mass."""
    model = mujoco.MjModel.from_xml_string(robot_xml(biped.robot, biped.knee))
    if exact:
        model = rigid_copy(model)
    return model


def rigid_copy(model: mujoco.MjModel) -> mujoco.MjModel:
    """A copy without armature (a profiled knee's stretch's too) and with massless knee links:
    the analytical robot exactly."""
    exact = copy.deepcopy(model)
    exact.dof_armature[:] = 0.0
    exact.tendon_armature[:] = 0.0
    for side, part in ((s, p) for s in SIDES for p in ("link", "slider")):
        name = f"{side}_knee_{part}"  # a profiled knee's slider too (validate.scene.profile_mjcf)
        if mujoco.mj_name2id(exact, mujoco.mjtObj.mjOBJ_BODY, name) >= 0:
            body = exact.body(name).id
            exact.body_mass[body] = 0.0
            exact.body_inertia[body] = 0.0
    return exact


def actuator_moments(model: mujoco.MjModel) -> np.ndarray:
    """B (nu, nv): generalized force of each actuator per unit control (constant here)."""
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    moments = np.zeros((model.nu, model.nv))
    for i in range(model.nu):
        data.ctrl[:] = 0.0
        data.ctrl[i] = 1.0
        mujoco.mj_fwdActuation(model, data)
        moments[i] = data.qfrc_actuator
    return moments


def equality_jacobian(model: mujoco.MjModel, data: mujoco.MjData | None = None) -> np.ndarray:
    """J_eq (neq, nv) of the joint equalities joint1 = c0 + c1 joint2 (linear ones); of a
    profiled knee's (``validate.scene.profile_mjcf``: quadratic, and a tendon), MuJoCo's own rows
    at ``data``'s configuration (after ``mj_fwdPosition``)."""
    if data is not None and model_profile(model) is not None:
        n = data.nefc
        rows = data.efc_J[: n * model.nv].reshape(n, model.nv)
        return rows[data.efc_type[:n] == mujoco.mjtConstraint.mjCNSTR_EQUALITY].copy()
    rows = np.zeros((model.neq, model.nv))
    for k in range(model.neq):
        joint1, joint2 = model.eq_obj1id[k], model.eq_obj2id[k]
        rows[k, model.jnt_dofadr[joint1]] = 1.0
        rows[k, model.jnt_dofadr[joint2]] = -model.eq_data[k, 1]
    return rows


@dataclass
class InverseDynamics:
    """MuJoCo's torques, ground wrench, ZMP and knee coupling forces along a gait."""

    torques: np.ndarray  # (N, 6) Γ1..Γ6 [N·m]
    wrench: np.ndarray  # (N, 3) [Fx, Fz, Cy]
    zmp: np.ndarray  # (N,) [m]
    coupling: np.ndarray  # (N, neq) equality forces [N·m]


def mujoco_inverse_dynamics(
    model: mujoco.MjModel, biped: Biped, q, qd, qdd, stance="left", swing_wrench=None
):
    """Solve τ = Bᵀu + J_cᵀλ + J_eqᵀμ sample by sample (see the module docstring).

    With ``swing_wrench`` (N, 3) [Fx, Fz, Cy] the swing foot is on the ground too (double
    support, ``biped.model.double_support``): its wrench, given, joins the known side,
    τ − J_wᵀ F_w = Bᵀu + J_cᵀλ + J_eqᵀμ, and the system stays square: MuJoCo's torques and
    stance wrench for the model's split of the load.

    Raises ModelError when the system is not square (a rolling knee without its two
    equalities leaves its hinges free: no unique solution).
    """
    mapped: Mapping = mapping(model, stance, biped.radii)
    data = mujoco.MjData(model)
    motors = np.array([model.actuator(name).id for name in JOINT_ORDER])
    gears = model.actuator_gear[motors, 0]
    moments = actuator_moments(model)[motors]
    j_eq = None if model_profile(model) is not None else equality_jacobian(model)
    unknowns = len(motors) + 3 + model.neq
    if unknowns != model.nv:
        raise ModelError(
            f"the model has {model.nv} degrees of freedom for 6 motors, 3 ground reactions "
            f"and {model.neq} equalities: its inverse dynamics needs {model.nv - 9} "
            "equalities (one per rolling knee: knee_lower = (r2 / r1) knee_upper)"
        )
    site = model.site(f"{stance}_ankle").id
    swing_site = model.site(f"{other(stance)}_ankle").id
    jacp, jacr = np.zeros((3, model.nv)), np.zeros((3, model.nv))
    qpos, qvel, qacc = mapped.qpos(q), mapped.qvel(q, qd), mapped.qacc(q, qd, qdd)
    n = len(qpos)
    torques, wrench = np.zeros((n, 6)), np.zeros((n, 3))
    coupling = np.zeros((n, model.neq))
    tau = np.zeros(model.nv)
    for k in range(n):
        data.qpos[:], data.qvel[:], data.qacc[:] = qpos[k], qvel[k], qacc[k]
        mujoco.mj_fwdPosition(model, data)
        mujoco.mj_fwdVelocity(model, data)
        mujoco.mj_rne(model, data, 1, tau)
        mujoco.mj_jacSite(model, data, jacp, jacr, site)
        contact = np.stack([jacp[0], jacp[2], -jacr[1]])
        known = tau
        if swing_wrench is not None:
            mujoco.mj_jacSite(model, data, jacp, jacr, swing_site)
            held = np.stack([jacp[0], jacp[2], -jacr[1]])
            known = tau - held.T @ swing_wrench[k]
        rows = equality_jacobian(model, data) if j_eq is None else j_eq
        system = np.concatenate([moments, contact, rows]).T
        try:
            solution = np.linalg.solve(system, known)
        except np.linalg.LinAlgError:
            raise ModelError(
                "MuJoCo's model gives a singular inverse dynamics (motors, ground and "
                "equalities do not determine its motion)"
            ) from None
        # Paper's sign: Γ = -(MuJoCo's joint torque) = -gear u.
        torques[k] = -(gears * solution[:6])[mapped.columns]
        wrench[k] = solution[6:9]
        coupling[k] = solution[9:]
    hp = biped.robot.ankle_height
    zmp = (torques[:, 0] - hp * wrench[:, 0]) / wrench[:, 1]
    return InverseDynamics(torques, wrench, zmp, coupling)


@dataclass
class KneeForces:
    """MuJoCo's force of the thigh on the lower leg through each knee, stance then swing."""

    force: np.ndarray  # (N, 2, 2) [N]: knee, (x, z)
    axis: np.ndarray  # (N, 2, 2): knee, the unit vector e from MuJoCo's joints (x, z)

    @property
    def normal(self) -> np.ndarray:
        """N = F · e (N, 2) [N]: > 0 compression."""
        return (self.force * self.axis).sum(-1)

    @property
    def tangential(self) -> np.ndarray:
        """T = F · e' (N, 2) [N], e' = e turned +90° in the x-z plane."""
        across = np.stack([-self.axis[..., 1], self.axis[..., 0]], axis=-1)
        return (self.force * across).sum(-1)


def _knee_bodies(model: mujoco.MjModel, side: str) -> tuple[int, int, int]:
    """The body below a knee whose subtree is the lower leg (the rolling knee's link, else the
    shank), and the joints whose anchors span its axis e: knee_upper → knee_lower (C2 → C1),
    else knee → ankle."""
    if mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, f"{side}_knee_link") >= 0:
        ends = (f"{side}_knee_upper", f"{side}_knee_lower")
        return model.body(f"{side}_knee_link").id, *(model.joint(n).id for n in ends)
    ends = (f"{side}_knee", f"{side}_ankle")
    return model.body(f"{side}_shank").id, *(model.joint(n).id for n in ends)


def mujoco_knee_forces(
    model: mujoco.MjModel, biped: Biped, q, qd, qdd, wrench, stance="left"
) -> KneeForces:
    """The force the thigh exerts on the lower leg's subtree (the translational part of
    ``cfrc_int``, world frame, after ``mj_rnePostConstraint``) along a motion, the ground's
    force (Fx, Fz) of ``wrench`` (N, 3) applied to the stance foot (``xfrc_applied``; where
    it acts changes only the rotational part) and no other constraint force, and each knee's
    axis from MuJoCo's joint anchors."""
    mapped = mapping(model, stance, biped.radii)
    data = mujoco.MjData(model)
    knees = [_knee_bodies(model, side) for side in (stance, other(stance))]
    foot = model.body(f"{stance}_foot").id
    profiled = model_profile(model) is not None
    qpos, qvel, qacc = mapped.qpos(q), mapped.qvel(q, qd), mapped.qacc(q, qd, qdd)
    force, axis = np.zeros((len(qpos), 2, 2)), np.zeros((len(qpos), 2, 2))
    for k in range(len(qpos)):
        data.qpos[:], data.qvel[:], data.qacc[:] = qpos[k], qvel[k], qacc[k]
        mujoco.mj_fwdPosition(model, data)
        mujoco.mj_fwdVelocity(model, data)
        data.efc_force[:] = 0.0
        data.xfrc_applied[:] = 0.0
        data.xfrc_applied[foot, [0, 2]] = wrench[k][:2]
        mujoco.mj_rnePostConstraint(model, data)
        for j, (body, start, end) in enumerate(knees):
            force[k, j] = data.cfrc_int[body, [3, 5]]
            if profiled:  # the common normal u(γ): the knee link's −z
                axis[k, j] = -data.xmat[body][[2, 8]]
                continue
            vector = (data.xanchor[end] - data.xanchor[start])[[0, 2]]
            axis[k, j] = vector / np.linalg.norm(vector)
    return KneeForces(force, axis)


def knee_link_effect(biped: Biped, q, qd, qdd, stance="left") -> float:
    """Largest torque change [N·m] that the MJCF's knee-link mass makes along the motion."""
    model = load_model(biped)
    with_link = copy.deepcopy(model)
    with_link.dof_armature[:] = 0.0
    exact = rigid_copy(model)
    a = mujoco_inverse_dynamics(with_link, biped, q, qd, qdd, stance).torques
    b = mujoco_inverse_dynamics(exact, biped, q, qd, qdd, stance).torques
    return float(np.abs(a - b).max())


def mujoco_impact(
    model: mujoco.MjModel,
    biped: Biped,
    q,
    qd_minus,
    stance: str = "left",
    both_feet: bool = False,
):
    """Impact map (eqs. 21-22) with MuJoCo's mass matrix and the landing foot's Jacobian.

    The swing foot (the other side than ``stance``) lands flat: its ankle stops and its angle
    stays (rows x, z, rotation about -y); the knee equalities of the rolling knee hold through
    the impact as well. Solves [M  -Aᵀ; A  0] [q̇⁺; ι] = [M q̇⁻; 0] and returns MuJoCo's q̇⁺
    (nv,) and the ground impulse (3,), in MuJoCo's coordinates for ``stance``. With
    ``both_feet`` the stance foot is held too (the landing that starts a double support,
    ``biped.model.impact.both_feet_impact``): its three rows first, the impulse (6,) on the
    stance then the swing foot.
    """
    mapped = mapping(model, stance, biped.radii)
    data = mujoco.MjData(model)
    data.qpos[:] = mapped.qpos(q)
    mujoco.mj_fwdPosition(model, data)
    mass = np.zeros((model.nv, model.nv))
    mujoco.mj_fullM(model, data, mass)
    feet = (stance, other(stance)) if both_feet else (other(stance),)
    ankles = []
    for side in feet:
        jacp, jacr = np.zeros((3, model.nv)), np.zeros((3, model.nv))
        mujoco.mj_jacSite(model, data, jacp, jacr, model.site(f"{side}_ankle").id)
        ankles.append(np.stack([jacp[0], jacp[2], -jacr[1]]))
    equalities = equality_jacobian(model, data)
    rows = np.concatenate([*ankles, equalities])
    k = len(rows)
    system = np.block([[mass, -rows.T], [rows, np.zeros((k, k))]])
    rhs = np.concatenate([mass @ mapped.qvel(q, qd_minus), np.zeros(k)])
    solution = np.linalg.solve(system, rhs)
    return solution[: model.nv], solution[model.nv : model.nv + 3 * len(feet)]
