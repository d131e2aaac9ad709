"""Forward simulation of a gait in MuJoCo with contact, legs alternating every step.

Control: the gait's torques as feedforward plus joint-space feedback,

    u = Γ(τ) + kp (θ_ref(τ) - θ) + kv (θ̇_ref(τ) - θ̇)

with τ the time since the current step began. The feedback lives in MuJoCo position and
velocity actuators (``validate.mjcf.robot_xml(servos=...)``), so a step's whole control is an
open-loop sequence of feedforward torques and references, played by ``mujoco.rollout``
without Python in the loop. A step ends when the swing foot's touch sensor reports contact
after mid-step; the next step then starts from that state with the legs swapped (τ = 0). If
the foot is late, the reference holds the end posture; if it never lands the robot has fallen.

Status: with the paper's constraints (swing foot z >= 0) the optimal gaits clear the ground
by millimetres and the robots walk a few steps before a scuff trips them. With safety margins
(``biped.criteria.Safety``: a few centimetres of clearance, a ZMP kept 2 cm inside the sole)
some optimal gaits walk 20 steps with the stance foot still to a fraction of a millimetre, but
not all: the joint-space feedback here is not yet robust enough for every optimum.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import mujoco
import numpy as np
from mujoco import rollout

from biped.dynamics import Biped, zmp_from
from biped.gait import Step, angles_at
from validate.mapping import mapping, other
from validate.mjcf import SIDES, scene_model

JOINT_ORDER = tuple(f"{side}_{joint}" for side in SIDES for joint in ("hip", "knee", "ankle"))
# Joint-space feedback gains: stiffness [N·m/rad] and damping [N·m·s/rad].
KP = 1000.0
KV = 40.0
# Damping of the stance ankle as a fraction of kv (see ``set_gains``).
STANCE_ANKLE_DAMPING = 0.2
# A step waits for the swing foot at most this many periods.
STEP_TIMEOUT = 1.5
# Normal force [N] of the touch sensor that counts as a touchdown.
TOUCH_THRESHOLD = 1.0


def joint_matrix(model: mujoco.MjModel) -> np.ndarray:
    """S (6, nq): the six actuated joint coordinates (knee flexion for the rolling knee) from
    qpos, in ``JOINT_ORDER``; also maps qvel (nq = nv for these models)."""
    matrix = np.zeros((6, model.nq))
    for row, name in enumerate(JOINT_ORDER):
        if mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, name) >= 0:
            matrix[row, model.joint(name).qposadr[0]] = 1.0
        else:  # rolling knee: the flexion is split over two hinges
            for part in ("upper", "lower"):
                matrix[row, model.joint(f"{name}_{part}").qposadr[0]] = 1.0
    return matrix


def set_gains(model: mujoco.MjModel, stance: str, kp: float, kv: float) -> None:
    """Feedback gains of one step: ``kp``, ``kv`` on every joint, the stance ankle's damping
    scaled by ``STANCE_ANKLE_DAMPING`` (tuned: full damping on the joint that carries the
    whole body made the walks fall sooner in our trials).
    """
    for side in SIDES:
        for joint in ("hip", "knee", "ankle"):
            damping = STANCE_ANKLE_DAMPING * kv if (joint == "ankle" and side == stance) else kv
            position = model.actuator(f"{side}_{joint}_position").id
            velocity = model.actuator(f"{side}_{joint}_velocity").id
            model.actuator_gainprm[position, 0] = kp
            model.actuator_biasprm[position, 1] = -kp
            model.actuator_gainprm[velocity, 0] = damping
            model.actuator_biasprm[velocity, 2] = -damping


def step_controls(biped: Biped, step: Step, model: mujoco.MjModel, stance: str, n: int):
    """Control sequence (n, nu) of one step with ``stance`` leg, τ = k dt clamped at T."""
    tau = np.minimum(np.arange(n) * model.opt.timestep, step.period)
    angles, rates, accel = angles_at(step, tau / step.period)
    held = tau >= step.period
    rates[held], accel[held] = 0.0, 0.0
    q, qd, _, torques, _, _ = biped.single_support(angles, rates, accel)
    select = joint_matrix(model)
    mapped = mapping(model, stance, biped.radii)
    ctrl = np.zeros((n, model.nu))
    ctrl[:, mapped.actuator_order] = torques
    ctrl[:, 6:12] = mapped.qpos(q) @ select.T
    ctrl[:, 12:18] = mapped.qpos(qd) @ select.T
    return ctrl


@dataclass
class Simulation:
    """States, controls and sensors of a forward simulation, and its step events."""

    model: mujoco.MjModel
    time: np.ndarray  # (N,) [s]
    qpos: np.ndarray  # (N, nq)
    qvel: np.ndarray  # (N, nv)
    ctrl: np.ndarray  # (N, nu) control applied during the step that led to this state
    sensors: np.ndarray  # (N, nsensordata)
    step_starts: list = field(default_factory=list)  # index of each step's first state
    stances: list = field(default_factory=list)  # stance side of each step
    landed: list = field(default_factory=list)  # whether each step ended on a touchdown
    warnings: int = 0  # MuJoCo warnings raised during the simulation
    kp: float = KP
    kv: float = KV

    def sensor(self, name: str) -> np.ndarray:
        """Readings (N, dim) of a named sensor."""
        sensor = self.model.sensor(name)
        return self.sensors[:, sensor.adr[0] : sensor.adr[0] + sensor.dim[0]]


def simulate(biped: Biped, step: Step, steps: int = 20, kp: float = KP, kv: float = KV):
    """Play ``steps`` steps of the gait from its start state, left leg in stance first."""
    model = scene_model(biped.robot, biped.knee, servos=(kp, kv))
    data = mujoco.MjData(model)
    q0, qd0 = step.start
    start = mapping(model, "left", biped.radii)
    data.qpos[:] = start.qpos(q0)
    data.qvel[:] = start.qpos(qd0)
    mujoco.mj_forward(model, data)
    spec = mujoco.mjtState.mjSTATE_FULLPHYSICS
    state = np.zeros(mujoco.mj_stateSize(model, spec))
    mujoco.mj_getState(model, data, state, spec)
    n = int(np.ceil(STEP_TIMEOUT * step.period / model.opt.timestep))
    controls = {side: step_controls(biped, step, model, side, n) for side in SIDES}
    earliest = int(0.5 * step.period / model.opt.timestep)
    chunk = max(1, int(0.05 * step.period / model.opt.timestep))
    parts = []
    result = Simulation(model, *(None,) * 5, kp=kp, kv=kv)
    count = 0
    for j in range(steps):
        stance = SIDES[j % 2]
        touch = model.sensor(f"{other(stance)}_touch").adr[0]
        set_gains(model, stance, kp, kv)
        # Roll out to mid-step, then in short chunks until the swing foot lands.
        done, landed = 0, False
        pieces = []
        while done < n and not landed:
            size = earliest if done == 0 else min(chunk, n - done)
            states, sensors = rollout.rollout(
                model, data, state, controls[stance][None, done : done + size]
            )
            states, sensors = states[0], sensors[0]
            # rollout resets data.warning at each call: count them chunk by chunk.
            result.warnings += int(sum(w.number for w in data.warning))
            finite = np.all(np.isfinite(states), axis=1)
            down = np.flatnonzero(sensors[:, touch] > TOUCH_THRESHOLD) if done else []
            end = down[0] + 1 if len(down) else size
            if not finite[:end].all():
                end = int(np.argmin(finite))
            pieces.append((states[:end], controls[stance][done : done + end], sensors[:end]))
            landed = bool(len(down)) and finite[:end].all()
            done += end
            if not finite.all() or end == 0:
                break
            state = states[end - 1]
        parts += pieces
        result.step_starts.append(count)
        result.stances.append(stance)
        result.landed.append(landed)
        count += done
        if not landed:
            break
    states = np.concatenate([p[0] for p in parts])
    nq, nv = model.nq, model.nv
    result.time = states[:, 0]
    result.qpos = states[:, 1 : 1 + nq]
    result.qvel = states[:, 1 + nq : 1 + nq + nv]
    result.ctrl = np.concatenate([p[1] for p in parts])
    result.sensors = np.concatenate([p[2] for p in parts])
    return result


def reference_along(biped: Biped, step: Step, sim: Simulation):
    """The gait at every simulation state, its phase restarting at each touchdown.

    Returns:
        q (N, 9), torques (N, 6), wrench (N, 3) and ZMP (N,) of the analytical gait.
    """
    phase = np.zeros(len(sim.time))
    starts = sim.step_starts + [len(sim.time)]
    for j in range(len(sim.stances)):
        a, b = starts[j], starts[j + 1]
        elapsed = sim.time[a:b] - sim.time[a] + sim.model.opt.timestep
        phase[a:b] = np.minimum(elapsed, step.period)
    angles, rates, accel = angles_at(step, phase / step.period)
    q, _, _, torques, wrench, _ = biped.single_support(angles, rates, accel)
    return q, torques, wrench, zmp_from(torques, wrench, biped.robot.ankle_height)
