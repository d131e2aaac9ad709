"""Forward simulation of a gait file in MuJoCo with contact, legs alternating every step.

What is played is the file: the motors apply the torques of its samples (``validate.samples``)
and the joints follow the motion of its samples. Control, per joint, at every physics step:

    u = Γ(τ) + J_r θ̈(τ) ṡ²  +  kp (θ_ref(τ) - θ) + kv (θ̇_ref(τ) ṡ - θ̇)
        feedforward             feedback

where Γ(τ) is the file's torque and J_r θ̈ what the joint's own drive takes to turn its rotor
(MuJoCo's armature, ``Layout.rotor_inertia``: the paper's robot has no rotors, its torques are
those at the joints). The gait's time τ is not the clock but the phase of the step: the hip's
advance over the stance ankle, x_H - x_ankle, mapped through the gait's own x_H(τ) (increasing
over a step), and ṡ = ẋ_H / ẋ_H,ref(τ) the rate at which the robot goes through it. A robot a
little late or early is then driven along the gait's path, not pulled back towards a clock;
this is what a time reference cannot do for a walker, whose forward motion over its stance
foot is an inverted pendulum.

The phase is read from the state every ``RESYNC`` and carried forward at the hip's speed in
between, so MuJoCo runs each stretch on its own (``mujoco.rollout``, no Python in the loop)
with the feedback closed at every physics step by its servos (``validate.model.with_servos``).

The stance ankle has no servo: its torque places the centre of pressure under the foot, and a
servo there (kp = 1000 N·m/rad against a pendulum of m g l ≈ 600 N·m/rad) would move the
centre of pressure by centimetres for a few hundredths of a radian, roll the foot and trip the
robot. It carries the file's Γ1 and the ankle strategy of a walker, a torque on the speed:

    u_ankle = Γ1(τ) + J_r θ̈1 ṡ²  +  K (ẋ_H - ẋ_H,ref(τ))        K = ``SPEED_GAIN``

(a robot a little fast moves its centre of pressure forward by K Δẋ / F_z, 3 mm for 1 cm/s,
and slows down). The gait's orbit is not stable on its own: played with the phase alone, the
optimal gaits lose speed step after step in MuJoCo (1.3 T a step after 10 steps) and their
swing foot, clearing the ground by a millimetre, ends up scuffing it. The five other joints
track their reference with ``KP``, ``KV`` (times ``WalkSettings.kp_scale``, ``kv_scale``).

A step ends when the swing foot, after leaving the ground, touches it in the landing window
(the last ``1 - LANDING_WINDOW`` of the step, by phase); the legs then swap roles. A foot
late for the floor keeps coming down: past the end of the step the references go on at the
step's end rates. A touch between the lift-off (the first ``LIFT_WINDOW`` of the step) and
the landing window is a scuff: the step goes on (``validate.contact`` reports it). If the
foot has not landed after ``STEP_TIMEOUT`` periods, or the hip has dropped below ``FALLEN``
of its height, the walk ends.

``Walker`` prepares a gait on a model once; ``Walker.walk`` runs it under ``WalkSettings``
(gains, friction, a push): the robustness of a gait is many walks of one walker.
"""

from __future__ import annotations

import contextlib
import copy
import functools
import threading
from collections.abc import Iterator
from dataclasses import dataclass, field

import mujoco
import numpy as np
from mujoco import rollout

from biped.errors import BipedError
from biped.model.dynamics import Biped
from biped.model.kinematics import XH, ZH
from validate import DEFAULT_STEPS
from validate.layout import Layout
from validate.mapping import mapping, other
from validate.mjcf import SIDES
from validate.model import JOINT_ORDER, model_spec, with_servos
from validate.samples import GaitSamples, gait_biped

__all__ = ["JOINT_ORDER", "Push", "Simulation", "WalkSettings", "Walker", "simulate"]

# Joint-space feedback gains of the five tracked joints: stiffness [N·m/rad], damping
# [N·m·s/rad]. The stance ankle has none (see the module docstring).
KP = 1000.0
KV = 40.0
# A step waits for the swing foot at most this many periods.
STEP_TIMEOUT = 2.0
# Normal force [N] of the touch sensor that counts as a touch of the ground.
TOUCH_THRESHOLD = 1.0
# Fraction of the step (by phase) from which a touch of the swing foot is its landing: the
# gait's swing foot is then within a few millimetres of the ground, coming down.
LANDING_WINDOW = 0.9
# Fraction of the step (by phase) during which the trailing foot leaves the floor: a touch
# then is the lift-off, not a scuff (the gait's foot is 2 mm up at its end).
LIFT_WINDOW = 0.05
# Points of the phase table (hip advance over one step).
PHASE_POINTS = 2001
# The phase rate ṡ is kept in this range (a robot stopped or thrown forward is not tracked
# by scaling its reference rates further).
RATE_RANGE = (0.25, 4.0)
# Gain [N·s] of the stance ankle's torque on the hip's speed error (the ankle strategy).
SPEED_GAIN = 200.0
# Period [s] at which the controller reads the phase from the state.
RESYNC = 0.02
# Height of the hip, as a fraction of its height at the ends of the step, below which the
# robot has fallen and the simulation stops (a walk keeps it within a few per cent).
FALLEN = 0.75


@dataclass(frozen=True)
class Push:
    """A shove on the trunk: a constant horizontal force on its centre of mass during one
    reading period ``RESYNC`` (longer if a landing cuts that period short), of ``impulse``
    in all.

    Attributes:
        impulse: [N·s] forward (> 0) or backward (< 0).
        time: [s] from the start of the walk; the push starts at the first reading of the
            phase at or after it (within ``RESYNC``).
    """

    impulse: float
    time: float


@dataclass(frozen=True)
class WalkSettings:
    """How a gait is walked (the defaults are the validation's walk).

    Attributes:
        kp_scale: the servos' stiffness is ``KP`` times this.
        kv_scale: the servos' damping is ``KV`` times this.
        friction: sliding friction coefficient of the soles and the floor (None: the
            model's, ``biped.model.robot.FOOT_FRICTION``).
        push: a shove on the trunk (None: none).
    """

    kp_scale: float = 1.0
    kv_scale: float = 1.0
    friction: float | None = None
    push: Push | None = None

    @property
    def kp(self) -> float:
        return KP * self.kp_scale

    @property
    def kv(self) -> float:
        return KV * self.kv_scale


def joint_matrix(model: mujoco.MjModel) -> np.ndarray:
    """S (6, nq): the six actuated joint coordinates from qpos, in ``JOINT_ORDER``."""
    return Layout(model).joints


def set_gains(model: mujoco.MjModel, layout: Layout, stance: str, kp: float, kv: float):
    """Feedback gains of one step: ``kp``, ``kv`` on every joint but the stance ankle."""
    for row, name in enumerate(JOINT_ORDER):
        free = name == f"{stance}_ankle"
        stiffness, damping = (0.0, 0.0) if free else (kp, kv)
        position, velocity = layout.positions[row], layout.velocities[row]
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
        controls: stance side -> (N, 24) in ``JOINT_ORDER``: the file's torques of the six
            motors (as their controls), joint references, reference rates, and what each
            motor adds per unit ṡ² to turn its rotor (``Layout.rotor_inertia`` θ̈_ref).
    """

    advance: np.ndarray
    tau: np.ndarray
    speed: np.ndarray
    controls: dict

    @functools.cached_property
    def interpolants(self) -> dict:
        """Stance side -> (48, N - 1): ``controls`` as columns (the first 24 rows, less the
        last point) over each column's increments to the next point (the other 24): what
        the walk interpolates, laid out for one gather."""
        return {
            side: np.ascontiguousarray(np.hstack([rows[:-1], np.diff(rows, axis=0)]).T)
            for side, rows in self.controls.items()
        }


def phase_table(
    samples: GaitSamples, layout: Layout, radii, points: int = PHASE_POINTS
) -> PhaseTable:
    """Tabulate the file's gait against the hip's advance; raises if the hip does not advance."""
    tau = np.linspace(0.0, samples.period, 4 * points)
    x_hip = samples.at("q", tau)[:, XH]
    speed = samples.at("qd", tau)[:, XH]
    if not np.all(speed > 0.0):
        raise BipedError(
            f"the hip's speed falls to {speed.min():.3g} m/s during the step: a phase "
            "needs a hip moving forward throughout (allowed > 0)"
        )
    advance = np.linspace(x_hip[0], x_hip[-1], points)
    tau = np.interp(advance, x_hip, tau)
    q, qd, qdd = (samples.at(name, tau) for name in ("q", "qd", "qdd"))
    torques = samples.at("torques", tau)
    controls = {}
    for side in SIDES:
        mapped = mapping(layout.model, side, radii)
        table = np.zeros((points, 24))
        # Motor controls: MuJoCo's joint torque -Γ, per unit of gear (validate.mjcf: gear -1).
        table[:, mapped.columns] = -torques
        table[:, :6] /= layout.gears
        table[:, 6:12] = layout.joint_angles(mapped.qpos(q))
        table[:, 12:18] = layout.joint_angles(mapped.qpos(qd))
        table[:, 18:24] = layout.rotor_inertia * layout.joint_angles(mapped.qpos(qdd))
        table[:, 18:24] /= layout.gears
        controls[side] = table
    return PhaseTable(advance, tau, speed=qd[:, XH], controls=controls)


@dataclass
class Simulation:
    """States, controls and sensors of a forward simulation, and its step events. Row k holds
    the state at time[k], the controls of the physics step that followed it and the sensors
    MuJoCo computed at it."""

    model: mujoco.MjModel
    layout: Layout
    time: np.ndarray  # (N,) [s]
    qpos: np.ndarray  # (N, nq)
    qvel: np.ndarray  # (N, nv)
    ctrl: np.ndarray  # (N, nu) motor controls, joint references, reference rates
    sensors: np.ndarray  # (N, nsensordata)
    phase: np.ndarray  # (N,) the gait's time τ the controller followed [s]
    speed_torque: np.ndarray = None  # (N,) the stance ankle's torque on the speed [N·m]
    step_starts: list = field(default_factory=list)  # index of each step's first state
    stances: list = field(default_factory=list)  # stance side of each step
    landed: list = field(default_factory=list)  # whether each step ended on a touchdown
    warnings: int = 0  # MuJoCo warnings raised during the simulation
    settings: WalkSettings = WalkSettings()
    pushed: float = 0.0  # impulse given by the push [N·s]

    @property
    def kp(self) -> float:
        return self.settings.kp

    @property
    def kv(self) -> float:
        return self.settings.kv

    def sensor(self, name: str) -> np.ndarray:
        """Readings (N, dim) of a named sensor."""
        sensor = self.model.sensor(name)
        return self.sensors[:, sensor.adr[0] : sensor.adr[0] + sensor.dim[0]]

    def step_slices(self) -> list[slice]:
        """Rows of each step."""
        ends = self.step_starts[1:] + [len(self.time)]
        return [slice(a, b) for a, b in zip(self.step_starts, ends, strict=True)]

    def stance_of(self) -> np.ndarray:
        """Stance side (N,) of every state."""
        return np.repeat(self.stances, np.diff(self.step_starts + [len(self.time)]))

    # -------------------------------------------------------------- named quantities (N,)
    def hip_x(self) -> np.ndarray:
        return self.layout.hip_x(self.qpos)

    def hip_height(self) -> np.ndarray:
        return self.layout.hip_height(self.qpos)

    def trunk_angle(self) -> np.ndarray:
        return self.layout.trunk_angle(self.qpos)

    def hip_speed(self) -> np.ndarray:
        return self.layout.hip_speed(self.qvel)

    def ankle_x(self, side: str) -> np.ndarray:
        return self.layout.ankle(self.sensors, side)[:, 0]

    def heel(self, side: str) -> np.ndarray:
        """(N, 3) [m]."""
        return self.layout.heel(self.sensors, side)

    def toe(self, side: str) -> np.ndarray:
        """(N, 3) [m]."""
        return self.layout.toe(self.sensors, side)

    def touch(self, side: str) -> np.ndarray:
        """Normal force [N] on a sole."""
        return self.layout.touch(self.sensors, side)

    def stance_foot_slip(self, settle: int = 0) -> np.ndarray:
        """Travel [m] of each step's stance sole on the ground (the spread of its middle's
        x) after its first ``settle`` states: a foot rolling on its sole barely moves its
        middle, a foot sliding moves it by the slide."""
        slips = []
        for rows, stance in zip(self.step_slices(), self.stances, strict=True):
            middle = 0.5 * (self.heel(stance)[rows, 0] + self.toe(stance)[rows, 0])
            slips.append(float(np.ptp(middle[settle:])) if len(middle) > settle else 0.0)
        return np.array(slips)

    # -------------------------------------------------------------- torques (N, 6)
    def motors(self) -> np.ndarray:
        """Torques (N, 6) the motors applied, in the paper's sign (Γ), in ``JOINT_ORDER``."""
        layout = self.layout
        low, high = self.model.actuator_ctrlrange[layout.motors].T
        limited = self.model.actuator_ctrllimited[layout.motors].astype(bool)
        u = self.ctrl[:, layout.motors]
        u = np.where(limited, np.clip(u, low, high), u)
        return -u * layout.gears

    def _speed_feedback(self) -> np.ndarray:
        """(N, 6) the stance ankle's torque on the speed, in its column."""
        torque = np.zeros((len(self.time), 6))
        for side in SIDES:
            rows = self.stance_of() == side
            torque[rows, JOINT_ORDER.index(f"{side}_ankle")] = self.speed_torque[rows]
        return torque

    def feedforward(self) -> np.ndarray:
        """The motors' torques (N, 6) less the ankle's torque on the speed: the file's torques
        and the rotors' (paper's sign, ``JOINT_ORDER``)."""
        return self.motors() - self._speed_feedback()

    def feedback(self) -> np.ndarray:
        """Torques (N, 6) of the position and velocity servos and of the stance ankle on the
        speed, in the paper's sign, in ``JOINT_ORDER``. The damping acts on the velocity at
        the end of each physics step (MuJoCo integrates it implicitly): reading it at the
        start would add h kv θ̈, an apparent inertia of 0.08 kg·m² at 2 ms and
        kv = 40 N·m·s/rad."""
        layout = self.layout
        stiffness = np.full((len(self.time), 6), self.kp)
        damping = np.full((len(self.time), 6), self.kv)
        for side in SIDES:
            free = self.stance_of() == side
            column = JOINT_ORDER.index(f"{side}_ankle")
            stiffness[free, column] = damping[free, column] = 0.0
        rates = layout.joint_angles(self.qvel)
        after = np.vstack([rates[1:], rates[-1:]])
        ends = [start - 1 for start in self.step_starts[1:]]  # gains change at a step's end
        after[ends] = rates[ends]
        servo = stiffness * (self.ctrl[:, layout.positions] - layout.joint_angles(self.qpos))
        servo += damping * (self.ctrl[:, layout.velocities] - after)
        # The servos act on MuJoCo's joint angle, minus θ; the stance ankle's speed torque.
        return -servo + self._speed_feedback()


class Walker:
    """A gait file prepared for walking on one MuJoCo model.

    Args:
        gait: the gait file's content (``biped.records.gait_file.read`` or ``to_dict``).
        model: the scene to walk on (``validate.model.model_spec``: a file, or by default the
            committed model of the gait's knee for Table 1, the generated one otherwise);
            a spec, or a path.
    """

    def __init__(self, gait: dict, model: mujoco.MjSpec | str | None = None):
        self.gait = gait
        self.biped: Biped = gait_biped(gait)
        self.samples = GaitSamples.from_gait(gait)
        spec = model if isinstance(model, mujoco.MjSpec) else model_spec(gait, self.biped, model)
        self.model = with_servos(spec, self.biped.knee, KP, KV)
        self.layout = Layout(self.model)
        self.table = phase_table(self.samples, self.layout, self.biped.radii)
        self._spare_data = []  # MjData of finished walks (list.pop and append are atomic)

    @property
    def period(self) -> float:
        return self.samples.period

    def walk(
        self, steps: int = DEFAULT_STEPS, settings: WalkSettings = WalkSettings()
    ) -> Simulation:
        """Play ``steps`` steps of the gait from its start state, left leg in stance first."""
        return _walk(self, steps, settings)


def simulate(
    gait: dict, steps: int = DEFAULT_STEPS, settings: WalkSettings = WalkSettings(), model=None
) -> Simulation:
    """``Walker(gait, model).walk(steps, settings)``."""
    return Walker(gait, model).walk(steps, settings)


# MuJoCo's warning handler while walks silence it: (walks under way, the handler before).
_QUIET = [0, None]
_QUIET_LOCK = threading.Lock()


@contextlib.contextmanager
def quiet_mujoco() -> Iterator[None]:
    """Within the block, MuJoCo's warnings are neither printed nor written to its log file
    (MuJoCo's own handler writes ``MUJOCO_LOG.TXT`` into the working directory): a walk counts
    them itself (``Simulation.warnings``) and a walk that raises one fails. Nests, and holds
    across threads: the handler comes back when the last block ends."""
    with _QUIET_LOCK:
        if _QUIET[0] == 0:
            _QUIET[1] = mujoco.get_mju_user_warning()
            mujoco.set_mju_user_warning(lambda message: None)
        _QUIET[0] += 1
    try:
        yield
    finally:
        with _QUIET_LOCK:
            _QUIET[0] -= 1
            if _QUIET[0] == 0:
                mujoco.set_mju_user_warning(_QUIET[1])


def _walk(walker: Walker, steps: int, settings: WalkSettings) -> Simulation:
    model = copy.deepcopy(walker.model)  # gains and friction change in it
    if settings.friction is not None:
        collides = (model.geom_contype != 0) | (model.geom_conaffinity != 0)
        model.geom_friction[collides, 0] = settings.friction
    # The data of a finished walk serves (the copy has the same sizes), reset as new.
    spare = walker._spare_data
    try:
        data = spare.pop()
    except IndexError:  # none spare (or another thread took it)
        data = mujoco.MjData(model)
    mujoco.mj_resetData(model, data)
    try:
        with quiet_mujoco():  # counted in the result
            return _walk_on(walker, steps, settings, model, data)
    finally:
        spare.append(data)


def _walk_on(walker, steps, settings, model, data) -> Simulation:
    layout = walker.layout.of(model)
    table, samples = walker.table, walker.samples
    q0, qd0 = samples.start()
    start = mapping(model, "left", walker.biped.radii)
    data.qpos[:] = start.qpos(q0)
    data.qvel[:] = start.qpos(qd0)
    mujoco.mj_forward(model, data)
    spec = mujoco.mjtState.mjSTATE_FULLPHYSICS
    dt = model.opt.timestep
    chunk = max(1, round(RESYNC / dt))
    period = samples.period
    capacity = int(np.ceil(steps * STEP_TIMEOUT * period / dt)) + chunk
    # MuJoCo reads each reading period's controls from these logs and writes its states and
    # sensors straight into them: row k holds the state at the k-th physics step, the
    # sensors computed at it and the controls of the step that follows it.
    log_state = np.empty((capacity, mujoco.mj_stateSize(model, spec)))
    log_ctrl = np.zeros((capacity, model.nu))
    log_sensors = np.empty((capacity, model.nsensordata))
    log_where = np.empty(capacity)  # position in the phase table
    log_speed = np.empty(capacity)
    mujoco.mj_getState(model, data, log_state[0], spec)
    log_sensors[0] = data.sensordata
    data.warning.number[:] = 0
    result = Simulation(model, layout, *(None,) * 6, settings=settings)
    x0, x_end = table.advance[0], table.advance[-1]
    last = len(table.advance) - 1
    per_metre = last / (x_end - x0)  # table rows per metre of hip advance
    speeds = table.speed.tolist()
    end_speed = speeds[-1]
    landing_row = LANDING_WINDOW * last
    floor = FALLEN * min(q0[ZH], samples.end()[0][ZH])
    ticks = np.arange(chunk) * dt
    last_tick = float(ticks[-1])
    columns = np.concatenate([layout.motors, layout.positions, layout.velocities])
    if np.array_equal(columns, np.arange(len(columns))):  # as validate.model orders them
        columns = slice(0, len(columns))
    warning_counts = data.warning.number  # a view: every rollout resets it, then counts
    no_warnings = warning_counts.tobytes()
    interpolants = table.interpolants
    index = np.empty(chunk, dtype=np.intp)
    weight = np.empty(chunk)
    # The table's columns at the period's points and their increments to the next point
    # (``PhaseTable.interpolants``), gathered into one buffer, and named views of it.
    gathered = np.empty((48, chunk))
    rows, increments = gathered[:24], gathered[24:]
    torques, references, rates, rotors = rows[:6], rows[6:12], rows[12:18], rows[18:24]
    commands = rows[:18].T  # (chunk, 18): the period's controls in ``columns`` order
    rotor_torques = np.empty((6, chunk))
    lowest = np.minimum.reduce
    timeout = STEP_TIMEOUT * period
    push = settings.push
    remaining = 0.0 if push is None else float(push.impulse)  # impulse still to give [N·s]
    # A push goes in as an applied force on the trunk (xfrc_applied) beside the controls.
    only_controls = int(mujoco.mjtState.mjSTATE_CTRL)
    with_force = int(mujoco.mjtState.mjSTATE_CTRL | mujoco.mjtState.mjSTATE_XFRC_APPLIED)
    pushed_in = np.zeros((1, chunk, model.nu + 6 * model.nbody))
    hip_x_at, hip_speed_at = layout.state_index("hip_x"), layout.state_index("hip_speed")
    hip_height_at = layout.state_index("hip_height")
    warmstart = data.qacc_warmstart[None]
    models, datas = [model], [data]
    k = 0
    with rollout.Rollout(nthread=0) as runner:
        for j in range(steps):
            stance = SIDES[j % 2]
            interpolant = interpolants[stance]
            set_gains(model, layout, stance, settings.kp, settings.kv)
            result.step_starts.append(k)
            result.stances.append(stance)
            began, landed, fallen, lifted = log_state[k, 0], False, False, False
            ankle_at = layout.sensor_index(stance, "ankle_pos")
            touch_at = layout.sensor_index(other(stance), "touch")
            ankle_column = JOINT_ORDER.index(f"{stance}_ankle")
            ankle_gear = float(layout.gears[ankle_column])
            ankle_torque = rows[ankle_column]
            while log_state.item(k, 0) - began < timeout and k < capacity - chunk:
                # The phase now, and as it goes on at the hip's present speed (the stance
                # ankle's position is the reading of one physics step before: the foot is
                # on the ground).
                hip_speed = log_state.item(k, hip_speed_at)
                here = log_state.item(k, hip_x_at) - log_sensors.item(max(k - 1, 0), ankle_at)
                where = log_where[k : k + chunk]
                np.multiply(ticks, hip_speed, out=where)
                where += here
                where -= x0
                where *= per_metre
                # ``where`` is monotonic over the reading period: its ends bound it
                first, final = where.item(0), where.item(-1)
                low, high = (first, final) if first <= final else (final, first)
                if low < 0.0 or high > last:
                    np.clip(where, 0.0, last, out=where)
                index[:] = where  # truncated: where >= 0
                if high >= last:
                    np.minimum(index, last - 1, out=index)
                np.subtract(where, index, out=weight)
                # The table between its points, column by column (24, chunk); ``index`` is
                # within it, and "clip" writes straight into the buffer ("raise" copies).
                interpolant.take(index, axis=1, out=gathered, mode="clip")
                increments *= weight
                rows += increments
                if last_tick * hip_speed + here > x_end:  # the last of ``advance``, below
                    # Past the end of the step the reference goes on at the end's rates: the
                    # swing foot keeps coming down to the floor.
                    advance = ticks * hip_speed
                    advance += here
                    beyond = np.maximum(advance - x_end, 0.0) / end_speed
                    references += rates * beyond
                a, b = index.item(0), weight.item(0)
                planned = speeds[a] + (speeds[a + 1] - speeds[a]) * b
                rate = min(max(hip_speed / planned, RATE_RANGE[0]), RATE_RANGE[1])
                rates *= rate
                np.multiply(rotors, rate * rate, out=rotor_torques)
                torques += rotor_torques
                # The ankle strategy: the stance ankle's torque grows with the hip's excess
                # speed (its centre of pressure moves forward and slows the robot down).
                speed_torque = SPEED_GAIN * (hip_speed - planned)
                ankle_torque -= speed_torque / ankle_gear
                block = log_ctrl[k : k + chunk]
                block[:, columns] = commands
                pushing = remaining != 0.0 and log_state.item(k, 0) >= push.time
                if pushing:  # the rest of the push's impulse over this reading period
                    force = remaining / (chunk * dt)
                    pushed_in[0][:, : model.nu] = block
                    pushed_in[0][:, model.nu + 6 * layout.trunk] = force
                runner.rollout(
                    models,
                    datas,
                    log_state[k : k + 1],
                    pushed_in if pushing else block[None],
                    control_spec=with_force if pushing else only_controls,
                    nstep=chunk,
                    initial_warmstart=warmstart,
                    state=log_state[None, k + 1 : k + 1 + chunk],
                    sensordata=log_sensors[None, k : k + chunk],
                    skip_checks=True,
                )
                if warning_counts.tobytes() != no_warnings:  # reset by every rollout
                    result.warnings += int(warning_counts.sum())
                # log_state[k + 1 + r]: the state after physics step r of this period;
                # log_sensors[k + r]: the sensors computed before it, at the state it
                # started from.
                n = chunk
                # A landing: the swing foot, off the ground since some time in this step,
                # touches it in the landing window (a foot that never lifts makes no steps).
                aloft = True
                if not lifted or final >= landing_row:
                    contact = log_sensors[k : k + chunk, touch_at] > TOUCH_THRESHOLD
                    if not lifted:
                        aloft = np.logical_or.accumulate(~contact)
                        lifted = bool(aloft[-1])
                    if final >= landing_row and contact.any():
                        down = np.flatnonzero((where >= landing_row) & contact & aloft)
                        if len(down):
                            n, landed = int(down[0]) + 1, True
                heights = log_state[k + 1 : k + 1 + n, hip_height_at]
                if not lowest(heights) >= floor:  # below the floor, or not finite
                    n, fallen, landed = int(np.argmax(~(heights >= floor))) + 1, True, False
                if pushing:
                    result.pushed += force * n * dt
                    remaining = 0.0 if n == chunk else remaining - force * n * dt
                log_speed[k : k + n] = speed_torque
                k += n
                if landed or fallen:
                    break
            result.landed.append(landed)
            if not landed:
                break
    states = log_state[:k]
    result.time = states[:, 0]
    result.qpos = layout.state_qpos(states)
    result.qvel = layout.state_qvel(states)
    result.ctrl = log_ctrl[:k]
    result.sensors = log_sensors[:k]
    result.phase = np.interp(log_where[:k], np.arange(last + 1), table.tau)
    result.speed_torque = log_speed[:k]
    return result


def reference_along(samples: GaitSamples, sim: Simulation):
    """The gait file's samples at the phase the controller followed, at every simulation
    state.

    Returns:
        q (N, 9), torques (N, 6), wrench (N, 3) and ZMP (N,) of the gait.
    """
    fields = ("q", "torques", "wrench", "zmp")
    q, torques, wrench, zmp = (samples.at(name, sim.phase) for name in fields)
    return q, torques, wrench, zmp[:, 0]
