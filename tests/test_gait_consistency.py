"""Gait files checked against their own parameters: samples, costs, constraints, feasible and
impact recomputed (no MuJoCo); an edited figure, or a gait of another robot or knee, is refused
naming the field and the file (``biped validate`` and ``biped figures`` exit 2)."""

import json
import os
import subprocess
import sys

import pytest

from biped import Robot
from biped.records import gait_file
from biped.records.gait_file import Gait
from biped_cli import main
from tests.conftest import edited_gait_file, refusal, small_optimum


@pytest.fixture(scope="module")
def content():
    """The JSON content of a rolling-knee gait file at 0.3 m/s."""
    optimum = small_optimum("rolling")
    return json.loads(json.dumps(Gait.from_optimum(optimum, Robot.paper()).to_dict()))


_write = edited_gait_file


def _refusal(path) -> str:
    """The one-line refusal of ``read_consistent`` (the file reads as a gait file)."""
    gait_file.read(path)  # the format is right: only the consistency is wrong
    return refusal(gait_file.read_consistent, path)


def test_an_untouched_file_is_consistent(content, tmp_path):
    """A file as written reads back consistent."""
    gait = gait_file.read_consistent(_write(content, tmp_path))
    assert gait.knee == "rolling"


def test_a_file_is_consistent_on_other_cpu_features(content, tmp_path):
    """Checked by a process with numpy's widest vector instructions off and one BLAS thread
    (as on another machine), the file still belongs to its parameters."""
    path = _write(content, tmp_path)
    env = {
        **os.environ,
        "NPY_DISABLE_CPU_FEATURES": "AVX512_ICL X86_V4",
        "OPENBLAS_NUM_THREADS": "1",
    }
    code = f"from biped.records import gait_file; gait_file.read_consistent({str(path)!r}); print('ok')"
    done = subprocess.run(
        [sys.executable, "-c", code], env=env, capture_output=True, text=True, timeout=120
    )
    assert done.returncode == 0 and done.stdout.strip() == "ok", done.stderr


def _scale_row(field, row, factor):
    def change(gait):
        gait["samples"][field][row] = [x * factor for x in gait["samples"][field][row]]

    return change


@pytest.mark.parametrize(
    "change, needle",
    [
        (lambda g: g["costs"].update(sthenic=g["costs"]["sthenic"] / 2), "costs.sthenic = "),
        (lambda g: g["costs"].update(energy=g["costs"]["energy"] * 1.001), "costs.energy = "),
        (
            lambda g: g["samples"]["torques"][17].__setitem__(
                1, g["samples"]["torques"][17][1] + 1e-3
            ),
            "samples.torques do not belong to the parameters (off by 0.001 N·m at t = ",
        ),
        (
            lambda g: g["samples"].update(
                torques=[[0.8 * x for x in r] for r in g["samples"]["torques"]]
            ),
            "samples.torques do not belong to the parameters",
        ),
        (_scale_row("q", 40, 1.01), "samples.q do not belong to the parameters"),
        (_scale_row("wrench", 3, 1.1), "samples.wrench do not belong to the parameters"),
        (
            lambda g: g["samples"].update(zmp=[z + 0.01 for z in g["samples"]["zmp"]]),
            "samples.zmp do not belong to the parameters (off by 0.01 m",
        ),
        (
            lambda g: g["constraints"].update(
                {k: v + 0.5 for k, v in list(g["constraints"].items())[:1]}
            ),
            "constraints.",
        ),
        (lambda g: g.update(feasible=not g["feasible"]), "feasible = "),
        (
            lambda g: g["impact"].update(impulse=[2 * x for x in g["impact"]["impulse"]]),
            "impact.impulse does not belong to the parameters",
        ),
        (
            lambda g: g["impact"].update(consistent=not g["impact"]["consistent"]),
            "impact.consistent",
        ),
        (
            lambda g: g["knee_loads"]["normal"][60].__setitem__(
                1, g["knee_loads"]["normal"][60][1] - 1.0
            ),
            "knee_loads.normal do not belong to the parameters (off by 1 N)",
        ),
        (
            lambda g: g["knee_loads"].update(
                tangential=[[-x for x in r] for r in g["knee_loads"]["tangential"]]
            ),
            "knee_loads.tangential do not belong to the parameters",
        ),
        (
            lambda g: g["knee_loads"].update(max_tension=[0.0, 0.0]),
            "knee_loads.max_tension do not belong to the parameters",
        ),
        (
            lambda g: g["knee_loads"].update(max_slip_ratio=[0.01, 0.01]),
            "knee_loads.max_slip_ratio has None where its parameters give a number",
        ),
        (
            lambda g: g["knee_loads"].update(needs_ligaments=False),
            "knee_loads.needs_ligaments = False, its parameters give true",
        ),
        (
            lambda g: g["knee_loads"].pop("max_compression"),
            "knee_loads.max_compression is not the (2,) numbers it should be",
        ),
    ],
    ids=[
        "sthenic halved",
        "energy +0.1 %",
        "one torque +1 mN·m",
        "torques x0.8",
        "q row x1.01",
        "wrench row x1.1",
        "zmp +1 cm",
        "constraint +0.5",
        "feasible flipped",
        "impulse doubled",
        "impact consistency flipped",
        "swing knee's normal force -1 N",
        "tangential forces reversed",
        "no tension",
        "a ratio for a knee never compressed",
        "no ligaments",
        "largest compression missing",
    ],
)
def test_an_edited_field_is_named(content, tmp_path, change, needle):
    """Each edit of a derived field is refused naming that field, and the file."""
    message = _refusal(_write(content, tmp_path, change))
    assert needle in message, message


def test_a_gait_of_another_robot_is_refused(content, tmp_path):
    """The same parameters on a robot with 10 % more trunk mass: the impact that starts the
    step (so the motion) and the torques change; the file's samples do not belong to them."""

    def heavier(gait):
        gait["robot"]["trunk_mass"] *= 1.1

    message = _refusal(_write(content, tmp_path, heavier))
    assert "samples." in message and "do not belong to the parameters" in message, message


def test_a_gait_of_the_other_knee_is_refused(content, tmp_path):
    """The rolling knee's gait relabelled revolute: the same parameters make another motion."""
    message = _refusal(_write(content, tmp_path, lambda g: g.update(knee="revolute")))
    assert "do not belong to the parameters" in message, message


def test_validate_refuses_an_edited_file_before_any_work(content, tmp_path, capsys):
    """`biped validate` exits 2 with one line naming the field and the file (no MuJoCo run,
    no recording)."""
    path = _write(content, tmp_path, lambda g: g["costs"].update(sthenic=g["costs"]["sthenic"] / 2))
    rrd = tmp_path / "walk.rrd"
    assert main(["validate", str(path), "--rrd", str(rrd), "--steps", "1"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "costs.sthenic" in err[0] and str(path) in err[0], err
    assert not rrd.exists()


def test_figures_refuse_an_edited_sweep_file(content, tmp_path, capsys):
    """`biped figures` exits 2 naming the edited file and field, writing no figure."""
    sweep = tmp_path / "sweep"
    sweep.mkdir()
    path = _write(
        content, sweep, lambda g: g.update(feasible=not g["feasible"]), "rolling-sthenic-0.300.json"
    )
    out = tmp_path / "figures"
    assert main(["figures", "--sweep", str(sweep), "--out", str(out)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "feasible = " in err[0] and str(path) in err[0], err
    assert not out.exists() or not list(out.iterdir())


# The commands that read gait files: name -> its arguments for a gait file and a scratch folder.
GAIT_READERS = {
    "validate": lambda gait, tmp: ["validate", gait, "--rrd", f"{tmp}/walk.rrd", "--steps", "1"],
    "robustness": lambda gait, tmp: ["robustness", gait, "--out", f"{tmp}/out"],
    "orbit": lambda gait, tmp: ["orbit", gait, "--out", f"{tmp}/out"],
    "report": lambda gait, tmp: ["report", gait, "--out", f"{tmp}/out"],
    "size": lambda gait, tmp: ["size", gait],
    "profile-speeds": lambda gait, tmp: ["profile-speeds", gait, "--out", f"{tmp}/out/rows.json"],
    "figures": lambda sweep, tmp: ["figures", "--sweep", sweep, "--out", f"{tmp}/out"],
    "validate.outputs.video": lambda gait, tmp: [gait, "--out", f"{tmp}/walk.mp4", "--steps", "1"],
}


def test_every_command_taking_gait_files_is_checked_here():
    """Each subcommand with a GAIT.json argument is among the readers tested below."""
    from biped_cli.main import build_parser

    takes_gaits = {
        name
        for name, sub in build_parser().command_parsers.items()
        if any(a.metavar == "GAIT.json" for a in sub._actions if not a.option_strings)
    }
    assert takes_gaits and takes_gaits <= set(GAIT_READERS), takes_gaits


@pytest.mark.parametrize("command", GAIT_READERS)
def test_every_reader_refuses_edited_torques(command, content, tmp_path, capsys):
    """A gait file whose torques were doubled is refused by every command that reads gait
    files (a sweep's file of any name for figures): exit 2, one line naming the field and
    the file, nothing written."""
    from validate.outputs import video

    def doubled(gait):
        gait["samples"]["torques"] = [[2 * x for x in row] for row in gait["samples"]["torques"]]

    folder = tmp_path / "in"
    folder.mkdir()
    path = _write(content, folder, doubled, "mine.json")
    argv = GAIT_READERS[command](str(folder if command == "figures" else path), tmp_path)
    code = video.main(argv) if command == "validate.outputs.video" else main(argv)
    err = capsys.readouterr().err.strip().splitlines()
    assert code == 2
    assert len(err) == 1 and "samples.torques" in err[0] and str(path) in err[0], err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["in"]
