"""What MuJoCo's walk did with its feet, read from a simulation after the fact.

    ground_reaction   the stance foot's ground force and centre of pressure (single support)
    feet_forces       each foot's ground force and centre of pressure in one state (both
                      feet on the ground: a double support replayed)
    feet_reaction     a two-phase walk's ground force on each foot, stance and swing, and
                      its supports (one foot or two) along the walk
    foot_tilt         the supporting feet's tilt and the lift of their heels and toes, each
                      step (a two-phase walk's front foot from its touchdown)
    scuffs            the swing foot's touches of the floor before its landing window (a
                      two-phase gait's double support after its landing is none)
    clearance         how high the swing foot passes over the floor, in MuJoCo and in the gait
    advances          how far the hip goes forward in each step

A foot is a rigid sole between its heel and toe sites (``validate.scene.mjcf``): its tilt is the
angle of the heel-to-toe segment from the floor, and a heel or toe lifts when its site rises
above the floor. A flat, loaded sole sits a fraction of a millimetre in the soft floor; a
foot that rolls on its toe or heel edge (the centre of pressure at the edge, which a ZMP
outside the sole means in a simulator) tilts and lifts its other end.
"""

from __future__ import annotations

from dataclasses import dataclass

import mujoco
import numpy as np

from biped.model.dynamics import Biped
from validate.scene.mapping import other
from validate.walk.samples import GaitSamples
from validate.walk.simulate import LANDING_WINDOW, LIFT_WINDOW, TOUCH_THRESHOLD, Simulation

# Post-process every this many simulation states for the ground reaction.
SAMPLE_EVERY = 5
# Fraction of a step after its landing during which the stance foot settles (impact
# transient): left out of the foot's slip and tilt.
SETTLE = 0.05


def ground_reaction(sim: Simulation) -> dict:
    """Stance-foot force (N, 2) [Fx, Fz] [N] and centre of pressure (N,) [m, from the stance
    ankle] in single support every ``SAMPLE_EVERY`` states (NaN elsewhere)."""
    model, layout = sim.model, sim.layout
    data = mujoco.MjData(model)
    force = np.full((len(sim.time), 2), np.nan)
    cop = np.full(len(sim.time), np.nan)
    frame = np.zeros(6)
    stance_of = sim.stance_of()
    for k in range(0, len(sim.time), SAMPLE_EVERY):
        data.qpos[:], data.qvel[:], data.ctrl[:] = sim.qpos[k], sim.qvel[k], sim.ctrl[k]
        mujoco.mj_forward(model, data)
        stance = stance_of[k]
        swing_geoms = layout.foot_geoms[other(stance)]
        ankle_x = layout.ankle(sim.sensors[k], stance)[0]
        f_sum, moment, swing_touch = np.zeros(3), 0.0, False
        for i in range(data.ncon):
            contact = data.contact[i]
            if contact.geom1 in swing_geoms or contact.geom2 in swing_geoms:
                swing_touch = True
                continue
            if contact.efc_address < 0:
                continue
            mujoco.mj_contactForce(model, data, i, frame)
            world = contact.frame.reshape(3, 3).T @ frame[:3]
            f_sum += world
            moment += (contact.pos[0] - ankle_x) * world[2]
        if not swing_touch and f_sum[2] > 0.0:
            force[k] = f_sum[[0, 2]]
            cop[k] = moment / f_sum[2]
    return {"force": force, "cop": cop}


def feet_forces(model: mujoco.MjModel, data: mujoco.MjData, layout, sides) -> np.ndarray:
    """(len(sides), 3) [Fx, Fz [N], x of the centre of pressure from that foot's ankle [m]]
    of the floor on each foot of ``sides`` in ``data``'s state (after ``mj_forward``); NaN
    for a foot without contact force (its centre of pressure unknown)."""
    frame = np.zeros(6)
    out = np.zeros((len(sides), 3))
    for row, side in enumerate(sides):
        geoms, ankle_x = layout.foot_geoms[side], data.site(f"{side}_ankle").xpos[0]
        f_sum, moment = np.zeros(3), 0.0
        for i in range(data.ncon):
            contact = data.contact[i]
            if contact.efc_address < 0 or not (contact.geom1 in geoms or contact.geom2 in geoms):
                continue
            mujoco.mj_contactForce(model, data, i, frame)
            world = contact.frame.reshape(3, 3).T @ frame[:3]
            f_sum += world
            moment += (contact.pos[0] - ankle_x) * world[2]
        cop = moment / f_sum[2] if f_sum[2] > 0.0 else np.nan
        out[row] = f_sum[0], f_sum[2], cop
    return out


def feet_reaction(sim: Simulation) -> dict:
    """A walk's ground force on each foot of a step, by role: ``"stance"`` (the step's stance
    foot, the rear one in a double support) and ``"swing"`` (its swing foot, the front one
    once landed), each (N, 2) [Fx, Fz] [N] every ``SAMPLE_EVERY`` states (NaN elsewhere; 0
    on a foot off the floor); ``"supports"`` (N,): the feet MuJoCo's walk is on, 1 or 2
    (two from a two-phase step's touchdown to its end, ``Simulation.touchdowns``)."""
    model, layout = sim.model, sim.layout
    data = mujoco.MjData(model)
    forces = {role: np.full((len(sim.time), 2), np.nan) for role in ("stance", "swing")}
    stance_of = sim.stance_of()
    for k in range(0, len(sim.time), SAMPLE_EVERY):
        data.qpos[:], data.qvel[:], data.ctrl[:] = sim.qpos[k], sim.qvel[k], sim.ctrl[k]
        mujoco.mj_forward(model, data)
        feet = feet_forces(model, data, layout, (stance_of[k], other(stance_of[k])))
        forces["stance"][k], forces["swing"][k] = feet[0, :2], feet[1, :2]
    supports = np.ones(len(sim.time))
    touchdowns = sim.touchdowns if sim.double_support else []
    for rows, down in zip(sim.step_slices(), touchdowns, strict=False):
        if down is not None:
            supports[down : rows.stop] = 2.0
    return {**forces, "supports": supports}


@dataclass
class FootTilt:
    """The supporting feet in each step (``Simulation.supports``), after they settle.

    Attributes:
        tilt: (steps,) largest |angle| of a sole from the floor [rad].
        heel_lift, toe_lift: (steps,) highest a heel, resp. toe, rises above the floor [m].
    """

    tilt: np.ndarray
    heel_lift: np.ndarray
    toe_lift: np.ndarray


def foot_tilt(sim: Simulation, period: float) -> FootTilt:
    """Each step's supporting feet (``Simulation.supports``: the stance foot, and in a
    two-phase walk the front foot from its touchdown), the first ``SETTLE`` of the
    ``period`` after each landing left out."""
    skip = int(SETTLE * period / sim.model.opt.timestep)
    tilt, heel_lift, toe_lift = [], [], []
    for spans in sim.supports(skip):
        feet = [_sole_tilt(sim, side, rows) for side, rows in spans]
        tilt.append(max(f[0] for f in feet))
        heel_lift.append(max(f[1] for f in feet))
        toe_lift.append(max(f[2] for f in feet))
    return FootTilt(np.array(tilt), np.array(heel_lift), np.array(toe_lift))


def _sole_tilt(sim: Simulation, side: str, rows: slice) -> tuple[float, float, float]:
    """A sole's largest |tilt| [rad], heel and toe heights [m] over ``rows`` (0: none)."""
    heel, toe = sim.heel(side)[rows], sim.toe(side)[rows]
    if not len(heel):
        return 0.0, 0.0, 0.0
    angle = np.arctan2(toe[:, 2] - heel[:, 2], toe[:, 0] - heel[:, 0])
    return float(np.abs(angle).max()), float(heel[:, 2].max()), float(toe[:, 2].max())


@dataclass
class Scuffs:
    """Touches of the floor by the swing foot between its lift-off (``LIFT_WINDOW``) and its
    landing window (``LANDING_WINDOW``), each a fraction of the swing's time T (the gait's
    landing: a two-phase gait's double support after it is no scuff).

    Attributes:
        steps: indices of the steps with a scuff.
        duration: (steps,) time the swing foot spent on the floor in each step [s].
        depth: (steps,) deepest its heel or toe went into the floor in each step [m].
        first_phase: (steps,) fraction of the step at its first scuff (NaN: none).
    """

    steps: list
    duration: np.ndarray
    depth: np.ndarray
    first_phase: np.ndarray


def scuffs(sim: Simulation, swing_time: float) -> Scuffs:
    """The scuffs of a walk whose swing lasts ``swing_time`` [s] (``GaitSamples.landing_time``)."""
    dt = sim.model.opt.timestep
    duration, depth, first = [], [], []
    for rows, stance in zip(sim.step_slices(), sim.stances, strict=True):
        swing = other(stance)
        touching = sim.touch(swing)[rows] > TOUCH_THRESHOLD
        phase = sim.phase[rows] / swing_time
        scuff = touching & (phase >= LIFT_WINDOW) & (phase < LANDING_WINDOW)
        lowest = np.minimum(sim.heel(swing)[rows, 2], sim.toe(swing)[rows, 2])
        duration.append(float(scuff.sum() * dt))
        depth.append(float(max(0.0, -lowest[scuff].min())) if scuff.any() else 0.0)
        first.append(float(phase[np.argmax(scuff)]) if scuff.any() else float("nan"))
    duration = np.array(duration)
    return Scuffs(
        steps=[int(j) for j in np.flatnonzero(duration > 0.0)],
        duration=duration,
        depth=np.array(depth),
        first_phase=np.array(first),
    )


@dataclass
class Clearance:
    """How high the lowest point of the swing sole passes over the floor between its lift-off
    and its landing window (``LIFT_WINDOW`` to ``LANDING_WINDOW`` of the swing's time) [m].

    Attributes:
        walk: (steps,) in MuJoCo, each step.
        gait: in the gait file.
    """

    walk: np.ndarray
    gait: float


def clearance(biped: Biped, samples: GaitSamples, sim: Simulation) -> Clearance:
    walk, swing_time = [], samples.landing_time
    for rows, stance in zip(sim.step_slices(), sim.stances, strict=True):
        swing = other(stance)
        phase = sim.phase[rows] / swing_time
        window = (phase >= LIFT_WINDOW) & (phase < LANDING_WINDOW)
        lowest = np.minimum(sim.heel(swing)[rows, 2], sim.toe(swing)[rows, 2])
        walk.append(float(lowest[window].min()) if window.any() else float("nan"))
    t = np.linspace(LIFT_WINDOW, LANDING_WINDOW, 400) * swing_time
    feet = biped.points(samples.at("q", t), ["swing_heel", "swing_toe"])[..., 1]
    return Clearance(walk=np.array(walk), gait=float(feet.min()))


def advances(sim: Simulation) -> np.ndarray:
    """(steps,) how far the hip goes forward in each step [m]."""
    hip = sim.hip_x()
    return np.array([hip[rows.stop - 1] - hip[rows.start] for rows in sim.step_slices()])
