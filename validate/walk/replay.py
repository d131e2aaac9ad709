"""Replay of one step of a gait file in MuJoCo: do the file's torques make the file's motion?

The step is played from the file's start state, on the floor, against the clock: every
motor applies the file's torque Γ(t) (and what its rotor takes, ``Layout.rotor_inertia``),
and a servo on every joint, the stance ankle included, holds the joint on the file's motion
θ(t). When the torques are the motion's, the motion needs nothing more and the servos stay
idle; when a joint's torque is off, that joint's servo supplies what is missing. The figure
of a joint is the share of its torque its servo had to add:

    share_i = rms(u_fb,i) / rms(u_ff,i + u_fb,i)        over the step, less its ends

0.2 for a torque 20 % too small or too large, 1 for a joint without its torque. The
feedforward check (``validate.checks.checks.check_feedforward``) reports it and judges each servo's
RMS torque against the robot's torque scale instead (the largest RMS torque of its joints,
``SERVO_SHARE``): a joint that carries little torque (a swing ankle's 0.05-0.2 N·m) has a
large share of little servo torque, which changes nothing the robot does. The exact
torques leave what the simulator's own physics adds: the servos are stiff against the links
but not against the whole robot leaning on its stance foot (gravity's 600 N·m/rad about the
ankle), and the soles are stiff springs, not a rigid floor. What they add falls with the
physics step (halving it halves every servo's torque: MuJoCo's integration error), so the
replay runs at ``TIMESTEP`` (62.5 µs) with the contact as stiff as that step allows
(``SOLREF``): shares of 0.007 at most for the optimal gaits at 0.3 m/s (servos of
2000 N·m/rad, which pull harder on the same integration error than 1000 N·m/rad's 0.005;
their RMS torque 0.34 % of the torque scale at most, 0.21 % at 1000) and below 0.025 for
the designed gaits with a 2 cm clearance (whose swing ankle carries 0.08 N·m RMS), against
0.1 or more for any one joint 20 % off. At 0.25 ms the same exact torques reached 0.077 at
that swing ankle.

A two-phase gait's double support (``GaitSamples.double_support``) replays the same way from
its landing state, both feet on the floor, at half the step (``DOUBLE_SUPPORT_TIMESTEP``: the
closed chain's integration error is larger, and falls faster than the step): the six
motors' torques are the file's, which with both feet held fix the ground's forces on each
foot (nine equations, three accelerations and six forces: no choice left to the contact),
so ``feet`` reads MuJoCo's force and centre of pressure on each foot
(``validate.walk.contact.feet_forces``) every ``FEET_EVERY`` physics steps of the window,
beside the file's.

The window leaves out the first ``WINDOW[0]`` of the step (the contact settles under the
stance foot, which starts exactly on the floor) and the last ``1 - WINDOW[1]`` (the swing foot
comes down to the floor, where the landing belongs to the walk).
"""

from __future__ import annotations

from dataclasses import dataclass

import mujoco
import numpy as np
from mujoco import rollout

from biped.model.dynamics import JOINTS, Biped
from validate.scene.layout import Layout
from validate.scene.mapping import mapping, other, rotor_torques
from validate.scene.model import JOINT_ORDER, with_servos
from validate.walk.contact import feet_forces
from validate.walk.samples import GaitSamples
from validate.walk.simulate import KP, KV

# Physics step of the replay [s] and the contact's time constant and damping ratio there
# (the shortest MuJoCo allows: two steps).
TIMESTEP = 0.0000625
SOLREF = (2 * TIMESTEP, 1.0)
# The double support's replay step [s]: its closed chain through both feet's contacts makes
# MuJoCo's integration error larger, and it falls faster than the step (the servos' share
# of the rolling knee's two-phase optimum at 0.3 m/s: 18 % at 125 µs, 6.4 % at 62.5 µs,
# 2.5 % at 31.25 µs; the revolute knee's 5.5, 2.1, 0.7 %; the single support's 0.13 % at
# 62.5 µs), so it replays at half the single support's step.
DOUBLE_SUPPORT_TIMESTEP = TIMESTEP / 2
# Part of the step compared, as fractions of the period.
WINDOW = (0.05, 0.95)
# Physics steps between two readings of the feet's forces (``Replay.feet``).
FEET_EVERY = 1


@dataclass
class Replay:
    """One step replayed; arrays in the paper's joint order (``biped.model.dynamics.JOINTS``:
    stance ankle, knee, hip, swing hip, knee, ankle) and the paper's torque sign.

    Attributes:
        stance: the model's stance side.
        time: (M,) the gait's time at each physics step [s].
        feedforward: (M, 6) torques of the motors: the file's and the rotors' [N·m].
        feedback: (M, 6) torques of the servos [N·m].
        angle_error: (M, 6) joint angle less the file's [rad].
        compared: (M,) the rows inside ``WINDOW``.
        feet: with ``feet=True``, the times read (K,) [s] and MuJoCo's [Fx, Fz, x_cop] (K, 2, 3)
            on the stance (rear) then the swing (front) foot [N, N, m from its ankle]; None
            otherwise.
    """

    stance: str
    time: np.ndarray
    feedforward: np.ndarray
    feedback: np.ndarray
    angle_error: np.ndarray
    compared: np.ndarray
    feet: tuple | None = None

    def shares(self) -> np.ndarray:
        """(6,) the share of each joint's torque its servo added (see the module)."""
        fb, total = self.feedback[self.compared], (self.feedforward + self.feedback)[self.compared]
        return _rms(fb) / np.maximum(_rms(total), 1e-12)

    def feedback_rms(self) -> np.ndarray:
        """(6,) RMS of each servo's torque [N·m]."""
        return _rms(self.feedback[self.compared])

    def torque_rms(self) -> np.ndarray:
        """(6,) RMS of each joint's torque in the file [N·m] (motors less rotors)."""
        return _rms(self.feedforward[self.compared])


def _rms(values) -> np.ndarray:
    return np.sqrt(np.mean(np.square(values), axis=0))


def replay_model(spec: mujoco.MjSpec, knee: str, timestep: float = TIMESTEP) -> mujoco.MjModel:
    """The model of ``spec`` with servos on every joint, at ``timestep`` [s] (``TIMESTEP``;
    a double support's: ``DOUBLE_SUPPORT_TIMESTEP``), its contacts' time constant two steps
    (``SOLREF`` at ``TIMESTEP``)."""
    model = with_servos(spec, knee, KP, KV)
    model.opt.timestep = timestep
    model.geom_solref[:] = (2 * timestep, SOLREF[1])
    return model


def replay_step(
    model: mujoco.MjModel,
    samples: GaitSamples,
    biped: Biped,
    stance: str = "left",
    feet: bool = False,
) -> Replay:
    """Replay one step of ``samples`` on ``model`` (``replay_model``) with ``stance`` the
    stance side; with ``feet``, both feet's ground forces read along the window."""
    layout = Layout(model)
    mapped = mapping(model, stance, biped.radii)
    h = model.opt.timestep
    period = samples.period
    n = int(np.floor(WINDOW[1] * period / h))
    t = np.arange(n) * h
    middle = t + 0.5 * h  # the controls act over each step: the torques at its middle
    q, qd = samples.at("q", t), samples.at("qd", t)
    torques, qdd = samples.at("torques", middle), samples.at("qdd", middle)
    at_middle = samples.at("q", middle), samples.at("qd", middle)
    rotors = rotor_torques(mapped, layout, *at_middle, qdd)
    to_joint = mapped.columns  # paper joint i -> column of JOINT_ORDER
    # Motors: MuJoCo's joint torque -Γ plus the rotor's J_r θ̈_mj, per unit of gear.
    joint_torque = np.zeros((n, 6))
    joint_torque[:, to_joint] = -torques
    joint_torque += rotors
    controls = np.zeros((1, n, model.nu))
    controls[0][:, layout.motors] = joint_torque / layout.gears
    controls[0][:, layout.positions] = layout.joint_angles(mapped.qpos(q))
    controls[0][:, layout.velocities] = layout.joint_angles(mapped.qvel(q, qd))

    data = mujoco.MjData(model)
    data.qpos[:] = mapped.qpos(q[0])
    data.qvel[:] = mapped.qvel(q[0], qd[0])
    mujoco.mj_forward(model, data)
    spec = mujoco.mjtState.mjSTATE_FULLPHYSICS
    state = np.empty(mujoco.mj_stateSize(model, spec))
    mujoco.mj_getState(model, data, state, spec)
    states = np.empty((1, n, state.size))
    rollout.rollout(model, data, state, controls, nstep=n, state=states)
    after = states[0]
    before = np.vstack([state, after[:-1]])
    angles = layout.joint_angles(layout.state_qpos(before))
    rates_after = layout.joint_angles(layout.state_qvel(after))  # implicit damping
    kp = model.actuator_gainprm[layout.positions, 0]
    kv = model.actuator_gainprm[layout.velocities, 0]
    servo = kp * (controls[0][:, layout.positions] - angles)
    servo += kv * (controls[0][:, layout.velocities] - rates_after)
    motors = controls[0][:, layout.motors] * layout.gears
    rotor = rotors
    # Paper's sign and order: Γ = -(MuJoCo's joint torque).
    feedforward = -(motors - rotor)[:, to_joint]
    feedback = -servo[:, to_joint]
    error = (angles - controls[0][:, layout.positions])[:, to_joint]
    compared = t >= WINDOW[0] * period
    read = None
    if feet:
        rows = np.flatnonzero(compared)[::FEET_EVERY]
        sides = (stance, other(stance))
        forces = np.empty((len(rows), 2, 3))
        for j, k in enumerate(rows):  # the state and controls of step k: its forces
            mujoco.mj_setState(model, data, before[k], spec)
            data.ctrl[:] = controls[0][k]
            mujoco.mj_forward(model, data)
            forces[j] = feet_forces(model, data, layout, sides)
        read = (t[rows], forces)
    return Replay(
        stance=stance,
        time=t,
        feedforward=feedforward,
        feedback=feedback,
        angle_error=-error,
        compared=compared,
        feet=read,
    )


__all__ = [
    "DOUBLE_SUPPORT_TIMESTEP",
    "JOINTS",
    "JOINT_ORDER",
    "Replay",
    "replay_model",
    "replay_step",
]
