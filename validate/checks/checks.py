"""The checks of a gait file against MuJoCo, each a ``Check``: a verdict, figures, notes and,
when it fails, its causes in words of ``CAUSES``. Each tolerance is stated on a physical
scale beside its constant, and a failing check's note gives the figure on that scale.

model             the MJCF is the gait's robot: the rolling knee's equalities and their
                  ratio r2 / r1, and every field of ``biped.Robot`` the MJCF holds
                  (``validate.scene.model.parameter_differences``: the first that differs named
                  with both values); its mass beside the gait's ("model mismatch")
inverse_dynamics  the file's Γ, F_e, ZMP against MuJoCo's dynamics of the model along the
                  file's motion (``EXACT``; "model mismatch")
knee_loads        MuJoCo's force of the thigh on the lower leg through each knee (its
                  ``cfrc_int``) along the file's motion against the file's knee loads, normal
                  and tangential, both knees (``EXACT`` N: two exact rigid models, the knee
                  equalities' softness out of the inverse dynamics; 5e-13 N measured;
                  "model mismatch")
impact            the file's start velocities and impulse against MuJoCo's impact map
                  (mass matrix and foot Jacobian) applied to the file's end state (``EXACT``;
                  "model mismatch")
feedforward       each step replayed against the clock with the file's torques
                  (``validate.walk.replay``): the torque each joint's servo had to add, RMS over
                  the step, below ``SERVO_SHARE`` of the robot's torque scale (the largest
                  RMS torque of its joints) for every joint ("servo share"); each joint's
                  share of its own torque reported beside it
forward           the file walked in MuJoCo with contact (``validate.walk.simulate``): every step
                  lands and advances the hip by ``STEP_ADVANCE`` of the step length at
                  least ("did not advance"), no fall ("fell"), no slip of the stance foot
                  (``MAX_SLIP``, also as a share of the step: "slipped"), the stance foot
                  flat (tilt below ``MAX_FOOT_TILT``, its sole's far end within 2.6 mm of the
                  floor: "tilted"), no scuff of the swing foot before its landing window
                  ("scuffed"), no MuJoCo warning ("MuJoCo warning"); ground reaction, centre
                  of pressure, velocity jump at touchdown, feedback, energy, clearance, the
                  rolling-knee equality, and per joint the torques (the gait's, MuJoCo's, the
                  servos') over the step reported beside the gait's
gains             the same walk at kp × ``GAIN_SCALES``: the range of gains it walks over
                  (the causes of the walks that fail)

A model the harness cannot use as the gait's robot (``validate.scene.model.ModelError``: a rolling
knee without its equalities) fails the checks that need it, with the reason as a note
("model mismatch"). The orbit check (``validate.checks.orbit``) fails as "unstable orbit".
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field, replace

import mujoco
import numpy as np

from biped.model.dynamics import JOINTS, Biped
from biped.model.kinematics import ZH
from biped.model.knee_loads import KNEE_SIDES, knee_forces
from biped.model.profile import KneeProfile
from biped.model.units import PURE, unit_text
from biped.records.gait_file import Gait
from validate.checks.crosscheck import (
    mujoco_impact,
    mujoco_inverse_dynamics,
    mujoco_knee_forces,
    rigid_copy,
)
from validate.checks.knee_fit import TARGET, knee_fit
from validate.checks.units import FIGURE_UNITS, PROFILES, WalkFigures
from validate.scene.mapping import mapping, other
from validate.scene.mjcf import SIDES
from validate.scene.model import ModelError, model_problems
from validate.walk import contact
from validate.walk.replay import DOUBLE_SUPPORT_TIMESTEP, replay_model, replay_step
from validate.walk.samples import GaitSamples
from validate.walk.simulate import Simulation, Walker, WalkSettings, reference_along

# The validation's walk: the servos' and the speed loop's gains of ``validate.walk.simulate``.
WALK = WalkSettings()

# Agreement of two exact rigid-body models of one robot, in each figure's unit (N·m, N, m,
# m/s, rad/s, N·s): a millionth of the torques (1-10 N·m), of the weight (687 N) and of the
# sole (0.26 m) of the gaits it compares; two models of one robot agree to rounding (1e-13
# measured), a robot 5 % off in any field of Table 1 differs by 1e-3 or more.
EXACT = 1e-6
# Largest torque a joint's servo may add in the replay (``validate.walk.replay``), RMS over the
# step, as a share of the robot's torque scale: the largest RMS torque of its joints over
# that step (a stance hip's or ankle's: 1.7 N·m for the optimal gaits at 0.3 m/s, 7.3 N·m at
# 0.6 m/s). Judged against that scale, not against each joint's own torque: a swing ankle
# carrying 0.12 N·m needs 0.015 N·m of servo torque for the millisecond after its torque
# jumps at the mid-step knot, 12 % of its own torque but 0.6 % of the scale. Measured
# (``tests/test_wrong_models.py``): the correct gaits of both knees at 0.2-0.6 m/s, walkable
# or with 2-3 cm of clearance, need 0.0064 at most (that swing ankle, at 0.2 m/s with 3 cm,
# with servos of 1000 or 2000 N·m/rad alike); the optimal gaits at 0.3 m/s 0.0034 (0.0021
# at 1000: the stiffer servos pull harder on MuJoCo's integration error); the Table 1 gaits
# on a model 10 % off need 0.026 (r1; 0.017 at 1000) to 1.1 (the trunk's centre of mass;
# 0.67), 0.058 (a thigh's inertia; 0.05), 0.69 (the trunk's mass; 0.47).
SERVO_SHARE = 0.01
# The same in a two-phase gait's double support replayed, both feet on the floor: the two
# stiff soft contacts of a closed chain chatter (each foot's force swings by hundreds of
# newtons from one physics step to the next), and the servos answer; MuJoCo's integration
# error, which this is, falls faster than the step (``validate.walk.replay``:
# ``DOUBLE_SUPPORT_TIMESTEP``, 31.25 µs). Measured there, the optima at 0.3 m/s with the load
# handed over (double support 0.1-0.4 of the step): rolling 0.025 (its front ankle), revolute
# 0.0073; the rolling knee's file on the revolute knee's model 0.63, the revolute knee's on
# the rolling knee's 7.4.
DOUBLE_SUPPORT_SERVO_SHARE = 0.05
# Ground force of each foot in a double support replayed: MuJoCo's, averaged over
# ``FORCE_WINDOW`` [s] (the chatter above averages out), against the file's, the RMS over the
# phase of |ΔF| (Fx, Fz) below this share of the weight. Measured (the optima above): the
# rolling knee's 11.7 N RMS (1.7 % of its 687 N) on its rear foot, 15.6 N on its front
# foot, the revolute knee's 4.6 and 5.4 N; the rolling knee's file on the revolute knee's
# model 360 N and 428 N. Before the load was handed over (double support 0.1-0.2): its
# double support 10 % longer (the same torques) 61 N and 52 N, and 0.137 of the servos.
FOOT_FORCE_SHARE = 0.05
FORCE_WINDOW = 0.0025
# Stance-foot travel during its stance, after the landing settles [m]: 0.56 % of the 0.18 m
# step of the optimal gaits at 0.3 m/s (0.12 mm measured), a tenth of the 1 cm the hip's
# advance is read to.
MAX_SLIP = 1e-3
# Share of the weight below which a foot's normal force carries no ZMP worth comparing (a foot
# handing its load over: its ZMP is 0 / 0 there).
ZMP_LOAD = 0.01
# Largest tilt [rad] of the stance foot: a loaded sole on the soft floor tilts by a
# fraction of a milliradian; 0.01 rad lifts the far end of the 25.8 cm sole by 2.6 mm.
MAX_FOOT_TILT = 0.01
# Fall: hip lower than this fraction of its planned minimum (8.9 cm below the 0.89 m of the
# optimal gaits), or trunk beyond this angle (29°).
HIP_DROP = 0.9
TRUNK_LIMIT = 0.5  # [rad]
# A step counts only if the hip advances by this fraction of the step length in it (a robot
# shuffling in place makes short "steps" that land).
STEP_ADVANCE = 0.5
# Fraction of a step after touchdown left out of the comparisons with the gait: MuJoCo's
# soft landing takes that long to settle (59 ms at 0.3 m/s).
LANDING = 0.1
# Time after a landing's first contact at which its velocity jump is read [s].
JUMP_WINDOW = 0.02
# A walk whose swing foot clears the floor by less than this [m] is decided by scuffing:
# the verdict would change with a millimetre of tracking error.
SCUFF_MARGIN = 1e-3
# Scales of the servos' stiffness KP (the damping stays) of the gains check.
GAIN_SCALES = (0.5, 2.0)
# Points of the forward check's torque profiles over one step (``walk_figures``).
PROFILE_POINTS = 50
# Why a check fails, in words: every failing check names its causes among these (``Check``).
CAUSES = (
    "fell",  # the hip dropped or the trunk tipped over
    "scuffed",  # the swing foot touched the floor before its landing
    "slipped",  # the stance foot slid
    "tilted",  # the stance foot rolled onto an edge of its sole
    "unstable orbit",  # the walk's return map is not shown to shrink an error
    "servo share",  # the gait's torques alone do not make its motion
    "model mismatch",  # the model is not the gait's robot, or its dynamics not the gait's
    "MuJoCo warning",  # the simulator warned (an unstable integration)
    "did not advance",  # a step did not land, or landed without carrying the hip forward
    "foot forces",  # a double support's feet are not pushed by the ground as the gait's
    "not run",  # a check not built for this gait (a two-phase gait's walk): unknown, not passed
)


@dataclass
class Check:
    """One check of a gait.

    Attributes:
        name: its key in the report (``inverse_dynamics``, ``forward``, ...).
        passed: the verdict.
        figures: name -> value (numbers, booleans, [low, high] pairs; NaN: not measured).
        notes: sentences that go with the verdict.
        shown: the figures ``line`` prints (None: all).
        causes: why it fails, among ``CAUSES`` (empty when it passes).
    """

    name: str
    passed: bool
    figures: dict
    notes: list = field(default_factory=list)
    shown: tuple | None = None
    causes: list = field(default_factory=list)

    def __post_init__(self):
        unknown = [cause for cause in self.causes if cause not in CAUSES]
        if unknown:
            raise ValueError(f"cause {unknown[0]!r} of check {self.name}: allowed {CAUSES}")

    def line(self) -> str:
        """PASS or FAIL, the name, the causes first, the figures shown with units, notes."""
        names = self.figures if self.shown is None else self.shown
        values = ", ".join(
            f"{k} {_fmt(self.figures[k])}{_unit(self.name, k)}"
            for k in names
            if k in self.figures and k not in PROFILES
        )
        causes = f"[{', '.join(self.causes)}] " if self.causes else ""
        text = f"{'PASS' if self.passed else 'FAIL'}  {self.name:17} {causes}{values}".rstrip()
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


def _peak(values) -> float:
    """Largest magnitude; NaN for no values."""
    return float(np.abs(values).max()) if np.size(values) else float("nan")


def _median(values) -> float:
    """Median; NaN for no values (a walk too short to measure)."""
    return float(np.median(values)) if np.size(values) else float("nan")


def _model_failure(name: str, error: Exception) -> Check:
    return Check(name, False, {}, notes=[f"model error: {error}"], causes=[MISMATCH])


MISMATCH = "model mismatch"


def _exact_verdict(name: str, figures: dict, what: str, scales: dict, notes=None) -> Check:
    """A check of two exact models (``EXACT``): passed when every figure of ``scales`` is
    below it; else a note giving the largest of each against its physical scale
    (name -> (scale, what it is)), cause "model mismatch"."""
    notes = list(notes or [])
    passed = all(figures[key] < EXACT for key in scales)
    if not passed:
        said = []
        for key, (scale, of) in scales.items():
            unit = _unit(name, key)
            share = f", {100 * figures[key] / scale:.2g} % of {of}" if scale > 0 else ""
            said.append(f"{key} {figures[key]:.3g}{unit}{share}")
        notes.insert(
            0,
            f"{what}: {'; '.join(said)} (allowed < {EXACT:g} in each unit: two models of one "
            "robot agree to rounding)",
        )
    return Check(name, passed, figures, notes, causes=[] if passed else [MISMATCH])


def not_run(name: str, why: str) -> Check:
    """The check ``name`` not run on this gait, for the reason ``why``: a failure, cause "not
    run" (unknown, never passed)."""
    return Check(name, False, {}, notes=[f"not run: {why}"], causes=["not run"])


def check_model(model: mujoco.MjModel, biped: Biped) -> Check:
    """The model is the gait's robot (``validate.scene.model.model_problems``); masses reported.
    A profiled knee's also MuJoCo's knee against the analytical one over the knee's range
    (``validate.checks.knee_fit``: its largest distance and angle, each below ``TARGET``)."""
    problems = model_problems(model, biped)
    trunk = model.body("trunk").id
    mass = float(model.body_subtreemass[trunk])
    figures = {"mass_difference": mass - biped.robot.total_mass, "problems": len(problems)}
    if biped.knee == "rolling" and biped.robot.profiled and not problems:
        fit = knee_fit(model, KneeProfile.of(biped.robot))
        figures["knee_position_error"], figures["knee_angle_error"] = fit.position, fit.angle
        for what, value, target, unit in (
            ("distance", fit.position, TARGET[0], "m"),
            ("angle", fit.angle, TARGET[1], "rad"),
        ):
            if not value < target:  # NaN (not measured) fails too
                problems.append(
                    f"MuJoCo's knee differs from the analytical one by a {what} of "
                    f"{value:.3g} {unit} over the knee's range (allowed < {target:g} {unit})"
                )
        figures["problems"] = len(problems)
    return Check("model", not problems, figures, notes=problems, causes=[MISMATCH] * bool(problems))


def check_inverse_dynamics(model: mujoco.MjModel, biped: Biped, samples: GaitSamples) -> Check:
    """MuJoCo's Newton-Euler along the file's motion against its torques, ground wrench and
    ZMP. Along a two-phase gait's double support both feet are held: the front foot's wrench
    is the file's, given to MuJoCo (with both feet held the motors and the feet are twelve
    unknowns in nine equations: the split is the gait's, not MuJoCo's to find), and what is
    compared is what follows from it, the six torques and the rear foot's wrench and ZMP."""
    try:
        result = mujoco_inverse_dynamics(
            rigid_copy(model),
            biped,
            samples.q,
            samples.qd,
            samples.qdd,
            swing_wrench=samples.swing_wrench,
        )
    except ModelError as error:
        return _model_failure("inverse_dynamics", error)
    zmp = samples.zmp[:, 0]
    wrench = np.abs(result.wrench - samples.wrench)  # Fx, Fz [N], Cy [N·m]
    # the ZMP where the foot carries a load: a foot handing its load over (a two-phase gait's
    # rear foot at lift-off) has none there, its ZMP 0 / 0; its wrench is compared
    loaded = samples.wrench[:, 1] > ZMP_LOAD * biped.robot.weight
    figures = {
        "max_torque_error": float(np.abs(result.torques - samples.torques).max()),
        "max_force_error": float(wrench[:, :2].max()),
        "max_moment_error": float(wrench[:, 2].max()),
        "max_zmp_error": float(np.abs(result.zmp - zmp)[loaded].max()),
    }
    if result.coupling.size:
        figures["max_knee_coupling"] = float(np.abs(result.coupling).max())
    weight = biped.robot.weight
    scales = {
        "max_torque_error": (_peak(samples.torques), "the largest joint torque"),
        "max_force_error": (weight, "the weight"),
        "max_moment_error": (_peak(samples.wrench[:, 2]), "the largest ground moment"),
        "max_zmp_error": (biped.robot.foot_length, "the sole"),
    }
    what = "MuJoCo's inverse dynamics of the model are not the gait file's"
    notes = []
    if samples.two_phase:
        notes.append(
            "both phases; in double support the front foot's wrench is the file's, given to "
            "MuJoCo: compared the torques and the rear foot's wrench and ZMP"
        )
    return _exact_verdict("inverse_dynamics", figures, what, scales, notes)


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
    weight = biped.robot.weight
    scales = {f"max_knee_{part}_error": (weight, "the weight") for part in ("normal", "tangential")}
    what = "MuJoCo's force through the knees is not the gait file's"
    return _exact_verdict(name, figures, what, scales, notes)


def check_impact(model: mujoco.MjModel, biped: Biped, samples: GaitSamples, gait: Gait) -> Check:
    """MuJoCo's impact map of the file's end state against the file's start velocities (the
    legs swapped: the new stance leg is the old swing leg) and its impulse."""
    exact = rigid_copy(model)
    q, qd_minus = samples.end()
    mj_qd_plus, mj_impulse = mujoco_impact(exact, biped, q, qd_minus)
    start = mapping(exact, "right", biped.radii).qvel(samples.q[0], samples.qd[0])
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
    start_rates = np.abs(start)
    scales = {
        "max_linear_velocity_error": (_peak(start_rates[slide]), "the largest hip speed"),
        "max_angular_velocity_error": (_peak(start_rates[~slide]), "the largest joint rate"),
    }
    if impulse is not None:
        size = float(np.linalg.norm(mj_impulse[:2]))
        scales["max_force_impulse_error"] = (size, "the impulse")
        scales["max_moment_impulse_error"] = (abs(float(mj_impulse[2])), "its moment")
    what = "MuJoCo's impact map is not the gait file's"
    check = _exact_verdict("impact", figures, what, scales, notes)
    if impulse is None:  # nothing to compare the impulse with: not shown to be MuJoCo's
        check.passed, check.causes = False, [MISMATCH]
    return check


def check_two_phase_impact(
    model: mujoco.MjModel, biped: Biped, samples: GaitSamples, gait: Gait
) -> Check:
    """A two-phase gait's landing, which holds both feet: MuJoCo's impact map with both
    ankles held (``mujoco_impact(both_feet=True)``) applied to the file's state before the
    landing, against the file's velocities after it (the double support's first sample, in
    the same labels: no leg swap) and its impulses on the rear then the front foot
    (``EXACT``; zero for a zero-speed landing)."""
    exact = rigid_copy(model)
    q, qd_minus = samples.single_support().end()
    mj_qd_plus, mj_impulse = mujoco_impact(exact, biped, q, qd_minus, both_feet=True)
    double = samples.double_support()
    start = mapping(exact, "left", biped.radii).qvel(double.q[0], double.qd[0])
    velocity = np.abs(mj_qd_plus - start)
    slide = exact.jnt_type[exact.dof_jntid] == mujoco.mjtJoint.mjJNT_SLIDE  # m/s, else rad/s
    impulse = np.asarray(gait.double_support.landing_impulse, dtype=float)
    error = np.abs(mj_impulse - impulse).reshape(2, 3)  # rear, front: Ix, Iz [N·s], Iy [N·m·s]
    figures = {
        "max_linear_velocity_error": float(velocity[slide].max()),
        "max_angular_velocity_error": float(velocity[~slide].max()),
        "normal_impulse": float(mj_impulse[4]),  # on the landing (front) foot
        "rear_normal_impulse": float(mj_impulse[1]),
        "landing_speed": float(np.linalg.norm(biped.point_jacobian(q, "swing_ankle") @ qd_minus)),
        "max_force_impulse_error": float(error[:, :2].max()),
        "max_moment_impulse_error": float(error[:, 2].max()),
    }
    start_rates = np.abs(start)
    size = float(np.linalg.norm(mj_impulse.reshape(2, 3)[:, :2]))
    scales = {
        "max_linear_velocity_error": (_peak(start_rates[slide]), "the largest hip speed"),
        "max_angular_velocity_error": (_peak(start_rates[~slide]), "the largest joint rate"),
        "max_force_impulse_error": (size, "the impulses"),
        "max_moment_impulse_error": (_peak(mj_impulse.reshape(2, 3)[:, 2]), "their moments"),
    }
    notes = ["the landing holds both feet: MuJoCo's impact map with both ankles held"]
    what = "MuJoCo's impact map holding both feet is not the gait file's landing"
    return _exact_verdict("impact", figures, what, scales, notes)


def check_feedforward(spec: mujoco.MjSpec, biped: Biped, samples: GaitSamples) -> Check:
    """Both stance sides replayed (``validate.walk.replay``): each joint's servo torque, RMS over
    the step, against the robot's torque scale (the largest RMS torque of its joints over
    the step), below ``SERVO_SHARE`` at every joint; each joint's share of its own torque
    reported beside it."""
    model = replay_model(spec, biped.knee)
    replays = [replay_step(model, samples, biped, stance) for stance in SIDES]
    shares = np.max([r.shares() for r in replays], axis=0)
    feedback = np.max([r.feedback_rms() for r in replays], axis=0)
    torques = np.max([r.torque_rms() for r in replays], axis=0)
    scale = float(torques.max())
    ratios = feedback / scale if scale > 0 else np.full(len(JOINTS), np.nan)
    figures = {
        "max_feedback_ratio": float(ratios.max()),
        "torque_scale": scale,
        "max_feedback_share": float(shares.max()),
    }
    per_joint = (
        ("feedback_ratio", ratios),
        ("feedback_share", shares),
        ("feedback_rms", feedback),
        ("torque_rms", torques),
    )
    for name, values in per_joint:
        figures |= {f"{name}_{joint}": float(v) for joint, v in zip(JOINTS, values, strict=True)}
    passed = bool(ratios.max() < SERVO_SHARE)  # NaN (no torque to compare with) fails
    notes = []
    if not scale > 0:
        notes.append("no joint carries torque in the replay: no scale to judge the servos by")
    elif not passed:  # the file's torques alone do not make its motion in MuJoCo
        worst = [
            f"{v:.3g} N·m at {joint} ({100 * r:.2g} %)"
            for joint, v, r in zip(JOINTS, feedback, ratios, strict=True)
            if not r < SERVO_SHARE
        ]
        notes.append(
            "replayed in MuJoCo, the gait's torques need the servos to follow its motion: they "
            f"add {', '.join(worst)} RMS, of the robot's torque scale {scale:.3g} N·m (its "
            f"largest joint's RMS torque; allowed < {100 * SERVO_SHARE:g} %: "
            f"{SERVO_SHARE * scale:.2g} N·m)"
        )
    shown = ("max_feedback_ratio", "torque_scale") + tuple(f"feedback_ratio_{j}" for j in JOINTS)
    causes = [] if passed else ["servo share"]
    return Check("feedforward", passed, figures, notes, shown=shown, causes=causes)


def check_two_phase_feedforward(spec: mujoco.MjSpec, biped: Biped, samples: GaitSamples) -> Check:
    """A two-phase gait's both phases replayed (``validate.walk.replay``), each from its own
    start, both stance sides: the single support as ``check_feedforward``'s step, the double
    support from its landing with both feet on the floor. Each servo's RMS torque against the
    robot's torque scale, below ``SERVO_SHARE`` in single support and
    ``DOUBLE_SUPPORT_SERVO_SHARE`` in double support; in double support each foot's ground
    force, MuJoCo's averaged over ``FORCE_WINDOW``, against the file's (the rear foot's
    ``wrench``, the front foot's ``swing_wrench``): the RMS of |ΔF| below
    ``FOOT_FORCE_SHARE`` of the weight, the centres of pressure reported beside it."""
    model = replay_model(spec, biped.knee)
    chain = replay_model(spec, biped.knee, DOUBLE_SUPPORT_TIMESTEP)  # both feet held
    single, double = samples.single_support(), samples.double_support()
    phases = {
        "single": [replay_step(model, single, biped, side) for side in SIDES],
        "double": [replay_step(chain, double, biped, side, feet=True) for side in SIDES],
    }
    torques = np.max([r.torque_rms() for rs in phases.values() for r in rs], axis=0)
    scale = float(torques.max())
    figures, notes = {"torque_scale": scale}, []
    passed = scale > 0
    for phase, allowed in (("single", SERVO_SHARE), ("double", DOUBLE_SUPPORT_SERVO_SHARE)):
        feedback = np.max([r.feedback_rms() for r in phases[phase]], axis=0)
        ratios = feedback / scale if scale > 0 else np.full(len(JOINTS), np.nan)
        figures[f"{phase}_max_feedback_ratio"] = float(ratios.max())
        figures |= {
            f"{phase}_feedback_ratio_{j}": float(v) for j, v in zip(JOINTS, ratios, strict=True)
        }
        if not ratios.max() < allowed:
            passed = False
            notes.append(
                f"{phase} support replayed: the servos add up to {100 * ratios.max():.2g} % of "
                f"the robot's torque scale {scale:.3g} N·m (allowed < {100 * allowed:g} %)"
            )
    errors = _feet_errors(biped, double, phases["double"])
    figures |= errors
    weight = biped.robot.weight
    for foot in ("rear", "front"):
        rms = errors[f"{foot}_force_rms_error"]
        if not rms < FOOT_FORCE_SHARE * weight:  # NaN (no reading) fails too
            passed = False
            notes.append(
                f"double support replayed: MuJoCo's ground force on the {foot} foot differs "
                f"from the gait's by {rms:.3g} N RMS ({100 * rms / weight:.2g} % of the weight; "
                f"allowed < {100 * FOOT_FORCE_SHARE:g} %)"
            )
    causes = [] if passed else ["servo share"] * any("servos" in n for n in notes)
    causes += ["foot forces"] * any("ground force" in n for n in notes)
    if not passed and not causes:
        causes = ["servo share"]  # no torque scale
    shown = (
        "single_max_feedback_ratio",
        "double_max_feedback_ratio",
        "torque_scale",
        "rear_force_rms_error",
        "front_force_rms_error",
    )
    return Check("feedforward", passed, figures, notes, shown=shown, causes=causes)


def _feet_errors(biped: Biped, double: GaitSamples, replays) -> dict:
    """Each foot's ground force in the double support replays, MuJoCo's averaged over
    ``FORCE_WINDOW``, against the file's averaged alike: RMS and largest |ΔF| [N], RMS
    difference of the centre of pressure [m] (windows where MuJoCo's foot carries load)."""
    hp = biped.robot.ankle_height
    wrenches = {"rear": double.wrench, "front": double.swing_wrench}
    differences = {foot: ([], []) for foot in wrenches}
    for replay in replays:
        times, forces = replay.feet
        per = max(1, int(round(FORCE_WINDOW / (times[1] - times[0])))) if len(times) > 1 else 1
        count = len(times) // per * per
        for k, (foot, name) in enumerate((("rear", "wrench"), ("front", "swing_wrench"))):
            file = double.at(name, times[:count])
            cop_file = (file[:, 2] - hp * file[:, 0]) / file[:, 1]
            found = forces[:count, k]
            force = np.hypot(*(_windows(found[:, :2], per) - _windows(file[:, :2], per)).T)
            load = _windows(found[:, 1], per)
            moment = _windows(np.nan_to_num(found[:, 2]) * found[:, 1], per)
            cop = np.where(load > 0, moment / np.where(load > 0, load, 1.0), np.nan)
            differences[foot][0].extend(force)
            differences[foot][1].extend(cop - _windows(cop_file, per))
    figures = {}
    for foot, (force, cop) in differences.items():
        force, cop = np.array(force), np.array(cop)
        figures[f"{foot}_force_rms_error"] = _rms(force)
        figures[f"{foot}_force_max_error"] = _peak(force)
        figures[f"{foot}_cop_rms_error"] = _rms(cop[np.isfinite(cop)])
    return figures


def _windows(values, size: int) -> np.ndarray:
    """The means of ``values`` over consecutive windows of ``size`` rows."""
    values = np.asarray(values)
    return values.reshape(-1, size, *values.shape[1:]).mean(axis=1)


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
        to_paper = mapping(model, stance, biped.radii).to_paper
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
    reaction (``validate.walk.contact.ground_reaction``) only when it is given."""
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
    # A step that lands without carrying the hip forward (shuffling), or none that lands
    # while the robot stays up (standing), does not advance; a hip or trunk beyond its
    # limits is a fall.
    shuffled = bool(np.any(np.array(sim.landed) & (advance < STEP_ADVANCE)))
    fell = bool(hip.min() < lowest or np.abs(trunk).max() > TRUNK_LIMIT)
    counted = slice(0, max(walked, 1))
    durations = np.diff(sim.time[sim.step_starts].tolist() + [sim.time[-1] + dt])[counted]
    figures = {
        "steps": walked,
        "fell": fell,
        "stalled": bool(shuffled or (not all(sim.landed) and not fell)),
        "step_length": float(samples.step_length),
        "max_slip": float(slips.max()),
        "max_slip_share": float(slips.max() / samples.step_length),
        "step_duration_range": [float(durations.min() / period), float(durations.max() / period)],
        "step_advance_range": [float(advance[counted].min()), float(advance[counted].max())],
        "max_landing_slide": float(sim.stance_foot_slip(settle, landing=True).max()),
        **_foot_figures(biped, samples, sim, tilt, counted),
        **_tracking_figures(biped, samples, sim, reaction, walked, reference),
        "warnings": int(sim.warnings),
        "distance": float(sim.hip_x()[-1] - sim.hip_x()[0]),
        "seconds_simulated": float(sim.time[-1] - sim.time[0]),
    }
    figures["analytic_energy_per_step"] = float(energy)
    figures["energy_ratio"] = _ratio(figures["energy_per_step"], float(energy))
    if biped.knee == "rolling":
        figures.update(knee_equality_violations(sim))
    return WalkFigures(**figures).to_dict()  # the names, their order and units declared there


def _foot_figures(biped, samples, sim: Simulation, tilt, counted: slice) -> dict:
    """``walk_figures`` of the feet: the stance foot's tilt, the swing foot's scuffs and its
    clearance over the steps ``counted``."""
    scuffs = contact.scuffs(sim, samples.landing_time)
    clearance = contact.clearance(biped, samples, sim)
    return {
        "sole_length": float(biped.robot.foot_length),
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
    # Since the landing: the step's start, or a two-phase gait's touchdown (τ = T).
    since = sim.phase[:end] - (samples.landing if samples.two_phase else 0.0)
    steady = ~((since >= 0.0) & (since < LANDING * samples.period))
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
        "touchdown_jump_error": _median(
            [] if sim.double_support else touchdown_jumps(biped, sim, max(walked, 1))
        ),
        "ground_force_rms_error": _rms((force[compared] - wrench_ref[compared, :2]) / weight),
        "feedforward_rms": _rms(feedforward[steady]),
        "feedback_rms": _rms(feedback[steady]),
        "feedback_share": float(np.sqrt(fb_square / max(ff_square + fb_square, 1e-12))),
        "landing_feedback_rms": _rms(feedback[~steady]),
        "energy_per_step": float(np.trapezoid(power, sim.time[:end]) / max(walked, 1)),
        **_joint_figures(biped, samples, sim, end, steady, torques_ref[:end]),
    }


def _paper_joints(sim: Simulation, radii, torques: np.ndarray) -> np.ndarray:
    """(N, 6) torques of ``JOINT_ORDER`` in the paper's joint order (Γ1..Γ6: stance ankle to
    swing ankle), by the stance side of each row."""
    out = np.empty_like(torques)
    stance = sim.stance_of()[: len(torques)]
    for side in SIDES:
        rows = stance == side
        out[rows] = torques[rows][:, mapping(sim.model, side, radii).columns]
    return out


def _joint_figures(biped, samples, sim: Simulation, end: int, steady, reference) -> dict:
    """``walk_figures`` per joint (the paper's order, ``JOINTS``) over the steps walked: the
    RMS of the gait's torque at the phase followed, of MuJoCo's (its motors and servos), of
    the rotors' part (the motors less the gait's Γ: MuJoCo's armature, which the paper's
    robot lacks) and of the servos' part, the landings (``LANDING``) left out; and the
    profiles of the four over one step (the mean over the steps walked, landings in, at
    ``PROFILE_POINTS`` phases)."""
    servo = _paper_joints(sim, biped.radii, sim.feedback()[:end])
    motors = _paper_joints(sim, biped.radii, sim.feedforward()[:end])
    total = motors + servo
    rotor = motors - reference  # what the motors add to the gait's Γ: J_r θ̈ of the rotors
    phase = np.clip(sim.phase[:end] / samples.period, 0.0, 1.0)
    where = np.minimum((phase * PROFILE_POINTS).astype(int), PROFILE_POINTS - 1)
    centres = (np.arange(PROFILE_POINTS) + 0.5) / PROFILE_POINTS

    def profile(values):  # (PROFILE_POINTS, 6), NaN where no state of the walk fell
        out = np.full((PROFILE_POINTS, values.shape[1]), np.nan)
        for k in range(PROFILE_POINTS):
            if np.any(where == k):
                out[k] = values[where == k].mean(axis=0)
        return out.tolist()

    def rms(values):
        if not steady.any():  # no steady state walked: not measured
            return [float("nan")] * values.shape[1]
        return np.sqrt(np.mean(values[steady] ** 2, axis=0)).tolist()

    return {
        "gait_torque_rms": rms(reference),
        "mujoco_torque_rms": rms(total),
        "rotor_torque_rms": rms(rotor),
        "servo_torque_rms": rms(servo),
        "landing_window": LANDING,
        "profile_phase": centres.tolist(),
        "gait_torque_profile": samples.at("torques", centres * samples.period).tolist(),
        "mujoco_torque_profile": profile(total),
        "rotor_torque_profile": profile(rotor),
        "servo_torque_profile": profile(servo),
    }


def knee_equality_violations(sim: Simulation) -> dict:
    """Largest violations of the rolling knees' equalities over the walk, by their unit: the
    angle equalities between two hinges [rad] (the circles' knee) and the length equalities
    [m] (a profiled knee's arc lengths, ``knee_arc`` a slide, and its pinned stretch tendon).
    Each is MuJoCo's own residual: the first object's change from its reference position less
    the equality's quartic of the second's."""
    model, worst = sim.model, {"rad": 0.0, "m": 0.0}
    for k in range(model.neq):
        if model.eq_type[k] == mujoco.mjtEq.mjEQ_JOINT:
            first, unit = _joint_position(model, sim.qpos, model.eq_obj1id[k])
            second, _ = _joint_position(model, sim.qpos, model.eq_obj2id[k])
        elif model.eq_type[k] == mujoco.mjtEq.mjEQ_TENDON:
            first, unit = _tendon_length(model, sim.qpos, model.eq_obj1id[k]), "m"
            second = _tendon_length(model, sim.qpos, model.eq_obj2id[k])
        else:
            continue
        quartic = np.polynomial.polynomial.polyval(second, model.eq_data[k, :5])
        worst[unit] = max(worst[unit], float(np.abs(first - quartic).max()))
    return {
        "max_knee_equality_violation": worst["rad"],
        "max_knee_length_violation": worst["m"] if model.ntendon and _profiled(model) else None,
    }


def _joint_position(model, qpos: np.ndarray, joint: int) -> tuple[np.ndarray, str]:
    """A hinge's or a slide's change from its reference position over the walk, and its unit;
    no joint (-1): zero."""
    if joint < 0:
        return np.zeros(len(qpos)), "rad"
    address = model.jnt_qposadr[joint]
    slide = model.jnt_type[joint] == mujoco.mjtJoint.mjJNT_SLIDE
    return qpos[:, address] - model.qpos0[address], "m" if slide else "rad"


def _tendon_length(model, qpos: np.ndarray, tendon: int) -> np.ndarray:
    """A fixed tendon's change from its reference length over the walk [m]; none (-1): zero."""
    if tendon < 0:
        return np.zeros(len(qpos))
    first = model.tendon_adr[tendon]
    wraps = range(first, first + model.tendon_num[tendon])
    length = sum(model.wrap_prm[w] * qpos[:, model.jnt_qposadr[model.wrap_objid[w]]] for w in wraps)
    return length - model.tendon_length0[tendon]


def _profiled(model) -> bool:
    """Whether the model's knees are profiled (a slide among their joints)."""
    return any(
        model.jnt_type[j] == mujoco.mjtJoint.mjJNT_SLIDE
        and "knee" in (mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_JOINT, j) or "")
        for j in range(model.njnt)
    )


def scuff_notes(sim: Simulation, swing: float, figures: dict, steps: int) -> list:
    """What the swing foot's clearance says of a walk of ``walk_figures`` whose swing lasts
    ``swing`` [s] (``GaitSamples.landing_time``): its scuffs, and whether they alone fail
    it, or how near it came to scuffing (``SCUFF_MARGIN``)."""
    scuffs = contact.scuffs(sim, swing)
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


def walk_findings(figures: dict, steps: int) -> list[tuple[str, str]]:
    """Why the walk of ``walk_figures`` is not a walk of ``steps`` steps, as (cause, words)
    pairs, the cause among ``CAUSES``, each tolerance on its physical scale (empty: it is)."""
    found = []
    if figures["fell"]:
        found.append(
            (
                "fell",
                f"fell (the hip below {HIP_DROP:.0%} of its lowest in the gait, or the trunk "
                f"beyond {np.degrees(TRUNK_LIMIT):.0f}°)",
            )
        )
    if figures["stalled"]:
        found.append(
            (
                "did not advance",
                "a step did not land, or landed having carried the hip less than "
                f"{STEP_ADVANCE:g} of the step length",
            )
        )
    if not figures["max_slip"] < MAX_SLIP:
        step = figures["step_length"]
        found.append(
            (
                "slipped",
                f"stance foot slipped {figures['max_slip'] * 1e3:.3g} mm, "
                f"{100 * figures['max_slip_share']:.2g} % of the {step:.3g} m step "
                f"(allowed < {MAX_SLIP * 1e3:g} mm, {100 * MAX_SLIP / step:.2g} %)",
            )
        )
    if not figures["max_foot_tilt"] < MAX_FOOT_TILT:
        sole = figures["sole_length"]
        lifted = max(figures["max_heel_lift"], figures["max_toe_lift"])
        end = "heel" if figures["max_heel_lift"] >= figures["max_toe_lift"] else "toe"
        found.append(
            (
                "tilted",
                f"stance foot tilted {figures['max_foot_tilt']:.3g} rad, its {end} "
                f"{lifted * 1e3:.3g} mm off the floor (allowed < {MAX_FOOT_TILT:g} rad: "
                f"{MAX_FOOT_TILT * sole * 1e3:.2g} mm at the far end of the "
                f"{sole * 100:.3g} cm sole)",
            )
        )
    if figures["scuff_steps"] != 0:
        scuffed = figures["scuff_steps"]
        found.append(
            (
                "scuffed",
                f"swing foot scuffed the floor in {scuffed} step{'s' * (scuffed != 1)} "
                f"({figures['scuff_duration'] * 1e3:.3g} ms in all, "
                f"{figures['scuff_depth'] * 1e3:.2g} mm deep; allowed none)",
            )
        )
    if figures["warnings"] != 0:
        found.append(("MuJoCo warning", f"{figures['warnings']} MuJoCo warnings"))
    if figures["steps"] < steps:  # first: the count, then why the steps stopped counting
        why = found[0][0] if found else "did not advance"
        found.insert(0, (why, f"{figures['steps']} of {steps} steps within the limits"))
    return found


def walk_failures(figures: dict, steps: int) -> list[str]:
    """Why the walk of ``walk_figures`` is not a walk of ``steps`` steps, in words (empty:
    it is)."""
    return [words for _, words in walk_findings(figures, steps)]


def walk_causes(figures: dict, steps: int) -> list[str]:
    """The causes (``CAUSES``, in that order) of ``walk_findings``: empty for a walk."""
    found = {cause for cause, _ in walk_findings(figures, steps)}
    return [cause for cause in CAUSES if cause in found]


def walks(figures: dict, steps: int) -> bool:
    """The walk of ``walk_figures`` is a walk of ``steps`` steps."""
    return not walk_failures(figures, steps)


def walk_verdict(walker: Walker, sim: Simulation, steps: int) -> list[str]:
    """The forward check's verdict on a walk of ``walker`` (``Walker.walk``): why it is not a
    walk of ``steps`` steps (``walk_failures``; empty: it is)."""
    figures = walk_figures(walker.biped, walker.samples, sim, energy=float("nan"))
    return walk_failures(figures, steps)


def check_forward(walker: Walker, steps: int, energy: float, settings: WalkSettings = WALK):
    """Walk under ``settings`` (the validation's gains by default) and check; returns (check,
    simulation, ground reaction)."""
    began = time.perf_counter()
    sim = walker.walk(steps, settings)
    wall = time.perf_counter() - began
    reaction = contact.ground_reaction(sim)
    figures = walk_figures(walker.biped, walker.samples, sim, energy, reaction)
    figures["real_time_factor"] = figures["seconds_simulated"] / wall
    notes = scuff_notes(sim, walker.samples.landing_time, figures, steps)
    failures = walk_failures(figures, steps)
    if failures:  # why, in words, beside the figures (the atlas's lines give only the notes)
        notes = [f"not a walk of {steps} steps: " + ", ".join(failures), *notes]
    shown = (
        "steps",
        "fell",
        "max_slip",
        "max_slip_share",
        "max_foot_tilt",
        "scuff_steps",
        "swing_clearance",
        "step_advance_range",
        "feedback_share",
        "zmp_rms_error",
        "energy_ratio",
        "warnings",
        "real_time_factor",
    )
    causes = walk_causes(figures, steps)
    check = Check("forward", not failures, figures, notes, shown=shown, causes=causes)
    return check, sim, reaction


def _key(scale: float) -> str:
    """A gain scale in a figure's name: 0.5 -> '0_5' (a key without dots)."""
    return f"{scale:g}".replace(".", "_")


def check_gains(
    walker: Walker, steps: int, energy: float, forward: Check, settings: WalkSettings = WALK
) -> Check:
    """The walk at kp × ``GAIN_SCALES`` beside the forward check's (``settings``: its gains,
    the validation's by default; the scales multiply its stiffness)."""
    results = {1.0: walks(forward.figures, steps)}
    clearances = {1.0: forward.figures["swing_clearance"]}
    found = set(walk_causes(forward.figures, steps))
    notes = []
    for scale in GAIN_SCALES:
        sim = walker.walk(steps, replace(settings, kp_scale=scale * settings.kp_scale))
        figures = walk_figures(walker.biped, walker.samples, sim, energy)
        results[scale] = walks(figures, steps)
        clearances[scale] = figures["swing_clearance"]
        found |= set(walk_causes(figures, steps))
        notes += [
            f"kp × {scale:g}: {note}"
            for note in scuff_notes(sim, walker.samples.landing_time, figures, steps)
        ]
    scales = sorted(results)
    walked = [s for s in scales if results[s]]
    figures = {f"walks_at_kp_x{_key(scale)}": results[scale] for scale in scales}
    figures |= {f"swing_clearance_at_kp_x{_key(scale)}": clearances[scale] for scale in scales}
    figures["kp"] = settings.kp
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
    causes = [] if passed else [cause for cause in CAUSES if cause in found]
    return Check("gains", passed, figures, notes, causes=causes)
