"""The validation report, its recording and the validate command."""

import json

import numpy as np
import pytest
import rerun.chunk

from biped import Robot
from biped.records.gait_file import Gait
from biped_cli import main
from tests.conftest import small_optimum


@pytest.fixture(scope="module")
def gait_path(tmp_path_factory):
    """A gait file of the rolling knee at 0.3 m/s, produced by the optimiser."""
    optimum = small_optimum("rolling")
    path = tmp_path_factory.mktemp("gait") / "rolling.json"
    Gait.from_optimum(optimum, Robot.paper()).write(path)
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
    for check, name, unit in (
        ("inverse_dynamics", "max_force_error", "N"),
        ("inverse_dynamics", "max_moment_error", "N·m"),
        ("impact", "max_linear_velocity_error", "m/s"),
        ("impact", "max_angular_velocity_error", "rad/s"),
        ("impact", "max_force_impulse_error", "N·s"),
        ("impact", "max_moment_impulse_error", "N·m·s"),
    ):  # one figure, one unit: an error of quantities of two units is two figures
        assert content[check][name] < 1e-6 and content["units"][f"{check}.{name}"] == unit
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


def _run(args, capsys):
    """``biped`` with ``args``: (exit status, stdout, stderr)."""
    code = main(args)
    out, err = capsys.readouterr()
    return code, out, err


@pytest.fixture(scope="module")
def heavy_gait(tmp_path_factory):
    """The optimal revolute gait at 0.3 m/s of a robot whose trunk is 10 % heavier."""
    import dataclasses

    from biped import Biped
    from biped.optimization.optimize import optimize
    from biped.optimization.problem import GaitProblem

    paper = Robot.paper()
    robot = dataclasses.replace(paper, trunk_mass=1.1 * paper.trunk_mass)
    optimum = optimize(GaitProblem(Biped(robot, "revolute"), 0.3))
    path = tmp_path_factory.mktemp("heavy") / "heavy.json"
    return Gait.from_optimum(optimum, robot).write(path)


def test_a_gait_of_a_heavier_trunk_fails_on_the_table_1_model(heavy_gait, tmp_path, capsys):
    """A gait made for a trunk 10 % heavier, played on the committed Table 1 model (--model):
    its torques are not those of that robot's motion, and the replay of its steps fails at
    the joints that carry the trunk, its note giving the share the servos add to each,
    beside inverse dynamics; on the model of its own robot (the default) the same replay
    passes."""
    from validate.scene.mjcf import FOLDER

    rrd = str(tmp_path / "heavy.rrd")
    model = str(FOLDER / "scene_revolute.xml")
    args = ["validate", str(heavy_gait), "--steps", "1", "--json", "--rrd", rrd]
    code, out, _ = _run([*args, "--model", model], capsys)
    table_1 = json.loads(out)
    assert code == 1 and not table_1["passed"]
    assert not table_1["feedforward"]["passed"] and not table_1["inverse_dynamics"]["passed"]
    assert table_1["model"]["mass_difference"] == pytest.approx(-0.1 * Robot.paper().trunk_mass)
    assert not table_1["model"]["passed"] and "trunk_mass" in table_1["model"]["notes"][0]
    replay = table_1["feedforward"]
    stance = [replay[f"feedback_share_stance_{j}"] for j in ("knee", "hip")]
    assert min(stance) > 0.1
    assert replay["causes"] == ["servo share"] and table_1["model"]["causes"] == ["model mismatch"]
    (note,) = replay["notes"]  # what MuJoCo's replay measured, not a bad file
    for joint in ("knee", "hip"):  # each servo's torque against the robot's torque scale
        torque, ratio = (replay[f"{f}_stance_{joint}"] for f in ("feedback_rms", "feedback_ratio"))
        assert ratio == pytest.approx(torque / replay["torque_scale"]) and ratio > 0.1
        assert f"{torque:.3g} N·m at stance_{joint} ({100 * ratio:.2g} %)" in note, note
    assert f"of the robot's torque scale {replay['torque_scale']:.3g} N·m" in note
    assert "servos" in note and "not its motion" not in note
    assert table_1["units"]["feedforward.torque_scale"] == "N·m"
    _, out, _ = _run(args, capsys)
    own = json.loads(out)
    assert own["feedforward"]["passed"] and own["inverse_dynamics"]["passed"]
    assert own["model"]["passed"] and own["impact"]["passed"]


def test_a_rolling_gait_on_the_revolute_model_is_refused(gait_path, tmp_path, capsys):
    """--model of the other knee: one line naming the model and both knees, exit 2, before
    any work (no recording)."""
    from validate.scene.mjcf import FOLDER

    rrd = tmp_path / "refused.rrd"
    model = str(FOLDER / "scene_revolute.xml")
    code, _, err = _run(["validate", str(gait_path), "--model", model, "--rrd", str(rrd)], capsys)
    assert code == 2 and len(err.strip().splitlines()) == 1
    assert "revolute knee" in err and "rolling knee" in err and "scene_revolute.xml" in err
    assert not rrd.exists()
    code, _, err = _run(["validate", str(gait_path), "--model", str(tmp_path / "no.xml")], capsys)
    assert code == 2 and len(err.strip().splitlines()) == 1 and "no.xml" in err


def _rolling_model(folder, change) -> str:
    """The committed rolling-knee scene copied to ``folder`` with its robot file changed by
    ``change(text) -> text``; returns the scene's path."""
    from validate.scene.mjcf import FOLDER

    folder.mkdir(parents=True, exist_ok=True)
    robot = (FOLDER / "biped_rolling.xml").read_text()
    (folder / "biped_rolling.xml").write_text(change(robot))
    (folder / "scene_rolling.xml").write_text((FOLDER / "scene_rolling.xml").read_text())
    return str(folder / "scene_rolling.xml")


def test_model_errors_are_fail_lines(gait_path, tmp_path, capsys):
    """A rolling-knee model without its knee equalities, or with another ratio r2 / r1, is not
    the gait's robot: the model check and inverse dynamics print FAIL lines naming why, exit
    1, no traceback."""
    import re

    missing = _rolling_model(
        tmp_path / "missing", lambda text: re.sub(r"<equality>.*?</equality>", "", text, flags=re.S)
    )
    ratio = _rolling_model(
        tmp_path / "ratio", lambda text: text.replace('polycoef="0 1 ', 'polycoef="0 1.2 ')
    )
    cases = (
        (missing, "no equality", "degrees of freedom"),  # the system is not square
        (ratio, "knee_lower = 1.2 knee_upper", "max_torque_error"),  # another robot's torques
    )
    for model, reason, inverse in cases:
        rrd = str(tmp_path / f"{reason[:2]}.rrd")
        code, out, err = _run(
            ["validate", str(gait_path), "--steps", "1", "--model", model, "--rrd", rrd], capsys
        )
        assert code == 1 and "Traceback" not in err, err
        lines = {
            line.split()[1]: line
            for line in out.splitlines()
            if line[:4].strip() and "  " in line[:2]
        }
        assert lines["model"].startswith("  FAIL  model             [model mismatch] ")
        assert reason in lines["model"]
        assert (
            lines["inverse_dynamics"].startswith("  FAIL") and inverse in lines["inverse_dynamics"]
        )
        if model == missing:  # no knee force without the knee's inverse dynamics
            assert lines["knee_loads"].startswith("  FAIL") and inverse in lines["knee_loads"]


def test_json_has_one_object_per_check_with_its_verdict_and_units(report):
    """Each check is an object with ``passed``, ``notes`` and ``causes`` (none when it passes,
    else words of ``CAUSES``); every number has its unit, the per-joint torques too."""
    from biped.model.units import missing
    from validate.checks.checks import CAUSES

    code, content, _ = report
    for name in ("model", "inverse_dynamics", "impact", "feedforward", "forward", "gains"):
        assert isinstance(content[name]["passed"], bool), name
        assert isinstance(content[name]["notes"], list), name
        causes = content[name]["causes"]  # why it fails, in the fixed words; none if it passes
        assert set(causes) <= set(CAUSES) and bool(causes) is not content[name]["passed"]
    assert missing(content, content["units"]) == []
    forward = content["forward"]
    for name in ("gait_torque_rms", "mujoco_torque_rms", "rotor_torque_rms", "servo_torque_rms"):
        assert len(forward[name]) == 6 and content["units"][f"forward.{name}"] == "N·m"
    assert content["units"]["forward.max_slip_share"] == "S"


ROBOT_FIELDS = [f.name for f in Robot.body_fields()]  # in their order (the actuators: no MJCF)


@pytest.fixture(scope="module")
def table_1_models():
    """The committed Table 1 scene of each knee, compiled."""
    import mujoco

    from validate.scene.mjcf import FOLDER

    return {
        knee: mujoco.MjModel.from_xml_path(str(FOLDER / f"scene_{knee}.xml"))
        for knee in ("revolute", "rolling")
    }


@pytest.mark.parametrize(
    "knee, field",
    [
        (knee, field)
        for field in ROBOT_FIELDS
        for knee in ("revolute", "rolling")
        if knee == "rolling" or field not in ("r1", "r2")  # a revolute knee has no radii
        if field not in ("k1", "k2")  # 0 in Table 1: a profile (tests/test_profile_mjcf.py)
    ],
)
def test_the_model_check_names_a_field_that_differs(table_1_models, knee, field):
    """A gait's robot with one field 5 % off Table 1: the Table 1 model fails the model check
    naming that field first with both values, the model generated from that robot passes."""
    import dataclasses

    from biped import Biped
    from validate.checks.checks import check_model
    from validate.scene.mjcf import scene_model

    paper = Robot.paper()
    robot = dataclasses.replace(paper, **{field: 1.05 * getattr(paper, field)})
    biped = Biped(robot, knee)
    check = check_model(table_1_models[knee], biped)
    assert not check.passed
    named = [note for note in check.notes if note.startswith(f"{field}:")]
    assert named and named[0] == check.notes[-1] and "differing too" not in named[0], check.notes
    assert f"{getattr(paper, field):.6g}" in named[0] and f"{getattr(robot, field):.6g}" in named[0]
    assert check.line().startswith("FAIL  model") and named[0] in check.line()
    assert check_model(scene_model(robot, knee), biped).passed


def test_a_revolute_model_does_not_hold_the_knee_radii(table_1_models):
    """The radii of a revolute-knee robot are not its dynamics: the Table 1 revolute model is
    the model of a revolute robot whose r1, r2 differ."""
    import dataclasses

    from biped import Biped
    from validate.checks.checks import check_model

    robot = dataclasses.replace(Robot.paper(), r1=0.08, r2=0.02)
    assert check_model(table_1_models["revolute"], Biped(robot, "revolute")).passed


@pytest.mark.parametrize("knee", ["revolute", "rolling"])
def test_a_gait_under_other_gravity_passes_on_its_own_model(knee):
    """A gait of a robot under g = 9.5 m/s²: its generated model holds that gravity, so inverse
    dynamics and the model check pass there; the Table 1 model fails the model check naming
    gravity and inverse dynamics."""
    import dataclasses

    from biped import Biped
    from biped.optimization.optimize import optimize
    from biped.optimization.problem import GaitProblem
    from tests.conftest import gait_of
    from validate.checks import checks
    from validate.scene.mjcf import FOLDER
    from validate.scene.model import compile_spec, model_spec
    from validate.walk.samples import GaitSamples

    robot = dataclasses.replace(Robot.paper(), gravity=9.5)
    biped = Biped(robot, knee)
    optimum = optimize(
        GaitProblem(biped, 0.3), method="nelder-mead", max_restarts=0, evaluations_per_run=100
    )
    gait = gait_of(optimum, robot)
    samples = GaitSamples.from_gait(gait)
    own = compile_spec(model_spec(biped))
    assert own.opt.gravity[2] == -9.5
    assert checks.check_model(own, biped).passed
    assert checks.check_inverse_dynamics(own, biped, samples).passed
    table_1 = compile_spec(model_spec(biped, FOLDER / f"scene_{knee}.xml"))
    model = checks.check_model(table_1, biped)
    assert not model.passed and model.notes[-1].startswith("gravity: 9.81 m/s² in the model")
    assert not checks.check_inverse_dynamics(table_1, biped, samples).passed


@pytest.mark.parametrize("knee", ["revolute", "rolling"])
def test_the_knee_loads_check_fails_a_wrong_radius_or_lower_leg_mass(table_1_models, knee):
    """The gait file's knee loads are MuJoCo's on the Table 1 model (to 1e-6 N, rounding
    measured); loads computed for a shank 10 % heavier, or for r1 = r2 = 0.04 m, fail on it,
    as the file's loads fail on the MJCF of r1 = r2 = 0.04 m (the revolute knee has no
    radii: it passes there)."""
    import dataclasses

    from biped import Biped
    from biped.model.knee_loads import knee_forces
    from tests.conftest import gait_of
    from validate.checks.checks import check_knee_loads
    from validate.scene.model import compile_spec, model_spec
    from validate.walk.samples import GaitSamples

    gait = gait_of(small_optimum(knee))
    samples = GaitSamples.from_gait(gait)
    table_1 = table_1_models[knee]
    check = check_knee_loads(table_1, gait.biped, samples, gait.knee_loads)
    assert check.passed and check.figures["max_knee_normal_error"] < 1e-9, check.line()
    assert check.figures["max_swing_knee_tension"] > 30.0
    paper = Robot.paper()
    small = dataclasses.replace(paper, r1=0.04, r2=0.04)
    for robot in (dataclasses.replace(paper, shank_mass=1.1 * paper.shank_mass), small):
        loads = knee_forces(Biped(robot, knee), samples.q, samples.qd, samples.qdd)
        wrong = check_knee_loads(table_1, gait.biped, samples, loads)
        assert wrong.passed is (knee == "revolute" and robot is small), wrong.line()
    other = compile_spec(model_spec(Biped(small, knee)))
    wrong = check_knee_loads(other, gait.biped, samples, gait.knee_loads)
    assert wrong.passed is (knee == "revolute"), wrong.line()
    if knee == "rolling":
        assert wrong.figures["max_knee_normal_error"] > 0.01, wrong.line()
    assert check_knee_loads(table_1, gait.biped, samples).notes == [
        "the gait file has no knee_loads: computed from its samples"
    ]


def test_the_report_reads_back_as_the_record_it_was_written_from(report):
    """The report's JSON is ``ValidationReport.to_dict``'s: read back (``from_dict``) it is the
    same record, each check with its figures, units, notes and causes; a report whose
    verdict is not its checks' is refused, naming the failed ones."""
    from biped.records.validation_report import ValidationReport

    _, content, _ = report
    record = ValidationReport.from_dict(content)
    assert record.to_dict() == content and record.passed is content["passed"]
    forward = record.check("forward")
    assert (
        forward.units["max_slip"] == "m" and forward.figures["steps"] == content["forward"]["steps"]
    )
    assert record.check("no such check") is None
    failed = {**content, "forward": {**content["forward"], "passed": False}}
    with pytest.raises(ValueError, match="failed are: forward"):
        ValidationReport.from_dict({**failed, "passed": True})
    assert ValidationReport.from_dict({**failed, "passed": False}).failed() == ("forward",)


def test_a_bezier_gait_is_validated_as_a_splines(tmp_path, capsys):
    """A Bézier gait file (--family bezier) is played in MuJoCo as a spline's: its inverse
    dynamics, impact and feedforward replay agree with the model and it walks 3 steps."""
    from biped.model.bezier import Bezier
    from biped.model.dynamics import Biped
    from biped.optimization.optimize import optimize
    from biped.optimization.problem import GaitProblem

    problem = GaitProblem(Biped(Robot.paper(), "rolling"), 0.3, knots=Bezier(5))
    path = Gait.from_optimum(optimize(problem, starts=1), Robot.paper()).write(
        tmp_path / "bezier.json"
    )
    rrd = tmp_path / "bezier.rrd"
    _, out, _ = _run(["validate", str(path), "--steps", "3", "--rrd", str(rrd), "--json"], capsys)
    content = json.loads(out)
    for name in ("model", "inverse_dynamics", "impact", "feedforward", "forward"):
        assert content[name]["passed"], (name, content[name])
