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
    ],
)
def test_bad_files_are_rejected(tmp_path, name, text, needle):
    """Unknown fields, bad values, bad syntax and unknown formats raise clear errors."""
    path = tmp_path / name
    path.write_text(text)
    with pytest.raises(ParameterError, match=needle.replace(".", r"\.")):
        biped.Robot.from_file(path)


def test_unknown_knee_is_rejected():
    """Only 'revolute' and 'rolling' are knee kinematics."""
    with pytest.raises(biped.BipedError, match="'hinge'.*allowed 'revolute', 'rolling'"):
        biped.Biped(biped.Robot.paper(), knee="hinge")
