"""The ``biped`` command: output of the demo and one-line errors with exit status 2."""

import pytest

from biped_cli import main


def test_demo_prints_both_knees(capsys):
    """The demo holds a posture: Fz is the robot's weight for both knees."""
    assert main(["demo"]) == 0
    out = capsys.readouterr().out
    assert "revolute" in out and "rolling" in out
    fz = [line for line in out.splitlines() if line.startswith("Fz [N]")][0].split()[2:]
    assert [float(v) for v in fz] == pytest.approx([70.0 * 9.81] * 2)


@pytest.mark.parametrize(
    "argv, needle",
    [
        (["demo", "--hip-height", "2.0"], "out of reach"),
        (["demo", "--robot", "missing.toml"], "missing.toml"),
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
    """argparse rejects an unknown knee with exit status 2."""
    with pytest.raises(SystemExit) as exit_info:
        main(["demo", "--knee", "hinge"])
    assert exit_info.value.code == 2
    assert "hinge" in capsys.readouterr().err


FAST = ["--evaluations", "300", "--restarts", "0", "--polish", "30"]


def test_optimize_writes_a_complete_gait_file(tmp_path, capsys):
    """optimize writes every documented field, ≥ 200 samples from t = 0 to T inclusive."""
    from biped import gait_file

    out = tmp_path / "gait.json"
    assert main(["optimize", "--knee", "rolling", "--speed", "0.3", "--out", str(out), *FAST]) == 0
    gait = gait_file.read(out)
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
        assert key in gait
    assert gait["knee"] == "rolling" and gait["feasible"] is True and gait["speed"] == 0.3
    assert (
        isinstance(gait["impact"]["consistent"], bool)
        and len(gait["impact"]["trailing_foot_lift"]) == 2
    )
    assert set(gait["costs"]) >= {"sthenic", "energy"}
    assert gait["robot"].r1 == 0.05 and len(gait["parameters"]) == 21
    t = gait["samples"]["t"]
    assert len(t) >= 200 and t[0] == 0.0 and t[-1] == pytest.approx(gait["period"])
    assert gait["step_length"] == pytest.approx(gait["speed"] * gait["period"])
    assert gait["samples"]["q"].shape == (len(t), 9) and gait["samples"]["torques"].shape == (
        len(t),
        6,
    )
    assert "wrote" in capsys.readouterr().out


def test_infeasible_optimum_writes_nothing(tmp_path, capsys):
    """An infeasible result names the violated constraints, exits 1 and writes no file."""
    out = tmp_path / "gait.json"
    argv = ["optimize", "--knee", "revolute", "--speed", "0.3", "--out", str(out)]
    assert main([*argv, "--evaluations", "1", "--restarts", "0", "--polish", "0"]) == 1
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
        (["demo", "--knee", "rolling", "--hip-ahead", "nan"], "allowed finite numbers"),
    ],
)
def test_bad_arguments_one_line_exit_2(capsys, argv, needle):
    """Bad arguments: one line on stderr naming the value, exit status 2."""
    try:
        code = main(argv)
    except SystemExit as exit_info:
        code = exit_info.code
    assert code == 2
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
    ],
)
def test_pipeline_rejects_bad_options(capsys, argv, needle):
    """Bad pipeline options are one line on stderr and exit 2, before any work."""
    with pytest.raises(SystemExit) as exit_info:
        main(argv)
    assert exit_info.value.code == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and needle in err[0]


def test_pipeline_refuses_a_file_as_output_folder(capsys):
    """--out naming a file is one line on stderr and exit 2, before the optimisation."""
    assert main(["pipeline", "--out", __file__]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "allowed a folder" in err[0]


def test_pipeline_writes_gait_report_and_recording(tmp_path, capsys):
    """One knee, a small budget and 2 steps: the gait file, its report and its recording are
    written where the command says, and the exit status is the report's verdict."""
    import json

    from biped import gait_file

    out, rrd = tmp_path / "pipeline", tmp_path / "recordings"
    argv = ["pipeline", "--knees", "rolling", "--steps", "2", "--restarts", "0"]
    argv += ["--evaluations", "300", "--polish", "30", "--out", str(out)]
    code = main(argv + ["--recordings", str(rrd)])
    printed = capsys.readouterr().out
    gait = gait_file.read(out / "rolling-sthenic-0.300.json")
    assert gait["knee"] == "rolling" and gait["speed"] == 0.3
    report = json.loads((out / "rolling-sthenic-0.300.report.json").read_text())
    assert code == (0 if report["passed"] else 1)
    assert report["inverse_dynamics"]["max_torque_error"] < 1e-6
    assert report["forward"]["steps"] == 2 and not report["forward"]["fell"]
    recording = rrd / "rolling-sthenic-0.300.rrd"
    assert recording.stat().st_size > 0 and str(recording) in printed
