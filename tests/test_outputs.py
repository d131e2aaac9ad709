"""Outputs never overwrite another run's: recordings are named from the gait file's own path,
and a recording another gait file owns is refused, by validate and by pipeline, before any
work; validation reports carry a unit for every figure."""

import json
import os
from pathlib import Path

import pytest

from biped import Robot, gait_file
from biped_cli import main
from biped_cli.outputs import belongs_to, check_owner, claim, output_name, owner
from tests.conftest import small_optimum

NAME = "rolling-sthenic-0.300"


def _stamp(path: Path):
    return path.read_bytes(), path.stat().st_mtime_ns


@pytest.fixture
def gaits(tmp_path, monkeypatch):
    """The same gait file name in logs/pipeline and logs/sweep, run from tmp_path."""
    monkeypatch.chdir(tmp_path)
    content = gait_file.to_dict(small_optimum("rolling"), Robot.paper(), seed=0)
    paths = {}
    for folder in ("pipeline", "sweep"):
        paths[folder] = gait_file.write_json(Path("logs") / folder / f"{NAME}.json", content)
    return paths


def test_validating_a_sweep_gait_keeps_the_pipelines_recording(gaits, capsys):
    """The pipeline's recording of logs/pipeline/X.json survives 'biped validate
    logs/sweep/X.json', which records to logs/recordings/sweep-X.rrd; naming the pipeline's
    recording with --rrd is refused (exit 2); the report has a unit for every figure."""
    from biped_cli.commands import _validate_and_record

    pipeline = Path("logs/recordings") / f"{NAME}.rrd"  # as biped pipeline names it
    gait = gait_file.read(gaits["pipeline"])
    _validate_and_record(gait, 1, pipeline, source=gaits["pipeline"])
    before = _stamp(pipeline)
    assert main(["validate", str(gaits["sweep"]), "--steps", "1", "--json"]) in (0, 1)
    report = json.loads(capsys.readouterr().out)
    ours = Path("logs/recordings") / f"sweep-{NAME}.rrd"
    assert report["recording"] == str(ours) and ours.stat().st_size > 1000
    assert _stamp(pipeline) == before
    assert belongs_to(ours, gaits["sweep"]) and belongs_to(pipeline, gaits["pipeline"])
    assert belongs_to(pipeline, gaits["sweep"]) is False
    args = ["validate", str(gaits["sweep"]), "--steps", "1", "--rrd", str(pipeline)]
    assert main(args) == 2
    err = capsys.readouterr().err
    assert "another gait file" in err and str(gaits["pipeline"].resolve()) in err
    assert len(err.strip().splitlines()) == 1
    assert _stamp(pipeline) == before
    # Every figure of the report has its unit; the figures keep their names.
    from biped.units import missing

    assert missing(report, report["units"]) == []
    assert report["units"]["forward.max_slip"] == "m"
    assert isinstance(report["forward"]["max_slip"], float)


def test_a_recording_of_another_folder_of_the_same_name_is_refused(gaits, capsys):
    """other/sweep/X.json would record to sweep-X.rrd, which logs/sweep/X.json owns: refused
    before any work, the recording untouched."""
    recording = Path("logs/recordings") / f"sweep-{NAME}.rrd"
    recording.parent.mkdir(parents=True)
    recording.write_bytes(b"a recording")
    claim(recording, gaits["sweep"])
    other = Path("other/sweep") / f"{NAME}.json"
    other.parent.mkdir(parents=True)
    other.write_bytes(gaits["sweep"].read_bytes())
    assert output_name(other) == output_name(gaits["sweep"]) == f"sweep-{NAME}"
    assert main(["validate", str(other), "--steps", "1"]) == 2
    assert "another gait file" in capsys.readouterr().err
    assert recording.read_bytes() == b"a recording"
    check_owner(recording, gaits["sweep"])  # its own gait may replace it
    check_owner(Path("logs/recordings/free.rrd"), other)  # a free name too


def test_pipeline_refuses_recordings_of_another_output_folder(gaits, capsys, monkeypatch):
    """A pipeline whose --recordings hold the recordings of another --out's gaits stops
    before optimizing, naming the recording's gait."""
    import biped.optimize

    def no_work(*args, **kwargs):
        raise AssertionError("optimized before checking its outputs")

    monkeypatch.setattr(biped.optimize, "optimize", no_work)
    recording = Path("logs/recordings") / f"{NAME}.rrd"
    recording.parent.mkdir(parents=True)
    recording.write_bytes(b"the pipeline's")
    claim(recording, gaits["pipeline"])
    args = ["pipeline", "--knees", "rolling", "--out", "elsewhere", "--no-video"]
    assert main(args) == 2
    err = capsys.readouterr().err
    assert "--recordings" in err and "another gait file" in err
    assert recording.read_bytes() == b"the pipeline's"


def test_owner_records_name_the_gait_and_its_content(tmp_path):
    """The owner record holds the gait file's absolute path and content hash: an edited gait
    file no longer owns the recording's content; a recording without a record is free."""
    gait = tmp_path / "g.json"
    gait.write_text("{}")
    recording = tmp_path / "g.rrd"
    recording.write_bytes(b"x")
    assert owner(recording) is None and belongs_to(recording, gait) is None
    check_owner(recording, tmp_path / "other.json")  # no record: may be replaced
    claim(recording, gait)
    assert owner(recording)["gait"] == str(gait.resolve())
    assert belongs_to(recording, gait) is True
    gait.write_text('{"edited": true}')
    assert belongs_to(recording, gait) is False
    with pytest.raises(Exception, match="another gait file"):
        check_owner(recording, tmp_path / "other.json")
    assert not [p for p in os.listdir(tmp_path) if p.endswith(".tmp")]
