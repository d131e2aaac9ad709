"""Robot parameters: Table 1, validation and loading from files."""

import dataclasses
import json

import pytest

import biped
from biped.errors import ParameterError


def test_paper_robot_is_table_1():
    """Table 1 gives a 70 kg, 1.70 m robot with 5 cm knee radii."""
    robot = biped.Robot.paper()
    assert robot.total_mass == pytest.approx(70.0, abs=1e-9)
    assert robot.height == pytest.approx(1.70, abs=1e-9)
    assert (robot.r1, robot.r2) == (0.05, 0.05)


@pytest.mark.parametrize(
    "field, value",
    [
        ("trunk_mass", 0.0),
        ("shank_mass", -1.0),
        ("thigh_length", -0.4),
        ("foot_inertia", 0.0),
        ("thigh_com", 0.5),  # beyond the thigh
        ("shank_com", 0.0),
        ("r1", -0.01),
        ("r1", 0.4182),  # r1 >= shank length
        ("r2", 0.5),  # r2 >= thigh length
        ("foot_heel", 0.3),  # heel beyond the sole
        ("foot_com", 0.1),  # below the sole
        ("gravity", float("nan")),
        ("trunk_mass", "heavy"),
    ],
)
def test_invalid_parameter_names_field_and_value(field, value):
    """An invalid parameter raises an error naming the field, the value and the range."""
    with pytest.raises(ParameterError) as error:
        dataclasses.replace(biped.Robot.paper(), **{field: value})
    message = str(error.value)
    assert field in message and repr(value) in message and "allowed" in message


def test_load_toml_and_json(tmp_path):
    """A file overrides Table 1 field by field, in TOML or JSON."""
    toml = tmp_path / "robot.toml"
    toml.write_text("r1 = 0.08\nr2 = 0.02\ntrunk_mass = 40.0\n")
    robot = biped.Robot.from_file(toml)
    assert (robot.r1, robot.r2, robot.trunk_mass) == (0.08, 0.02, 40.0)
    assert robot.thigh_mass == biped.Robot.paper().thigh_mass
    path = tmp_path / "robot.json"
    path.write_text(json.dumps(robot.to_dict()))
    assert biped.Robot.from_file(path) == robot


@pytest.mark.parametrize(
    "name, text, needle",
    [
        ("robot.toml", "knee_radius = 0.1\n", "knee_radius"),
        ("robot.toml", "r1 = 0.5\n", "r1"),
        ("robot.toml", "r1 = \n", "valid TOML"),
        ("robot.json", "[1, 2]", "table"),
        ("robot.yaml", "r1: 0.1", ".json or .toml"),
        ("robot.toml", b"r1 = 0.1\n\xff\xfe\x00", "UTF-8"),
        ("robot.json", '{"trunk_mass": 1e999}', "finite"),
        ("robot.json", '{"trunk_mass": 1' + "0" * 400 + "}", "finite"),
    ],
)
def test_bad_files_are_rejected(tmp_path, name, text, needle):
    """Unknown fields, bad values, bad syntax, binary content and unknown formats raise clear errors."""
    path = tmp_path / name
    path.write_bytes(text if isinstance(text, bytes) else text.encode())
    with pytest.raises(ParameterError, match=needle.replace(".", r"\.")):
        biped.Robot.from_file(path)


def test_unknown_knee_is_rejected():
    """Only 'revolute' and 'rolling' are knee kinematics."""
    with pytest.raises(biped.BipedError, match="'hinge'.*allowed 'revolute', 'rolling'"):
        biped.Biped(biped.Robot.paper(), knee="hinge")


@pytest.mark.parametrize(
    "field, value, allowed",
    [
        ("trunk_mass", 1e308, "0.001 to 1000 kg"),
        ("foot_mass", 1e-9, "0.001 to 1000 kg"),
        ("trunk_inertia", 1e9, "1e-08 to 10000 kg·m²"),
        ("foot_inertia", 1e-12, "1e-08 to 10000 kg·m²"),
        ("thigh_length", 1e6, "0.001 to 10 m"),
        ("ankle_height", 1e-6, "0.001 to 10 m"),
        ("gravity", 1e5, "0.1 to 100 m/s²"),
    ],
)
def test_absurd_parameters_are_refused_with_the_plausible_range(field, value, allowed):
    """Masses, inertias, lengths and gravity beyond their plausible range are refused, naming it."""
    with pytest.raises(ParameterError) as error:
        dataclasses.replace(biped.Robot.paper(), **{field: value})
    message = str(error.value)
    assert field in message and repr(value) in message and allowed in message


@pytest.mark.parametrize(
    "changes",
    [
        {"trunk_mass": 1000.0, "trunk_inertia": 1e4, "gravity": 0.1},
        {"foot_mass": 0.001, "foot_inertia": 1e-8, "shank_length": 10.0, "thigh_length": 10.0},
    ],
)
def test_plausible_range_is_inclusive(changes):
    """The ends of the plausible ranges are accepted."""
    robot = dataclasses.replace(biped.Robot.paper(), **changes)
    assert all(getattr(robot, k) == v for k, v in changes.items())
