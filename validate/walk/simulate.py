"""Forward simulation of a gait file in MuJoCo with contact, legs alternating every step.

What is played is the file: the motors apply the torques of its samples (``validate.walk.samples``)
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
with the feedback closed at every physics step by its servos (``validate.scene.model.with_servos``).

The stance ankle has no servo: its torque places the centre of pressure under the foot, and a
servo there (kp = 2000 N·m/rad against a pendulum of m g l ≈ 600 N·m/rad) would move the
centre of pressure by centimetres for a few hundredths of a radian, roll the foot and trip the
robot. It carries the file's Γ1 and the ankle strategy of a walker, a torque on the speed:

    u_ankle = Γ1(τ) + J_r θ̈1 ṡ²  +  K (ẋ_H - ẋ_H,ref(τ))        K = ``SPEED_GAIN``

(a robot a little fast moves its centre of pressure forward by K Δẋ / F_z, 3 mm for 1 cm/s,
and slows down). Without it the gait's speed is held by the servos alone: with the
validation's stiffness the optimal gaits at 0.3 m/s still walk their period (0.98-0.99 T a
step), with three quarters of it they settle on another orbit, 1.13-1.14 T a step, and with
half of it they lose speed step after step (1.3 T a step after 10 steps) until their swing
foot, clearing the ground by a millimetre, scuffs it. The five other joints
track their reference with ``KP``, ``KV`` (times ``WalkSettings.kp_scale``, ``kv_scale``; K
times ``WalkSettings.speed_scale``).

A step ends when the swing foot, after leaving the ground, touches it in the landing window
(the last ``1 - LANDING_WINDOW`` of the step, by phase); the legs then swap roles. A foot
late for the floor keeps coming down: past the end of the step the references go on at the
step's end rates. A touch between the lift-off (the first ``LIFT_WINDOW`` of the step) and
the landing window is a scuff: the step goes on (``validate.walk.contact`` reports it). If the
foot has not landed after ``STEP_TIMEOUT`` periods, or the hip has dropped below ``FALLEN``
of its height, the walk ends.

A two-phase gait (``GaitSamples.double_support``) is walked the same way through both
phases: the phase table runs from lift-off through the single support and the double
support to the next lift-off (the hip advances over the rear ankle throughout). The swing
foot's touch in the landing window (the last ``1 - LANDING_WINDOW`` of the single support's
advance) is its touchdown (``Simulation.touchdowns``); the controller goes on with both
feet on the floor, the rear ankle free as the stance ankle, every other joint on its servo,
and the step ends at the rear foot's lift-off: the phase at the end of the table with the
front foot on the floor. The legs then swap and the next step lifts the former rear foot.
Once the front foot has landed (the first reading at or past the file's landing τ = T after
the touchdown) its leg's references are re-anchored on the foot where it landed, so that the
servos' chain closes (``validate.walk.anchor``, ``LandedChain``; ``WalkSettings.close_chain``
off: the file's references throughout).

``Walker`` prepares a gait on a model once; ``Walker.walk`` runs it under ``WalkSettings``
(gains, friction, a push): the robustness of a gait is many walks of one walker. A walk starts
from the file's start state, or from another state of the left leg in stance (``start``), and
may end its last step when the hip has advanced by a given distance over the stance ankle
(``stop_advance``): the return map of ``validate.checks.orbit`` is walks from one section of the
orbit to the next.
"""

from __future__ import annotations

import contextlib
import copy
import functools
from collections.abc import Iterator
from dataclasses import dataclass, field

import mujoco
import numpy as np
from mujoco import rollout

from biped.errors import BipedError
from biped.model.dynamics import Biped
from biped.model.kinematics import XH, ZH
from biped.records.gait_file import Gait
from validate import DEFAULT_STEPS, SERVO_KP
from validate.scene.layout import Layout
from validate.scene.mapping import mapping, other, rotor_torques
from validate.scene.mjcf import SIDES
from validate.scene.model import JOINT_ORDER, model_spec, with_servos
from validate.walk.anchor import ChainAnchor, landed_step_length
from validate.walk.samples import GaitSamples

__all__ = ["JOINT_ORDER", "Push", "Simulation", "WalkSettings", "Walker", "simulate"]

# Joint-space feedback gains of the five tracked joints: stiffness [N·m/rad], damping
# [N·m·s/rad]. The stance ankle has none (see the module docstring).
KP = SERVO_KP
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
# Columns of a phase table's controls (``PhaseTable.controls``), six each in ``JOINT_ORDER``:
# the motors' torques, the servos' references and reference rates (the actuators' commands),
# and the rotors' torques per unit ṡ².
TORQUES, REFERENCES, RATES, ROTORS = (slice(6 * i, 6 * i + 6) for i in range(4))
CONTROLS, COMMANDS = 24, slice(0, 18)


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
        speed_scale: the stance ankle's gain on the hip's speed is ``SPEED_GAIN`` times this
            (0: the speed loop off).
        friction: sliding friction coefficient of the soles and the floor (None: the
            model's, ``biped.model.robot.FOOT_FRICTION``).
        push: a shove on the trunk (None: none).
        close_chain: a two-phase gait's front leg re-anchored at its touchdown on the foot
            where it landed (``validate.walk.anchor``; False: the file's references
            throughout the double support). No effect on a gait of single support.
    """

    kp_scale: float = 1.0
    kv_scale: float = 1.0
    speed_scale: float = 1.0
    friction: float | None = None
    push: Push | None = None
    close_chain: bool = True

    @property
    def kp(self) -> float:
        return KP * self.kp_scale

    @property
    def kv(self) -> float:
        return KV * self.kv_scale

    @property
    def speed_gain(self) -> float:
        """[N·s] the stance ankle's torque per m/s of the hip's excess speed."""
        return SPEED_GAIN * self.speed_scale


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
        controls: stance side -> (N, ``CONTROLS``): the file's torques of the six motors (as
            their controls), joint references, reference rates, and what each motor adds per
            unit ṡ² to turn its rotor (``Layout.rotor_inertia`` θ̈_ref): ``TORQUES``, ...
        double_support: the step ends with a double support (a two-phase gait's, from its
            landing to the rear foot's lift-off at the table's end).
        motion: a two-phase gait's (q, q̇) (N, 9) each at the table's points, the paper's
            coordinates of the left leg in stance (``validate.walk.anchor``); None: a gait
            of single support.
    """

    advance: np.ndarray
    tau: np.ndarray
    speed: np.ndarray
    controls: dict
    double_support: bool = False
    motion: tuple[np.ndarray, np.ndarray] | None = None

    @functools.cached_property
    def interpolants(self) -> dict:
        """Stance side -> ``interpolant`` of its ``controls``."""
        return {side: interpolant(rows) for side, rows in self.controls.items()}


def interpolant(controls: np.ndarray) -> np.ndarray:
    """(2 ``CONTROLS``, N - 1): ``controls`` (N, ``CONTROLS``) as columns (less the last
    point) over each column's increments to the next point: what the walk interpolates,
    laid out for one gather."""
    return np.ascontiguousarray(np.hstack([controls[:-1], np.diff(controls, axis=0)]).T)


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
        table = controls[side] = np.zeros((points, CONTROLS))
        # Motor controls: MuJoCo's joint torque -Γ, per unit of gear (validate.scene.mjcf: gear -1).
        table[:, TORQUES][:, mapped.columns] = -torques
        table[:, TORQUES] /= layout.gears
        table[:, REFERENCES] = layout.joint_angles(mapped.qpos(q))
        table[:, RATES] = layout.joint_angles(mapped.qvel(q, qd))
        table[:, ROTORS] = rotor_torques(mapped, layout, q, qd, qdd)
        table[:, ROTORS] /= layout.gears
    return PhaseTable(
        advance,
        tau,
        speed=qd[:, XH],
        controls=controls,
        double_support=samples.two_phase,
        motion=(q, qd) if samples.two_phase else None,
    )


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
    landed: list = field(default_factory=list)  # whether each step ended on its event
    # A two-phase gait's walk: each step's touchdown row (None: none), the double support
    # from it to the step's end (its lift-off); a single support's steps end at touchdown.
    double_support: bool = False
    touchdowns: list = field(default_factory=list)
    # Each step's front leg re-anchored at its touchdown (``validate.walk.anchor.Anchoring``;
    # None: not re-anchored, ``WalkSettings.close_chain`` off or no touchdown).
    anchorings: list = field(default_factory=list)
    warnings: int = 0  # MuJoCo warnings raised during the simulation
    settings: WalkSettings = WalkSettings()
    pushed: float = 0.0  # impulse given by the push [N·s]

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

    def supports(self, settle: int = 0) -> list[list[tuple[str, slice]]]:
        """Per step, each foot's rows while it is a support, its landing settled (its first
        ``settle`` states after touchdown left out): a single support's stance foot after
        the step's first ``settle`` states; a two-phase walk's stance foot from its
        touchdown in the step before (settled; the walk's start for the first step) to the
        step's lift-off, and its front foot from its touchdown (settled) to the lift-off."""
        steps = zip(self.step_slices(), self.stances, strict=True)
        if not self.double_support:
            return [[(stance, slice(min(r.start + settle, r.stop), r.stop))] for r, stance in steps]
        spans, since = [], 0  # the walk starts with both feet at rest on the floor
        for (rows, stance), down in zip(steps, self.touchdowns, strict=True):
            step = [(stance, slice(since, rows.stop))]  # since: at or before its start
            if down is not None:
                since = min(down + settle, rows.stop)
                step.append((other(stance), slice(since, rows.stop)))
            spans.append(step)
        return spans

    def landings(self, settle: int = 0) -> list[tuple[str, slice]]:
        """Per step, the landing foot and its first ``settle`` states on the floor: the
        stance foot at a single support's step start, the front foot from a two-phase
        step's touchdown (none: an empty slice)."""
        steps = zip(self.step_slices(), self.stances, strict=True)
        if not self.double_support:
            return [(stance, slice(r.start, min(r.start + settle, r.stop))) for r, stance in steps]
        return [
            (
                other(stance),
                slice(r.stop, r.stop) if down is None else slice(down, min(down + settle, r.stop)),
            )
            for (r, stance), down in zip(steps, self.touchdowns, strict=True)
        ]

    def stance_foot_slip(self, settle: int = 0, landing: bool = False) -> np.ndarray:
        """Travel [m] of each step's supporting soles on the ground (the spread of a sole's
        middle x, the largest of the feet's ``supports``), or during the landing foot's
        first ``settle`` states (``landing``): a foot rolling on its sole barely moves its
        middle, a foot sliding moves it by the slide."""
        steps = [[span] for span in self.landings(settle)] if landing else self.supports(settle)
        return np.array(
            [max(self._sole_travel(side, rows) for side, rows in step) for step in steps]
        )

    def _sole_travel(self, side: str, rows: slice) -> float:
        """[m] the spread of a sole's middle x over ``rows`` (0: none)."""
        middle = 0.5 * (self.heel(side)[rows, 0] + self.toe(side)[rows, 0])
        return float(np.ptp(middle)) if len(middle) else 0.0

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
        start would add h kv θ̈, an apparent inertia of 0.04 kg·m² at 1 ms and
        kv = 40 N·m·s/rad."""
        layout = self.layout
        stiffness = np.full((len(self.time), 6), self.settings.kp)
        damping = np.full((len(self.time), 6), self.settings.kv)
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
        gait: the gait (``Gait``).
        model: the scene to walk on (``validate.scene.model.model_spec``: a file, or by default the
            committed model of the gait's knee for Table 1, the generated one otherwise);
            a spec, or a path.
    """

    def __init__(self, gait: Gait, model: mujoco.MjSpec | str | None = None):
        self.gait = gait
        self.biped: Biped = self.gait.biped
        self.samples = GaitSamples.from_gait(self.gait)
        spec = model if isinstance(model, mujoco.MjSpec) else model_spec(self.biped, model)
        self.model = with_servos(spec, self.biped.knee, KP, KV)
        self.layout = Layout(self.model)
        self.table = phase_table(self.samples, self.layout, self.biped.radii)
        self.spare_data = []  # MjData of finished walks (list.pop and append are atomic)

    @property
    def period(self) -> float:
        return self.samples.period

    def walk(
        self,
        steps: int = DEFAULT_STEPS,
        settings: WalkSettings = WalkSettings(),
        start: tuple[np.ndarray, np.ndarray] | None = None,
        stop_advance: float | None = None,
    ) -> Simulation:
        """Play ``steps`` steps of the gait, left leg in stance first.

        Args:
            start: (q, q̇) (9,) each, the paper's coordinates of the left leg in stance, its
                ankle at x = 0 (None: the file's start state).
            stop_advance: [m] the last step ends at the end of the reading period in which
                the hip's advance over the stance ankle passes this (None: at its landing);
                that step is not ``landed``.
        """
        return _walk(self, steps, settings, start, stop_advance)


def simulate(
    gait: Gait,
    steps: int = DEFAULT_STEPS,
    settings: WalkSettings = WalkSettings(),
    model=None,
) -> Simulation:
    """``Walker(gait, model).walk(steps, settings)``."""
    return Walker(gait, model).walk(steps, settings)


@contextlib.contextmanager
def quiet_mujoco() -> Iterator[None]:
    """Within the block, MuJoCo's warnings are neither printed nor written to its log file
    (MuJoCo's own handler writes ``MUJOCO_LOG.TXT`` into the working directory): a walk counts
    them itself (``Simulation.warnings``) and a walk that raises one fails. The handler before
    comes back when the block ends (walks run one at a time in a process)."""
    before = mujoco.get_mju_user_warning()
    mujoco.set_mju_user_warning(lambda message: None)
    try:
        yield
    finally:
        mujoco.set_mju_user_warning(before)


def _walk(walker: Walker, steps: int, settings: WalkSettings, start, stop_advance) -> Simulation:
    model = copy.deepcopy(walker.model)  # gains and friction change in it
    if settings.friction is not None:
        collides = (model.geom_contype != 0) | (model.geom_conaffinity != 0)
        model.geom_friction[collides, 0] = settings.friction
    # The data of a finished walk serves (the copy has the same sizes), reset as new.
    spare = walker.spare_data
    try:
        data = spare.pop()
    except IndexError:  # none spare (or another thread took it)
        data = mujoco.MjData(model)
    mujoco.mj_resetData(model, data)
    try:
        with quiet_mujoco():  # counted in the result
            return _walk_on(walker, steps, settings, model, data, start, stop_advance)
    finally:
        spare.append(data)


class WalkLog:
    """The walk's preallocated record, which MuJoCo's rollouts write into and read their
    controls from: row k holds the state at the k-th physics step, the sensors computed at it,
    the controls of the step that follows it, the controller's place in the phase table
    (``where``) and the stance ankle's torque on the speed. ``rows`` are written; per step,
    its first row, stance side and whether it landed; ``warnings``: MuJoCo's, counted."""

    SPEC = mujoco.mjtState.mjSTATE_FULLPHYSICS

    def __init__(self, model: mujoco.MjModel, data: mujoco.MjData, capacity: int):
        self.state = np.empty((capacity, mujoco.mj_stateSize(model, self.SPEC)))
        self.ctrl = np.zeros((capacity, model.nu))
        self.sensors = np.empty((capacity, model.nsensordata))
        self.where, self.speed_torque = np.empty(capacity), np.empty(capacity)
        self.rows, self.step_starts, self.stances, self.landed = 0, [], [], []
        self.touchdowns = []  # a two-phase walk's, per step (``StepEvents.touchdown``)
        self.anchorings = []  # a two-phase walk's, per step (``LandedChain.anchoring``)
        mujoco.mj_getState(model, data, self.state[0], self.SPEC)
        self.sensors[0] = data.sensordata
        self.models, self.datas, self.warmstart = [model], [data], data.qacc_warmstart[None]
        self.counts = data.warning.number  # a view: every rollout resets it, then counts
        self.counts[:] = 0
        self.no_warnings, self.warnings = self.counts.tobytes(), 0

    def rollout(self, runner, k: int, nstep: int, controls: np.ndarray, spec: int) -> None:
        """MuJoCo's ``nstep`` physics steps from row k under ``controls`` (of ``spec``):
        state[k + 1 + r] is the state after step r, sensors[k + r] those computed before it."""
        runner.rollout(
            self.models,
            self.datas,
            self.state[k : k + 1],
            controls,
            control_spec=spec,
            nstep=nstep,
            initial_warmstart=self.warmstart,
            state=self.state[None, k + 1 : k + 1 + nstep],
            sensordata=self.sensors[None, k : k + nstep],
            skip_checks=True,
        )
        if self.counts.tobytes() != self.no_warnings:
            self.warnings += int(self.counts.sum())

    def simulation(self, layout: Layout, table: PhaseTable, **results) -> Simulation:
        """The rows written, a ``Simulation`` with ``results`` (settings, pushed)."""
        k, states = self.rows, self.state[: self.rows]
        return Simulation(
            layout.model,
            layout,
            time=states[:, 0],
            qpos=layout.state_qpos(states),
            qvel=layout.state_qvel(states),
            ctrl=self.ctrl[:k],
            sensors=self.sensors[:k],
            phase=np.interp(self.where[:k], np.arange(len(table.tau)), table.tau),
            speed_torque=self.speed_torque[:k],
            step_starts=self.step_starts,
            stances=self.stances,
            landed=self.landed,
            double_support=table.double_support,
            touchdowns=self.touchdowns,
            anchorings=self.anchorings,
            warnings=self.warnings,
            **results,
        )


class PhaseController:
    """The controls of each reading period (the module docstring's u and u_ankle): the phase
    read from the state and carried on at the hip's speed, the phase table's rows there
    (``PhaseTable.interpolants``) gathered into one buffer, scaled through its named views
    and written into the log in the actuators' order."""

    def __init__(self, table: PhaseTable, layout: Layout, chunk: int, dt: float, speed_gain: float):
        self.interpolants, self.layout, self.speed_gain = table.interpolants, layout, speed_gain
        self.x0, self.x_end, self.last = table.advance[0], table.advance[-1], len(table.tau) - 1
        self.per_metre = self.last / (self.x_end - self.x0)  # table rows per metre of advance
        self.speeds = table.speed.tolist()
        self.ticks = np.arange(chunk) * dt  # [s] from the reading
        self.last_tick = float(self.ticks[-1])
        self.index, self.weight = np.empty(chunk, dtype=np.intp), np.empty(chunk)
        # The table's rows at the period's points, over their increments to the next point.
        self.gathered = np.empty((2 * CONTROLS, chunk))
        self.rows, self.increments = self.gathered[:CONTROLS], self.gathered[CONTROLS:]
        named = (self.rows[part] for part in (TORQUES, REFERENCES, RATES, ROTORS))
        self.torques, self.references, self.rates, self.rotors = named
        self.rotor_torques = np.empty_like(self.rotors)
        columns = np.concatenate([layout.motors, layout.positions, layout.velocities])
        self.commands = self.rows[COMMANDS].T  # (chunk, 18): in ``columns`` order
        ordered = np.array_equal(columns, np.arange(len(columns)))  # as validate.scene.model does
        self.columns = slice(0, len(columns)) if ordered else columns
        self.hip_x_at, self.hip_speed_at = map(layout.state_index, ("hip_x", "hip_speed"))

    def start_step(self, stance: str) -> None:
        self.interpolant = self.interpolants[stance]
        self.ankle_at = self.layout.sensor_index(stance, "ankle_pos")
        ankle = JOINT_ORDER.index(f"{stance}_ankle")
        self.ankle_gear, self.ankle_torque = float(self.layout.gears[ankle]), self.rows[ankle]

    def before_step(self, log: WalkLog, k: int) -> np.ndarray:
        """The controls of the reading period from row k, written into the log (returned)."""
        # The phase now, and as it goes on at the hip's present speed (the stance ankle's
        # position is the reading of one physics step before: the foot is on the ground).
        hip_speed = log.state.item(k, self.hip_speed_at)
        here = log.state.item(k, self.hip_x_at) - log.sensors.item(max(k - 1, 0), self.ankle_at)
        period = slice(k, k + len(self.ticks))
        where = log.where[period]
        np.multiply(self.ticks, hip_speed, out=where)  # in place: no temporaries per period
        where += here
        where -= self.x0
        where *= self.per_metre
        a, b = self._gather(where)
        if self.last_tick * hip_speed + here > self.x_end:  # the last of ``advance``, below
            # Past the end of the step the reference goes on at the end's rates: the swing
            # foot keeps coming down to the floor.
            beyond = np.maximum(self.ticks * hip_speed + here - self.x_end, 0.0)
            self.references += self.rates * (beyond / self.speeds[-1])
        planned = self.speeds[a] + (self.speeds[a + 1] - self.speeds[a]) * b
        rate = min(max(hip_speed / planned, RATE_RANGE[0]), RATE_RANGE[1])
        self.rates *= rate
        self.torques += np.multiply(self.rotors, rate * rate, out=self.rotor_torques)
        # The ankle strategy: the stance ankle's torque grows with the hip's excess speed
        # (its centre of pressure moves forward and slows the robot down).
        speed_torque = log.speed_torque[period] = self.speed_gain * (hip_speed - planned)
        self.ankle_torque -= speed_torque / self.ankle_gear
        block = log.ctrl[period]
        block[:, self.columns] = self.commands
        return block

    def anchor(self, controls: np.ndarray) -> None:
        """Follow ``controls`` (N, ``CONTROLS``) for the rest of the step."""
        self.interpolant = interpolant(controls)

    def advance(self, log: WalkLog, k: int) -> float:
        """[m] the hip's advance over the stance ankle at row k (the phase's reading)."""
        return log.state.item(k, self.hip_x_at) - log.sensors.item(k, self.ankle_at)

    def _gather(self, where: np.ndarray) -> tuple[int, float]:
        """The table between its points at ``where`` (table rows, clipped to the table) into
        ``rows``; returns the first point's row and weight."""
        last, index, weight = self.last, self.index, self.weight
        # ``where`` is monotonic over the reading period: its ends bound it
        first, final = where.item(0), where.item(-1)
        low, high = (first, final) if first <= final else (final, first)
        if low < 0.0 or high > last:
            np.clip(where, 0.0, last, out=where)
        index[:] = where  # truncated: where >= 0
        if high >= last:
            np.minimum(index, last - 1, out=index)
        np.subtract(where, index, out=weight)
        # ``index`` is within the table: "clip" writes straight into the buffer ("raise" copies)
        self.interpolant.take(index, axis=1, out=self.gathered, mode="clip")
        self.increments *= weight
        self.rows += self.increments
        return index.item(0), weight.item(0)


class StepEvents:
    """How a step ends (the module docstring): the swing foot, off the ground since some time
    in the step, touches it in the landing window (``landed``); a two-phase gait's step goes
    on through its double support from that touchdown (``touchdown``, its row) and ends at
    the rear foot's lift-off, the phase at the end of the step with the front foot on the
    floor. Or the hip drops below ``floor`` [m] (``fallen``), ``timeout`` [s] passes, or the
    log is full (``rows``)."""

    def __init__(
        self, layout: Layout, table: PhaseTable, samples: GaitSamples, floor, timeout, rows
    ):
        self.layout, self.floor, self.timeout, self.rows = layout, floor, timeout, rows
        last_row = len(table.tau) - 1
        # The landing's row: the end of the step, or a two-phase gait's touchdown (τ = T).
        landing = last_row
        self.lift_row = None  # a step of single support ends at its touchdown
        if samples.two_phase:
            landing = float(np.interp(samples.landing, table.tau, np.arange(len(table.tau))))
            self.lift_row = last_row
        self.landing_row = LANDING_WINDOW * landing
        self.hip_height_at = layout.state_index("hip_height")

    def start_step(self, stance: str, log: WalkLog) -> None:
        self.touch_at = self.layout.sensor_index(other(stance), "touch")
        self.began = log.state[log.rows, 0]
        self.lifted = self.landed = self.fallen = False
        self.touchdown = None  # [row] of a two-phase step's touchdown

    def running(self, log: WalkLog, chunk: int) -> bool:
        k = log.rows
        ended = self.landed or self.fallen or k >= self.rows - chunk
        return not ended and log.state.item(k, 0) - self.began < self.timeout

    def after_step(self, log: WalkLog, k: int, chunk: int) -> int:
        """The physics steps of the period from row k that belong to the step: up to its
        landing (a two-phase step's lift-off) or its fall, if either came in it."""
        n, aloft, where = chunk, True, log.where[k : k + chunk]  # clipped: in the window alike
        if not self.lifted or where.item(-1) >= self.landing_row:
            contact = log.sensors[k : k + chunk, self.touch_at] > TOUCH_THRESHOLD
            if not self.lifted:  # a foot that never lifts makes no steps
                aloft = np.logical_or.accumulate(~contact)
                self.lifted = bool(aloft[-1])
            if where.item(-1) >= self.landing_row and contact.any() and self.touchdown is None:
                down = np.flatnonzero((where >= self.landing_row) & contact & aloft)
                if len(down) and self.lift_row is None:
                    n, self.landed = int(down[0]) + 1, True
                elif len(down):
                    self.touchdown = k + int(down[0])
            if self.touchdown is not None and where.item(-1) >= self.lift_row:
                after = np.arange(k, k + chunk) >= self.touchdown
                lift = np.flatnonzero((where >= self.lift_row) & contact & after)
                if len(lift):
                    n, self.landed = int(lift[0]) + 1, True
        heights = log.state[k + 1 : k + 1 + n, self.hip_height_at]
        if not np.minimum.reduce(heights) >= self.floor:  # below the floor, or not finite
            n, self.fallen, self.landed = int(np.argmax(~(heights >= self.floor))) + 1, True, False
            if self.touchdown is not None and self.touchdown >= k + n:
                self.touchdown = None
        return n


class LandedChain:
    """The double support closed on the landed feet (``validate.walk.anchor``): at a
    step's touchdown, the front leg's references re-anchored on the foot where it landed,
    from the table's point of the touchdown to the step's end; ``anchoring``: the step's
    (None before its touchdown)."""

    def __init__(
        self, table: PhaseTable, samples: GaitSamples, layout: Layout, biped: Biped, log: WalkLog
    ):
        self.table, self.log, self.layout, self.biped = table, log, layout, biped
        self.anchor = ChainAnchor(table, layout, biped)
        # The table's (fractional) row of the file's landing, τ = T.
        self.landing_row = float(np.interp(samples.landing, table.tau, np.arange(len(table.tau))))
        self.landing_row = 0.0

    def start_step(self, stance: str) -> None:
        self.stance, self.anchoring = stance, None

    def after_step(self, events: StepEvents, controller: PhaseController) -> None:
        """Re-anchor once: at the end of the first reading period after the touchdown that
        reaches the file's landing (τ = T), the foot then at rest where it landed."""
        log = self.log
        row = log.rows - 1  # the period's last state
        if self.anchoring is not None or events.touchdown is None or events.fallen:
            return
        if log.where[row] < self.landing_row:
            return
        step_length = landed_step_length(self.layout, self.biped, log.sensors[row], self.stance)
        self.anchoring = self.anchor.anchoring(int(log.where[row]), step_length)
        references, rates = self.anchor.servo_commands(self.stance, self.anchoring)
        controls = self.table.controls[self.stance].copy()
        controls[self.anchoring.start :, REFERENCES] = references
        controls[self.anchoring.start :, RATES] = rates
        controller.anchor(controls)


class Shove:
    """The push of ``WalkSettings.push``: the rest of its impulse as a constant force on the
    trunk (MuJoCo's applied force, beside the controls) over each reading period from its
    time until it is given; ``pushed`` [N·s]: what was given."""

    ONLY_CONTROLS = int(mujoco.mjtState.mjSTATE_CTRL)
    WITH_FORCE = int(mujoco.mjtState.mjSTATE_CTRL | mujoco.mjtState.mjSTATE_XFRC_APPLIED)

    def __init__(self, push: Push | None, model: mujoco.MjModel, layout: Layout, chunk, dt):
        self.push, self.chunk, self.dt, self.nu = push, chunk, dt, model.nu
        self.remaining = 0.0 if push is None else float(push.impulse)  # still to give [N·s]
        self.pushed, self.force = 0.0, None
        self.trunk_force_x = model.nu + 6 * layout.trunk
        self.controls = np.zeros((1, chunk, model.nu + 6 * model.nbody))

    def before_step(self, log: WalkLog, k: int, block: np.ndarray) -> tuple[np.ndarray, int]:
        """The rollout's controls of the period from row k, and their ``mjtState`` spec."""
        self.force = None
        if not (self.remaining != 0.0 and log.state.item(k, 0) >= self.push.time):
            return block[None], self.ONLY_CONTROLS
        self.force = self.remaining / (self.chunk * self.dt)
        self.controls[0][:, : self.nu] = block
        self.controls[0][:, self.trunk_force_x] = self.force
        return self.controls, self.WITH_FORCE

    def after_step(self, n: int) -> None:
        """The first ``n`` physics steps of the period were walked."""
        if self.force is not None:
            self.pushed += self.force * n * self.dt
            self.remaining = 0.0 if n == self.chunk else self.remaining - self.force * n * self.dt


def _walk_on(walker, steps, settings, model, data, start=None, stop_advance=None) -> Simulation:
    layout, samples, period = walker.layout.of(model), walker.samples, walker.period
    q0, qd0 = samples.start() if start is None else start
    left = mapping(model, "left", walker.biped.radii)
    data.qpos[:], data.qvel[:] = left.qpos(q0), left.qvel(q0, qd0)
    mujoco.mj_forward(model, data)
    dt = model.opt.timestep
    chunk = max(1, round(RESYNC / dt))  # physics steps per reading period
    log = WalkLog(model, data, int(np.ceil(steps * STEP_TIMEOUT * period / dt)) + chunk)
    controller = PhaseController(walker.table, layout, chunk, dt, settings.speed_gain)
    floor = FALLEN * min(samples.start()[0][ZH], samples.end()[0][ZH])
    timeout = STEP_TIMEOUT * period
    closes = walker.table.double_support and settings.close_chain
    events = StepEvents(layout, walker.table, samples, floor, timeout, len(log.where))
    shove = Shove(settings.push, model, layout, chunk, dt)
    anchor = LandedChain(walker.table, samples, layout, walker.biped, log) if closes else None
    if anchor is not None:
        anchor.landing_row = float(np.searchsorted(walker.table.tau, samples.landing))
    with rollout.Rollout(nthread=0) as runner:
        for j, stance in enumerate((SIDES * steps)[:steps]):
            stop = None if stop_advance is None or j < steps - 1 else stop_advance
            set_gains(model, layout, stance, settings.kp, settings.kv)
            log.step_starts.append(log.rows)
            log.stances.append(stance)
            controller.start_step(stance)
            events.start_step(stance, log)
            if anchor is not None:
                anchor.start_step(stance)
            while events.running(log, chunk):
                k = log.rows
                block = controller.before_step(log, k)
                log.rollout(runner, k, chunk, *shove.before_step(log, k, block))
                n = events.after_step(log, k, chunk)
                shove.after_step(n)
                log.rows += n
                if anchor is not None:
                    anchor.after_step(events, controller)
                if stop is not None and controller.advance(log, log.rows - 1) > stop:
                    events.landed = False
                    break
            log.landed.append(events.landed)
            if walker.table.double_support:
                log.touchdowns.append(events.touchdown)
                log.anchorings.append(None if anchor is None else anchor.anchoring)
            if not events.landed:
                break
    return log.simulation(layout, walker.table, settings=settings, pushed=shove.pushed)


def reference_along(samples: GaitSamples, sim: Simulation):
    """The gait file's samples at the phase the controller followed, at every simulation
    state.

    Returns:
        q (N, 9), torques (N, 6), wrench (N, 3) and ZMP (N,) of the gait.
    """
    fields = ("q", "torques", "wrench", "zmp")
    q, torques, wrench, zmp = (samples.at(name, sim.phase) for name in fields)
    return q, torques, wrench, zmp[:, 0]
