"""Gait files: written with their provenance, read back with errors that name the bad field."""

import json

import pytest

from biped import Robot, gait_file
from biped.errors import BipedError
from biped.provenance import PACKAGE
from tests.conftest import small_optimum


@pytest.fixture(scope="module")
def content():
    """The JSON content of a rolling-knee gait file at 0.3 m/s."""
    optimum = small_optimum("rolling")
    return json.loads(json.dumps(gait_file.to_dict(optimum, Robot.paper(), seed=0)))


def test_gait_file_round_trip_with_provenance(content, tmp_path):
    """A written gait file reads back; it records the versions that produced it."""
    path = gait_file.write_json(tmp_path / "g.json", content)
    gait = gait_file.read(path)
    assert gait["knee"] == "rolling" and gait["samples"]["q"].shape[1] == 9
    record = gait["provenance"]
    assert record["package"] == PACKAGE and record["version"]
    assert record["numpy"] and record["scipy"] and record["python"] and record["command"]
    assert {"casadi", "mujoco", "platform"} <= set(record)


def _corrupt(content, tmp_path, change):
    edited = json.loads(json.dumps(content))
    change(edited)
    path = tmp_path / "edited.json"
    path.write_text(json.dumps(edited))
    with pytest.raises(BipedError) as error:
        gait_file.read(path)
    message = str(error.value)
    assert str(path) in message and "\n" not in message
    return message


def test_nan_in_samples_is_named_not_finite(content, tmp_path):
    """A NaN in samples.q names samples.q, where, and says it is not finite."""
    edited = json.loads(json.dumps(content))
    edited["samples"]["q"][5][2] = float("nan")
    path = tmp_path / "nan.json"
    path.write_text(json.dumps(edited))  # NaN, as Python's json writes it
    with pytest.raises(BipedError, match=r"samples\.q\[5, 2\] = nan is not finite"):
        gait_file.read(path)


def test_short_samples_t_blames_samples_t(content, tmp_path):
    """A samples.t shorter than the other samples is the one named."""
    message = _corrupt(content, tmp_path, lambda g: g["samples"]["t"].pop())
    assert "samples.t has" in message and "the other samples" in message


def test_short_samples_q_blames_samples_q(content, tmp_path):
    """The field that differs from the others is named, whichever it is."""
    message = _corrupt(content, tmp_path, lambda g: g["samples"]["q"].pop())
    assert "samples.q has" in message


def test_unwalkable_speed_names_the_field(content, tmp_path):
    """A speed of 50 m/s names the field speed and what is allowed."""

    def change(gait):
        gait["speed"] = 50
        gait["step_length"] = 50 * gait["period"]

    message = _corrupt(content, tmp_path, change)
    assert "speed = 50" in message and "allowed" in message


@pytest.mark.parametrize(
    "change, needle",
    [
        (lambda g: g.update(step_length=g["step_length"] * 2), "step_length"),
        (lambda g: g.update(speed=1e-9, step_length=1e-9 * g["period"]), "speed = 1e-09"),
        (lambda g: g["costs"].update(sthenic=10**400), "costs"),
        (lambda g: g["robot"].update(trunk_mass=1e308), "trunk_mass"),
        (lambda g: g["samples"].update(zmp=[[0.0]] * len(g["samples"]["t"])), "samples.zmp"),
        (lambda g: g["samples"].pop("wrench"), "samples.wrench missing"),
        (lambda g: g["samples"].update(t=[-x for x in g["samples"]["t"]]), "samples.t"),
        (lambda g: g.update(period=g["period"] * 2, step_length=g["step_length"] * 2), "period"),
    ],
)
def test_bad_fields_are_named(content, tmp_path, change, needle):
    """Inconsistent or absurd fields are refused naming the field and the file."""
    assert needle in _corrupt(content, tmp_path, change)


def test_deeply_nested_json_is_one_error(tmp_path):
    """JSON nested beyond Python's recursion limit is refused as invalid JSON."""
    path = tmp_path / "deep.json"
    path.write_text("[" * 100_000 + "]" * 100_000)
    with pytest.raises(BipedError, match="not valid JSON"):
        gait_file.read(path)
