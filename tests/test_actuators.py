"""Actuators: the robot file's motors, the drive's formulas, the electrical figures of a gait."""

import dataclasses

import numpy as np
import pytest

import biped
from biped.errors import ParameterError
from biped.model.actuators import JOINT_KINDS, Actuator, Actuators, drive
from biped.model.criteria import ACTUATOR_MARGIN, Safety, evaluate_step, simpson_weights
from biped.model.gait import build_step
from biped.optimization.problem import GaitProblem

SAMPLES = 40


def _evaluation(actuators=None, knee="rolling"):
    """A walkable step (the first guess at 0.3 m/s) evaluated with ``actuators``."""
    robot = dataclasses.replace(biped.Robot.paper(), actuators=actuators)
    model = biped.Biped(robot, knee)
    problem = GaitProblem(model, 0.3)
    step = build_step(model, 0.3, problem.first_parameters())
    return model, step, evaluate_step(model, step, SAMPLES)


def test_joint_kinds_follow_the_joints():
    """Each joint of eq. (32) is driven by the actuator of its kind."""
    assert JOINT_KINDS == tuple(joint.split("_")[1] for joint in biped.JOINTS)


def test_lossless_actuator_gives_the_paper_energy():
    """R = 0, no friction, no rotor, η = 1: P_i = Γ_i θ̇_i, so E without regeneration is the
    positive work and 2 E − E_regenerated is the paper's energy criterion C_E."""
    model, step, ev = _evaluation(Actuators.same(Actuator.lossless()))
    rates = model.joint_angles(ev.qd)
    np.testing.assert_allclose(ev.drive.power, ev.torques * rates, rtol=1e-12, atol=1e-12)
    assert 2 * ev.electrical - ev.electrical_net == pytest.approx(ev.energy, rel=1e-12)
    weights = step.period * simpson_weights(SAMPLES, 1)
    positive = weights @ np.maximum(ev.torques * rates, 0.0).sum(-1)
    assert ev.electrical == pytest.approx(positive, rel=1e-12)


def test_copper_losses_are_the_squared_torques_scaled():
    """Without friction and rotor: copper losses = R / (k_t N η)² ∫ Γ² per joint, so with
    equal actuators the sthenic criterion ranks gaits like the copper losses."""
    actuator = Actuator.lossless(resistance=0.3, gear_efficiency=0.8, gear_ratio=50.0)
    model, step, ev = _evaluation(Actuators.same(actuator))
    weights = step.period * simpson_weights(SAMPLES, 1)
    scale = actuator.resistance / (actuator.torque_constant * 50.0 * 0.8) ** 2
    np.testing.assert_allclose(
        weights @ ev.drive.copper, scale * (weights @ ev.torques**2), rtol=1e-12
    )
    total = weights @ ev.drive.copper.sum(-1)
    assert total == pytest.approx(scale * ev.sthenic * step.step_length, rel=1e-12)


def test_power_balance():
    """u i = R i² + θ̇ (Γ + Γ_f) / η + J_r N² θ̇ θ̈ with the default actuators."""
    model, step, ev = _evaluation()
    k = Actuators.default().constants()
    rates, accels = model.joint_angles(ev.qd), model.joint_angles(ev.qdd)
    friction = k["viscous_friction"] * rates + k["coulomb_friction"] * np.tanh(rates / 1e-2)
    mechanical = rates * (ev.torques + friction) / k["gear_efficiency"]
    rotor = k["rotor_inertia"] * k["gear_ratio"] ** 2 * rates * accels
    np.testing.assert_allclose(ev.drive.power, ev.drive.copper + mechanical + rotor, atol=1e-9)


def test_drive_is_one_formula_for_numpy_and_casadi():
    """The CasADi drive of a sample is the numpy drive to 1e-12."""
    import casadi as ca

    k = Actuators.default().constants()
    rng = np.random.default_rng(3)
    torque, speed, accel = rng.normal(0, 5, (3, 6))
    numeric = drive(k, torque, speed, accel)
    columns = {name: ca.DM(value) for name, value in k.items()}
    symbolic = drive(columns, ca.DM(torque), ca.DM(speed), ca.DM(accel), tanh=ca.tanh)
    for f in dataclasses.fields(numeric):
        np.testing.assert_allclose(
            np.asarray(getattr(symbolic, f.name)).ravel(), getattr(numeric, f.name), rtol=1e-12
        )


def test_robot_file_actuators(tmp_path):
    """A TOML robot file sets every joint's actuator ([actuator]) and one kind's
    ([actuators.knee]); its JSON form reads back equal."""
    path = tmp_path / "robot.toml"
    path.write_text("r1 = 0.06\n[actuator]\ngear_ratio = 100\n[actuators.knee]\nresistance = 0.3\n")
    robot = biped.Robot.from_file(path)
    assert robot.actuators.hip.gear_ratio == robot.actuators.knee.gear_ratio == 100.0
    assert robot.actuators.knee.resistance == 0.3
    assert robot.actuators.ankle.resistance == Actuator.default().resistance
    assert biped.Robot.from_mapping(robot.to_dict()) == robot
    assert "actuators" not in biped.Robot.paper().to_dict()  # the default set is not written


@pytest.mark.parametrize(
    "values, needle",
    [
        ({"actuator": {"resistance": -1.0}}, "actuator.resistance = -1.0"),
        ({"actuators": {"knee": {"gear_efficiency": 1.5}}}, "actuators.knee.gear_efficiency"),
        ({"actuators": {"elbow": {}}}, "actuators.elbow"),
        ({"actuator": {"peak_torque": 1.0}}, "actuator.peak_torque = 1.0"),
        ({"actuator": {"voltage": 48}}, "actuator.voltage"),
        ({"actuator": {"torque_constant": "big"}}, "actuator.torque_constant = 'big'"),
    ],
)
def test_bad_actuator_names_the_value(values, needle):
    """A bad actuator field raises an error naming the field and the value."""
    with pytest.raises(ParameterError) as error:
        biped.Robot.from_mapping(values)
    assert needle in str(error.value) and "allowed" in str(error.value)


@pytest.mark.parametrize("knee", biped.KNEES)
def test_electrical_graph_equals_numeric_figures(knee):
    """The CasADi graph's motor powers, voltages, electrical criterion and actuator-limit
    margins are the numeric model's to 1e-12 at random variables. The Coulomb friction is
    0.5 N·m here: at the default's 4.7 N·m (the AK80-64's back-drive torque) the slope of
    c tanh(θ̇ / ω_c) at rest, c / ω_c = 470 N·m·s/rad, turns the last bit of a rate near 0 into
    4e-11 W of power, which says nothing of the formulas."""
    from biped.optimization.problem import SCALES
    from biped.optimization.symbolic import StepGraph

    safety = Safety(actuator_limits=True)
    actuators = Actuators.from_mapping({"coulomb_friction": 0.5}, {"knee": {"gear_ratio": 30}})
    robot = dataclasses.replace(biped.Robot.paper(), actuators=actuators)
    problem = GaitProblem(biped.Biped(robot, knee), 0.3, safety=safety)
    graph = StepGraph(problem.model, 25, safety, motors=True)
    names = ["electrical_power", "voltage", "electrical", "constraints"]
    function = ca_function(graph, names)
    rng = np.random.default_rng(11)
    for _ in range(3):
        z = problem.first_guess() + 0.3 * SCALES * rng.standard_normal(21)
        z[:2] = rng.uniform(0.05, 0.3, 2)
        out = dict(zip(names, function(z, problem.speed), strict=True))
        step = build_step(problem.model, problem.speed, problem.to_parameters(z))
        ev = evaluate_step(problem.model, step, 25, safety=safety)

        def same(symbolic, value):
            value = np.asarray(value)
            np.testing.assert_allclose(
                np.asarray(symbolic), value, rtol=1e-12, atol=1e-12 * np.max(np.abs(value))
            )

        same(out["electrical_power"].full().T, ev.drive.power)
        same(out["voltage"].full().T, ev.drive.voltage)
        same(float(out["electrical"]), ev.electrical / step.step_length)
        limits = out["constraints"].full().ravel()[-ev.actuator_margins.size :]
        # both sample, then limit, then joint; the solver's keep a margin
        same(limits + ACTUATOR_MARGIN, ev.actuator_margins.ravel())


def ca_function(graph, names):
    import casadi as ca

    return ca.Function("f", graph.inputs, [getattr(graph, name) for name in names])


def test_torque_above_peak_is_infeasible_under_actuator_limits():
    """A motor whose peak torque is below the gait's makes the gait infeasible under the
    actuator limits, naming the joint and the limit; without them it changes nothing."""
    _, _, free = _evaluation()
    peak = float(np.abs(free.torques[:, 2]).max())  # the stance hip's
    weak = Actuator.default()
    weak = dataclasses.replace(weak, continuous_torque=0.5 * peak, peak_torque=0.9 * peak)
    actuators = Actuators(Actuator.default(), Actuator.default(), weak)
    robot = dataclasses.replace(biped.Robot.paper(), actuators=actuators)
    model = biped.Biped(robot, "rolling")
    step = build_step(model, 0.3, GaitProblem(model, 0.3).first_parameters())
    limited = evaluate_step(model, step, SAMPLES, safety=Safety(actuator_limits=True))
    assert not limited.feasible
    assert limited.violations()["stance_hip peak_torque"] == pytest.approx(1 - 1 / 0.9)
    unlimited = evaluate_step(model, step, SAMPLES)
    assert not any(" " in name for name in unlimited.violations())


def test_optimum_under_actuator_limits_stays_within_them():
    """An optimum under --actuator-limits keeps every torque within its motor's peak, where
    the free optimum exceeds it, and is feasible on the check grid."""
    from biped.optimization.optimize import optimize

    free = optimize(GaitProblem(biped.Biped(biped.Robot.paper(), "rolling"), 0.3), starts=1)
    peak = float(np.abs(free.evaluation.torques[:, 2]).max())
    weak = dataclasses.replace(Actuator.default(), continuous_torque=1.0, peak_torque=0.8 * peak)
    actuators = Actuators(Actuator.default(), Actuator.default(), weak)
    robot = dataclasses.replace(biped.Robot.paper(), actuators=actuators)
    safety = Safety(actuator_limits=True)
    problem = GaitProblem(biped.Biped(robot, "rolling"), 0.3, safety=safety)
    limited = optimize(problem, starts=1)
    assert limited.certified
    assert np.abs(limited.evaluation.torques[:, [2, 3]]).max() <= 0.8 * peak
    assert limited.value > free.value


def test_sthenic_optimum_is_bit_identical_with_or_without_actuators():
    """The actuators do not enter the sthenic problem: a robot file's motors leave its
    optimum, to the bit, as the default set's (and the paper's figures of its file)."""
    from biped.optimization.optimize import optimize
    from biped.records.gait_file import Gait

    paper = biped.Robot.paper()
    motors = dataclasses.replace(paper, actuators=Actuators.same(Actuator.lossless()))
    found = [
        optimize(GaitProblem(biped.Biped(r, "revolute"), 0.3), starts=1) for r in (paper, motors)
    ]
    assert np.array_equal(found[0].variables, found[1].variables)
    files = [
        Gait.from_optimum(o, r, provenance={}).to_dict()
        for o, r in zip(found, (paper, motors), strict=True)
    ]
    for key in ("parameters", "samples", "constraints", "impact"):
        assert files[0][key] == files[1][key], key
    assert files[0]["costs"]["sthenic"] == files[1]["costs"]["sthenic"]
    assert files[0]["electrical"] != files[1]["electrical"]
    assert "actuators" not in files[0]["robot"] and "actuators" in files[1]["robot"]
    assert files[1]["units"]["robot.actuators.hip.supply_voltage"] == "V"


def test_gait_file_electrical_figures_are_checked_and_old_files_read(tmp_path):
    """A gait file's electrical figures are recomputed on reading: an edited one is refused,
    naming it; a file written before the actuators (no electrical block, no
    costs.electrical) reads and is consistent."""
    import json

    from biped.errors import BipedError
    from biped.records.gait_file import Gait, read_consistent
    from tests.conftest import optimal_gait

    gait = Gait.from_optimum(optimal_gait("rolling"), biped.Robot.paper())
    content = gait.to_dict()
    edited = json.loads(json.dumps(content))
    edited["electrical"]["copper"][1] *= 1.01
    path = tmp_path / "edited.json"
    path.write_text(json.dumps(edited))
    with pytest.raises(BipedError, match="electrical.copper"):
        read_consistent(path)
    old = json.loads(json.dumps(content))
    del old["electrical"], old["costs"]["electrical"]
    old["units"] = {
        k: v for k, v in old["units"].items() if not k.startswith(("electrical", "costs.electr"))
    }
    path = tmp_path / "old.json"
    path.write_text(json.dumps(old))
    read = read_consistent(path)
    assert read.electrical is None and read.costs.electrical is None


def test_report_page_has_the_drive(tmp_path, capsys):
    """biped report's page gives the motors' figures per joint and the cost of transport."""
    from biped.records.gait_file import Gait
    from biped_cli.main import main
    from tests.conftest import optimal_gait

    path = tmp_path / "rolling.json"
    Gait.from_optimum(optimal_gait("rolling"), biped.Robot.paper()).write(path)
    assert main(["report", str(path), "--out", str(tmp_path / "pages")]) == 0
    page = next((tmp_path / "pages").glob("*.md")).read_text(encoding="utf-8")
    assert "## Drive (the default set's actuators" in page
    assert "| swing_knee |" in page and "| cost of transport, no regeneration |" in page
    assert "| energy drawn per step, with regeneration |" in page
    assert "electrical energy per metre walked (no regeneration)" in page


ROBOT_FILE = """r1 = 0.06
[actuator]
gear_ratio = 36.0
gear_efficiency = 0.81
continuous_torque = 31.8
peak_torque = 63.7
max_speed = 6.98
mass = 0.605

[actuators.knee]
resistance = 0.25
"""


def test_robot_file_with_actuators_drives_the_commands(tmp_path, capsys):
    """A robot file with actuators drives optimize (electrical, within the limits),
    validate, report, atlas and size; its gait file holds the actuators."""
    import json

    from biped_cli.main import main

    robot = tmp_path / "robot.toml"
    robot.write_text(ROBOT_FILE)
    gait = tmp_path / "gait.json"
    common = ["--robot", str(robot), "--speed", "0.3", "--criterion", "electrical"]
    optimize = ["optimize", "--knee", "rolling", *common, "--starts", "1", "--actuator-limits"]
    assert main([*optimize, "--out", str(gait)]) == 0
    content = json.loads(gait.read_text())
    assert content["robot"]["actuators"]["knee"]["resistance"] == 0.25
    assert content["safety"]["actuator_limits"] is True
    assert content["criterion"] == "electrical" and content["electrical"]["energy_per_metre"] > 0
    assert main(["validate", str(gait), "--steps", "3", "--rrd", str(tmp_path / "w.rrd")]) in (0, 1)
    assert main(["report", str(gait), "--out", str(tmp_path / "pages")]) == 0
    assert main(["size", str(gait)]) == 0
    atlas = ["atlas", "--robot", str(robot), "--speeds", "0.3", "--clearances", "0"]
    atlas += ["--criteria", "electrical", "--starts", "1", "--no-walks"]
    assert main([*atlas, "--out", str(tmp_path / "atlas")]) in (0, 1)
    assert (tmp_path / "atlas" / "atlas-electrical.png").exists()
    out = capsys.readouterr().out
    assert "PASS  model" in out and "PASS  inverse_dynamics" in out
    assert "total actuator mass" in out
