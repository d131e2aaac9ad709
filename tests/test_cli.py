"""The ``biped`` command: output of the demo, one-line errors (exit 2), interrupts (130, 143)."""

import os
import signal
import subprocess
import sys
import time

import numpy as np
import pytest

from biped_cli import main
from biped_cli.progress import Progress


def test_demo_prints_both_knees(capsys):
    """The demo holds a posture: Fz is the robot's weight for both knees."""
    assert main(["demo"]) == 0
    out = capsys.readouterr().out
    assert "revolute" in out and "rolling" in out
    fz = [line for line in out.splitlines() if line.startswith("Fz [N]")][0].split()[2:]
    assert [float(v) for v in fz] == pytest.approx([70.0 * 9.81] * 2)


# optimize with the options a double support's bad input is given beside.
_TWO_PHASE = ["optimize", "--knee", "rolling", "--speed", "0.3", "--out", "logs/never.json"]


@pytest.mark.parametrize(
    "argv, needle",
    [
        (["demo", "--hip-height", "2.0"], "out of reach"),
        (["demo", "--robot", "missing.toml"], "missing.toml"),
        (_TWO_PHASE + ["--double-support", "0.7"], "'0.7'"),
        (_TWO_PHASE + ["--double-support", "0.3:0.1"], "'0.3:0.1'"),
        (_TWO_PHASE + ["--double-support", "0.1", "--criterion", "energy"], "'energy'"),
        (_TWO_PHASE + ["--double-support", "0.1", "--knots", "3"], "knots = 3"),
        (_TWO_PHASE + ["--double-support", "0.1", "--method", "nelder-mead"], "nelder-mead"),
        (_TWO_PHASE + ["--family", "bezier"], "without --degree"),
        (_TWO_PHASE + ["--degree", "5"], "--degree 5 with --family spline"),
        (_TWO_PHASE + ["--family", "bezier", "--degree", "5", "--knots", "3"], "--knots 3"),
        (_TWO_PHASE + ["--family", "bezier", "--degree", "2"], "'2': allowed an integer from 3"),
        (_TWO_PHASE + ["--family", "cartesian", "--degree", "5"], "'cartesian'"),
    ],
)
def test_bad_input_is_one_line_and_exit_2(capsys, argv, needle):
    """Bad input prints one line on stderr naming the bad value, no traceback, exit 2."""
    assert main(argv) == 2
    captured = capsys.readouterr()
    lines = captured.err.strip().splitlines()
    assert len(lines) == 1 and needle in lines[0] and "Traceback" not in captured.err
    assert captured.out == ""


def test_unknown_knee_exits_2(capsys):
    """argparse rejects an unknown knee with exit status 2, returned by main."""
    assert main(["demo", "--knee", "hinge"]) == 2
    assert "hinge" in capsys.readouterr().err


FAST = ["--starts", "1"]


def test_optimize_writes_a_complete_gait_file(tmp_path, capsys):
    """optimize writes every documented field, ≥ 200 samples from t = 0 to T inclusive."""
    import json

    from biped.records import gait_file

    out = tmp_path / "gait.json"
    assert main(["optimize", "--knee", "rolling", "--speed", "0.3", "--out", str(out), *FAST]) == 0
    gait, content = gait_file.read(out), json.loads(out.read_text())
    for key in (
        "knee",
        "criterion",
        "speed",
        "period",
        "step_length",
        "feasible",
        "costs",
        "robot",
        "parameters",
        "samples",
    ):
        assert key in content
    assert gait.knee == "rolling" and gait.feasible is True and gait.speed == 0.3
    assert isinstance(gait.impact.consistent, bool) and len(gait.impact.trailing_foot_lift) == 2
    assert set(gait.costs.to_dict()) >= {"sthenic", "energy"}
    assert gait.robot.r1 == 0.05 and len(gait.parameters) == 21
    t = gait.samples.t
    assert len(t) >= 200 and t[0] == 0.0 and t[-1] == pytest.approx(gait.period)
    assert gait.step_length == pytest.approx(gait.speed * gait.period)
    assert gait.samples.q.shape == (len(t), 9) and gait.samples.torques.shape == (len(t), 6)
    assert "wrote" in capsys.readouterr().out


def test_infeasible_optimum_writes_nothing(tmp_path, capsys):
    """An infeasible result names the violated constraints, exits 1 and writes no file."""
    out = tmp_path / "gait.json"
    argv = ["optimize", "--knee", "revolute", "--speed", "0.3", "--out", str(out)]
    assert main([*argv, "--method", "nelder-mead", "--evaluations", "1", "--restarts", "0"]) == 1
    err = capsys.readouterr().err
    assert "infeasible" in err and "swing_toe = -" in err
    assert not out.exists() and not list(tmp_path.iterdir())


@pytest.mark.parametrize(
    "argv, needle",
    [
        (["optimize", "--knee", "hinge", "--speed", "0.3", "--out", "x.json"], "hinge"),
        (["optimize", "--knee", "rolling", "--speed", "0", "--out", "x.json"], "speed = '0'"),
        (["optimize", "--knee", "rolling", "--speed", "fast", "--out", "x.json"], "fast"),
        (["optimize", "--knee", "rolling", "--speed", "9", "--out", "x.json"], "speed = 9.0"),
        (["sweep", "--speeds", "0.3:0.1"], "START:STOP:COUNT"),
        (["sweep", "--speeds", "0.2,-0.1"], "speeds > 0"),
        (["sweep", "--jobs", "0"], "'0'"),
        (["sweep", "--clearance", "-0.01"], "clearance = '-0.01'"),
        (["optimize", "--knee", "rolling", "--speed", "0.3", "--out", "."], "is a folder"),
        (["demo", "--knee", "rolling", "--hip-ahead", "nan"], "allowed a finite number"),
        (["validate", "g.json", "--timestep", "0.004"], "timestep = '0.004' s: allowed"),
        (["validate", "g.json", "--timestep", "1e-5"], "timestep = '1e-5' s: allowed"),
        (["validate", "g.json", "--timestep", "fine"], "timestep = 'fine'"),
        (["validate", "g.json", "--kp-scale", "5"], "kp scale = '5': allowed 0.25 to 4"),
        (["validate", "g.json", "--kp-scale", "stiff"], "kp scale = 'stiff'"),
    ],
)
def test_bad_arguments_one_line_exit_2(capsys, argv, needle):
    """Bad arguments: one line on stderr naming the value, exit status 2."""
    assert main(argv) == 2
    lines = capsys.readouterr().err.strip().splitlines()
    assert len(lines) == 1 and needle in lines[0], lines


def test_figures_reject_a_corrupt_gait_file(tmp_path, capsys):
    """A corrupt gait file in the sweep folder is one clear line and exit 2."""
    (tmp_path / "rolling-sthenic-0.300.json").write_text('{"format": "biped-gait/1", "knee": ')
    assert main(["figures", "--sweep", str(tmp_path), "--out", str(tmp_path / "fig")]) == 2
    lines = capsys.readouterr().err.strip().splitlines()
    assert len(lines) == 1 and "rolling-sthenic-0.300.json" in lines[0]


@pytest.mark.parametrize(
    "argv, needle",
    [
        (["pipeline", "--speed", "-0.3"], "-0.3"),
        (["pipeline", "--steps", "0"], "'0'"),
        (["pipeline", "--knees", "hinge"], "hinge"),
        (["pipeline", "--double-support", "0.7"], "'0.7'"),
        (["pipeline", "--double-support", "0.3:0.1"], "'0.3:0.1'"),
        (["pipeline", "--double-support", "0.1", "--landing", "soft"], "'soft'"),
        (["pipeline", "--double-support", "0.1", "--criterion", "energy"], "--criterion energy"),
        (["pipeline", "--double-support", "0.1", "--knots", "3"], "--knots 3"),
        (
            ["pipeline", "--double-support", "0.1", "--family", "bezier", "--degree", "5"],
            "--family bezier",
        ),
        (["pipeline", "--double-support", "0.1", "--design"], "--design"),
        (["pipeline", "--double-support", "0.1", "--method", "nelder-mead"], "nelder-mead"),
    ],
)
def test_pipeline_rejects_bad_options(capsys, argv, needle, tmp_path):
    """Bad pipeline options are one line on stderr and exit 2, before any work: with
    --double-support, what the two-phase problem does not build (another criterion, gait
    family or method, a knee design) too; nothing written."""
    out = tmp_path / "out"
    assert main(argv + ["--out", str(out), "--recordings", str(tmp_path / "r")]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and needle in err[0] and not out.exists()


def test_pipeline_refuses_a_file_as_output_folder(capsys):
    """--out naming a file is one line on stderr and exit 2, before the optimisation."""
    assert main(["pipeline", "--out", __file__]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "allowed a folder" in err[0]


def test_pipeline_writes_gait_report_and_recording(tmp_path, capsys, monkeypatch):
    """One knee, a small budget and 2 steps: the gait file, its report and its recording are
    written where the command says, and the exit status is the report's verdict; the gait is
    validated in memory (its file is never read back)."""
    import json

    from biped.records import gait_file

    read = gait_file.read
    monkeypatch.setattr(gait_file, "read", lambda *a, **k: pytest.fail("gait file read back"))
    out, rrd = tmp_path / "pipeline", tmp_path / "recordings"
    argv = ["pipeline", "--knees", "rolling", "--steps", "2", *FAST, "--out", str(out)]
    code = main(argv + ["--recordings", str(rrd)])
    printed = capsys.readouterr().out
    monkeypatch.setattr(gait_file, "read", read)
    gait = gait_file.read(out / "rolling-sthenic-0.300.json")
    assert gait.knee == "rolling" and gait.speed == 0.3
    report = json.loads((out / "rolling-sthenic-0.300.report.json").read_text())
    assert code == (0 if report["passed"] else 1)
    assert report["inverse_dynamics"]["max_torque_error"] < 1e-6
    assert report["forward"]["steps"] == 2 and not report["forward"]["fell"]
    recording = rrd / "rolling-sthenic-0.300.rrd"
    assert recording.stat().st_size > 0 and str(recording) in printed
    for record in (gait.provenance, report["provenance"]):
        assert record["command"].startswith("biped pipeline --knees rolling")
        assert record["version"] and record["numpy"] and record["mujoco"]


def _one_line(capsys, code, expected_code=2):
    """The single line on stderr of a command that exited with ``expected_code``."""
    captured = capsys.readouterr()
    lines = captured.err.strip().splitlines()
    assert code == expected_code, captured.err
    assert len(lines) == 1 and "Traceback" not in captured.err, captured.err
    return lines[0]


@pytest.fixture
def robot_files(tmp_path):
    """Robot files a user might get wrong: binary, absurd, without knee radii."""
    files = {
        "binary": ("robot.toml", b"r1 = 0.08\n\x89PNG\r\n\x1a\n\x00\xff"),
        "absurd": ("absurd.json", b'{"trunk_mass": 1e308}'),
        "no_radii": ("flat.toml", b"r1 = 0.0\nr2 = 0.0\n"),
    }
    paths = {}
    for key, (name, content) in files.items():
        paths[key] = tmp_path / name
        paths[key].write_bytes(content)
    return paths


@pytest.mark.parametrize(
    "robot, needle",
    [("binary", "UTF-8"), ("absurd", "trunk_mass = 1e+308"), ("absurd", "0.001 to 1000 kg")],
)
def test_bad_robot_file_is_one_line(capsys, robot_files, robot, needle):
    """Binary content and absurd parameters: one line naming the file or field, exit 2."""
    line = _one_line(capsys, main(["demo", "--robot", str(robot_files[robot])]))
    assert needle in line


def test_pipeline_refuses_a_rolling_knee_mujoco_cannot_model(capsys, robot_files, tmp_path):
    """A rolling knee with r1 = r2 = 0 is refused before any work, nothing written."""
    out = tmp_path / "out"
    argv = ["pipeline", "--robot", str(robot_files["no_radii"]), "--out", str(out)]
    line = _one_line(capsys, main(argv))
    assert "r1 = 0.0" in line and "allowed r1, r2 > 0" in line and not out.exists()


OPTIMIZE = ["optimize", "--knee", "rolling", "--speed", "0.3", "--out", "x.json"]


@pytest.mark.parametrize(
    "argv, needles",
    [
        (["demo", "--hip-height", "5"], ["--hip-height 5 m", "hip at 4.93"]),
        (
            ["optimize", "--knee", "rolling", "--speed", "0.3", "--out", "x.json", "--seed", "-1"],
            ["--seed", "'-1'"],
        ),
        (
            ["optimize", "--knee", "rolling", "--speed", "1e-9", "--out", "x.json"],
            ["1e-9", "0.01 m/s"],
        ),
        (["sweep", "--speeds", "0.001,0.3"], ["0.001", "0.01 m/s"]),
        (["sweep", "--speeds", "0.1:0.3:100000000"], ["100000000", "1000"]),
        (["validate", "x.json", "--steps", "1000000000"], ["1000000000", "1 to 1000"]),
        (["pipeline", "--steps", "1001"], ["1001", "1 to 1000"]),
        (["sweep", "--knees", "rolling", "rolling"], ["--knees", "'rolling' given twice"]),
        (["sweep", "--jobs", "1000000"], ["--jobs", "1 to 256"]),
        (["demo", "--hip-ahead", "inf"], ["--hip-ahead", "finite"]),
        (["optimize", "--knee", "rolling", "--speed", "inf", "--out", "x.json"], ["inf", "finite"]),
        (
            ["validate", "x.json", "--connect", "notaurl"],
            ["--connect", "'notaurl'", "rerun+http://"],
        ),
        (
            ["optimize", "--knee", "rolling", "--speed", "0.3", "--out", "/proc/x.json"],
            ["--out '/proc/x.json'", "not writable", "allowed"],
        ),
        # an option the method would not use, or a budget without bound
        (
            [*OPTIMIZE, "--method", "nelder-mead", "--starts", "5"],
            ["--starts 5", "allowed with --method ipopt"],
        ),
        ([*OPTIMIZE, "--restarts", "3"], ["--restarts 3", "--nelder-mead-starts K"]),
        ([*OPTIMIZE, "--evaluations", "10"], ["--evaluations 10", "--method nelder-mead"]),
        (["pipeline", "--restarts", "3"], ["--restarts 3", "--nelder-mead-starts K"]),
        ([*OPTIMIZE, "--starts", "100000"], ["--starts", "'100000'", "1 to 100"]),
        (["sweep", "--nelder-mead-starts", "2"], ["unrecognized", "--nelder-mead-starts"]),
        (["atlas", "--starts", "101"], ["--starts", "'101'", "1 to 100"]),
        # a gait family named by options that do not go together, or not taken there
        (["sweep", "--degree", "7"], ["--degree 7 with --family spline", "allowed with bezier"]),
        (["atlas", "--family", "bezier"], ["--family bezier without --degree", "allowed"]),
        (
            ["pipeline", "--knots", "3", "--family", "bezier", "--degree", "7"],
            ["--knots 3 with --family bezier", "allowed --degree N"],
        ),
        (
            ["pipeline", "--design", "--family", "bezier", "--degree", "7"],
            ["--design with the family n = 7", "allowed with the paper's spline"],
        ),
        (["atlas", "--family", "bezier", "--degree", "21"], ["--degree", "'21'", "3 to 20"]),
        (["figures", "--sweep", "/nonexistent"], ["'/nonexistent' does not exist", "allowed"]),
        (["figures", "--sweep", "README.md"], ["'README.md' is a file", "allowed a folder"]),
        # an abbreviated option is not read as the option it begins
        ([*OPTIMIZE, "--start", "2"], ["unrecognized arguments: --start 2"]),
        (["sweep", "--speed", "0.3"], ["unrecognized arguments: --speed 0.3"]),
        # a range that runs downward is a typo, not a descent
        (["sweep", "--speeds", "0.3:0.2:2"], ["'0.3:0.2:2'", "START 0.3 > STOP 0.2", "allowed"]),
        (["design-map", "--r1", "0.05:0.01:3"], ["'0.05:0.01:3'", "allowed START <= STOP"]),
    ],
)
def test_refused_values_are_named_with_what_is_allowed(capsys, argv, needles):
    """Each refused value is one line naming the option or value and what is allowed, exit 2."""
    line = _one_line(capsys, main(argv))
    assert all(needle in line for needle in needles), line


def _replace_command(monkeypatch, body):
    """Make ``biped demo`` run ``body`` instead of the demo."""

    def command(args):
        return body()

    program = sys.modules["biped_cli.commands"]  # where the demo's parser takes it
    monkeypatch.setattr(program, "cmd_demo", command)


def test_ctrl_c_in_a_command_is_one_line_and_exit_130(capsys, monkeypatch):
    """KeyboardInterrupt inside a command: exit 130 and one line, no traceback."""

    def interrupted():
        raise KeyboardInterrupt

    _replace_command(monkeypatch, interrupted)
    assert "interrupted" in _one_line(capsys, main(["demo"]), 130)


def test_sigterm_in_a_command_is_one_line_and_exit_143(capsys, monkeypatch):
    """SIGTERM while a command runs: exit 143 and one line; the previous handler is back."""
    previous = signal.getsignal(signal.SIGTERM)

    def terminated():
        os.kill(os.getpid(), signal.SIGTERM)
        time.sleep(10)  # interrupted by the handler
        return 0

    _replace_command(monkeypatch, terminated)
    assert "interrupted (SIGTERM)" in _one_line(capsys, main(["demo"]), 143)
    assert signal.getsignal(signal.SIGTERM) is previous


@pytest.mark.parametrize(
    "signum, status, name", [(signal.SIGINT, 130, "Ctrl-C"), (signal.SIGTERM, 143, "SIGTERM")]
)
@pytest.mark.parametrize("turned_into", ["ImportError", "ArgumentError"])
def test_an_interrupt_a_library_turns_into_its_error_is_the_interrupt(
    capsys, monkeypatch, signum, status, name, turned_into
):
    """A Ctrl-C or SIGTERM whose exception a library turns into its own error: a pybind11 module
    loading (MuJoCo, matplotlib) raises ``ImportError: initialization failed`` caused by it,
    ctypes ``ArgumentError: argument 1: Terminated:`` without it. The command ends as
    interrupted (it said "internal error"); the same error with no signal stays a bug."""
    import ctypes

    def library(signalled):
        def command():
            try:
                if signalled:
                    os.kill(os.getpid(), signum)
                time.sleep(0.01)
                raise KeyboardInterrupt  # stands for the signal's exception without one
            except KeyboardInterrupt as interrupt:
                if turned_into == "ImportError":
                    raise ImportError("initialization failed") from interrupt
                raise ctypes.ArgumentError(f"argument 1: {type(interrupt).__name__}: ") from None

        return command

    _replace_command(monkeypatch, library(True))
    assert _one_line(capsys, main(["demo"]), status) == f"biped demo: interrupted ({name})"
    _replace_command(monkeypatch, library(False))
    assert f"internal error: {turned_into}" in _one_line(capsys, main(["demo"]))


def test_unexpected_error_is_one_line_with_a_hint(capsys, monkeypatch):
    """A bug is one line saying so and how to see more; --debug shows the traceback."""

    def bug():
        return {}["missing"]

    _replace_command(monkeypatch, bug)
    line = _one_line(capsys, main(["demo"]))
    assert "internal error: KeyError" in line and "--debug" in line
    assert main(["demo", "--debug"]) == 2
    err = capsys.readouterr().err
    assert "Traceback" in err and err.strip().splitlines()[-1] == line


def test_numpy_warnings_stay_off_the_terminal(capsys, monkeypatch):
    """Overflow in numpy inside a command prints no warning (and --debug shows it)."""

    def overflow():
        print(np.expm1(np.array([1000.0]))[0])
        return 0

    _replace_command(monkeypatch, overflow)
    assert main(["demo"]) == 0
    captured = capsys.readouterr()
    assert captured.out.strip() == "inf" and captured.err == ""
    with pytest.warns(RuntimeWarning, match="overflow"):
        assert main(["demo", "--debug"]) == 0


def test_version_and_python_m_biped(capsys):
    """--version prints the package's version; python -m biped runs the same program."""
    from biped.records.provenance import version

    assert main(["--version"]) == 0
    assert capsys.readouterr().out.strip() == f"biped {version()}"
    done = subprocess.run(
        [sys.executable, "-m", "biped", "demo", "--hip-height", "5"],
        capture_output=True,
        text=True,
        timeout=60,
    )
    assert done.returncode == 2 and done.stdout == ""
    assert done.stderr.count("\n") == 1 and "--hip-height 5 m" in done.stderr


def test_help_documents_exit_statuses(capsys):
    """biped --help exits 0 and states the exit statuses."""
    assert main(["--help"]) == 0
    out = capsys.readouterr().out
    assert "130 / 143" in out and "1 a result fails a check" in out


class _Terminal:
    """A stream that says it is a terminal."""

    def __init__(self):
        self.text = ""

    def write(self, text):
        self.text += text

    def flush(self):
        pass

    def isatty(self):
        return True


def test_progress_draws_on_a_terminal_only(capsys):
    """The bar draws one line (carriage returns, no newline) on a terminal, nothing elsewhere
    in a short run."""
    import io

    piped = io.StringIO()
    terminal = _Terminal()
    for stream in (piped, terminal):
        with Progress(4, "validate", stream=stream) as bar:
            for i in range(4):
                bar.update(note=f"gait{i}.json")
                bar.advance()
    assert piped.getvalue() == ""
    assert "\n" not in terminal.text and "validate  4/4" in terminal.text
    assert terminal.text.endswith("\r\x1b[K")  # erased at the end
    assert capsys.readouterr().err == ""  # stderr under pytest is not a terminal
