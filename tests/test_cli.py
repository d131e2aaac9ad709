"""The ``biped`` command: output of the demo and one-line errors with exit status 2."""

import pytest

from biped.cli import main


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
