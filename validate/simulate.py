"""Forward simulation of a gait in MuJoCo with contact, legs alternating every step.

Control, per joint, at every physics step:

    u = Γ(τ) + kp (θ_ref(τ) - θ) + kv (θ̇_ref(τ) ṡ - θ̇)

where the gait's time τ is not the clock but the phase of the step: the hip's advance over the
stance ankle, x_H - x_ankle, mapped through the gait's own x_H(τ) (increasing over a step), and
ṡ = ẋ_H / ẋ_H,ref(τ) the rate at which the robot goes through it. A robot a little late or
early is then driven along the gait's path, not pulled back towards a clock; this is what a
time reference cannot do for a walker, whose forward motion over its stance foot is an
inverted pendulum.

The phase is read from the state every ``RESYNC`` (10 ms) and carried forward at the hip's
speed in between, so MuJoCo runs each 10 ms on its own (``mujoco.rollout``, no Python in the
loop) with the feedback closed at every physics step by its servos.

The stance ankle carries the feedforward torque Γ1 alone, no feedback: its torque places the
centre of pressure under the foot, and a servo there (kp = 1000 N·m/rad against a pendulum
of m g l ≈ 600 N·m/rad) would move the centre of pressure by centimetres for a few
hundredths of a radian, roll the foot and trip the robot. The five other joints track their
reference with ``KP``, ``KV``. The feedback lives in MuJoCo position and velocity actuators
(``validate.mjcf.robot_xml(servos=...)``): Python sets the references and the feedforward,
MuJoCo computes the feedback inside its implicit integration step.

A step ends when the swing foot, after leaving the ground, touches it again past mid-step
(its touch sensor); the legs then swap roles. If the foot is late, the reference holds the
end posture; if it has not landed after ``STEP_TIMEOUT`` periods, or the hip has dropped to
a quarter below its height, the walk ends.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import mujoco
import numpy as np
from mujoco import rollout

from biped.dynamics import Biped, zmp_from
from biped.errors import BipedError
from biped.gait import Step, angles_at
from biped.kinematics import XH, ZH
from validate.mapping import mapping, other
from validate.mjcf import SIDES, scene_model

JOINT_ORDER = tuple(f"{side}_{joint}" for side in SIDES for joint in ("hip", "knee", "ankle"))
# Joint-space feedback gains of the five tracked joints: stiffness [N·m/rad], damping
# [N·m·s/rad]. The stance ankle has none (see the module docstring).
KP = 1000.0
KV = 40.0
# A step waits for the swing foot at most this many periods.
STEP_TIMEOUT = 2.0
# Normal force [N] of the touch sensor that counts as a touchdown.
TOUCH_THRESHOLD = 1.0
# Points of the phase table (hip advance over one step).
PHASE_POINTS = 2001
# The phase rate ṡ is kept in this range (a robot stopped or thrown forward is not tracked
# by scaling its reference rates further).
RATE_RANGE = (0.25, 4.0)
# Period [s] at which the controller reads the phase from the state.
RESYNC = 0.01
# Height of the hip, as a fraction of its height at the ends of the step, below which the
# robot has fallen and the simulation stops (a walk keeps it within a few per cent).
FALLEN = 0.75


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
    """Feedback gains of one step: ``kp``, ``kv`` on every joint but the stance ankle."""
    for side in SIDES:
        for joint in ("hip", "knee", "ankle"):
            free = joint == "ankle" and side == stance
            stiffness, damping = (0.0, 0.0) if free else (kp, kv)
            position = model.actuator(f"{side}_{joint}_position").id
            velocity = model.actuator(f"{side}_{joint}_velocity").id
            model.actuator_gainprm[position, 0] = stiffness
            model.actuator_biasprm[position, 1] = -stiffness
            model.actuator_gainprm[velocity, 0] = damping
            model.actuator_biasprm[velocity, 2] = -damping


@dataclass(frozen=True)
class PhaseTable:
    """The gait on a uniform grid of hip advance x = x_H - x_ankle over one step.

    Attributes:
        advance: (N,) x [m], from the start of the step to its end.
        tau: (N,) the gait's time at each x [s].
        speed: (N,) planned ẋ_H at each x [m/s].
        controls: stance side -> (N, 18) feedforward torques of the six motors, then joint
            references and reference rates in ``JOINT_ORDER`` (MuJoCo's joint coordinates).
    """

    advance: np.ndarray
    tau: np.ndarray
    speed: np.ndarray
    controls: dict


def phase_table(biped: Biped, step: Step, model: mujoco.MjModel, points: int = PHASE_POINTS):
    """Tabulate the gait against the hip's advance; raises if the hip does not advance."""
    tau = np.linspace(0.0, step.period, 4 * points)
    angles, rates, accel = angles_at(step, tau / step.period)
    q, qd, *_ = biped.single_support(angles, rates, accel)
    if not np.all(qd[:, XH] > 0.0):
        raise BipedError(
            f"the hip's speed falls to {qd[:, XH].min():.3g} m/s during the step: a phase "
            "needs a hip moving forward throughout (allowed > 0)"
        )
    advance = np.linspace(q[0, XH], q[-1, XH], points)
    tau = np.interp(advance, q[:, XH], tau)
    angles, rates, accel = angles_at(step, tau / step.period)
    q, qd, _, torques, _, _ = biped.single_support(angles, rates, accel)
    select = joint_matrix(model)
    controls = {}
    for side in SIDES:
        mapped = mapping(model, side, biped.radii)
        table = np.zeros((points, 18))
        table[:, mapped.actuator_order] = torques
        table[:, 6:12] = mapped.qpos(q) @ select.T
        table[:, 12:18] = mapped.qpos(qd) @ select.T
        controls[side] = table
    return PhaseTable(advance, tau, qd[:, XH], controls)


@dataclass
class Simulation:
    """States, controls and sensors of a forward simulation, and its step events. Row k holds
    the state at time[k], the controls of the physics step that followed it and the sensors
    MuJoCo computed at it."""

    model: mujoco.MjModel
    time: np.ndarray  # (N,) [s]
    qpos: np.ndarray  # (N, nq)
    qvel: np.ndarray  # (N, nv)
    ctrl: np.ndarray  # (N, nu) feedforward torques, joint references, reference rates
    sensors: np.ndarray  # (N, nsensordata)
    phase: np.ndarray  # (N,) the gait's time τ the controller followed [s]
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

    def stance_of(self) -> np.ndarray:
        """Stance side (N,) of every state."""
        return np.repeat(self.stances, np.diff(self.step_starts + [len(self.time)]))

    def motors(self) -> np.ndarray:
        """Feedforward torques (N, 6) the motors applied, in ``JOINT_ORDER``."""
        low, high = self.model.actuator_ctrlrange[:6].T
        return np.clip(self.ctrl[:, :6], low, high)

    def feedback(self) -> np.ndarray:
        """Torques (N, 6) of the position and velocity servos, in the paper's sign
        (conjugate to θ of eq. 32, like the motors' Γ), in ``JOINT_ORDER``."""
        select = joint_matrix(self.model)
        stiffness = np.full((len(self.time), 6), self.kp)
        damping = np.full((len(self.time), 6), self.kv)
        for i, side in enumerate(SIDES):
            free = self.stance_of() == side
            stiffness[free, 3 * i + 2] = damping[free, 3 * i + 2] = 0.0
        servo = stiffness * (self.ctrl[:, 6:12] - self.qpos @ select.T)
        servo += damping * (self.ctrl[:, 12:18] - self.qvel @ select.T)
        return -servo  # the servos act on MuJoCo's joint angle, minus θ


def simulate(
    biped: Biped,
    step: Step,
    steps: int = 20,
    kp: float = KP,
    kv: float = KV,
    feedforward: float = 1.0,
):
    """Play ``steps`` steps of the gait from its start state, left leg in stance first.

    Args:
        feedforward: scale of the gait's torques in the control (1: the gait's own; other
            values show what the check of a walk detects of wrong torques).
    """
    model = scene_model(biped.robot, biped.knee, servos=(kp, kv))
    data = mujoco.MjData(model)
    table = phase_table(biped, step, model)
    if feedforward != 1.0:
        for controls in table.controls.values():
            controls[:, :6] *= feedforward
    q0, qd0 = step.start
    start = mapping(model, "left", biped.radii)
    data.qpos[:] = start.qpos(q0)
    data.qvel[:] = start.qpos(qd0)
    mujoco.mj_forward(model, data)
    spec = mujoco.mjtState.mjSTATE_FULLPHYSICS
    state = np.empty(mujoco.mj_stateSize(model, spec))
    mujoco.mj_getState(model, data, state, spec)
    sensors = data.sensordata.copy()
    data.warning.number[:] = 0
    nq, nv = model.nq, model.nv

    dt = model.opt.timestep
    chunk = max(1, round(RESYNC / dt))
    capacity = int(np.ceil(steps * STEP_TIMEOUT * step.period / dt)) + chunk
    log = {
        "state": np.empty((capacity, state.size)),
        "ctrl": np.empty((capacity, model.nu)),
        "sensors": np.empty((capacity, model.nsensordata)),
        "phase": np.empty(capacity),
    }
    result = Simulation(model, *(None,) * 6, kp=kp, kv=kv)
    x0, span = table.advance[0], table.advance[-1] - table.advance[0]
    last = len(table.advance) - 1
    ankle = {side: model.sensor(f"{side}_ankle_pos").adr[0] for side in SIDES}
    touch = {side: model.sensor(f"{side}_touch").adr[0] for side in SIDES}
    floor = FALLEN * min(q0[ZH], step.end[0][ZH])
    ticks = np.arange(chunk) * dt
    state = state[None]
    out_state = np.empty((1, chunk, state.size))
    out_sensors = np.empty((1, chunk, model.nsensordata))
    k = 0
    for j in range(steps):
        stance = SIDES[j % 2]
        controls = table.controls[stance]
        set_gains(model, stance, kp, kv)
        result.step_starts.append(k)
        result.stances.append(stance)
        began, landed, fallen, lifted = state[0, 0], False, False, False
        landing = touch[other(stance)]
        while state[0, 0] - began < STEP_TIMEOUT * step.period and k < capacity - chunk:
            # The phase now, and as it goes on at the hip's present speed (the stance ankle's
            # position is the reading of one physics step before: the foot is on the ground).
            hip_speed = state[0, 1 + nq]
            advance = state[0, 1] - sensors[ankle[stance]] + hip_speed * ticks
            where = np.clip((advance - x0) / span, 0.0, 1.0) * last
            i = np.minimum(where.astype(int), last - 1)
            w = (where - i)[:, None]
            rows = controls[i] * (1.0 - w) + controls[i + 1] * w
            rate = hip_speed / (
                table.speed[i[0]] * (1.0 - w[0, 0]) + table.speed[i[0] + 1] * w[0, 0]
            )
            rows[:, 12:18] *= min(max(rate, RATE_RANGE[0]), RATE_RANGE[1])
            rows[where >= last, 12:18] = 0.0  # past the end of the step: hold the posture
            rollout.rollout(
                [model],
                [data],
                state,
                rows[None],
                nstep=chunk,
                initial_warmstart=data.qacc_warmstart[None],
                state=out_state,
                sensordata=out_sensors,
                skip_checks=True,
            )
            result.warnings += int(data.warning.number.sum())  # reset by every rollout
            states, readings = out_state[0], out_sensors[0]
            # states[r]: the state after physics step r; readings[r]: the sensors computed
            # before it, at the state the step started from.
            n = chunk
            contact = readings[:, landing] > TOUCH_THRESHOLD
            # A touchdown: the swing foot, off the ground since some time in this step, touches
            # it past mid-step (a foot that never lifts does not make steps).
            aloft = lifted | np.logical_or.accumulate(~contact)
            down = np.flatnonzero((where > 0.5 * last) & contact & aloft)
            lifted = bool(aloft[-1])
            if len(down):
                n, landed = down[0] + 1, True
            bad = ~np.isfinite(states[:n, 2]) | (states[:n, 2] < floor)
            if bad.any():
                n, fallen, landed = int(np.argmax(bad)) + 1, True, False
            log["state"][k] = state[0]
            log["state"][k + 1 : k + n] = states[: n - 1]
            log["ctrl"][k : k + n] = rows[:n]
            log["sensors"][k : k + n] = readings[:n]
            log["phase"][k : k + n] = (
                table.tau[i[:n]] * (1.0 - w[:n, 0]) + table.tau[i[:n] + 1] * w[:n, 0]
            )
            k += n
            state, sensors = states[n - 1 : n].copy(), readings[n - 1]
            if landed or fallen:
                break
        result.landed.append(landed)
        if not landed:
            break
    states = log["state"][:k]
    result.time = states[:, 0]
    result.qpos = states[:, 1 : 1 + nq]
    result.qvel = states[:, 1 + nq : 1 + nq + nv]
    result.ctrl = log["ctrl"][:k]
    result.sensors = log["sensors"][:k]
    result.phase = log["phase"][:k]
    return result


def reference_along(biped: Biped, step: Step, sim: Simulation):
    """The gait at the phase the controller followed at every simulation state.

    Returns:
        q (N, 9), torques (N, 6), wrench (N, 3) and ZMP (N,) of the analytical gait.
    """
    angles, rates, accel = angles_at(step, sim.phase / step.period)
    q, _, _, torques, wrench, _ = biped.single_support(angles, rates, accel)
    return q, torques, wrench, zmp_from(torques, wrench, biped.robot.ankle_height)
