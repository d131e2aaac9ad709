"""Knee co-design: the graph with symbolic radii is the numeric model of every radius, its
derivatives with respect to the radii are the numeric model's, zero radii are the revolute
knee, the designed knee beats the paper's and walks in MuJoCo as analysed."""

import dataclasses

import casadi as ca
import numpy as np
import pytest

import biped
from biped.model.criteria import PAPER_SAFETY, Safety, evaluate_step
from biped.model.gait import build_step
from biped.optimization.design import (
    DesignProblem,
    check_radii,
    optimize_at,
    optimize_design,
    radius_limits,
)
from biped.optimization.problem import SCALES, GaitProblem
from biped.optimization.symbolic import StepGraph
from tests.conftest import optimal_gait

ROBOT = biped.Robot.paper()
SAMPLES = 25
SPEED = 0.3


@pytest.fixture(scope="module")
def graph():
    return StepGraph(biped.Biped(ROBOT, "rolling"), SAMPLES, PAPER_SAFETY, design=True)


_DESIGNS: dict = {}


def optimal_design(safety=PAPER_SAFETY) -> "biped.optimization.design.Design":
    """The design optimum at 0.3 m/s (sthenic, default starts and seed), once per session."""
    if safety not in _DESIGNS:
        _DESIGNS[safety] = optimize_design(DesignProblem(ROBOT, SPEED, safety=safety))
    return _DESIGNS[safety]


def gait_at(radii, knee="rolling", speed=SPEED, criterion="sthenic"):
    robot = dataclasses.replace(ROBOT, r1=radii[0], r2=radii[1])
    return GaitProblem(biped.Biped(robot, knee), speed, criterion)


def random_variables(problem, rng):
    z = problem.first_guess() + 0.3 * SCALES * rng.standard_normal(21)
    z[:2] = rng.uniform(0.05, 0.3, 2)
    return z


def numeric(problem, z):
    step = build_step(problem.model, problem.speed, problem.to_parameters(z))
    return evaluate_step(problem.model, step, SAMPLES)


def test_design_graph_is_the_numeric_model_at_any_radii(graph):
    """With the radii as symbols the graph gives, at random radii, the torques, wrench and
    both criteria of the numeric model built with those radii (1e-12 relative)."""
    function = graph.function()
    rng = np.random.default_rng(11)
    limits = radius_limits(ROBOT)
    for _ in range(3):
        radii = tuple(rng.uniform(0.0, limits))
        problem = gait_at(radii)
        z = random_variables(problem, rng)
        out = function(z=z, speed=SPEED, radii=radii)
        ev = numeric(problem, z)
        scale = np.abs(ev.torques).max()
        np.testing.assert_allclose(out["torques"].full().T, ev.torques, atol=1e-12 * scale)
        np.testing.assert_allclose(out["wrench"].full().T, ev.wrench, rtol=1e-12, atol=1e-9)
        assert float(out["sthenic"]) == pytest.approx(ev.sthenic, rel=1e-12)
        assert float(out["energy"]) == pytest.approx(ev.energy, rel=1e-12)
        # and the radii matter: the Table 1 robot's torques are far from these
        other = numeric(gait_at((0.05, 0.05)), z)
        assert np.abs(other.torques - ev.torques).max() > 1e-3


@pytest.mark.parametrize("criterion", ["sthenic", "energy"])
def test_criterion_derivative_in_the_radii_matches_finite_differences(graph, criterion):
    """d criterion / d r1 and d r2 of the graph equal central finite differences of the
    numeric model with the robot's radii changed (the gait's variables held)."""
    expression = getattr(graph, criterion)
    gradient = ca.Function(
        "g", [graph.z, graph.speed, graph.radii], [ca.gradient(expression, graph.radii)]
    )
    rng = np.random.default_rng(5)
    for radii in [(0.07, 0.11), (0.16, 0.02)]:
        z = random_variables(gait_at(radii), rng)
        exact = gradient(z, SPEED, radii).full().ravel()
        assert np.abs(exact).max() > 1.0  # the radii move the criterion
        for i in range(2):
            h = 1e-6
            up, down = list(radii), list(radii)
            up[i] += h
            down[i] -= h
            difference = (
                getattr(numeric(gait_at(up, criterion=criterion), z), criterion)
                - getattr(numeric(gait_at(down, criterion=criterion), z), criterion)
            ) / (2 * h)
            assert difference == pytest.approx(exact[i], rel=1e-5, abs=1e-6 * np.abs(exact).max())


def test_zero_radii_are_the_revolute_knee(graph):
    """At r1 = r2 = 0 the design graph's criteria equal the revolute knee's numeric ones to
    1e-12 for the same gait, and so they do with one radius 0 (a circle rolling on a point
    turns about it: a hinge); 1 mm of both radii changes them far beyond that."""
    function = graph.function()
    problem = gait_at((0.0, 0.0), knee="revolute")
    rng = np.random.default_rng(8)
    for _ in range(3):
        z = random_variables(problem, rng)
        ev = numeric(problem, z)
        out = function(z=z, speed=SPEED, radii=(0.0, 0.0))
        assert float(out["sthenic"]) == pytest.approx(ev.sthenic, rel=1e-12)
        assert float(out["energy"]) == pytest.approx(ev.energy, rel=1e-12)
        for hinge in [(0.1, 0.0), (0.0, 0.1)]:
            out = function(z=z, speed=SPEED, radii=hinge)
            assert float(out["sthenic"]) == pytest.approx(ev.sthenic, rel=1e-12)
        near = function(z=z, speed=SPEED, radii=(1e-3, 1e-3))
        assert abs(float(near["sthenic"]) / ev.sthenic - 1.0) > 1e-6


def test_design_beats_the_table_1_knee():
    """The design optimum from its own starts is certified, within the bounds and at least
    as good as the optimal gait of the Table 1 knee (5 cm radii) at the same speed, which
    is one point of its design space; its gait file's robot carries the radii."""
    design = optimal_design()
    assert design.report.converged and design.certified
    assert design.report.starts_at_best >= 2
    limits = radius_limits(ROBOT)
    assert all(0.0 <= r <= u for r, u in zip(design.radii, limits, strict=True))
    assert (design.robot.r1, design.robot.r2) == design.radii
    assert design.value <= optimal_gait("rolling").value * (1 + 1e-9)
    assert design.value <= optimal_gait("revolute").value


def test_design_graph_with_radii_held_finds_the_gait_optimum_of_those_radii():
    """The design graph with the radii held (the map's solver, one graph for every radius)
    reaches the optimum 'biped optimize' finds for the robot built with those radii; held
    at other radii, it does not."""
    from biped.optimization.optimize import optimize

    problem = DesignProblem(ROBOT, SPEED)
    radii = (0.12, 0.2)
    held = optimize_at(problem, radii, starts=1)
    own = optimize(gait_at(radii), starts=1)
    assert held.certified and own.certified
    assert held.value == pytest.approx(own.value, rel=1e-8)
    assert (held.problem.model.robot.r1, held.problem.model.robot.r2) == radii
    other = optimize_at(problem, (0.05, 0.05), starts=1)
    assert abs(other.value / own.value - 1) > 1e-3


def test_designed_robot_passes_the_inverse_dynamics_crosscheck():
    """The MJCF generated for the designed radii gives MuJoCo's inverse dynamics of the
    designed gait the analytical torques and wrench to rounding; the Table 1 robot's MJCF
    does not (the check tells the radii)."""
    from validate.checks.crosscheck import load_model, mujoco_inverse_dynamics
    from validate.checks.validation import EXACT

    design = optimal_design()
    ev = design.optimum.evaluation
    samples = slice(None, None, 10)
    q, qd, qdd = ev.q[samples], ev.qd[samples], ev.qdd[samples]
    model = biped.Biped(design.robot, "rolling")
    mine = mujoco_inverse_dynamics(load_model(model, exact=True), model, q, qd, qdd)
    assert np.abs(mine.torques - ev.torques[samples]).max() < EXACT
    assert np.abs(mine.wrench - ev.wrench[samples]).max() < EXACT
    table1 = biped.Biped(ROBOT, "rolling")
    other = mujoco_inverse_dynamics(load_model(table1, exact=True), model, q, qd, qdd)
    assert np.abs(other.torques - ev.torques[samples]).max() > 1e3 * EXACT


def test_bad_design_input_is_refused():
    """Radii bounds outside the segments, a bad speed or criterion: a clear error naming the
    value and what is allowed."""
    r1_max, r2_max = radius_limits(ROBOT)
    assert r1_max == ROBOT.shank_com and r2_max == ROBOT.thigh_length - ROBOT.thigh_com
    with pytest.raises(biped.BipedError, match=r"r1 = 0.3 m: allowed 0 to 0.1811 m"):
        DesignProblem(ROBOT, SPEED, upper=(0.3, 0.1))
    with pytest.raises(biped.BipedError, match=r"r2 = -0.01 m"):
        check_radii(ROBOT, (0.05, -0.01))
    with pytest.raises(biped.BipedError, match="upper bound of r2 = 0.0 m: allowed > 0"):
        DesignProblem(ROBOT, SPEED, upper=(0.1, 0.0))
    with pytest.raises(biped.BipedError, match="stance foot leaves the ground"):
        DesignProblem(ROBOT, 5.0)
    with pytest.raises(biped.BipedError, match="criterion = 'power'"):
        DesignProblem(ROBOT, SPEED, "power")
    with pytest.raises(biped.BipedError, match="clearance"):
        DesignProblem(ROBOT, SPEED, safety=Safety(clearance=-1.0))


def test_design_that_does_not_converge_fails_loudly(monkeypatch):
    """With IPOPT cut to 3 iterations no start converges: the design's report carries
    IPOPT's status and the design is not certified."""
    from biped.optimization import design as design_module
    from biped.optimization import solver

    monkeypatch.setitem(solver.IPOPT_OPTIONS, "max_iter", 3)
    design_module._solver.cache_clear()
    try:
        result = optimize_design(DesignProblem(ROBOT, SPEED), starts=1)
        assert result.report.status == "Maximum_Iterations_Exceeded"
        assert not result.report.converged and not result.certified
    finally:
        design_module._solver.cache_clear()


@pytest.fixture(scope="module")
def designed(tmp_path_factory):
    """``biped design --speed 0.3`` (one start each): its exit status, output and file."""
    import contextlib
    import io

    from biped_cli import main

    path = tmp_path_factory.mktemp("design") / "design.json"
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        code = main(["design", "--speed", "0.3", "--starts", "1", "--out", str(path)])
    return code, out.getvalue(), err.getvalue(), path


def test_design_command_writes_the_designed_robot_and_compares(designed):
    """'biped design' exits 0, writes a gait file whose robot holds the optimal radii and
    prints the revolute knee, the Table 1 radii and the optimal radii with the changes
    against the revolute knee, each computed from the printed criteria."""
    from biped.records import gait_file

    code, out, err, path = designed
    assert code == 0, err
    gait = gait_file.read(path)
    radii = gait.design["radii"]
    assert (gait.robot.r1, gait.robot.r2) == (radii["r1"], radii["r2"])
    assert gait.knee == "rolling" and gait.optimizer.status == "converged"
    rows = {line[:24].strip(): line.split() for line in out.splitlines()[1:4]}
    assert set(rows) == {"revolute", "rolling, Table 1 radii", "rolling, optimal radii"}
    revolute = float(rows["revolute"][3])
    for label in ("rolling, Table 1 radii", "rolling, optimal radii"):
        sthenic, change = float(rows[label][-4]), float(rows[label][-2])
        assert change == pytest.approx(100 * (sthenic / revolute - 1), abs=0.01)
    design = float(rows["rolling, optimal radii"][-4])
    assert design == pytest.approx(gait.costs.sthenic, rel=1e-4)
    assert design <= float(rows["rolling, Table 1 radii"][-4]) <= revolute
    assert revolute == pytest.approx(optimal_gait("revolute").evaluation.sthenic, rel=1e-6)
    assert f"r1 = {radii['r1']:.4f} m" in out and "vs Table 1 radii" in out


def test_designed_gait_passes_validation_on_its_own_robot_only(designed):
    """The designed gait walks 20 steps in MuJoCo on the MJCF of its radii and passes every
    check; played on the Table 1 robot, the inverse-dynamics check fails."""
    from biped.records import gait_file
    from validate.checks.checks import check_inverse_dynamics
    from validate.checks.validation import validate
    from validate.scene.model import compile_spec, model_spec
    from validate.walk.samples import GaitSamples

    gait = gait_file.read(designed[3])
    result = validate(gait, steps=20)
    assert result.passed, [check.line() for check in result.checks]
    wrong = biped.Biped(ROBOT, "rolling")
    on_wrong = compile_spec(model_spec(wrong))
    assert not check_inverse_dynamics(on_wrong, wrong, GaitSamples.from_gait(gait)).passed


@pytest.mark.parametrize(
    "argv, needle",
    [
        (["design", "--speed", "0.3", "--max-r1", "0.3"], "--max-r1 0.3 m: allowed > 0.001 m"),
        (["design", "--speed", "0.3", "--max-r2", "0.001"], "--max-r2 0.001 m: allowed > 0.001"),
        (["design", "--speed", "0.3", "--max-r2", "-0.1"], "--max-r2 -0.1 m"),
        (["design", "--speed", "9"], "speed = 9.0 m/s"),
        (["design", "--speed", "0.3", "--clearance", "-1"], "clearance = '-1'"),
        (["design-map", "--r1", "0.5,0.1"], "r1 = 0.5 m: allowed 0 to 0.1811 m"),
        (["design-map", "--r2", "0:0.1:0"], "COUNT = 0"),
        (["design-map", "--r1", "-0.1"], "allowed radii >= 0 m"),
        (["design-map", "--speeds", "0.3,9"], "speed = 9.0 m/s"),
    ],
)
def test_bad_design_options_are_one_line_and_exit_2(tmp_path, capsys, argv, needle):
    """Bad radii bounds, grids or speeds: one line on stderr naming the value, exit 2,
    before any work."""
    from biped_cli import main

    out = ["--out", str(tmp_path / ("d.json" if argv[0] == "design" else "map"))]
    assert main(argv + out) == 2
    lines = capsys.readouterr().err.strip().splitlines()
    assert len(lines) == 1 and needle in lines[0], lines
    assert not (tmp_path / "map" / "design-map.json").exists()


def test_design_command_that_does_not_converge_exits_1(tmp_path, monkeypatch, capsys):
    """With IPOPT cut to 3 iterations 'biped design' exits 1 naming IPOPT's status and
    writes no file."""
    from biped.optimization import design as design_module
    from biped.optimization import solver
    from biped_cli import main

    monkeypatch.setitem(solver.IPOPT_OPTIONS, "max_iter", 3)
    design_module._solver.cache_clear()
    solver._solver.cache_clear()
    try:
        path = tmp_path / "design.json"
        assert main(["design", "--speed", "0.3", "--starts", "1", "--out", str(path)]) == 1
        assert "Maximum_Iterations_Exceeded" in capsys.readouterr().err
        assert not path.exists()
    finally:
        design_module._solver.cache_clear()
        solver._solver.cache_clear()


def test_pipeline_with_design_compares_three_knees_in_one_table(tmp_path, capsys):
    """'biped pipeline --design': the design's gait file (its robot with the optimal radii)
    and validation report are written beside the knees', and one table sets the revolute
    knee (the pipeline's own optimum), the Table 1 radii and the optimal radii side by
    side; the exit status is the verdict of every check."""
    import json

    from biped.records import gait_file
    from biped_cli import main

    out, rrd = tmp_path / "pipeline", tmp_path / "recordings"
    argv = ["pipeline", "--knees", "revolute", "--steps", "2", "--starts", "1", "--no-video"]
    code = main(argv + ["--design", "--out", str(out), "--recordings", str(rrd)])
    printed = capsys.readouterr().out
    table = [line for line in printed.splitlines() if line.startswith("[design] ")]
    labels = [line[9:33].strip() for line in table]
    assert {"revolute", "rolling, Table 1 radii", "rolling, optimal radii"} <= set(labels)
    gait = gait_file.read(out / "design-sthenic-0.300.json")
    radii = gait.design["radii"]
    assert (gait.robot.r1, gait.robot.r2) == (radii["r1"], radii["r2"])
    revolute = gait_file.read(out / "revolute-sthenic-0.300.json")
    compared = {knee["knee"]: knee for knee in gait.design["compared"]}
    assert compared["revolute"]["sthenic"] == revolute.costs.sthenic
    report = json.loads((out / "design-sthenic-0.300.report.json").read_text())
    assert report["inverse_dynamics"]["passed"] and report["impact"]["passed"]
    knee_report = json.loads((out / "revolute-sthenic-0.300.report.json").read_text())
    assert code == (0 if report["passed"] and knee_report["passed"] else 1)


def test_bounds_that_move_the_robots_own_radii_say_so():
    """A robot whose shank's centre of mass is 3 cm from the knee: its r1 is bounded to 3 cm,
    so its own 5 cm are moved there as the reference design, and the problem says so with
    both values and the bound; own radii of 0 move up to the radii's lower bound, 1 mm, above
    the revolute knee that r = 0 is; Table 1's radii move nowhere."""
    from biped.optimization.design import MIN_RADIUS

    problem = DesignProblem(dataclasses.replace(ROBOT, shank_com=0.03), SPEED)
    assert problem.lower == (MIN_RADIUS, MIN_RADIUS) and MIN_RADIUS == 0.001
    assert problem.reference_radii == (0.03, 0.05)
    [note] = problem.moved_reference()
    assert "r1 = 0.05 m lies beyond its upper bound 0.03 m" in note and "r1 = 0.03 m" in note
    hinge = DesignProblem(dataclasses.replace(ROBOT, r2=0.0), SPEED)
    assert hinge.reference_radii == (0.05, MIN_RADIUS)
    [note] = hinge.moved_reference()
    assert "r2 = 0 m lies beyond its lower bound 0.001 m" in note
    assert DesignProblem(ROBOT, SPEED).moved_reference() == []


def test_a_design_against_a_bound_is_said_and_validated(tmp_path, capsys):
    """'biped design --robot R.toml' with shank_com = 0.03 m and r1 = 0.03 m (its own radii
    within the bounds): its optimum lies at the radii's lower bound of 1 mm (said, where r = 0
    would be the revolute knee) and 'biped validate' plays the file it writes."""
    from biped.optimization.design import MIN_RADIUS
    from biped.records import gait_file
    from biped_cli import main

    robot, path = tmp_path / "R.toml", tmp_path / "design.json"
    robot.write_text("shank_com = 0.03\nr1 = 0.03\n")
    argv = ["design", "--robot", str(robot), "--speed", "0.3", "--starts", "1", "--out", str(path)]
    assert main(argv) == 0
    out = capsys.readouterr().out
    assert "lies beyond" not in out
    gait = gait_file.read(path)
    radii = gait.design["radii"]
    assert min(radii.values()) >= MIN_RADIUS and not gait.design["reference_moved"]
    assert any(value == MIN_RADIUS for value in radii.values())
    for name, value in radii.items():
        if value == MIN_RADIUS:
            assert f"note: {name} at its lower bound 0.001 m" in out
    rrd = tmp_path / "design.rrd"
    assert main(["validate", str(path), "--steps", "2", "--rrd", str(rrd)]) == 0


@pytest.mark.parametrize(
    "robot, argv, needles",
    [
        ("shank_com = 0.03\n", ["design"], ["its own r1 = 0.05 m", "bounds 0.001 to 0.03 m"]),
        ("r2 = 0.0\n", ["design-map", "--speeds", "0.3"], ["its own r2 = 0 m", "to 0.2362 m"]),
        ("", ["design", "--max-r1", "0.03"], ["r1 = 0.05 m", "or --max-r1 0.05"]),
        ("shank_com = 0.03\n", ["pipeline", "--design"], ["its own r1 = 0.05 m"]),
    ],
)
def test_a_robot_whose_radii_lie_beyond_the_designs_bounds_is_refused(
    tmp_path, capsys, robot, argv, needles
):
    """A robot whose own radii lie beyond the design's bounds is refused in one line naming
    the radius, its bounds and what is allowed, exit 2: never compared at the bound as if
    those were its radii."""
    from biped_cli import main

    path = tmp_path / "robot.toml"
    path.write_text(robot)
    given = ["--robot", str(path)] if robot else []
    speed = [] if argv[0] == "design-map" else ["--speed", "0.3"]
    out = str(tmp_path / ("d.json" if argv[0] == "design" else "out"))
    assert main([*argv, *given, *speed, "--out", out]) == 2
    lines = capsys.readouterr().err.strip().splitlines()
    assert len(lines) == 1 and all(n in lines[0] for n in needles), lines
    assert "allowed a robot whose radii lie within them" in lines[0]
    assert not list(tmp_path.glob("d.json")) and not (tmp_path / "out").exists()


def test_a_gait_file_given_as_the_robot_is_named(tmp_path, capsys):
    """A gait file (or another of the project's files) given as --robot: one line naming its
    kind, not the first of its fields a robot lacks, exit 2."""
    from biped_cli import main
    from tests.conftest import gait_of, small_optimum

    gait = gait_of(small_optimum("rolling")).write(tmp_path / "g.json")
    for command in (["design"], ["optimize", "--knee", "rolling"]):
        argv = [*command, "--robot", str(gait), "--speed", "0.3", "--out", str(tmp_path / "o")]
        assert main(argv) == 2
        lines = capsys.readouterr().err.strip().splitlines()
        assert len(lines) == 1 and f"--robot {str(gait)!r} is a gait file" in lines[0]
        assert "not a robot file: allowed" in lines[0] and "constraints" not in lines[0]
