"""Units of the validation report's figures (``validate.checks.validation``), for its ``units`` map.

Paths and notation as in ``biped.model.units``: ``"forward.max_slip": "m"``. "weight" is a
fraction of the robot's weight, "S" of the gait's step length. One figure has one unit: the
largest error of quantities of different units is one figure per unit (``max_force_error``
of Fx, Fz [N] and ``max_moment_error`` of Cy [N·m]).
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

from biped.model.dynamics import JOINTS
from biped.model.units import PERIOD, PURE, declared_units, unit_field

GAIN_KEYS = ("0_5", "1", "2")  # validate.checks.checks.GAIN_SCALES and the default, as keys


@dataclass(frozen=True)
class WalkFigures:
    """The figures of a forward walk (``validate.checks.checks.walk_figures``), each with its
    unit, in the report's order; ``max_knee_equality_violation`` for the rolling knee only."""

    # the leading steps that land and advance the hip, the stance foot still and flat
    steps: int = unit_field(PURE)
    fell: bool  # the hip too low or the trunk tilted (``validate.checks.checks.HIP_DROP``, ...)
    stalled: bool  # a step not landed, the robot up, or landed without advancing the hip
    step_length: float = unit_field("m")  # the gait's, the scale of the slip and the advance
    max_slip: float = unit_field("m")  # a supporting foot's travel on the floor, landing settled
    max_slip_share: float = unit_field("S")  # that over the step length
    step_duration_range: list = unit_field(PERIOD)  # of the steps walked
    step_advance_range: list = unit_field("S")  # the hip's advance in each of them
    max_landing_slide: float = unit_field("m")  # the landing foot's in the landing windows
    sole_length: float = unit_field("m")  # the robot's, the scale of the tilt
    max_foot_tilt: float = unit_field("rad")  # of a supporting foot
    max_heel_lift: float = unit_field("m")  # of the stance sole's heel
    max_toe_lift: float = unit_field("m")  # and toe
    scuff_steps: int = unit_field(PURE)  # the swing foot on the floor before its landing
    scuff_duration: float = unit_field("s")  # in all
    scuff_depth: float = unit_field("m")  # deepest
    swing_clearance: float = unit_field("m")  # the swing foot's least height, steps walked
    gait_swing_clearance: float = unit_field("m")  # the gait's own
    zmp_rms_error: float = unit_field("m")  # centre of pressure − the gait's ZMP, steady
    zmp_relative_error: float = unit_field(PURE)  # that over the rms of Γ1 / Fz
    touchdown_jump_error: float = unit_field(PURE)  # velocity jump − the impact map's, median
    ground_force_rms_error: float = unit_field("weight")  # (Fx, Fz) − the gait's, steady
    feedforward_rms: float = unit_field("N·m")  # the motors' torques (the gait's), steady
    feedback_rms: float = unit_field("N·m")  # the servos', steady
    feedback_share: float = unit_field(PURE)  # the servos' share of the torques
    landing_feedback_rms: float = unit_field("N·m")  # the servos' in the landing windows
    energy_per_step: float = unit_field("J")  # ∫ Σ |Γ θ̇| dt of MuJoCo's torques a step
    analytic_energy_per_step: float = unit_field("J")  # the gait's
    energy_ratio: float = unit_field(PURE)  # MuJoCo's energy per step over the gait's
    # Per joint, the paper's order (``biped.model.dynamics.JOINTS``: stance ankle, knee, hip,
    # swing hip, knee, ankle), the steps walked, steady: RMS of the gait's torque at the phase
    # followed, of MuJoCo's (motors and servos), of the rotors' part (the motors less the
    # gait's Γ) and of the servos' part.
    gait_torque_rms: list = unit_field("N·m")
    mujoco_torque_rms: list = unit_field("N·m")
    rotor_torque_rms: list = unit_field("N·m")
    servo_torque_rms: list = unit_field("N·m")
    landing_window: float = unit_field(PERIOD)  # after each touchdown, out of the RMS
    # The same over one step (the mean over the steps walked, landings in), at the phases
    # ``profile_phase``: (``validate.checks.checks.PROFILE_POINTS``, 6) each.
    profile_phase: list = unit_field(PERIOD)
    gait_torque_profile: list = unit_field("N·m")
    mujoco_torque_profile: list = unit_field("N·m")
    rotor_torque_profile: list = unit_field("N·m")
    servo_torque_profile: list = unit_field("N·m")
    warnings: int = unit_field(PURE)  # MuJoCo's
    distance: float = unit_field("m")  # the hip's travel
    seconds_simulated: float = unit_field("s")
    max_knee_equality_violation: float | None = unit_field("rad", default=None)
    max_knee_length_violation: float | None = unit_field("m", default=None)  # profiled knee

    def to_dict(self) -> dict:
        """The figures by name (those not measured left out)."""
        values = {f.name: getattr(self, f.name) for f in dataclasses.fields(self)}
        return {name: value for name, value in values.items() if value is not None}


# The figures of a walk over one step (``WalkFigures``): arrays a page draws, not a table's.
PROFILES = (
    "profile_phase",
    "gait_torque_profile",
    "mujoco_torque_profile",
    "rotor_torque_profile",
    "servo_torque_profile",
)

# Units of the section's coordinates (``validate.checks.orbit.COORDINATES``): six angles, six rates.
SECTION_UNITS = ["rad"] * 6 + ["rad/s"] * 6


@dataclass(frozen=True)
class OrbitFigures:
    """The figures of the orbit check (``validate.checks.orbit``), each with its unit, in the
    report's order; without an orbit (a walk fell) only the settings and ``verdict``."""

    verdict: str
    spectral_radius: float | None = unit_field(PURE, default=None)
    spectral_radius_spread: float | None = unit_field(PURE, default=None)
    spectral_radius_upper: float | None = unit_field(PURE, default=None)
    multipliers_real: list | None = unit_field(PURE, default=None)
    multipliers_imag: list | None = unit_field(PURE, default=None)
    multipliers_modulus: list | None = unit_field(PURE, default=None)
    flow_multiplier: float | None = unit_field(PURE, default=None)
    flow_multiplier_noise: float | None = unit_field(PURE, default=None)
    coordinates: list | None = None
    slowest_mode_real: list | None = unit_field(SECTION_UNITS, default=None)
    slowest_mode_imag: list | None = unit_field(SECTION_UNITS, default=None)
    fixed_point: list | None = unit_field(SECTION_UNITS, default=None)
    file_state: list | None = unit_field(SECTION_UNITS, default=None)
    fixed_point_angle_distance: float | None = unit_field("rad", default=None)
    fixed_point_rate_distance: float | None = unit_field("rad/s", default=None)
    residual_angle: float | None = unit_field("rad", default=None)
    residual_rate: float | None = unit_field("rad/s", default=None)
    noise_rate: float | None = unit_field("rad/s", default=None)
    period_ratio: float | None = unit_field(PURE, default=None)
    kp: float = unit_field("N·m/rad", default=0.0)
    kv: float = unit_field("N·m·s/rad", default=0.0)
    speed_gain: float = unit_field("N·s", default=0.0)
    step_angle: float = unit_field("rad", default=0.0)
    step_rate: float = unit_field("rad/s", default=0.0)
    phases: int = unit_field(PURE, default=0)
    section_advance: float = unit_field("m", default=0.0)
    section_phase: float = unit_field(PERIOD, default=0.0)
    walks: int = unit_field(PURE, default=0)

    def to_dict(self) -> dict:
        """The figures by name (those not measured left out)."""
        values = {f.name: getattr(self, f.name) for f in dataclasses.fields(self)}
        return {name: value for name, value in values.items() if value is not None}


FIGURE_UNITS = {
    "model": {
        "mass_difference": "kg",
        "problems": PURE,
        "knee_position_error": "m",  # a profiled knee's (``validate.checks.knee_fit``)
        "knee_angle_error": "rad",
    },
    "inverse_dynamics": {
        "max_torque_error": "N·m",
        "max_force_error": "N",  # of Fx, Fz
        "max_moment_error": "N·m",  # of Cy
        "max_zmp_error": "m",
        "max_knee_coupling": "N·m",
    },
    "knee_loads": {
        "max_knee_normal_error": "N",
        "max_knee_tangential_error": "N",
        "max_stance_knee_tension": "N",
        "max_swing_knee_tension": "N",
    },
    "impact": {
        "max_linear_velocity_error": "m/s",  # of the slide joints' rates
        "max_angular_velocity_error": "rad/s",  # of the hinges'
        "max_force_impulse_error": "N·s",  # of Ix, Iz
        "max_moment_impulse_error": "N·m·s",  # of Iy
        "normal_impulse": "N·s",
        "rear_normal_impulse": "N·s",  # a two-phase gait's landing (both feet held)
        "landing_speed": "m/s",
    },
    "feedforward": {
        "max_feedback_ratio": PURE,  # a servo's RMS torque over the robot's torque scale
        "torque_scale": "N·m",  # the largest RMS torque of the joints over the step
        **{f"feedback_ratio_{joint}": PURE for joint in JOINTS},
        "max_feedback_share": PURE,
        **{f"feedback_share_{joint}": PURE for joint in JOINTS},
        **{f"feedback_rms_{joint}": "N·m" for joint in JOINTS},
        **{f"torque_rms_{joint}": "N·m" for joint in JOINTS},
        # a two-phase gait's (``check_two_phase_feedforward``)
        **{f"{phase}_max_feedback_ratio": PURE for phase in ("single", "double")},
        **{
            f"{phase}_feedback_ratio_{joint}": PURE
            for phase in ("single", "double")
            for joint in JOINTS
        },
        **{
            f"{foot}_force_{kind}_error": "N"
            for foot in ("rear", "front")
            for kind in ("rms", "max")
        },
        **{f"{foot}_cop_rms_error": "m" for foot in ("rear", "front")},
    },
    "forward": {
        **declared_units(WalkFigures),
        "real_time_factor": PURE,
    },
    "gains": {
        **{f"swing_clearance_at_kp_x{key}": "m" for key in GAIN_KEYS},
        "kp": "N·m/rad",
        "kp_scale_range": PURE,
    },
    "orbit": declared_units(OrbitFigures),
}


def figure_units(check: str, figures) -> dict:
    """The unit of each figure of the check ``check`` that ``FIGURE_UNITS`` names, in the
    figures' order (figure name -> unit)."""
    known = FIGURE_UNITS.get(check, {})
    return {name: known[name] for name in figures if name in known}
