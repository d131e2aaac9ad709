"""Outputs never overwrite another run's: recordings are named from the gait file's own path,
and a recording another gait file owns is refused, by validate and by pipeline, before any
work; validation reports carry a unit for every figure."""

import json
import os
import stat
from pathlib import Path

import pytest

from biped import Robot
from biped.errors import BipedError
from biped.records import gait_file
from biped.records.gait_file import Gait
from biped_cli import main
from tests.conftest import small_optimum
from validate.outputs.outputs import belongs_to, check_owner, claim, output_name, owner

NAME = "rolling-sthenic-0.300"


def _stamp(path: Path):
    return path.read_bytes(), path.stat().st_mtime_ns


@pytest.fixture
def gaits(tmp_path, monkeypatch):
    """The same gait file name in logs/pipeline and logs/sweep, run from tmp_path."""
    monkeypatch.chdir(tmp_path)
    gait = Gait.from_optimum(small_optimum("rolling"), Robot.paper())
    paths = {}
    for folder in ("pipeline", "sweep"):
        paths[folder] = gait.write(Path("logs") / folder / f"{NAME}.json")
    return paths


def test_validating_a_sweep_gait_keeps_the_pipelines_recording(gaits, capsys):
    """The pipeline's recording of logs/pipeline/X.json survives 'biped validate
    logs/sweep/X.json', which records to logs/recordings/sweep-X.rrd; naming the pipeline's
    recording with --rrd is refused (exit 2); the report has a unit for every figure."""
    from validate.workflows import validate_and_record

    pipeline = Path("logs/recordings") / f"{NAME}.rrd"  # as biped pipeline names it
    gait = gait_file.read(gaits["pipeline"])
    validate_and_record(gait, pipeline, steps=1, source=gaits["pipeline"])
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
    from biped.model.units import missing

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
    import biped.optimization.optimize

    def no_work(*args, **kwargs):
        raise AssertionError("optimized before checking its outputs")

    monkeypatch.setattr(biped.optimization.optimize, "optimize", no_work)
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


def _refusal(capsys, code) -> str:
    """The one line on stderr of a command refused with exit 2."""
    captured = capsys.readouterr()
    lines = captured.err.strip().splitlines()
    assert code == 2 and len(lines) == 1 and "Traceback" not in captured.err, captured.err
    return lines[0]


def _tree(folder: Path) -> list[str]:
    """Every file and folder under ``folder``, hidden ones included."""
    return sorted(str(p.relative_to(folder)) for p in folder.rglob("*"))


@pytest.mark.parametrize(
    "command",
    [
        ["sweep", "--speeds", "0.3"],
        ["design-map"],
        ["figures"],
        ["pipeline"],
        ["report", "gait.json"],
        ["robustness", "gait.json"],
    ],
)
def test_an_output_folder_naming_a_file_is_refused_naming_option_and_path(
    command, tmp_path, monkeypatch, capsys
):
    """--out naming a file, for every command whose --out is a folder, is one line naming
    --out, the path and that a folder is allowed; nothing is written."""
    monkeypatch.chdir(tmp_path)
    Path("rk.json").write_text("{}")
    line = _refusal(capsys, main([*command, "--out", "rk.json"]))
    assert "--out 'rk.json'" in line and "allowed a folder" in line, line
    assert _tree(tmp_path) == ["rk.json"]


def test_a_refused_sweep_writes_nothing(tmp_path, monkeypatch, capsys):
    """A sweep refused for its folder (gait files of no sweep) or for the paper's method's
    record there (other settings) is refused before any optimization and leaves the folder
    as it was: no .independent/, no record."""
    import biped.studies.sweep
    from biped.model.criteria import Safety
    from biped.studies.paper_method import PaperMethod

    def no_work(*args, **kwargs):
        raise AssertionError("swept before its refusal")

    monkeypatch.chdir(tmp_path)
    foreign = Path("logs/pipeline")
    gait_file.write_json(foreign / f"{NAME}.json", {"not": "a sweep's"})
    before = _tree(tmp_path)
    line = _refusal(capsys, main(["sweep", "--speeds", "0.3", "--out", str(foreign)]))
    assert "no sweep.json" in line and "choose another --out folder" in line
    assert _tree(tmp_path) == before
    monkeypatch.setattr(biped.studies.sweep, "run_sweep", no_work)
    record = Path("S/paper-method/settings.json")
    record.parent.mkdir(parents=True)
    made = PaperMethod(Robot.paper(), Safety(clearance=0.0, zmp_margin=0.0), 0.3, seeds=5)
    record.write_text(json.dumps(made.to_dict()))
    before = _tree(tmp_path)
    argv = ["sweep", "--speeds", "0.3", "--paper-seeds", "1", "--out", "S"]
    line = _refusal(capsys, main(argv))
    assert str(record) in line and "seeds = 5" in line, line
    assert _tree(tmp_path) == before


def test_every_output_option_says_missing_folders_are_created():
    """The help of every option that names an output (--out, --recordings, --rrd, --video)
    says that its missing folders are created."""
    from biped_cli.main import build_parser

    outputs = ("--out", "--recordings", "--rrd", "--video")
    seen = 0
    for name, parser in build_parser().command_parsers.items():
        for action in parser._actions:
            if set(action.option_strings) & set(outputs):
                assert "created" in (action.help or ""), (name, action.option_strings)
                seen += 1
    assert seen >= 10  # optimize, sweep, figures, pipeline (2), design, design-map, ...


def test_the_printed_rerun_command_is_this_environments(tmp_path, monkeypatch):
    """'open with:' names the rerun beside this Python (a virtual environment's bin/, on the
    PATH only once activated), else the one on the PATH, else this Python's -m rerun; the
    recording's path is quoted for the shell."""
    import shlex
    import shutil
    import sys

    from validate.outputs.outputs import open_command, recording_lines, rerun_command

    command = shlex.split(rerun_command())
    assert os.access(command[0], os.X_OK), command
    bin_ = tmp_path / "env dir" / "bin"
    bin_.mkdir(parents=True)
    monkeypatch.setattr(sys, "executable", str(bin_ / "python"))
    monkeypatch.setattr(shutil, "which", lambda name: None)
    assert shlex.split(rerun_command()) == [str(bin_ / "python"), "-m", "rerun"]
    (bin_ / "rerun").write_text("#!/bin/sh\n")
    assert shlex.split(open_command("logs/a b.rrd")) == [str(bin_ / "rerun"), "logs/a b.rrd"]
    lines = recording_lines("r.rrd")
    assert lines[0].startswith("recording r.rrd") and "r.rrd.source.json" in lines[1]


def test_a_model_of_something_else_is_named(tmp_path, capsys):
    """--model naming a valid MJCF of another mechanism (a pendulum) is one line naming the
    file and what is allowed."""
    gait = Gait.from_optimum(small_optimum("revolute"), Robot.paper()).write(tmp_path / "g.json")
    pendulum = tmp_path / "pendulum.xml"
    pendulum.write_text(
        '<mujoco model="pendulum"><worldbody><body name="pole" pos="0 0 1">'
        '<joint name="hinge" axis="0 1 0"/><geom type="capsule" fromto="0 0 0 0 0 -0.5" '
        'size="0.02"/></body></worldbody></mujoco>'
    )
    line = _refusal(capsys, main(["validate", str(gait), "--model", str(pendulum)]))
    assert f"model {str(pendulum)!r} has neither" in line and "allowed an MJCF" in line, line


def test_pipeline_with_design_prints_every_file_it_writes_once(tmp_path, capsys, monkeypatch):
    """Every file 'biped pipeline --design' writes in --out and --recordings (gait files,
    reports, recordings, their owner records, the videos) is named on exactly one printed
    line, and every printed path is a file it wrote (the videos stubbed: nothing renders)."""
    import validate.outputs.video
    from biped.runtime.files import atomic_write_bytes

    def video(path, *args, gif=None, **kwargs):
        path = Path(path)
        path.parent.mkdir(parents=True, exist_ok=True)
        return [atomic_write_bytes(path, b"an mp4")]

    monkeypatch.setattr(validate.outputs.video, "write_video", video)
    out, rrd = tmp_path / "pipeline", tmp_path / "recordings"
    argv = ["pipeline", "--knees", "revolute", "--steps", "1", "--starts", "1", "--design"]
    assert main([*argv, "--out", str(out), "--recordings", str(rrd)]) in (0, 1)
    lines = capsys.readouterr().out.splitlines()
    tokens = [{t.strip(",;()") for t in line.split()} for line in lines]
    written = {str(p) for p in [*out.rglob("*"), *rrd.rglob("*")] if p.is_file()}
    assert str(rrd / "design-sthenic-0.300.mp4") in written
    for path in written:
        assert sum(path in line for line in tokens) == 1, path
    printed = {t for line in tokens for t in line if t.startswith(str(tmp_path))}
    assert printed == written


@pytest.mark.parametrize("name", ["walk.avi", "walk.gif", "walk"])
def test_a_video_path_of_another_container_is_refused_before_any_work(
    name, tmp_path, capsys, monkeypatch
):
    """--video takes a path ending in .mp4, the container written: walk.avi, walk.gif or no
    suffix is one line naming --video, the path and .mp4, before the gait is read; nothing
    is written."""
    import biped_cli.commands
    from biped_cli import main

    monkeypatch.setattr(
        biped_cli.commands, "read_gaits", lambda *a, **k: pytest.fail("read before refusing")
    )
    monkeypatch.chdir(tmp_path)
    assert main(["validate", "gait.json", "--video", name]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and f"--video {name!r}" in err[0] and "ending in .mp4" in err[0], err
    assert list(tmp_path.iterdir()) == []


def test_the_video_module_refuses_suffixes_it_does_not_write(tmp_path, capsys):
    """python -m validate.outputs.video refuses --out, --gif, --frame whose suffix is not .mp4, .gif,
    .png (exit 2, one line naming the option), before reading the gait file."""
    from validate.outputs.video import main

    for option, path, allowed in (
        ("--out", "walk.avi", ".mp4"),
        ("--gif", "walk.mp4", ".gif"),
        ("--frame", "walk.jpg", ".png"),
    ):
        assert main(["missing.json", option, str(tmp_path / path)]) == 2
        err = capsys.readouterr().err.strip().splitlines()
        assert len(err) == 1 and option in err[0] and f"ending in {allowed}" in err[0], err
    assert list(tmp_path.iterdir()) == []


def test_video_writers_create_missing_folders(tmp_path):
    """The MP4 and GIF writers create the missing folders of their path, as the command's
    --help says (three small frames: nothing is rendered)."""
    import numpy

    from validate.outputs.video import write_gif, write_mp4

    frames = [numpy.full((32, 32, 3), 40 * k, dtype=numpy.uint8) for k in range(3)]
    mp4 = write_mp4(tmp_path / "new" / "dir" / "walk.mp4", frames)
    gif = write_gif(tmp_path / "other" / "walk.gif", frames)
    assert mp4.stat().st_size > 0 and gif.stat().st_size > 0


def test_report_prints_every_file_it_writes_once(gaits, capsys):
    """'biped report' names each page and each of its figures on one 'wrote' line, and
    nothing else under --out."""
    assert main(["report", str(gaits["pipeline"]), "--out", "pages"]) == 0
    printed = [line.removeprefix("wrote ") for line in capsys.readouterr().out.splitlines()]
    written = sorted(str(p) for p in Path("pages").rglob("*") if p.is_file())
    assert sorted(printed) == written and len(written) > 1


def test_sweep_names_the_files_of_its_folder(tmp_path, capsys):
    """A sweep's last line names its record, its gait files and intermediate folder and the
    paper's method's, with counts that are those of the files written."""
    out = tmp_path / "S"
    argv = ["sweep", "--speeds", "0.3", "--knees", "revolute", "--criteria", "sthenic"]
    assert (
        main([*argv, "--starts", "1", "--paper-seeds", "1", "--jobs", "1", "--out", str(out)]) == 0
    )
    line = capsys.readouterr().out.strip().splitlines()[-1]
    gaits = list(out.glob("*-*.json"))
    runs = list((out / "paper-method").glob("*-*.json"))
    assert len(gaits) == len(runs) == 1 and (out / "sweep.json").is_file()
    assert line == (
        f"sweep results in {out}: sweep.json, 1 gait file <knee>-<criterion>-<speed>.json, "
        ".independent/ (each point's first solve), paper-method/ (settings.json and 1 gait file)"
    )


def test_a_gif_or_link_output_is_refused_before_any_work(tmp_path, monkeypatch, capsys):
    """The GIF beside --video, a FIFO there, and an --out that is a symbolic link (to a file
    or a device, as /dev/stdout) are refused before any work, naming the option."""
    monkeypatch.chdir(tmp_path)
    os.mkfifo("walk.gif")
    argv = ["validate", "missing.json", "--video", "walk.mp4", "--gif"]
    line = _refusal(capsys, main(argv))
    assert "--gif 'walk.gif'" in line and "a device, a FIFO or a socket" in line, line
    Path("file.json").write_text("{}")
    os.symlink("file.json", "link.json")
    argv = ["optimize", "--knee", "rolling", "--speed", "0.3", "--out", "link.json"]
    line = _refusal(capsys, main(argv))
    assert "--out 'link.json' is a symbolic link" in line, line
    assert Path("link.json").is_symlink() and Path("file.json").read_text() == "{}"


def test_the_pipeline_s_design_takes_starts_with_the_paper_s_method():
    """--method nelder-mead with --starts is refused, but not in a pipeline with --design,
    whose design stage runs IPOPT from --starts."""
    import argparse

    from biped_cli.args import _Default, budget

    def args(**given):
        defaults = dict(starts=_Default(3), nelder_mead_starts=_Default(0))
        defaults |= dict(restarts=_Default(1), evaluations=_Default(4000), seed=0)
        return argparse.Namespace(**{**defaults, "method": "nelder-mead", **given})

    with pytest.raises(BipedError, match="--starts 5"):
        budget(args(starts=5))
    assert budget(args(starts=5, design=True))["starts"] == 5
    with pytest.raises(BipedError, match="--nelder-mead-starts 2"):
        budget(args(nelder_mead_starts=2, design=True))


def test_a_sweep_with_a_point_not_certified_exits_1(tmp_path, capsys):
    """A stance knee bent 1 rad, a 20 cm clearance, a hip never slower than the walking speed
    (so at it throughout) and a stance foot held to a friction of 0.05: IPOPT finds no
    feasible gait at 0.2 m/s, the summary names the point and the sweep exits 1 (``biped
    sweep && biped figures`` stops there); the same sweep without them is certified, exit 0."""
    argv = ["sweep", "--speeds", "0.2", "--knees", "revolute", "--criteria", "sthenic"]
    argv += ["--starts", "1", "--paper-seeds", "0", "--jobs", "1"]
    asked = ["--clearance", "0.2", "--knee-bend", "1", "--hip-progress", "1", "--friction", "0.05"]
    assert main([*argv, *asked, "--out", str(tmp_path / "bent")]) == 1
    assert "NOT: revolute-sthenic-0.200.json NOT CONVERGED" in capsys.readouterr().err
    assert main([*argv, "--out", str(tmp_path / "straight")]) == 0


def test_a_frame_outside_the_walk_is_refused_naming_its_span():
    """--at beyond the walk's span, or before its start, is refused naming the value and the
    span; a time inside it picks the recorded state at that time."""
    from types import SimpleNamespace

    import numpy

    from biped.errors import BipedError
    from validate.outputs.video import frame_index

    walk = SimpleNamespace(simulation=SimpleNamespace(time=numpy.linspace(0.0, 12.1, 606)))
    assert frame_index(walk, 3.1) == int(numpy.searchsorted(walk.simulation.time, 3.1))
    assert frame_index(walk, 12.1) == 605
    for at in (99.0, -1.0, 12.2):
        with pytest.raises(BipedError, match=rf"--at {at!r} s: allowed 0 to 12.10 s"):
            frame_index(walk, at)


@pytest.mark.parametrize(
    "command",
    [["optimize", "--knee", "rolling", "--speed", "0.3"], ["design", "--speed", "0.3"], ["table"]],
)
def test_a_file_output_that_is_a_fifo_is_refused_before_any_work(
    command, tmp_path, monkeypatch, capsys
):
    """--out naming a FIFO (as /dev/null is a device) is one line naming --out and the path;
    the FIFO stays one (an atomic rename would have replaced it by a regular file)."""
    monkeypatch.chdir(tmp_path)
    os.mkfifo("pipe")
    line = _refusal(capsys, main([*command, "--out", "pipe"]))
    assert "--out 'pipe'" in line and "a device, a FIFO or a socket" in line, line
    assert stat.S_ISFIFO(Path("pipe").stat().st_mode)


def test_a_pipeline_without_video_removes_the_earlier_runs_video(tmp_path, monkeypatch):
    """--no-video leaves no earlier run's video beside the new recording of the same gait."""
    from types import SimpleNamespace

    from biped.model.criteria import PAPER_SAFETY
    from biped.records.validation_report import ValidationReport
    from validate import workflows

    def validated(gait, rrd, *, steps, video, source):
        assert video is None
        Path(rrd).write_bytes(b"a recording")
        result = SimpleNamespace(checks=[], passed=True)
        return result, ValidationReport(checks=(), recording=str(rrd))

    monkeypatch.setattr(workflows, "validate_and_record", validated)
    recordings = tmp_path / "recordings"
    recordings.mkdir()
    earlier = recordings / f"{NAME}.mp4"
    earlier.write_bytes(b"an earlier run's video")
    pipeline = workflows.Pipeline(
        Robot.paper(), 0.3, ("rolling",), "sthenic", PAPER_SAFETY, 1, tmp_path, recordings,
        {}, video=False,
    )  # fmt: skip
    said = []
    gait = Gait.from_optimum(small_optimum("rolling"), Robot.paper())
    pipeline.validated("rolling", gait.write(tmp_path / f"{NAME}.json"), gait, said.append)
    assert not earlier.exists() and (recordings / f"{NAME}.rrd").exists()
    assert any(str(earlier) in line and "removed" in line for line in said)


def test_report_reads_the_validation_biped_validate_wrote(gaits, capsys):
    """After 'biped validate X.json', 'biped report X.json' shows that validation (the
    report validate writes beside its recording), and no longer once X.json changes."""
    gait = gaits["sweep"]
    assert main(["validate", str(gait), "--steps", "1"]) in (0, 1)
    written = Path("logs/recordings") / f"sweep-{NAME}.report.json"
    assert f"report {written}" in capsys.readouterr().out
    assert json.loads(written.read_text())["gait"] == str(gait)
    assert main(["report", str(gait), "--out", "pages"]) == 0
    page = (Path("pages") / f"sweep-{NAME}.md").read_text()
    assert "Validation in MuJoCo: **" in page and "Not validated" not in page
    assert f"Report [`{written}`]" in page
    content = json.loads(gait.read_text())
    content["provenance"]["command"] = "edited"  # another file: the validation is not its
    gait.write_text(json.dumps(content))
    assert main(["report", str(gait), "--out", "pages"]) == 0
    assert "Not validated in MuJoCo" in (Path("pages") / f"sweep-{NAME}.md").read_text()
