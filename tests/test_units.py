"""The units map of gait files: a unit for every number, every column of a mixed array, and
the robot's fields in the units its own documentation states."""

import dataclasses
import inspect
import json
import re

import numpy as np
import pytest

from biped import Robot
from biped.model.units import PURE, missing, numeric_paths
from biped.records.gait_file import Gait
from tests.conftest import small_optimum


@pytest.fixture(scope="module")
def gait(tmp_path_factory):
    """A gait file's JSON content, as written."""
    path = tmp_path_factory.mktemp("units") / "rolling.json"
    Gait.from_optimum(small_optimum("rolling"), Robot.paper()).write(path)
    return json.loads(path.read_text())


def _value(content, path):
    """The values at a path ('optimizer.history[].value': one per list element)."""
    values = [content]
    for key in path.split("."):
        many = key.endswith("[]")
        values = [v[key.removesuffix("[]")] for v in values]
        if many:
            values = [item for v in values for item in v]
    return values


def test_every_number_of_a_gait_file_has_a_unit(gait):
    """The units map names every numeric field (and no field the file lacks); a list of
    units has one per column of its array; the keys of the figures are unchanged."""
    units = gait["units"]
    assert units == Gait.units(gait["criterion"])
    assert missing(gait, units) == []
    assert set(units) == set(numeric_paths(gait))
    for path, unit in units.items():
        if isinstance(unit, list):
            for value in _value(gait, path):
                assert np.shape(value)[-1] == len(unit), path
    assert units["costs.sthenic"] == "N²·m·s" and units["costs.energy"] == "J"
    assert units["samples.q"] == ["rad"] * 7 + ["m", "m"]
    assert units["samples.wrench"] == ["N", "N", "N·m"]
    assert units["optimizer.history[].value"] == units["optimizer.value"] == "N²·m·s"
    assert units["optimizer.iterations"] == PURE
    assert {"speed", "period", "step_length", "costs", "samples"} <= set(gait)


def test_a_number_without_a_unit_is_found(gait):
    """A field added without its unit, or a unit map missing one, is reported."""
    changed = {**gait, "costs": {**gait["costs"], "peak_power": 12.0}}
    assert missing(changed, gait["units"]) == ["costs.peak_power"]
    units = dict(gait["units"])
    del units["impact.impulse"]
    assert missing(gait, units) == ["impact.impulse"]
    assert "provenance.version" not in numeric_paths(gait) and "feasible" not in numeric_paths(gait)


def test_robot_units_are_those_its_fields_document():
    """Each Robot field's unit in the map is the one in brackets in its docstring."""
    source = inspect.getsource(Robot)
    stated = dict(re.findall(r"\n    (\w+): float(?: = [^\n]+)?\n    \"\"\"\[([^\]]+)\]", source))
    fields = [f.name for f in Robot.body_fields()]
    assert sorted(stated) == sorted(fields)
    units = Gait.units("energy", profile=True)  # a profiled knee writes k1, k2 too
    for name in fields:
        assert units[f"robot.{name}"] == stated[name], name
    assert units["optimizer.value"] == "J"


def test_actuator_units_are_those_its_fields_document():
    """Each Actuator field's unit in the map is the one in brackets in its docstring."""
    from biped.model.actuators import UNITS, Actuator

    source = inspect.getsource(Actuator)
    stated = dict(re.findall(r"\n    (\w+): float(?: = [^\n]+)?\n    \"\"\"\[([^\]]+)\]", source))
    assert stated == UNITS
    units = Gait.units("electrical", actuators=True)
    assert units["robot.actuators.knee.resistance"] == "Ω"
    assert units["costs.electrical"] == units["electrical.energy_per_metre"] == "J/m"


def test_printed_check_lines_carry_the_units_of_their_figures():
    from validate.checks.checks import Check

    line = Check(
        "forward", True, {"steps": 20, "max_slip": 2.5e-4, "step_advance_range": [1.0, 1.01]}
    ).line()
    assert "steps 20," in line  # a count has no unit
    assert "max_slip 0.00025 m," in line
    assert line.endswith("step_advance_range 1-1.01 S")
    # a figure of a check with no known unit prints bare, never with a guessed one
    assert Check("other", False, {"max_slip": 1.0}).line().endswith("max_slip 1")


def _all_units() -> dict:
    """Every unit the project's files declare, by where (a per-column list: each column)."""
    from biped.model.criteria import ALL_CRITERIA, WALKABLE
    from validate.checks.units import FIGURE_UNITS
    from validate.studies import robustness

    declared = {}
    for criterion in ALL_CRITERIA:
        for knots in (1, 3):
            every = dataclasses.replace(WALKABLE, knee_bend=0.1, actuator_limits=True)
            units = Gait.units(criterion, knots, every, actuators=True, design=True)
            declared.update({f"gait {criterion} {knots}: {k}": v for k, v in units.items()})
    for check, figures in FIGURE_UNITS.items():
        declared.update({f"report: {check}.{k}": v for k, v in figures.items()})
    content = {"limits": dict.fromkeys(robustness.LIMITS), "ranges": dict.fromkeys(["push"])}
    declared.update({f"robustness: {k}": v for k, v in robustness.units(content).items()})
    flat = {}
    for where, unit in declared.items():
        for i, each in enumerate(unit if isinstance(unit, list) else [unit]):
            flat[f"{where}[{i}]" if isinstance(unit, list) else where] = each
    return flat


def test_every_unit_is_one_unit_never_prose():
    """Every unit of a gait file, a validation report and a robustness map is one unit
    (SI symbols, "1", a fraction): no words in parentheses, no two units for one number."""
    from biped.model.units import is_unit

    bad = {where: unit for where, unit in _all_units().items() if not is_unit(unit)}
    assert bad == {}
    for prose in ("1 (IPOPT's measure)", "N, N·m", "J (the criterion on the solver's samples)"):
        assert not is_unit(prose)
    for unit in ("N²·m·s", "rad/s²", "N·m·s/rad", "kg·m²", "Ω", "1", "T", "weight"):
        assert is_unit(unit)


def test_a_failed_range_prints_unknown_never_nan():
    """A range that could not be measured (kp × 1 does not walk) prints n/a, never nan-nan."""
    from validate.checks.checks import Check

    line = Check("gains", False, {"kp_scale_range": [float("nan"), float("nan")]}).line()
    assert "kp_scale_range n/a" in line and "nan" not in line
    assert Check("gains", True, {"kp_scale_range": [0.5, 2.0]}).line().endswith("0.5-2")


def test_a_page_prints_units_per_column_as_units_never_a_list():
    """A figure with a unit per column (the orbit's fixed point: six angles, six rates) is
    printed on a page as runs of columns, never as a Python list."""
    from pathlib import Path

    from biped.model.units import unit_text
    from biped.pages.page import Page, _validation_lines
    from validate.checks.units import SECTION_UNITS
    from validate.checks.validation import Check, validation_report

    assert unit_text(SECTION_UNITS) == "rad (1-6), rad/s (7-12)"
    assert unit_text(["N", "N", "N·m"]) == "N (1-2), N·m (3)" and unit_text(["m"] * 3) == "m"
    report = validation_report([Check("orbit", True, {"fixed_point": [0.0] * 12})])
    gait = Gait.from_optimum(small_optimum("rolling"), Robot.paper())
    lines = _validation_lines(Page("p", Path("g.json"), gait, report), Path("."))
    row = next(line for line in lines if line.startswith("| fixed_point |"))
    assert row.endswith("| rad (1-6), rad/s (7-12) |") and "[" not in row


def test_every_number_of_a_designed_gait_file_has_a_unit(tmp_path):
    """A designed knee's gait file (biped design) gives a unit to every number of its
    ``design`` block too: the radii and their bounds [m], the knees compared, the changes."""
    from biped.model.units import is_unit
    from tests.conftest import designed_gait

    path = designed_gait().write(tmp_path / "design.json")
    content = json.loads(path.read_text())
    units = content["units"]
    assert missing(content, units) == [] and set(units) == set(numeric_paths(content))
    assert units["design.radii.r1"] == units["design.upper.r2"] == "m"
    assert units["design.compared[].energy"] == "J"
    assert units["design.gains_percent.design_vs_revolute"] == "%"
    assert all(is_unit(unit) for unit in units.values() if isinstance(unit, str))
    assert Gait.read(path, consistent=True).design == content["design"]
