"""Units of the validation report's figures (``validate.report``), for its ``units`` map.

Paths and notation as in ``biped.records.units``: ``"forward.max_slip": "m"``. "weight" is a
fraction
of the robot's weight, "S" of the gait's step length; a figure that is the largest of
several quantities of different units names them all ("N, N·m": the largest of the errors
of Fx, Fz [N] and Cy [N·m]).
"""

from __future__ import annotations

from biped.model.dynamics import JOINTS
from biped.records.units import PERIOD, PURE

GAIN_KEYS = ("0_5", "1", "2")  # validate.checks.GAIN_SCALES and the default, as keys

FIGURE_UNITS = {
    "model": {"mass_difference": "kg", "problems": PURE},
    "inverse_dynamics": {
        "max_torque_error": "N·m",
        "max_wrench_error": "N, N·m",
        "max_zmp_error": "m",
        "max_knee_coupling": "N·m",
    },
    "impact": {
        "max_velocity_error": "m/s, rad/s",
        "max_impulse_error": "N·s, N·m·s",
        "normal_impulse": "N·s",
        "landing_speed": "m/s",
    },
    "feedforward": {
        "max_feedback_share": PURE,
        **{f"feedback_share_{joint}": PURE for joint in JOINTS},
        **{f"feedback_rms_{joint}": "N·m" for joint in JOINTS},
        **{f"torque_rms_{joint}": "N·m" for joint in JOINTS},
    },
    "forward": {
        "steps": PURE,
        "max_slip": "m",
        "step_duration_range": PERIOD,
        "step_advance_range": "S",
        "max_landing_slide": "m",
        "max_foot_tilt": "rad",
        "max_heel_lift": "m",
        "max_toe_lift": "m",
        "scuff_steps": PURE,
        "scuff_duration": "s",
        "scuff_depth": "m",
        "swing_clearance": "m",
        "gait_swing_clearance": "m",
        "zmp_rms_error": "m",
        "zmp_relative_error": PURE,
        "touchdown_jump_error": PURE,
        "ground_force_rms_error": "weight",
        "feedforward_rms": "N·m",
        "feedback_rms": "N·m",
        "feedback_share": PURE,
        "landing_feedback_rms": "N·m",
        "energy_per_step": "J",
        "analytic_energy_per_step": "J",
        "warnings": PURE,
        "distance": "m",
        "seconds_simulated": "s",
        "max_knee_equality_violation": "rad",
        "real_time_factor": PURE,
    },
    "gains": {
        **{f"swing_clearance_at_kp_x{key}": "m" for key in GAIN_KEYS},
        "kp": "N·m/rad",
        "kp_scale_range": PURE,
    },
}


def report_units(report: dict) -> dict:
    """The ``units`` map of a report (``validate.report.as_json``): the unit of each figure
    of its checks that ``FIGURE_UNITS`` names."""
    units = {}
    for check, figures in report.items():
        if not isinstance(figures, dict):
            continue
        for name in figures:
            unit = FIGURE_UNITS.get(check, {}).get(name)
            if unit is not None:
                units[f"{check}.{name}"] = unit
    return units
