"""The file of a two-phase optimum (``biped optimize --double-support``): its problem, the
solver's answer, every parameter with its unit, and the single-support optimum it started
from, for comparison.

It is not a gait file: the commands that read gaits (validate, replay, pages, sweep) read the
single-support ``Gait`` only; nothing reads this file back yet.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from biped.optimization.two_phase import (
    TwoPhaseCheck,
    TwoPhaseOptimum,
    TwoPhaseProblem,
    variable_names,
)
from biped.records.gait_file import write_json
from biped.records.provenance import provenance

FORMAT = "biped two-phase optimum"
# The unit of a variable, from its name.
_UNITS = (
    ("accel", "rad/s²"),
    ("rate_x_hip", "m/s"),
    ("rate_z_hip", "m/s"),
    ("rate", "rad/s"),
    ("bend", "rad"),
    ("trunk", "rad"),
    ("period", "s"),
    ("double_support", "s"),
    ("front_cy", "N·m"),
    ("front_f", "N"),
)


def unit_of(name: str) -> str:
    """The unit of the two-phase variable ``name``."""
    for part, unit in _UNITS:
        if part in name:
            return unit
    raise KeyError(name)


def record(problem: TwoPhaseProblem, optimum: TwoPhaseOptimum, checked: TwoPhaseCheck) -> dict:
    """The file's content: the problem, the answer, its check on the numeric model, the
    variables by name with their units."""
    single = problem.single
    names = variable_names(problem.samples, problem.landing)
    return {
        "format": FORMAT,
        "knee": single.knee,
        "speed": single.speed,
        "criterion": single.criterion,
        "share_range": list(problem.share),
        "landing": problem.landing,
        "double_support_samples": problem.samples,
        "value": checked.value,
        "solver_value": optimum.value,
        "feasible": checked.feasible,
        "share": optimum.share,
        "single_support_value": optimum.single_value,
        "status": optimum.status,
        "iterations": optimum.iterations,
        "constraint_violation": optimum.constraint_violation,
        "seconds": optimum.seconds,
        "setup_seconds": optimum.setup_seconds,
        "variables": dict(zip(names, np.asarray(optimum.variables).tolist(), strict=True)),
        "units": {
            "speed": "m/s",
            "value": "N²·m·s",
            "solver_value": "N²·m·s",
            "single_support_value": "N²·m·s",
            "share": "1",
            "seconds": "s",
            "setup_seconds": "s",
            "variables": {name: unit_of(name) for name in names},
        },
        "provenance": provenance(),
    }


def write(
    path: str | Path, problem: TwoPhaseProblem, optimum: TwoPhaseOptimum, checked: TwoPhaseCheck
) -> Path:
    """Write the file atomically; returns its path."""
    return write_json(path, record(problem, optimum, checked))
