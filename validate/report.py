"""Validation of a gait: every cross-check against MuJoCo, as a report of named checks.

inverse_dynamics  analytical Γ, F_e, ZMP against MuJoCo's dynamics of the MJCF (1e-6)
impact            analytical q̇⁺ and impulse against MuJoCo's mass matrix and Jacobian (1e-6)
forward           the gait walked in MuJoCo with contact: every step lands, no fall, no
                  slip of the stance foot (< 1 mm), centre of pressure in the foot and on
                  the gait's ZMP (to 30 % of the ankle torque's effect on it, away from
                  the landings), no MuJoCo warning;
                  ground reaction, velocity jump at touchdown, feedback, energy and the
                  rolling-knee equality reported beside their analytical values
"""

from __future__ import annotations

import time
from dataclasses import dataclass

import mujoco
import numpy as np

from biped import gait_file
from biped.dynamics import Biped
from biped.gait import build_step
from validate.crosscheck import load_model, mujoco_impact, mujoco_inverse_dynamics
from validate.mapping import mapping, other
from validate.simulate import Simulation, joint_matrix, reference_along, set_gains, simulate

# Agreement of two exact rigid-body models of one robot.
EXACT = 1e-6
MAX_SLIP = 1e-3  # [m] stance-foot travel during its stance, after the landing settles
SETTLE = 0.05  # fraction of a step after touchdown excluded from the slip (impact transient)
# Fall: hip lower than this fraction of its planned minimum, or trunk beyond this angle.
HIP_DROP = 0.9
TRUNK_LIMIT = 0.5  # [rad]
# A step counts as walked only if it goes through the gait's step: it starts before this
# fraction of the gait's period is left and its swing foot lands past this fraction (a
# foot dragging on the ground, or shuffling, makes early "touchdowns" or short steps). When,
# is the walk's own affair: its step durations are reported.
LANDING_PLACE = 0.9
# Fraction of a step after touchdown left out of the comparisons with the gait: MuJoCo's
# soft landing takes that long to settle.
LANDING = 0.1
# The walk's centre of pressure must follow the gait's ZMP away from the landings, to this
# fraction of how far the gait's stance-ankle torque moves the ZMP (RMS of Γ1 / Fz): that is
# where the feedforward torques show, the feedback carrying the robot without them.
ZMP_AGREEMENT = 0.3
# Time after a landing's first contact at which its velocity jump is read [s].
JUMP_WINDOW = 0.02
SAMPLE_EVERY = 5  # post-process every 5th simulation state (5 ms)
# MuJoCo places a box-plane contact midway through the penetration, a fraction of a
# millimetre outside the sole's outline: the centre of pressure may lie that far out.
COP_TOLERANCE = 1e-3  # [m]


def _rms(values) -> float:
    """Root mean square; NaN for no values."""
    return float(np.sqrt(np.mean(np.square(values)))) if np.size(values) else float("nan")


def _root_mean(squares) -> float:
    """Square root of the mean of squared values; NaN for none."""
    return float(np.sqrt(np.mean(squares))) if np.size(squares) else float("nan")


def _median(values) -> float:
    """Median; NaN for no values (a walk too short to measure)."""
    return float(np.median(values)) if np.size(values) else float("nan")


@dataclass
class Check:
    name: str
    passed: bool
    figures: dict

    def line(self) -> str:
        values = ", ".join(f"{k} {_fmt(v)}" for k, v in self.figures.items())
        return f"{'PASS' if self.passed else 'FAIL'}  {self.name:17} {values}"


def _fmt(value) -> str:
    if value is None or (isinstance(value, float) and np.isnan(value)):
        return "n/a"
    if isinstance(value, bool):
        return "yes" if value else "no"
    if isinstance(value, (int, np.integer)):
        return str(int(value))
    if isinstance(value, (list, tuple)):
        return "-".join(f"{v:.3g}" for v in value)
    return f"{value:.3g}"


def check_inverse_dynamics(biped: Biped, gait: dict) -> Check:
    s = gait["samples"]
    result = mujoco_inverse_dynamics(
        load_model(biped, exact=True), biped, s["q"], s["qd"], s["qdd"]
    )
    figures = {
        "max_torque_error": float(np.abs(result.torques - s["torques"]).max()),
        "max_wrench_error": float(np.abs(result.wrench - s["wrench"]).max()),
        "max_zmp_error": float(np.abs(result.zmp - s["zmp"]).max()),
    }
    if result.coupling.size:
        figures["max_knee_coupling"] = float(np.abs(result.coupling).max())
    passed = max(figures["max_torque_error"], figures["max_wrench_error"]) < EXACT
    return Check("inverse_dynamics", passed and figures["max_zmp_error"] < EXACT, figures)


def check_impact(biped: Biped, step) -> Check:
    q, qd_minus = step.end
    qd_plus, impulse = biped.impact(q, qd_minus)
    model = load_model(biped, exact=True)
    mj_qd_plus, mj_impulse = mujoco_impact(model, biped, q, qd_minus)
    figures = {
        "max_velocity_error": float(
            np.abs(mj_qd_plus - mapping(model, "left", biped.radii).qpos(qd_plus)).max()
        ),
        "max_impulse_error": float(np.abs(mj_impulse - impulse).max()),
        "normal_impulse": float(impulse[1]),
        "landing_speed": float(np.linalg.norm(biped.point_jacobian(q, "swing_ankle") @ qd_minus)),
    }
    passed = max(figures["max_velocity_error"], figures["max_impulse_error"]) < EXACT
    return Check("impact", passed, figures)


def sole_x(sim: Simulation, side: str) -> np.ndarray:
    """Horizontal position (N,) of the middle of a sole, on the ground: a foot rolling on
    its sole barely moves it, a foot sliding moves it by the slide (the ankle, 6.6 cm
    above, would also move by 0.66 mm per 0.01 rad of roll)."""
    return 0.5 * (sim.sensor(f"{side}_heel_pos")[:, 0] + sim.sensor(f"{side}_toe_pos")[:, 0])


def contact_samples(biped: Biped, sim: Simulation) -> dict:
    """Stance-foot force (N, 2) and centre of pressure (N,) in single support every
    ``SAMPLE_EVERY`` states (NaN elsewhere); joint power (N,), squared feedback and squared
    total torques (N,) at every state."""
    model = sim.model
    data = mujoco.MjData(model)
    force = np.full((len(sim.time), 2), np.nan)
    cop = np.full(len(sim.time), np.nan)
    frame = np.zeros(6)
    stance_of = sim.stance_of()
    gains_of = None
    for k in range(0, len(sim.time), SAMPLE_EVERY):
        data.qpos[:], data.qvel[:], data.ctrl[:] = sim.qpos[k], sim.qvel[k], sim.ctrl[k]
        stance = stance_of[k]
        if stance != gains_of:  # the gains of that step, not the last one
            set_gains(model, stance, sim.kp, sim.kv)
            gains_of = stance
        mujoco.mj_forward(model, data)
        ankle = data.site(f"{stance}_ankle").xpos
        f_sum, moment, swing_touch = np.zeros(3), 0.0, False
        for i in range(data.ncon):
            contact = data.contact[i]
            names = model.geom(contact.geom1).name + model.geom(contact.geom2).name
            if f"{other(stance)}_sole" in names:
                swing_touch = True
                continue
            mujoco.mj_contactForce(model, data, i, frame)
            world = contact.frame.reshape(3, 3).T @ frame[:3]
            f_sum += world
            moment += (contact.pos[0] - ankle[0]) * world[2]
        if not swing_touch and f_sum[2] > 0.0:
            force[k] = f_sum[[0, 2]]
            cop[k] = moment / f_sum[2]
    # Paper-sign torques: motors have gear -1, the servos +1 (validate.mjcf).
    rates = -sim.qvel @ joint_matrix(model).T  # θ̇ of eq. (32), JOINT_ORDER
    feedback = sim.feedback()
    torque = sim.motors() + feedback
    return {
        "force": force,
        "cop": cop,
        "power": np.abs(torque * rates).sum(axis=1),
        "feedback": np.sum(feedback**2, axis=1),
        "total": np.sum(torque**2, axis=1),
    }


def touchdown_jumps(biped: Biped, sim: Simulation, steps: int, window: float = JUMP_WINDOW):
    """Relative error (per landing) of the velocity jump MuJoCo's walk shows at touchdown
    against the analytical impact map (eqs. 21-24) applied to MuJoCo's state just before it.

    MuJoCo's jump is measured ``window`` seconds after the first contact of the landing foot:
    its soft contact spreads the impact over milliseconds during which gravity and the
    servos also act, so the agreement is approximate by nature (reported, not checked).
    """
    model = sim.model
    touch_ahead = int(round(window / model.opt.timestep))
    errors = []
    for j in range(min(steps, len(sim.stances) - 1)):
        stance, end = sim.stances[j], sim.step_starts[j + 1]
        touch = sim.sensor(f"{other(stance)}_touch")[:end, 0]
        onset = end - 1
        while onset > 0 and touch[onset - 1] > 0.0:
            onset -= 1
        if onset + touch_ahead >= len(sim.time):
            break
        to_paper = np.linalg.pinv(mapping(model, stance, biped.radii).qpos_from_q)
        q, qd_minus = to_paper @ sim.qpos[onset - 1], to_paper @ sim.qvel[onset - 1]
        qd_plus, _ = biped.impact(q, qd_minus)
        seen = to_paper @ sim.qvel[onset - 1 + touch_ahead] - qd_minus
        errors.append(
            np.linalg.norm(seen - (qd_plus - qd_minus)) / np.linalg.norm(qd_plus - qd_minus)
        )
    return np.array(errors)


def forward_figures(biped: Biped, step, sim: Simulation, energy: float, contact=None) -> dict:
    """Figures of a forward simulation (see the module docstring)."""
    model = sim.model
    robot = biped.robot
    starts = sim.step_starts + [len(sim.time)]
    settle = int(SETTLE * step.period / model.opt.timestep)
    slips, slides = [], []
    for j, stance in enumerate(sim.stances):
        x = sole_x(sim, stance)[starts[j] : starts[j + 1]]
        slides.append(float(np.ptp(x[:settle])) if len(x) else 0.0)
        slips.append(float(np.ptp(x[settle:])) if len(x) > settle else 0.0)
    q_ref, torques_ref, wrench_ref, zmp_ref = reference_along(biped, step, sim)
    planned_hip = q_ref[:, 8].min()
    # Steps walked: leading steps that land, with the stance foot still, hip and trunk held.
    walked = 0
    for j in range(len(sim.stances)):
        a, b = starts[j], starts[j + 1]
        upright = (
            sim.qpos[a:b, 1].min() >= HIP_DROP * planned_hip
            and np.abs(sim.qpos[a:b, 2]).max() <= TRUNK_LIMIT
        )
        in_place = (
            sim.phase[a] <= (1.0 - LANDING_PLACE) * step.period
            and sim.phase[b - 1] >= LANDING_PLACE * step.period
        )
        if not (sim.landed[j] and upright and in_place and slips[j] < MAX_SLIP):
            break
        walked += 1
    durations = np.diff(sim.time[starts[:-1]].tolist() + [sim.time[-1] + model.opt.timestep])
    samples = contact if contact is not None else contact_samples(biped, sim)
    # Comparisons with the gait over the steps walked (at least the first): after a fall
    # they would only measure the fall. The landing transient of the soft contact is left
    # out of them (its impact is not the rigid one of the gait).
    end = starts[max(walked, 1)]
    force, cop = samples["force"][:end], samples["cop"][:end]
    steady = sim.phase[:end] >= LANDING * step.period
    power, feedback, total = (
        samples["power"][:end],
        samples["feedback"][:end],
        samples["total"][:end],
    )
    wrench_ref, zmp_ref = wrench_ref[:end], zmp_ref[:end]
    single = ~np.isnan(cop)
    compared = single & steady
    weight = robot.total_mass * robot.gravity
    feedforward = sim.motors()[:end]
    figures = {
        "steps": walked,
        "fell": bool(
            not all(sim.landed)
            or sim.qpos[:, 1].min() < HIP_DROP * planned_hip
            or np.abs(sim.qpos[:, 2]).max() > TRUNK_LIMIT
        ),
        "max_slip": float(max(slips)),
        "step_duration_range": [
            float(durations[: max(walked, 1)].min() / step.period),
            float(durations[: max(walked, 1)].max() / step.period),
        ],
        "max_landing_slide": float(max(slides)),
        "zmp_in_foot": bool(
            np.all(
                (cop[single] >= -robot.foot_heel - COP_TOLERANCE)
                & (cop[single] <= robot.foot_length - robot.foot_heel + COP_TOLERANCE)
            )
        ),
        "zmp_rms_error": _rms(cop[compared] - zmp_ref[compared]),
        "zmp_relative_error": _rms(cop[compared] - zmp_ref[compared])
        / _rms(torques_ref[:end][compared, 0] / wrench_ref[compared, 1]),
        "touchdown_jump_error": _median(touchdown_jumps(biped, sim, max(walked, 1))),
        "ground_force_rms_error": _rms((force[compared] - wrench_ref[compared, :2]) / weight),
        "feedforward_rms": _rms(feedforward[steady]),
        "feedback_rms": _root_mean(feedback[steady]),
        "feedback_share": float(np.sqrt(feedback[steady].sum() / max(total[steady].sum(), 1e-12))),
        "landing_feedback_rms": _root_mean(feedback[~steady]),
        "energy_per_step": float(np.trapezoid(power, sim.time[:end]) / max(walked, 1)),
        "analytic_energy_per_step": float(energy),
        "warnings": int(sim.warnings),
        "distance": float(sim.qpos[-1, 0] - sim.qpos[0, 0]),
        "seconds_simulated": float(sim.time[-1] - sim.time[0]),
    }
    if biped.knee == "rolling":
        worst = 0.0
        for k in range(model.neq):
            j1, j2 = model.eq_obj1id[k], model.eq_obj2id[k]
            a, b = model.jnt_qposadr[j1], model.jnt_qposadr[j2]
            worst = max(
                worst, float(np.abs(sim.qpos[:, a] - model.eq_data[k, 1] * sim.qpos[:, b]).max())
            )
        figures["max_knee_equality_violation"] = worst
    return figures


def check_forward(biped: Biped, step, steps: int, energy: float):
    """Simulate and check; returns (check, simulation, contact samples)."""
    began = time.perf_counter()
    sim = simulate(biped, step, steps)
    wall = time.perf_counter() - began
    samples = contact_samples(biped, sim)
    figures = forward_figures(biped, step, sim, energy, samples)
    figures["real_time_factor"] = figures["seconds_simulated"] / wall
    passed = (
        figures["steps"] >= steps
        and not figures["fell"]
        and figures["max_slip"] < MAX_SLIP
        and figures["zmp_in_foot"]
        and figures["zmp_relative_error"] < ZMP_AGREEMENT
        and figures["warnings"] == 0
    )
    return Check("forward", passed, figures), sim, samples


@dataclass
class Validation:
    checks: list
    biped: Biped
    step: object
    simulation: Simulation
    contact: dict

    @property
    def passed(self) -> bool:
        return all(check.passed for check in self.checks)


def validate(gait: dict, steps: int = 20) -> Validation:
    """All checks of a gait read by ``biped.gait_file.read``."""
    biped = Biped(gait["robot"], gait["knee"])
    step = build_step(biped, gait["speed"], gait_file.parameters(gait))
    checks = [check_inverse_dynamics(biped, gait), check_impact(biped, step)]
    forward, sim, contact = check_forward(biped, step, steps, gait["costs"]["energy"])
    checks.append(forward)
    return Validation(checks, biped, step, sim, contact)


def as_json(checks) -> dict:
    def clean(value):  # JSON has no NaN: a figure that could not be measured is null
        return None if isinstance(value, float) and np.isnan(value) else value

    content = {
        check.name: {**{k: clean(v) for k, v in check.figures.items()}, "passed": check.passed}
        for check in checks
    }
    content["passed"] = all(check.passed for check in checks)
    return content
