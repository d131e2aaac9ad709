"""The validation of a gait file: every check against MuJoCo on one model, and its report.

``validate`` runs the checks of ``validate.checks.checks`` (the walk's contact read by
``validate.walk.contact``) and the orbit check of ``validate.checks.orbit``, and returns them,
with the gait and what the recording and the video draw, as one ``Validation``
(``validate.outputs.record.record`` and ``validate.outputs.video.write_video`` take it whole);
``validation_report`` gives the report (``biped.records.validation_report.ValidationReport``):
one ``CheckResult`` per check with its figures and their units, ``passed``, ``notes`` and
``causes`` (why it fails, in words of ``validate.checks.checks.CAUSES``; ``Check.line`` prints
one line per check, its causes first).
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import mujoco
import numpy as np

from biped.model.dynamics import Biped
from biped.records.gait_file import Gait
from biped.records.validation_report import CheckResult, ValidationReport
from validate import DEFAULT_STEPS
from validate.checks import checks as c
from validate.checks.checks import EXACT, Check
from validate.checks.orbit import Orbit, check_orbit
from validate.checks.units import figure_units
from validate.scene.model import compile_spec, model_spec
from validate.walk.samples import GaitSamples
from validate.walk.simulate import Simulation, Walker, WalkSettings

__all__ = ["EXACT", "Check", "Validation", "validate", "validation_report"]


@dataclass
class Validation:
    """The checks of a gait and what the recording and the video draw."""

    gait: Gait  # the gait validated (its summary in the recording)
    checks: list[Check]
    biped: Biped
    samples: GaitSamples
    simulation: Simulation  # the forward check's walk
    contact: dict  # the walk's ground reaction (``validate.walk.contact.ground_reaction``)
    orbit: Orbit | None = None  # the walk's orbit and its multipliers (``validate.checks.orbit``)

    @property
    def passed(self) -> bool:
        return all(check.passed for check in self.checks)


def validate(
    gait: Gait,
    steps: int = DEFAULT_STEPS,
    model: str | Path | mujoco.MjSpec | None = None,
    settings: WalkSettings = c.WALK,
):
    """All checks of a gait on ``model``
    (``validate.scene.model.model_spec``: by default the committed model of the gait's knee for
    Table 1, the model generated from the gait's robot otherwise), its walks under
    ``settings`` (the validation's gains by default).

    Raises BipedError if the model cannot be read or is of the other knee.
    """
    biped, samples = gait.biped, GaitSamples.from_gait(gait)
    spec = model if isinstance(model, mujoco.MjSpec) else model_spec(biped, model)
    robot_model = compile_spec(spec)
    if gait.two_phase:
        checks, sim, reaction, found = two_phase_checks(gait, spec, steps, settings)
        return Validation(gait, checks, biped, samples, sim, reaction, found)
    energy = gait.costs.energy
    results = [
        c.check_model(robot_model, biped),
        c.check_inverse_dynamics(robot_model, biped, samples),
        c.check_knee_loads(robot_model, biped, samples, gait.knee_loads),
        c.check_impact(robot_model, biped, samples, gait),
        c.check_feedforward(spec, biped, samples),
    ]
    walker = Walker(gait, spec)
    forward, sim, reaction = c.check_forward(walker, steps, energy, settings)
    results += [forward, c.check_gains(walker, steps, energy, forward, settings)]
    orbit, found = check_orbit(walker, settings)
    return Validation(gait, results + [orbit], biped, samples, sim, reaction, found)


# Why the forward check's energy ratio is not measured on a two-phase gait file written
# before its double support's work was recorded.
NO_TWO_PHASE_ENERGY = (
    "energy_ratio not measured: the file, written before its double support's work was "
    "recorded, holds its single support's only, MuJoCo's is the whole step's"
)


def two_phase_checks(
    gait: Gait, spec: mujoco.MjSpec, steps: int = DEFAULT_STEPS, settings: WalkSettings = c.WALK
):
    """The checks of a two-phase gait: the model; the inverse dynamics along both phases;
    the knee loads along its single support (the file's are the single support's); the
    landing holding both feet against MuJoCo's impact map (``check_two_phase_impact``); the
    feedforward replay of both phases with both feet's ground forces
    (``check_two_phase_feedforward``); MuJoCo's walk of both phases (``check_forward``: the
    double support with both feet on the floor, each step ending at the rear foot's
    lift-off) and the same walk at other gains (``check_gains``); the walk's orbit
    (``check_orbit``: its section in the single support, ``LANDING`` of T after the rear
    foot's lift-off, the swing foot in the air). Returns (checks, the walk, its ground
    reaction, the ``Orbit``)."""
    biped, samples = gait.biped, GaitSamples.from_gait(gait)
    robot_model = compile_spec(spec)
    knee_loads = c.check_knee_loads(robot_model, biped, samples.single_support(), gait.knee_loads)
    knee_loads.notes.append("the single support phase only (the double support's not built)")
    walker = Walker(gait, spec)
    energy = gait.double_support.energy  # the joints' work over both phases [J per step]
    energy = float("nan") if energy is None else energy
    forward, sim, reaction = c.check_forward(walker, steps, energy, settings)
    if np.isnan(energy):
        forward.notes.append(NO_TWO_PHASE_ENERGY)
    checks = [
        c.check_model(robot_model, biped),
        c.check_inverse_dynamics(robot_model, biped, samples),
        knee_loads,
        c.check_two_phase_impact(robot_model, biped, samples, gait),
        c.check_two_phase_feedforward(spec, biped, samples),
        forward,
        c.check_gains(walker, steps, energy, forward, settings),
    ]
    orbit, found = check_orbit(walker, settings)
    return checks + [orbit], sim, reaction, found


def validation_report(checks) -> ValidationReport:
    """The report of ``checks`` (``biped.records.validation_report``): each check's figures
    (NaN, a figure that could not be measured, as None: JSON has none) with their units
    (``validate.checks.units.figure_units``), verdict, notes and causes."""
    return ValidationReport(tuple(check_result(check) for check in checks))


def check_result(check: Check) -> CheckResult:
    """A check as its report holds it, its figures as JSON values."""
    figures = {name: _clean(value) for name, value in check.figures.items()}
    return CheckResult(
        check.name,
        bool(check.passed),
        figures,
        figure_units(check.name, figures),
        tuple(check.notes),
        tuple(check.causes),  # why it fails, among validate.checks.checks.CAUSES
    )


def _clean(value):
    """A figure as a JSON value: Python's numbers, None for NaN (not measured)."""
    if isinstance(value, (np.bool_, bool)):
        return bool(value)
    if isinstance(value, (np.integer, int)):
        return int(value)
    if isinstance(value, (float, np.floating)):
        return None if np.isnan(value) else float(value)
    if isinstance(value, (list, tuple)):
        return [_clean(v) for v in value]
    return value
