"""The checks of a gait file against MuJoCo, each a ``Check``: a verdict, figures and notes.

model             the MJCF is the gait's robot: the rolling knee's equalities and their
                  ratio r2 / r1, and every field of ``biped.Robot`` the MJCF holds
                  (``validate.model.parameter_differences``: the first that differs named
                  with both values); its mass beside the gait's
inverse_dynamics  the file's Γ, F_e, ZMP against MuJoCo's dynamics of the model along the
                  file's motion (1e-6)
knee_loads        MuJoCo's force of the thigh on the lower leg through each knee (its
                  ``cfrc_int``) along the file's motion against the file's knee loads, normal
                  and tangential, both knees (1e-6 N: two exact rigid models, the knee
                  equalities' softness out of the inverse dynamics; 5e-13 N measured)
impact            the file's start velocities and impulse against MuJoCo's impact map
                  (mass matrix and foot Jacobian) applied to the file's end state (1e-6)
feedforward       each step replayed against the clock with the file's torques
                  (``validate.replay``): the share of each joint's torque its servo had to
                  add, below ``FEEDFORWARD_SHARE`` for every joint
forward           the file walked in MuJoCo with contact (``validate.simulate``): every step
                  lands and advances the hip by ``STEP_ADVANCE`` of the step length at
                  least, no fall, no slip of the stance foot (``MAX_SLIP``), the stance foot
                  flat (tilt below ``MAX_FOOT_TILT``), no scuff of the swing foot before its
                  landing window, no MuJoCo warning; ground reaction, centre of pressure,
                  velocity jump at touchdown, feedback, energy, clearance and the
                  rolling-knee equality reported beside the gait's
gains             the same walk at kp × ``GAIN_SCALES``: the range of gains it walks over

A model the harness cannot use as the gait's robot (``validate.model.ModelError``: a rolling
knee without its equalities) fails the checks that need it, with the reason as a note.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field

import mujoco
import numpy as np

from biped.model.dynamics import JOINTS, Biped
from biped.model.kinematics import ZH
from biped.model.knee_loads import KNEE_SIDES, knee_forces
from biped.model.units import PURE, unit_text
from biped.records.gait_file import Gait
from validate import contact
from validate.crosscheck import (
    mujoco_impact,
    mujoco_inverse_dynamics,
    mujoco_knee_forces,
    rigid_copy,
)
from validate.mapping import mapping, other
from validate.mjcf import SIDES
from validate.model import ModelError, model_problems
from validate.replay import replay_model, replay_step
from validate.samples import GaitSamples
from validate.simulate import KP, Simulation, Walker, WalkSettings, reference_along
from validate.units import FIGURE_UNITS, WalkFigures

# Agreement of two exact rigid-body models of one robot.
EXACT = 1e-6
# Largest share of a joint's torque its servo may add in the replay (``validate.replay``):
# the optimal gaits need 0.025 at most, a joint 20 % off 0.09 or more.
FEEDFORWARD_SHARE = 0.05
MAX_SLIP = 1e-3  # [m] stance-foot travel during its stance, after the landing settles
# Largest tilt [rad] of the stance foot: a loaded sole on the soft floor tilts by a
# fraction of a milliradian; 0.01 rad lifts the far end of a 26 cm sole by 2.6 mm.
MAX_FOOT_TILT = 0.01
# Fall: hip lower than this fraction of its planned minimum, or trunk beyond this angle.
HIP_DROP = 0.9
TRUNK_LIMIT = 0.5  # [rad]
# A step counts only if the hip advances by this fraction of the step length in it (a robot
# shuffling in place makes short "steps" that land).
STEP_ADVANCE = 0.5
# Fraction of a step after touchdown left out of the comparisons with the gait: MuJoCo's
# soft landing takes that long to settle.
LANDING = 0.1
# Time after a landing's first contact at which its velocity jump is read [s].
JUMP_WINDOW = 0.02
# A walk whose swing foot clears the floor by less than this [m] is decided by scuffing:
# the verdict would change with a millimetre of tracking error.
SCUFF_MARGIN = 1e-3
# Scales of the servos' stiffness KP (the damping stays) of the gains check.
GAIN_SCALES = (0.5, 2.0)


@dataclass
class Check:
    """One check of a gait.

    Attributes:
        name: its key in the report (``inverse_dynamics``, ``forward``, ...).
        passed: the verdict.
        figures: name -> value (numbers, booleans, [low, high] pairs; NaN: not measured).
        notes: sentences that go with the verdict.
        shown: the figures ``line`` prints (None: all).
    """

    name: str
    passed: bool
    figures: dict
    notes: list = field(default_factory=list)
    shown: tuple | None = None

    def line(self) -> str:
        names = self.figures if self.shown is None else self.shown
        values = ", ".join(
            f"{k} {_fmt(self.figures[k])}{_unit(self.name, k)}" for k in names if k in self.figures
        )
        text = f"{'PASS' if self.passed else 'FAIL'}  {self.name:17} {values}".rstrip()
        if not self.notes:
            return text
        return f"{text}{'; ' if values else '  '}{'; '.join(self.notes)}"


def _unit(check: str, name: str) -> str:
    """The unit of a figure as printed after its value ("" for a count or a ratio)."""
    unit = FIGURE_UNITS.get(check, {}).get(name, PURE)
    return "" if unit == PURE else f" {unit_text(unit)}"


def _fmt(value) -> str:
    if value is None or (isinstance(value, float) and np.isnan(value)):
        return "n/a"
    if isinstance(value, (bool, np.bool_)):
        return "yes" if value else "no"
    if isinstance(value, (int, np.integer)):
        return str(int(value))
    if isinstance(value, (list, tuple)):  # a range; one not measured is unknown, never nan
        shown = ["n/a" if v is None or np.isnan(v) else f"{v:.3g}" for v in value]
        return "n/a" if "n/a" in shown else "-".join(shown)
    return f"{value:.3g}"


def _rms(values) -> float:
    """Root mean square; NaN for no values."""
    return float(np.sqrt(np.mean(np.square(values)))) if np.size(values) else float("nan")


def _ratio(a: float, b: float) -> float:
    """a / b; NaN where b is 0 (a reference that does not move: no scale to compare with)."""
    return a / b if b != 0 else float("nan")


def _median(values) -> float:
    """Median; NaN for no values (a walk too short to measure)."""
    return float(np.median(values)) if np.size(values) else float("nan")


def _model_failure(name: str, error: Exception) -> Check:
    return Check(name, False, {}, notes=[f"model error: {error}"])


def check_model(model: mujoco.MjModel, biped: Biped) -> Check:
    """The model is the gait's robot (``validate.model.model_problems``); masses reported."""
    problems = model_problems(model, biped)
    trunk = model.body("trunk").id
    mass = float(model.body_subtreemass[trunk])
    figures = {"mass_difference": mass - biped.robot.total_mass, "problems": len(problems)}
    return Check("model", not problems, figures, notes=problems)


def check_inverse_dynamics(model: mujoco.MjModel, biped: Biped, samples: GaitSamples) -> Check:
    try:
        result = mujoco_inverse_dynamics(
            rigid_copy(model), biped, samples.q, samples.qd, samples.qdd
        )
    except ModelError as error:
        return _model_failure("inverse_dynamics", error)
    zmp = samples.zmp[:, 0]
    wrench = np.abs(result.wrench - samples.wrench)  # Fx, Fz [N], Cy [N·m]
    figures = {
        "max_torque_error": float(np.abs(result.torques - samples.torques).max()),
        "max_force_error": float(wrench[:, :2].max()),
        "max_moment_error": float(wrench[:, 2].max()),
        "max_zmp_error": float(np.abs(result.zmp - zmp).max()),
    }
    if result.coupling.size:
        figures["max_knee_coupling"] = float(np.abs(result.coupling).max())
    errors = ("max_torque_error", "max_force_error", "max_moment_error", "max_zmp_error")
    return Check("inverse_dynamics", max(figures[name] for name in errors) < EXACT, figures)


def check_knee_loads(
    model: mujoco.MjModel, biped: Biped, samples: GaitSamples, loads=None
) -> Check:
    """MuJoCo's force through each knee along the file's motion (``mujoco_knee_forces``, its
    own ground wrench) against the analytical one, ``loads`` (the gait file's ``knee_loads``,
    or any record with ``normal`` and ``tangential`` (N, 2); None: computed from the samples
    with ``biped``), normal and tangential, both knees, to ``EXACT`` [N]: along a given motion
    both are exact rigid-body models of the same robot (the rigid copy: no armature, massless
    knee links), and the equalities' softness, which a walk feels, plays no part."""
    name = "knee_loads"
    exact = rigid_copy(model)
    try:
        wrench = mujoco_inverse_dynamics(exact, biped, samples.q, samples.qd, samples.qdd).wrench
    except ModelError as error:
        return _model_failure(name, error)
    found = mujoco_knee_forces(exact, biped, samples.q, samples.qd, samples.qdd, wrench)
    notes = []
    if loads is None:
        loads = knee_forces(biped, samples.q, samples.qd, samples.qdd, samples.wrench)
        notes.append("the gait file has no knee_loads: computed from its samples")
    errors = {
        part: np.abs(getattr(found, part) - np.asarray(getattr(loads, part), dtype=float))
        for part in ("normal", "tangential")
    }
    figures = {f"max_knee_{part}_error": float(e.max()) for part, e in errors.items()}
    for k, side in enumerate(KNEE_SIDES):  # MuJoCo's
        figures[f"max_{side}_knee_tension"] = float(np.maximum(-found.normal[:, k], 0.0).max())
    passed = max(figures["max_knee_normal_error"], figures["max_knee_tangential_error"]) < EXACT
    return Check(name, passed, figures, notes)


def check_impact(model: mujoco.MjModel, biped: Biped, samples: GaitSamples, gait: Gait) -> Check:
    """MuJoCo's impact map of the file's end state against the file's start velocities (the
    legs swapped: the new stance leg is the old swing leg) and its impulse."""
    exact = rigid_copy(model)
    q, qd_minus = samples.end()
    mj_qd_plus, mj_impulse = mujoco_impact(exact, biped, q, qd_minus)
    start = mapping(exact, "right", biped.radii).qpos(samples.qd[0])
    velocity = np.abs(mj_qd_plus - start)
    slide = exact.jnt_type[exact.dof_jntid] == mujoco.mjtJoint.mjJNT_SLIDE  # m/s, else rad/s
    figures = {
        "max_linear_velocity_error": float(velocity[slide].max()),
        "max_angular_velocity_error": float(velocity[~slide].max()),
        "normal_impulse": float(mj_impulse[1]),
        "landing_speed": float(np.linalg.norm(biped.point_jacobian(q, "swing_ankle") @ qd_minus)),
    }
    impulse = None if gait.impact is None else gait.impact.impulse
    notes = []
    if impulse is not None:
        error = np.abs(mj_impulse - np.asarray(impulse))  # Ix, Iz [N·s], Iy [N·m·s]
        figures["max_force_impulse_error"] = float(error[:2].max())
        figures["max_moment_impulse_error"] = float(error[2])
    else:
        notes.append("the gait file has no impact.impulse to compare")
    errors = [v for k, v in figures.items() if k.endswith("_error")]
    return Check("impact", max(errors) < EXACT and impulse is not None, figures, notes)


def check_feedforward(spec: mujoco.MjSpec, biped: Biped, samples: GaitSamples) -> Check:
    """Both stance sides replayed; each joint's worst share (``validate.replay``)."""
    model = replay_model(spec, biped.knee)
    replays = [replay_step(model, samples, biped, stance) for stance in SIDES]
    shares = np.max([r.shares() for r in replays], axis=0)
    feedback = np.max([r.feedback_rms() for r in replays], axis=0)
    torques = np.max([r.torque_rms() for r in replays], axis=0)
    figures = {"max_feedback_share": float(shares.max())}
    for name, values in (("feedback_share", shares), ("feedback_rms", feedback)):
        figures |= {f"{name}_{joint}": float(v) for joint, v in zip(JOINTS, values, strict=True)}
    figures |= {f"torque_rms_{joint}": float(v) for joint, v in zip(JOINTS, torques, strict=True)}
    passed = bool(shares.max() < FEEDFORWARD_SHARE)
    notes = []
    if not passed:  # the file's torques alone do not make its motion in MuJoCo
        worst = [
            f"{100 * v:.1f} % of {joint}'s"
            for joint, v in zip(JOINTS, shares, strict=True)
            if v >= FEEDFORWARD_SHARE
        ]
        notes.append(
            "replayed in MuJoCo, the gait's torques need the servos to follow its motion: they "
            f"add {', '.join(worst)} torque (allowed < {100 * FEEDFORWARD_SHARE:g} % each)"
        )
    shown = ("max_feedback_share",) + tuple(f"feedback_share_{joint}" for joint in JOINTS)
    return Check("feedforward", passed, figures, notes, shown=shown)


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
        touch = sim.touch(other(stance))[:end]
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


def walk_figures(
    biped: Biped, samples: GaitSamples, sim: Simulation, energy: float, reaction=None
) -> dict:
    """Figures of a forward simulation (see the module docstring); those of the ground
    reaction (``validate.contact.ground_reaction``) only when it is given."""
    period, dt = samples.period, sim.model.opt.timestep
    settle = int(contact.SETTLE * period / dt)
    slips, tilt = sim.stance_foot_slip(settle), contact.foot_tilt(sim, period)
    advance = contact.advances(sim) / samples.step_length
    reference = reference_along(samples, sim)
    lowest = HIP_DROP * reference[0][:, ZH].min()  # the lowest hip allowed [m]
    hip, trunk = sim.hip_height(), sim.trunk_angle()
    # Steps walked: leading steps that land, advance the hip, with the stance foot still and
    # flat, hip and trunk held.
    walked = 0
    for j, rows in enumerate(sim.step_slices()):
        upright = hip[rows].min() >= lowest and np.abs(trunk[rows]).max() <= TRUNK_LIMIT
        if not (
            sim.landed[j]
            and upright
            and advance[j] >= STEP_ADVANCE
            and slips[j] < MAX_SLIP
            and tilt.tilt[j] < MAX_FOOT_TILT
        ):
            break
        walked += 1
    shuffled = bool(np.any(np.array(sim.landed) & (advance < STEP_ADVANCE)))
    counted = slice(0, max(walked, 1))
    durations = np.diff(sim.time[sim.step_starts].tolist() + [sim.time[-1] + dt])[counted]
    fell = hip.min() < lowest or np.abs(trunk).max() > TRUNK_LIMIT or shuffled
    figures = {
        "steps": walked,
        "fell": bool(not all(sim.landed) or fell),
        "max_slip": float(slips.max()),
        "step_duration_range": [float(durations.min() / period), float(durations.max() / period)],
        "step_advance_range": [float(advance[counted].min()), float(advance[counted].max())],
        "max_landing_slide": float(sim.stance_foot_slip(settle, landing=True).max()),
        **_foot_figures(biped, samples, sim, tilt, counted),
        **_tracking_figures(biped, samples, sim, reaction, walked, reference),
        "analytic_energy_per_step": float(energy),
        "warnings": int(sim.warnings),
        "distance": float(sim.hip_x()[-1] - sim.hip_x()[0]),
        "seconds_simulated": float(sim.time[-1] - sim.time[0]),
    }
    if biped.knee == "rolling":
        figures["max_knee_equality_violation"] = _knee_equality_violation(sim)
    return WalkFigures(**figures).to_dict()  # the names, their order and units declared there


def _foot_figures(biped, samples, sim: Simulation, tilt, counted: slice) -> dict:
    """``walk_figures`` of the feet: the stance foot's tilt, the swing foot's scuffs and its
    clearance over the steps ``counted``."""
    scuffs = contact.scuffs(sim, samples.period)
    clearance = contact.clearance(biped, samples, sim)
    return {
        "max_foot_tilt": float(tilt.tilt.max()),
        "max_heel_lift": float(tilt.heel_lift.max()),
        "max_toe_lift": float(tilt.toe_lift.max()),
        "scuff_steps": len(scuffs.steps),
        "scuff_duration": float(scuffs.duration.sum()),
        "scuff_depth": float(scuffs.depth.max()),
        "swing_clearance": float(np.nanmin(clearance.walk[counted])),
        "gait_swing_clearance": clearance.gait,
    }


def _tracking_figures(biped, samples, sim: Simulation, reaction, walked: int, reference):
    """``walk_figures`` of the walk against the gait (``reference_along``) over the steps
    walked (at least the first: after a fall they would only measure the fall), the landing
    transient of the soft contact (``LANDING``) left out: its impact is not the rigid one of
    the gait."""
    _, torques_ref, wrench_ref, zmp_ref = reference
    end = (sim.step_starts + [len(sim.time)])[max(walked, 1)]
    if reaction is None:  # not computed: its figures are not measured
        nan = np.full(len(sim.time), np.nan)
        reaction = {"force": np.stack([nan, nan], axis=1), "cop": nan}
    force, cop = reaction["force"][:end], reaction["cop"][:end]
    steady = sim.phase[:end] >= LANDING * samples.period
    wrench_ref, zmp_ref = wrench_ref[:end], zmp_ref[:end]
    compared = ~np.isnan(cop) & steady  # single support, steady
    weight = biped.robot.weight
    feedforward, feedback = sim.feedforward()[:end], sim.feedback()[:end]
    rates = -sim.layout.joint_angles(sim.qvel[:end])  # θ̇ of eq. (32), JOINT_ORDER
    power = np.abs((feedforward + feedback) * rates).sum(axis=1)
    ff_square, fb_square = np.sum(feedforward[steady] ** 2), np.sum(feedback[steady] ** 2)
    zmp_error = _rms(cop[compared] - zmp_ref[compared])
    return {
        "zmp_rms_error": zmp_error,
        "zmp_relative_error": _ratio(
            zmp_error, _rms(torques_ref[:end][compared, 0] / wrench_ref[compared, 1])
        ),
        "touchdown_jump_error": _median(touchdown_jumps(biped, sim, max(walked, 1))),
        "ground_force_rms_error": _rms((force[compared] - wrench_ref[compared, :2]) / weight),
        "feedforward_rms": _rms(feedforward[steady]),
        "feedback_rms": _rms(feedback[steady]),
        "feedback_share": float(np.sqrt(fb_square / max(ff_square + fb_square, 1e-12))),
        "landing_feedback_rms": _rms(feedback[~steady]),
        "energy_per_step": float(np.trapezoid(power, sim.time[:end]) / max(walked, 1)),
    }


def _knee_equality_violation(sim: Simulation) -> float:
    """Largest violation [rad] of the rolling knees' equalities over the walk."""
    model, worst = sim.model, 0.0
    for k in range(model.neq):
        a, b = model.jnt_qposadr[model.eq_obj1id[k]], model.jnt_qposadr[model.eq_obj2id[k]]
        violation = np.abs(sim.qpos[:, a] - model.eq_data[k, 1] * sim.qpos[:, b]).max()
        worst = max(worst, float(violation))
    return worst


def scuff_notes(sim: Simulation, period: float, figures: dict, steps: int) -> list:
    """What the swing foot's clearance says of a walk of ``walk_figures``: its scuffs, and
    whether they alone fail it, or how near it came to scuffing (``SCUFF_MARGIN``)."""
    scuffs = contact.scuffs(sim, period)
    if scuffs.steps:
        j = scuffs.steps[0]
        decided = walks({**figures, "scuff_steps": 0}, steps)
        return [
            ("decided by scuffing: " if decided else "")
            + f"the swing foot scuffed the floor in {len(scuffs.steps)} steps (first: step "
            f"{j + 1} at {scuffs.first_phase[j]:.2f} T, {scuffs.duration.sum() * 1e3:.0f} ms "
            f"in all, {scuffs.depth.max() * 1e3:.2f} mm deep)"
        ]
    if figures["swing_clearance"] < SCUFF_MARGIN:
        return [
            f"decided by scuffing: the swing foot cleared the floor by "
            f"{figures['swing_clearance'] * 1e3:.2f} mm (the gait by "
            f"{figures['gait_swing_clearance'] * 1e3:.2f} mm)"
        ]
    return []


def walk_failures(figures: dict, steps: int) -> list[str]:
    """Why the walk of ``walk_figures`` is not a walk of ``steps`` steps (empty: it is)."""
    failures = []
    if figures["steps"] < steps:
        failures.append(f"{figures['steps']} of {steps} steps within the limits")
    if figures["fell"]:
        failures.append("fell")
    if not figures["max_slip"] < MAX_SLIP:
        failures.append(
            f"stance foot slipped {figures['max_slip'] * 1e3:.3g} mm "
            f"(allowed < {MAX_SLIP * 1e3:g} mm)"
        )
    if not figures["max_foot_tilt"] < MAX_FOOT_TILT:
        failures.append(
            f"stance foot tilted {figures['max_foot_tilt']:.3g} rad "
            f"(allowed < {MAX_FOOT_TILT:g} rad)"
        )
    if figures["scuff_steps"] != 0:
        scuffed = figures["scuff_steps"]
        failures.append(f"swing foot scuffed the floor in {scuffed} step{'s' * (scuffed != 1)}")
    if figures["warnings"] != 0:
        failures.append(f"{figures['warnings']} MuJoCo warnings")
    return failures


def walks(figures: dict, steps: int) -> bool:
    """The walk of ``walk_figures`` is a walk of ``steps`` steps."""
    return not walk_failures(figures, steps)


def walk_verdict(walker: Walker, sim: Simulation, steps: int) -> list[str]:
    """The forward check's verdict on a walk of ``walker`` (``Walker.walk``): why it is not a
    walk of ``steps`` steps (``walk_failures``; empty: it is)."""
    figures = walk_figures(walker.biped, walker.samples, sim, energy=float("nan"))
    return walk_failures(figures, steps)


def check_forward(walker: Walker, steps: int, energy: float):
    """Walk at the default gains and check; returns (check, simulation, ground reaction)."""
    began = time.perf_counter()
    sim = walker.walk(steps)
    wall = time.perf_counter() - began
    reaction = contact.ground_reaction(sim)
    figures = walk_figures(walker.biped, walker.samples, sim, energy, reaction)
    figures["real_time_factor"] = figures["seconds_simulated"] / wall
    notes = scuff_notes(sim, walker.period, figures, steps)
    failures = walk_failures(figures, steps)
    if failures:  # why, in words, beside the figures (the atlas's lines give only the notes)
        notes = [f"not a walk of {steps} steps: " + ", ".join(failures), *notes]
    shown = (
        "steps",
        "fell",
        "max_slip",
        "max_foot_tilt",
        "scuff_steps",
        "swing_clearance",
        "step_advance_range",
        "feedback_share",
        "zmp_rms_error",
        "warnings",
        "real_time_factor",
    )
    check = Check("forward", not failures, figures, notes, shown=shown)
    return check, sim, reaction


def _key(scale: float) -> str:
    """A gain scale in a figure's name: 0.5 -> '0_5' (a key without dots)."""
    return f"{scale:g}".replace(".", "_")


def check_gains(walker: Walker, steps: int, energy: float, forward: Check) -> Check:
    """The walk at kp × ``GAIN_SCALES`` beside the default's."""
    results = {1.0: walks(forward.figures, steps)}
    clearances = {1.0: forward.figures["swing_clearance"]}
    notes = []
    for scale in GAIN_SCALES:
        sim = walker.walk(steps, WalkSettings(kp_scale=scale))
        figures = walk_figures(walker.biped, walker.samples, sim, energy)
        results[scale] = walks(figures, steps)
        clearances[scale] = figures["swing_clearance"]
        notes += [
            f"kp × {scale:g}: {note}" for note in scuff_notes(sim, walker.period, figures, steps)
        ]
    scales = sorted(results)
    walked = [s for s in scales if results[s]]
    figures = {f"walks_at_kp_x{_key(scale)}": results[scale] for scale in scales}
    figures |= {f"swing_clearance_at_kp_x{_key(scale)}": clearances[scale] for scale in scales}
    figures["kp"] = KP
    if results[1.0]:  # the range around the default over which it walks
        low = high = scales.index(1.0)
        while low > 0 and results[scales[low - 1]]:
            low -= 1
        while high < len(scales) - 1 and results[scales[high + 1]]:
            high += 1
        figures["kp_scale_range"] = [scales[low], scales[high]]
    else:
        figures["kp_scale_range"] = [float("nan"), float("nan")]
    passed = len(walked) == len(scales)
    if not passed:
        notes.insert(0, "walks at kp × " + (", ".join(f"{s:g}" for s in walked) or "none"))
    return Check("gains", passed, figures, notes)
