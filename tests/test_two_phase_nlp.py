"""The two-phase gait's NLP: its graph is the numeric model, its options are checked."""

import functools
import json

import numpy as np
import pytest

import biped
from biped.errors import BipedError
from biped.model import double_support as ds
from biped.model import two_phase as tp
from biped.model.criteria import Safety, simpson_weights
from biped.model.gait import sample
from biped.model.kinematics import Q5, QP2
from biped.model.robot import FOOT_FRICTION
from biped.optimization import two_phase as tpo
from biped.optimization.problem import GaitProblem
from tests.conftest import (
    edited_gait_file,
    optimal_gait,
    refusal,
    two_phase_result,
    two_phase_solver,
)

SPEED = 0.3  # [m/s]


def solver_of(knee: str, landing: str = "impact") -> tpo.TwoPhaseSolver:
    """The two-phase solver of ``knee`` at 0.3 m/s, a tenth to a fifth of the step in double
    support (built once per session, shared with the two-phase gaits of ``tests.conftest``)."""
    return two_phase_solver(knee, landing)


@pytest.mark.parametrize(
    "knee, landing", [("revolute", "impact"), ("rolling", "impact"), ("rolling", "zero-speed")]
)
def test_graph_is_the_numeric_model_over_both_phases(knee, landing):
    """At the start the solver takes from the single-support optimum, the graph's double
    support (postures, torques, both wrenches for the front foot's wrench of the variables,
    the landing's impulses) and its criterion over both phases equal the numeric model's
    (``biped.model.two_phase``, ``split_with_swing_wrench``), the closure's equalities
    hold and the handover's are the rear foot's wrench at lift-off."""
    solver = solver_of(knee, landing)
    problem = solver.problem
    z = tpo.start_from_single(problem, optimal_gait(knee).variables)
    value, g, torques, stance, swing, q, impulse = (
        np.asarray(x) for x in solver.evaluate(z, SPEED)
    )
    model = problem.single.model
    step = tp.build_two_phase(model, SPEED, tpo.to_parameters(problem, z), landing)
    samples = ds.sample_phase(model, step.double, problem.samples)
    front = z[-3 * (problem.samples + 1) :].reshape(-1, 3)
    expected, rear = ds.split_with_swing_wrench(model, samples.q, samples.qd, samples.qdd, front)
    np.testing.assert_allclose(q.T, samples.q, atol=1e-9)
    np.testing.assert_allclose(torques.T, expected, atol=1e-6)
    np.testing.assert_allclose(stance.T, rear, atol=1e-5)
    np.testing.assert_allclose(swing.T, front, atol=0.0)
    np.testing.assert_allclose(impulse.ravel(), step.impulse, atol=1e-9)
    equalities = g[solver.n_inequalities :].ravel()
    if landing == "zero-speed":  # the last three: the rear foot's wrench at lift-off, scaled
        equalities, handover = equalities[:-3], equalities[-3:]
        np.testing.assert_allclose(handover * tpo._WRENCH_SCALES, rear[-1], atol=1e-6)
    assert np.max(np.abs(equalities)) < 1e-9
    n = problem.single.samples_per_half
    *_, single_torques, _, _ = sample(model, step.single, n)
    single = step.single.period * simpson_weights(n) @ (single_torques**2).sum(1)
    double = step.double.duration * tpo._simpson(problem.samples) @ (expected**2).sum(1)
    assert value.item() == pytest.approx((single + double) / step.step_length, rel=1e-9)


@pytest.mark.parametrize(
    "text, message",
    [
        ("0.3:0.1", "LOW <= HIGH"),
        ("0.6", "< 0.5"),
        ("0:0", "above 0"),
        ("a:b", "allowed LOW:HIGH"),
    ],
)
def test_a_wrong_share_is_refused(text, message):
    """The share LOW:HIGH: 0 <= LOW <= HIGH < 0.5, HIGH > 0; anything else named."""
    with pytest.raises(BipedError, match=message):
        tpo.parse_share(text)


def test_share_is_parsed():
    """One number is both ends; two are the range."""
    assert tpo.parse_share("0.1:0.2") == (0.1, 0.2)
    assert tpo.parse_share("0.15") == (0.15, 0.15)


def test_what_is_not_built_is_refused():
    """The energy criteria, the walkable constraints and richer families are refused by
    name, not solved as something else."""
    model = biped.Biped(biped.Robot.paper(), "rolling")
    for single, word in (
        (GaitProblem(model, SPEED, "energy"), "criterion"),
        (GaitProblem(model, SPEED, safety=Safety(friction=0.6)), "walkable"),
        (GaitProblem(model, SPEED, knots=3), "knots"),
    ):
        with pytest.raises(BipedError, match=word):
            tpo.TwoPhaseProblem(single, (0.1, 0.2))


def rolling_optimum(landing: str = "impact") -> tpo.TwoPhaseOptimum:
    """IPOPT's answer for the rolling knee's problem of ``solver_of`` from its single-support
    optimum (one start, converged and feasible on the numeric model), solved once per session
    (the two-phase gait of ``tests.conftest`` is its file)."""
    result = two_phase_result("rolling", landing)
    assert result.best is not None, result.outcomes
    return result.best


@pytest.mark.parametrize("landing", ["impact", "zero-speed"])
def test_two_phase_optimum_converges_and_holds_on_the_numeric_model(landing):
    """IPOPT converges from the single-support optimum (rolling knee, 0.3 m/s, a tenth to a
    fifth of the step in double support), and on the numeric model the optimum's double
    support holds: both feet pushed, in their friction cones, their ZMPs in their soles (at
    the solver's samples and on the fine grid between them, to its tolerance), the rear foot pushed at the landing, the share
    in its range; MuJoCo agrees with both feet's forces."""
    problem = solver_of("rolling", landing).problem
    optimum = rolling_optimum(landing)
    assert optimum.converged, optimum.status
    assert 0.1 - 1e-8 <= optimum.share <= 0.2 + 1e-8
    model = problem.single.model
    parameters = tpo.to_parameters(problem, optimum.variables)
    step = tp.build_two_phase(model, SPEED, parameters, landing)
    samples = ds.sample_phase(model, step.double, problem.samples)
    front = optimum.variables[-3 * (problem.samples + 1) :].reshape(-1, 3)
    _, rear = ds.split_with_swing_wrench(model, samples.q, samples.qd, samples.qdd, front)
    # the load handed over after a zero-speed landing: the rear foot carries nothing at
    # lift-off, nor the front foot at its landing; elsewhere each foot is pushed, in its cone, its ZMP in its sole
    handed = ds.handover_rows(len(rear), landing == "zero-speed")
    if landing == "zero-speed":
        assert np.max(np.abs(rear[-1])) <= ds.HANDOVER_TOLERANCE
        np.testing.assert_array_equal(front[0], 0.0)
    for foot, wrench in zip(ds.FEET, (rear, front), strict=True):
        loaded = np.ones(len(wrench), dtype=bool)
        loaded[handed[foot]] = False
        margins = ds.foot_margins(model.robot, wrench)[loaded]
        assert np.min(margins[:, :3]) > 0.0  # pushed, inside the friction cone
        assert np.min(margins[:, 3:]) > -1e-6  # ZMP in the sole [m]
    checked = tpo.check(problem, optimum.variables)
    assert checked.feasible, checked.violations_line()
    # ... and between them: both feet's constraints on the file's 101 samples, the front
    # wrench linear in time between its 11 variables.
    assert checked.double_margins.shape == (10 * problem.samples + 1, 2, 5)
    assert np.min(checked.double_margins) > -1e-6
    landing_margins = np.array(tp.landing_margins(step.impulse))  # (rear, front) by kind
    if landing == "impact":  # both feet pushed, inside the floor's cone (the solver keeps 1 %)
        np.testing.assert_array_less(tpo.IMPULSE_MARGIN * (1 - 1e-6), landing_margins[:, 0])
        friction = np.abs(step.impulse[[0, 3]]) / step.impulse[[1, 4]]
        np.testing.assert_array_less(friction, FOOT_FRICTION)
    else:  # no impulse, nothing to constrain
        np.testing.assert_array_equal(landing_margins, 0.0)
    assert checked.value == pytest.approx(optimum.value, rel=1e-3)  # check grid vs solver's
    # A front foot pulled instead of pushed at one sample is named.
    wrong = optimum.variables.copy()
    wrong[tpo.variable_names(problem.samples, landing).index("front_fz_5")] = -10.0
    assert "front normal_force" in tpo.check(problem, wrong).violations()
    # MuJoCo's Newton-Euler, told the front foot's wrench, finds the same torques and rear
    # foot's wrench: both feet's forces of the optimum cross-checked.
    from validate.checks.crosscheck import load_model, mujoco_inverse_dynamics

    torques, _ = ds.split_with_swing_wrench(model, samples.q, samples.qd, samples.qdd, front)
    result = mujoco_inverse_dynamics(
        load_model(model, exact=True), model, samples.q, samples.qd, samples.qdd, "left", front
    )
    np.testing.assert_allclose(result.torques, torques, atol=1e-7)
    np.testing.assert_allclose(result.wrench, rear, atol=1e-7)


def test_optimize_double_support_writes_the_two_phase_gait_file(tmp_path, capsys):
    """``biped optimize --double-support`` prints both optima and writes the two-phase gait
    file: a gait file of both phases that reads back consistent with its parameters, its
    criterion over both phases the one printed, converged, the share in its range, every
    variable with its unit. The zero-speed landing (a 2 s solve; the impact landing's, 24 s,
    is solved and checked in ``test_two_phase_optimum_converges_and_holds_...``)."""
    import json

    from biped.records import gait_file
    from biped_cli import main

    out = tmp_path / "two.json"
    argv = ["optimize", "--knee", "rolling", "--speed", "0.3", "--out", str(out)]
    two = ["--starts", "1", "--double-support", "0.1:0.2", "--landing", "zero-speed"]
    assert main([*argv, *two]) == 0
    printed = capsys.readouterr().out
    assert "two phases (double support 0.1 to 0.2 of the step, zero-speed landing)" in printed
    content = json.loads(out.read_text())
    assert content["format"] == gait_file.FORMAT
    gait = gait_file.read_consistent(out, two_phase=True)
    double = gait.double_support
    assert gait.feasible and double.feasible and double.landing == "zero-speed"
    assert f"C = {double.sthenic:.6g} N²·m·s" in printed
    assert double.sthenic == pytest.approx(gait.optimizer.value, rel=1e-3)
    assert gait.optimizer.status == "converged"
    assert 0.1 - 1e-8 <= double.share <= 0.2 + 1e-8
    units = content["units"]
    variables = {k for k in units if k.startswith("optimizer.variables.")}
    assert variables == {
        f"optimizer.variables.{name}" for name in content["optimizer"]["variables"]
    }
    assert units["optimizer.variables.front_fz_0"] == "N"
    assert units["optimizer.variables.double_support"] == "s"
    assert units["optimizer.variables.lift_rate_x_hip"] == "m/s"
    assert units["optimizer.variables.lift_rate_trunk"] == "rad/s"
    assert units["parameters.landing_x_hip"] == "m"
    assert units["double_support.duration"] == "s"


def test_several_starts_keep_the_best_feasible_optimum():
    """``optimize_two_phase``: the best of three seeded starts is feasible on the numeric
    model, no worse than the first start's (the single-support optimum's) alone, and the
    counts and each start's outcome hold together; the same seed gives the same optimum.
    The zero-speed landing: the starts' bookkeeping is the landing's own, and its solves take
    2 s against the impact landing's 24 s."""
    solver = solver_of("rolling", "zero-speed")
    single = optimal_gait("rolling")
    result = tpo.optimize_two_phase(solver, single.variables, single.value, starts=3, seed=0)
    first = solver.solve(tpo.start_from_single(solver.problem, single.variables), single.value)
    assert result.best is not None and result.checked.feasible
    assert result.best.value <= first.value
    assert 1 <= result.at_best <= result.feasible <= result.converged <= result.starts == 3
    assert len(result.outcomes) == 3  # each start's end, said
    assert sum(o.startswith("Solve_Succeeded") for o in result.outcomes) == result.converged
    again = tpo.optimize_two_phase(solver, single.variables, single.value, starts=3, seed=0)
    np.testing.assert_array_equal(again.best.variables, result.best.variables)


def _sliding(problem, variables, forward: float) -> np.ndarray:
    """``variables`` (impact landing) with the rates before the landing changed, least, so that
    the swing sole touches down ``forward`` [m/s] faster along the floor."""
    model = problem.single.model
    z = np.array(variables, dtype=float)
    step = tp.build_two_phase(model, SPEED, tpo.to_parameters(problem, z), "impact")
    q_end, qd_end = step.single.end
    jacobian = model.point_jacobian(q_end, "swing_ankle")
    angles, rates = q_end[QP2 : Q5 + 1], qd_end[QP2 : Q5 + 1]
    columns = []
    for e in np.eye(5):
        _, qd, _ = model.stance_state(angles, np.concatenate([[0.0], e]))
        columns.append(jacobian @ qd)
    change = np.linalg.lstsq(np.column_stack(columns), [forward, 0.0], rcond=None)[0]
    at = tpo.variable_names(problem.samples, "impact").index("end_rate_q1")
    z[at : at + 5] = rates[1:] + change
    return z


def test_a_sliding_landing_is_rejected():
    """The landing's impulse on each foot pushes it and lies within the floor's friction cone
    (μ = ``FOOT_FRICTION``) in the solver and in the numeric check: the impact optimum's
    landing foot arriving 1 m/s faster along the floor needs more friction than the floor
    has (the check names it), and the single-support optimum's touchdown (the rolling
    knee's slides forward at 1.8 m/s) pulls the rear foot."""
    problem = solver_of("rolling").problem
    single = optimal_gait("rolling")
    optimum = rolling_optimum("impact")
    assert optimum.converged, optimum.status
    assert tpo.check(problem, optimum.variables).feasible
    sliding = _sliding(problem, optimum.variables, 1.0)
    step = tp.build_two_phase(
        problem.single.model, SPEED, tpo.to_parameters(problem, sliding), "impact"
    )
    assert abs(step.impulse[3]) > FOOT_FRICTION * step.impulse[4]  # outside the cone
    found = tpo.check(problem, sliding).violations()
    assert any(name.startswith("front impact_friction") for name in found), found
    assert min(tpo._landing_rows(step.impulse)) < 0.0  # the solver's rows of that landing
    # The single-support optimum's own touchdown, as the previous problem's start.
    z = tpo.start_from_single(problem, single.variables)
    at = tpo.variable_names(problem.samples, "impact").index("end_rate_q1")
    z[at : at + 5] = single.variables[at : at + 5]
    assert "rear normal_impulse" in tpo.check(problem, z).violations()


def test_constraints_held_at_the_samples_only_leave_the_sole_between_them(tmp_path):
    """The feet's constraints held at the 11 solver samples only (``per_interval`` 1, the
    problem before the fine grid) let the rolling knee's impact optimum put the rear foot's
    ZMP beyond its toe between the samples, under the file's own rule (the front wrench
    linear in time): the numeric check names it, the gait file says it is not feasible
    (its worst margin the fine grid's), a file that claims it feasible is refused; the
    problem on the fine grid holds every foot's constraint on all 101 samples."""
    from biped.records import gait_file
    from biped.records.gait_file import Gait
    from biped.records.two_phase_file import optimizer_record

    fine = solver_of("rolling")
    problem = fine.coarse.problem
    optimum = rolling_optimum("impact").first_stage  # the two-stage solve's first
    assert optimum.converged, optimum.status
    model, robot = problem.single.model, problem.single.model.robot
    step = tp.build_two_phase(model, SPEED, tpo.to_parameters(problem, optimum.variables), "impact")
    front = optimum.variables[-3 * (problem.samples + 1) :].reshape(-1, 3)
    between = ds.sample_split(model, step.double, front)
    at_samples = between.margins(robot)[:: ds.FINE_PER_INTERVAL]
    assert np.min(at_samples) > -1e-6  # every foot's constraint holds at the 11 samples
    toe = robot.foot_length - robot.foot_heel
    assert np.max(ds.zmp(between.stance_wrench, robot.ankle_height)) > toe + 0.1  # [m]
    found = tpo.check(problem, optimum.variables).violations()
    assert found.get("rear zmp_toe", 0.0) < -0.1, found
    result = tpo.TwoPhaseResult(optimum, None, 1, 1, 0, 1, optimum.seconds)
    gait = Gait.from_two_phase(
        robot=robot,
        knee="rolling",
        speed=SPEED,
        parameters=tpo.to_parameters(problem, optimum.variables),
        landing="impact",
        front_wrench=front,
        share_range=problem.share,
        optimizer=optimizer_record(problem, result, seed=0),
    )
    assert not gait.feasible and not gait.double_support.feasible
    assert gait.double_support.foot_margins["rear"][4] < -0.1  # zmp_toe [m], fine grid
    path = gait.write(tmp_path / "tips.json")
    assert not gait_file.read_consistent(path, two_phase=True).double_support.feasible
    claimed = edited_gait_file(
        json.loads(path.read_text()),
        tmp_path,
        lambda c: c["double_support"].update(feasible=True),
        name="claimed.json",
    )
    read = functools.partial(gait_file.read_consistent, two_phase=True)
    assert "double_support.feasible" in refusal(read, claimed)
    # The problem on the fine grid: its optimum holds on every one of the 101 samples.
    held = rolling_optimum("impact")
    assert held.converged, held.status
    assert np.min(tpo.check(fine.problem, held.variables).double_margins) > -1e-6
    assert held.value > optimum.value  # holding them between the samples costs torque
