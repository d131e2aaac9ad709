"""Where the validation's quantities live in one MuJoCo model, resolved by name once.

Every array the validation reads out of MuJoCo (a state vector, qpos, the sensors) is read
through a ``Layout``: ``layout.hip_x(qpos)`` rather than ``qpos[:, 0]``. The names are those
``validate.scene.mjcf`` writes (``validate.scene.model`` refuses a model without them).
"""

from __future__ import annotations

import copy

import mujoco
import numpy as np

from validate.scene.mapping import PROFILE_JOINTS, knee_joints
from validate.scene.mjcf import SIDES
from validate.scene.model import JOINT_ORDER
from validate.scene.profile_mjcf import model_profile


class Layout:
    """Addresses of the validation's joints, actuators, sensors and bodies in ``model``.

    Attributes:
        nq, nv: sizes of qpos and qvel.
        joints: (6, nq) S: the six actuated joint angles (knee flexion for the rolling knee,
            the sum of its two hinges) θ_mj = S qpos in ``JOINT_ORDER``, MuJoCo's sign; also
            maps qvel (nq = nv in these planar models).
        motors: (6,) ids of the motors, in ``JOINT_ORDER``.
        positions, velocities: (6,) ids of the servos (``validate.scene.model.with_servos``), or
            None in a model without them.
        rotor_inertia: (6,) inertia [kg·m²] each joint's drive adds to it (MuJoCo's armature,
            seen through the joint: a rolling knee's two hinges turn by r1/l and r2/l of its
            flexion, so their armatures add as a (r1/l)² + a (r2/l)²; a profiled knee's four
            joints by their rates at the straight knee, ``validate.scene.mapping.knee_joints``).
    """

    def __init__(self, model: mujoco.MjModel):
        self.model = model
        self.nq, self.nv = model.nq, model.nv
        self._rootx = model.joint("rootx").qposadr[0]
        self._rootz = model.joint("rootz").qposadr[0]
        self._rooty = model.joint("rooty").qposadr[0]
        self._rootx_dof = model.joint("rootx").dofadr[0]
        self.joints = np.zeros((6, model.nq))
        self.rotor_inertia = np.zeros(6)
        profile = model_profile(model)
        for row, name in enumerate(JOINT_ORDER):
            # (joint, its rate per unit of the joint angle, whether it sums to the angle)
            if mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, name) >= 0:
                parts = [(model.joint(name), 1.0, True)]
            elif profile is not None:  # the flexion over four joints: their rates at θ = 0
                _, rates, _ = knee_joints(profile, 0.0)
                parts = [
                    (model.joint(f"{name}_{part}"), rate, part in ("upper", "lower"))
                    for part, rate in zip(PROFILE_JOINTS, rates, strict=True)
                ]
            else:  # rolling knee: the flexion splits over two hinges, lower = c upper
                upper, lower = (model.joint(f"{name}_{part}") for part in ("upper", "lower"))
                c = _coupling(model, upper.id, lower.id)
                parts = [(upper, 1.0 / (1.0 + c), True), (lower, c / (1.0 + c), True)]
            for joint, share, summed in parts:
                self.joints[row, joint.qposadr[0]] = 1.0 if summed else 0.0
                self.rotor_inertia[row] += model.dof_armature[joint.dofadr[0]] * share**2
        self.motors = self._actuators("")
        self.gears = model.actuator_gear[self.motors, 0].copy()
        self.positions = self._actuators("_position")
        self.velocities = self._actuators("_velocity")
        self._sensor = {
            (side, kind): model.sensor(f"{side}_{kind}").adr[0]
            for side in SIDES
            for kind in ("touch", "ankle_pos", "heel_pos", "toe_pos")
        }
        self.trunk = model.body("trunk").id
        self.feet = {side: model.body(f"{side}_foot").id for side in SIDES}
        # Collision geoms of each foot (the soles' contact points).
        collides = (model.geom_contype != 0) | (model.geom_conaffinity != 0)
        self.foot_geoms = {
            side: np.flatnonzero(collides & (model.geom_bodyid == body))
            for side, body in self.feet.items()
        }

    def _actuators(self, suffix: str):
        ids = [
            mujoco.mj_name2id(self.model, mujoco.mjtObj.mjOBJ_ACTUATOR, f"{name}{suffix}")
            for name in JOINT_ORDER
        ]
        return None if min(ids) < 0 else np.array(ids)

    # ------------------------------------------------------------ coordinates (from qpos, qvel)
    def hip_x(self, qpos) -> np.ndarray:
        """x_H [m]: the hip's horizontal position."""
        return np.asarray(qpos)[..., self._rootx]

    def hip_height(self, qpos) -> np.ndarray:
        """z_H [m]: the hip above the floor."""
        return np.asarray(qpos)[..., self._rootz]

    def trunk_angle(self, qpos) -> np.ndarray:
        """q5 [rad]: the trunk's angle from the vertical, counter-clockwise."""
        return np.asarray(qpos)[..., self._rooty]

    def hip_speed(self, qvel) -> np.ndarray:
        """ẋ_H [m/s]."""
        return np.asarray(qvel)[..., self._rootx_dof]

    def joint_angles(self, qpos) -> np.ndarray:
        """(..., 6) MuJoCo's joint angles in ``JOINT_ORDER`` [rad] (minus the paper's θ)."""
        return np.asarray(qpos) @ self.joints.T

    # ------------------------------------------------------------ sensors (from sensordata)
    def touch(self, sensors, side: str) -> np.ndarray:
        """Normal force [N] on a sole (its touch sensor)."""
        return np.asarray(sensors)[..., self._sensor[side, "touch"]]

    def ankle(self, sensors, side: str) -> np.ndarray:
        """(..., 3) world position of an ankle [m]."""
        return self._position(sensors, side, "ankle_pos")

    def heel(self, sensors, side: str) -> np.ndarray:
        """(..., 3) world position of a heel (back end of the sole) [m]."""
        return self._position(sensors, side, "heel_pos")

    def toe(self, sensors, side: str) -> np.ndarray:
        """(..., 3) world position of a toe (front end of the sole) [m]."""
        return self._position(sensors, side, "toe_pos")

    def _position(self, sensors, side: str, kind: str) -> np.ndarray:
        adr = self._sensor[side, kind]
        return np.asarray(sensors)[..., adr : adr + 3]

    def of(self, model: mujoco.MjModel) -> Layout:
        """This layout for ``model``, a copy of its model (the same names, ids and sizes;
        other parameters, gains or friction, may differ)."""
        layout = copy.copy(self)
        layout.model = model
        return layout

    # ------------------------------------------------------------ state vectors
    def state_index(self, name: str) -> int:
        """Index in MuJoCo's full physics state vector (time first) of ``hip_x``,
        ``hip_height`` or ``hip_speed``."""
        offsets = {"hip_x": self._rootx, "hip_height": self._rootz}
        offsets["hip_speed"] = self.nq + self._rootx_dof
        return 1 + offsets[name]

    def sensor_index(self, side: str, kind: str) -> int:
        """Index in the sensor readings of a side's ``touch`` or of the x of its
        ``ankle_pos``, ``heel_pos``, ``toe_pos``."""
        return self._sensor[side, kind]

    def state_qpos(self, state) -> np.ndarray:
        """qpos of MuJoCo's full physics state vectors (time first)."""
        return np.asarray(state)[..., 1 : 1 + self.nq]

    def state_qvel(self, state) -> np.ndarray:
        """qvel of MuJoCo's full physics state vectors."""
        return np.asarray(state)[..., 1 + self.nq : 1 + self.nq + self.nv]


def _coupling(model: mujoco.MjModel, upper: int, lower: int) -> float:
    """c of the joint equality lower = c upper between two hinges (1 if there is none: the
    model is then reported by ``validate.scene.model.model_problems``)."""
    for k in range(model.neq):
        if model.eq_type[k] != mujoco.mjtEq.mjEQ_JOINT:
            continue
        pair = (model.eq_obj1id[k], model.eq_obj2id[k])
        if pair == (lower, upper) and model.eq_data[k, 1] != 0.0:
            return float(model.eq_data[k, 1])
        if pair == (upper, lower) and model.eq_data[k, 1] != 0.0:
            return 1.0 / float(model.eq_data[k, 1])
    return 1.0
