"""Units of the validation report's figures (``validate.validation``), for its ``units`` map.

Paths and notation as in ``biped.records.units``: ``"forward.max_slip": "m"``. "weight" is a
fraction of the robot's weight, "S" of the gait's step length; a figure that is the largest of
several quantities of different units names them all ("N, N·m": the largest of the errors
of Fx, Fz [N] and Cy [N·m]).
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

from biped.model.dynamics import JOINTS
from biped.records.units import PERIOD, PURE

GAIN_KEYS = ("0_5", "1", "2")  # validate.checks.GAIN_SCALES and the default, as keys


def _figure(unit: str | None, **kwargs):
    """A figure with its unit (None: a verdict, no number)."""
    return dataclasses.field(metadata={"unit": unit}, **kwargs)


@dataclass(frozen=True)
class WalkFigures:
    """The figures of a forward walk (``validate.checks.walk_figures``), each with its unit, in
    the report's order; ``max_knee_equality_violation`` for the rolling knee only."""

    steps: int = _figure(PURE)
    fell: bool = _figure(None)
    max_slip: float = _figure("m")
    step_duration_range: list = _figure(PERIOD)
    step_advance_range: list = _figure("S")
    max_landing_slide: float = _figure("m")
    max_foot_tilt: float = _figure("rad")
    max_heel_lift: float = _figure("m")
    max_toe_lift: float = _figure("m")
    scuff_steps: int = _figure(PURE)
    scuff_duration: float = _figure("s")
    scuff_depth: float = _figure("m")
    swing_clearance: float = _figure("m")
    gait_swing_clearance: float = _figure("m")
    zmp_rms_error: float = _figure("m")
    zmp_relative_error: float = _figure(PURE)
    touchdown_jump_error: float = _figure(PURE)
    ground_force_rms_error: float = _figure("weight")
    feedforward_rms: float = _figure("N·m")
    feedback_rms: float = _figure("N·m")
    feedback_share: float = _figure(PURE)
    landing_feedback_rms: float = _figure("N·m")
    energy_per_step: float = _figure("J")
    analytic_energy_per_step: float = _figure("J")
    warnings: int = _figure(PURE)
    distance: float = _figure("m")
    seconds_simulated: float = _figure("s")
    max_knee_equality_violation: float | None = _figure("rad", default=None)

    def to_dict(self) -> dict:
        """The figures by name (those not measured left out)."""
        values = {f.name: getattr(self, f.name) for f in dataclasses.fields(self)}
        return {name: value for name, value in values.items() if value is not None}


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
        **{
            f.name: f.metadata["unit"]
            for f in dataclasses.fields(WalkFigures)
            if f.metadata["unit"]
        },
        "real_time_factor": PURE,
    },
    "gains": {
        **{f"swing_clearance_at_kp_x{key}": "m" for key in GAIN_KEYS},
        "kp": "N·m/rad",
        "kp_scale_range": PURE,
    },
}


def report_units(report: dict) -> dict:
    """The ``units`` map of a report (``validate.validation.as_json``): the unit of each figure
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
