"""The validation report, its recording and the validate command."""

import json

import numpy as np
import pytest
import rerun.chunk

from biped import Robot, gait_file
from biped_cli import main
from tests.conftest import small_optimum


@pytest.fixture(scope="module")
def gait_path(tmp_path_factory):
    """A gait file of the rolling knee at 0.3 m/s, produced by the optimiser."""
    optimum = small_optimum("rolling")
    path = tmp_path_factory.mktemp("gait") / "rolling.json"
    gait_file.write_json(path, gait_file.to_dict(optimum, Robot.paper(), seed=0))
    return path


@pytest.fixture(scope="module")
def report(gait_path, tmp_path_factory):
    """The validate command's JSON report and recording for 3 steps."""
    rrd = tmp_path_factory.mktemp("rrd") / "rolling.rrd"
    import contextlib
    import io

    out = io.StringIO()
    with contextlib.redirect_stdout(out):
        code = main(["validate", str(gait_path), "--steps", "3", "--rrd", str(rrd), "--json"])
    return code, json.loads(out.getvalue()), rrd


def test_report_has_the_documented_figures(report):
    """JSON with the inverse-dynamics errors, steps, fall and slip; exit 0 iff all pass."""
    code, content, _ = report
    assert content["inverse_dynamics"]["max_torque_error"] < 1e-6
    assert content["inverse_dynamics"]["max_wrench_error"] < 1e-6
    assert content["impact"]["max_velocity_error"] < 1e-6
    forward = content["forward"]
    for key in (
        "steps",
        "fell",
        "max_slip",
        "feedback_share",
        "energy_per_step",
        "max_knee_equality_violation",
    ):
        assert key in forward
    assert isinstance(forward["fell"], bool) and forward["steps"] >= 0
    assert code == (0 if content["passed"] else 1)
    assert content["passed"] == all(
        content[k]["passed"] for k in ("inverse_dynamics", "impact", "forward")
    )


def test_recording_holds_both_robots_and_the_series(report):
    """The .rrd reads back with both robots drawn and torques of both sources on 'time'."""
    _, content, rrd = report
    assert content["recording"] == str(rrd)
    chunks = rerun.chunk.RrdReader(rrd).stream().to_chunks()
    paths = {chunk.entity_path for chunk in chunks}
    for expected in (
        "/world/analytic/trunk",
        "/world/mujoco/trunk",
        "/world/mujoco/left_shank/geometry",
        "/world/contact/force",
        "/summary",
        "/torques/Γ1_stance_ankle/analytic",
        "/torques/Γ1_stance_ankle/mujoco",
        "/ground/Fz/analytic",
        "/zmp/mujoco",
        "/phase",
    ):
        assert expected in paths, expected
    batch = [c for c in chunks if c.entity_path == "/ground/Fz/analytic"][0].to_record_batch()
    values = np.array([v[0] for v in batch.column("Scalars:scalars").to_pylist()])
    # The analytical normal force hovers around the robot's weight.
    assert 0.8 * 686.7 < np.median(values) < 1.2 * 686.7
    assert "time" in [c for c in chunks if c.entity_path == "/world/mujoco/trunk"][0].timeline_names


def test_validate_rejects_a_corrupt_gait(tmp_path, capsys):
    """A corrupt gait file is one line on stderr and exit 2."""
    bad = tmp_path / "bad.json"
    bad.write_text("{")
    assert main(["validate", str(bad)]) == 2
    assert len(capsys.readouterr().err.strip().splitlines()) == 1


def test_validate_several_gaits(gait_path, tmp_path, capsys, monkeypatch):
    """Several gaits: one report per file, keyed by it, and a recording per gait; --rrd, which
    names one recording, is refused with several gaits."""
    import shutil

    other = tmp_path / "again.json"
    shutil.copy(gait_path, other)
    monkeypatch.chdir(tmp_path)
    assert main(["validate", str(gait_path), str(other), "--rrd", "x.rrd"]) == 2
    assert "--rrd" in capsys.readouterr().err
    # Two files of one name in folders of one name would write one recording (named from
    # the folder and the file): refused before any work.
    twin = tmp_path / "twin" / gait_path.parent.name
    twin.mkdir(parents=True)
    shutil.copy(gait_path, twin / gait_path.name)
    assert main(["validate", str(gait_path), str(twin / gait_path.name)]) == 2
    assert "would share the recording" in capsys.readouterr().err
    code = main(["validate", str(gait_path), str(other), "--steps", "1", "--json"])
    content = json.loads(capsys.readouterr().out)
    assert set(content) == {str(gait_path), str(other)}
    assert code == (0 if all(r["passed"] for r in content.values()) else 1)
    for report in content.values():
        assert (tmp_path / report["recording"]).stat().st_size > 0
