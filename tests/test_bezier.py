"""The Bézier gait family (``biped.model.bezier``): its curves meet the step's end
conditions (flat feet, leg swap, impact map) exactly, a degree's curve is the same motion
in every higher degree (a nested ladder), its rates and accelerations are the
derivatives of its angles, and its solver holds the knees on the check grid."""

import dataclasses
import json

import numpy as np
import pytest

import biped
from biped.model.bezier import DEGREES, MAX_DEGREE, MIN_DEGREE, Bezier, bernstein, elevate
from biped.model.criteria import MARGINS, WALKABLE, Safety, evaluate_step
from biped.model.gait import (
    FREE_SWAP,
    build_step,
    check_embedding,
    embedded,
    parameter_names,
    piece_grid,
    sample,
    spline_basis,
)
from biped.model.gait import evaluate as evaluate_at
from biped.model.kinematics import swap_legs
from biped.optimization.ladder import check_ladder
from biped.optimization.optimize import BELOW_START, optimize
from biped.optimization.problem import (
    CHECK_SAMPLES,
    SOLVER_SAMPLES,
    GaitProblem,
    bounds,
    scales,
    variable_names,
)
from biped.optimization.solver import forget_solvers
from biped.optimization.symbolic import KNEE_BETWEEN_SAMPLES_MARGIN, KNEES, StepGraph
from biped.records.gait_file import Gait
from tests.conftest import assert_graph_is_the_model

SPEED = 0.3


def build_bezier_step(model, speed, p, degree):
    return build_step(model, speed, p, Bezier(degree))


def evaluate(step, t):
    return evaluate_at(step, t, 0)


def embedded_parameters(step, p, degree):
    return np.concatenate([p[:8], embedded(step, Bezier(degree)).ravel(), p[-1:]])


def _model(knee="rolling"):
    return biped.Biped(biped.Robot.paper(), knee=knee)


def _parameters(model, degree, seed=0):
    """A step of ``degree``: the paper's first guess's ends, interior points spread evenly
    between the fixed ones and perturbed by 0.05 rad (seeded)."""
    paper = GaitProblem(model, SPEED).first_parameters()
    p = np.concatenate([paper[:8], np.zeros(6 * (degree - 3)), paper[-1:]])
    ends = build_bezier_step(model, SPEED, np.concatenate([paper[:8], paper[-1:]]), 3)
    line = np.linspace(ends.coefficients[1], ends.coefficients[2], degree - 1)[1:-1]
    noise = 0.05 * np.random.default_rng(seed).standard_normal(line.shape)
    p[8:-1] = (line + noise).ravel()
    return p


def test_the_degrees_are_named_and_others_refused():
    assert DEGREES == tuple(range(MIN_DEGREE, MAX_DEGREE + 1)) and MIN_DEGREE == 3
    assert [len(parameter_names(Bezier(n))) for n in (3, 5, 9)] == [9, 21, 45]
    assert parameter_names(Bezier(5))[8:14] == tuple(
        f"control2_{a}" for a in ("qp2", "q1", "q2", "q3", "q4", "q5")
    )
    for bad in (2, MAX_DEGREE + 1, True, "5", 5.0):
        with pytest.raises(biped.BipedError, match="degree = .*allowed an integer from 3 to"):
            Bezier(bad)
    model = _model()
    with pytest.raises(biped.BipedError, match=r"shape \(20,\): allowed \(21,\)"):
        build_bezier_step(model, SPEED, np.zeros(20), 5)


@pytest.mark.parametrize("knee", biped.KNEES)
@pytest.mark.parametrize("degree", [3, 5, 9])
def test_a_curve_meets_the_steps_end_conditions(knee, degree):
    """At t = 0 and T the angles and rates are the step's states (the stance foot's angle
    0, both feet flat), the end posture is the start's with the legs swapped, and the start
    rates are the impact map of the end rates, the legs swapped: computed here from the end
    state alone."""
    model = _model(knee)
    step = build_bezier_step(model, SPEED, _parameters(model, degree), degree)
    angles, rates, _ = evaluate(step, np.array([0.0, 1.0]))
    (q0, qd0), (q1, qd1) = step.start, step.end
    np.testing.assert_allclose(angles[0], q0[1:7], atol=1e-14)
    np.testing.assert_allclose(rates[0], qd0[1:7], atol=1e-12)
    np.testing.assert_allclose(angles[1], q1[1:7], atol=1e-14)
    np.testing.assert_allclose(rates[1], qd1[1:7], atol=1e-12)
    assert angles[1][0] == 0.0 and rates[1][0] == 0.0  # swing foot flat and at rest
    np.testing.assert_allclose(angles[1], angles[0][FREE_SWAP], atol=1e-14)
    qd_plus, _ = model.impact(q1, qd1)
    _, start = swap_legs(model, q1, qd_plus)
    np.testing.assert_allclose(rates[0], start[1:7], atol=1e-12)
    # the end state is the stance state of those angles and rates (the hip from them)
    q_end, qd_end, _ = model.stance_state(angles[1], rates[1])
    np.testing.assert_allclose(q_end, q1, atol=1e-14)
    np.testing.assert_allclose(qd_end, qd1, atol=1e-12)


def test_a_wrong_end_point_breaks_the_start_rates():
    """The check above fails a curve whose second control point is not q(0) + T q̇(0) / n."""
    model = _model()
    step = build_bezier_step(model, SPEED, _parameters(model, 5), 5)
    control = np.array(step.coefficients)
    control[1] *= 1.0 + 1.0 / 5  # as if the slope were T q̇ / (n − 1)
    rates = (bernstein(5, [0.0])[1] @ control) / step.period
    assert not np.allclose(rates[0], step.start[1][1:7], atol=1e-6)


@pytest.mark.parametrize("degree, higher", [(3, 4), (5, 6), (5, 9), (9, 20)])
def test_a_higher_degree_holds_the_curve(degree, higher):
    """Degree elevation: the curve of ``degree`` given to ``higher`` is the same motion
    (angles, rates, accelerations to 1e-12 of their size on a fine grid) and the same
    inverse dynamics; the nested ladder's rungs are never worse than the one below."""
    model = _model()
    p = _parameters(model, degree)
    step = build_bezier_step(model, SPEED, p, degree)
    rich = build_bezier_step(model, SPEED, embedded_parameters(step, p, higher), higher)
    assert rich.knots == Bezier(higher) and rich.coefficients.shape == (higher + 1, 6)
    t = np.linspace(0.0, 1.0, 641)
    for found, expected in zip(evaluate(rich, t), evaluate(step, t), strict=True):
        np.testing.assert_allclose(found, expected, rtol=0, atol=1e-12 * np.abs(expected).max())
    motion = zip(sample(model, rich, 40)[:6], sample(model, step, 40)[:6], strict=True)
    for found, expected in motion:  # t, q, q̇, q̈, torques, wrench
        np.testing.assert_allclose(found, expected, rtol=0, atol=1e-9 * np.abs(expected).max())


def test_a_wrong_elevation_is_another_curve():
    """The shares of the elevation swapped (P'_i = (1 − i/(n+1)) P_(i−1) + i/(n+1) P_i) give
    another motion: the check above would fail it."""
    model = _model()
    step = build_bezier_step(model, SPEED, _parameters(model, 5), 5)
    control = step.coefficients
    n = control.shape[0] - 1
    share = (np.arange(n + 2) / (n + 1))[:, None]
    padded = np.vstack([np.zeros((1, 6)), control])
    upper = np.vstack([control, np.zeros((1, 6))])
    wrong = (1.0 - share) * padded + share * upper
    t = np.linspace(0.0, 1.0, 33)
    right = bernstein(n + 1, t)[0] @ elevate(control)
    np.testing.assert_allclose(right, bernstein(n, t)[0] @ control, atol=1e-14)
    assert np.abs(bernstein(n + 1, t)[0] @ wrong - right).max() > 1e-3


def test_a_lower_degree_or_a_spline_is_refused():
    """A Bézier curve is held by the Bézier families of no lower degree, and by a spline
    family only as a single cubic; a spline with a knot by no Bézier family."""
    model = _model()
    step = build_bezier_step(model, SPEED, _parameters(model, 7), 7)
    with pytest.raises(biped.BipedError, match="Bézier of degree 5 does not hold the Bézier of"):
        embedded(step, Bezier(5))
    for below, above in ((Bezier(5), 7), (1, Bezier(9)), (3, Bezier(5))):
        with pytest.raises(biped.BipedError, match="does not hold"):
            check_embedding(below, above)
    check_embedding(Bezier(3), 1)  # a single cubic is a spline of every family


def test_a_single_cubic_is_a_spline_of_the_papers_family():
    """Degree 3 given to the paper's spline (its knot's angles and rates, through
    ``at_knots``) and to 3 knots: the same motion."""
    model = _model()
    step = build_bezier_step(model, SPEED, _parameters(model, 3), 3)
    p = _parameters(model, 3)
    spline = build_step(model, SPEED, np.concatenate([p[:8], embedded(step, 3).ravel(), p[-1:]]), 3)
    t = np.linspace(0.0, 0.25, 9)
    for found, expected in zip(evaluate_at(spline, t, 0), evaluate(step, t), strict=True):
        np.testing.assert_allclose(found, expected, rtol=0, atol=1e-12 * np.abs(expected).max())


@pytest.mark.parametrize("degree", [3, 7, 12])
def test_rates_and_accelerations_are_the_angles_derivatives(degree):
    """Central differences (h = 1e-5 s) of the angles and of the rates in physical time
    match the rates and accelerations."""
    model = _model()
    step = build_bezier_step(model, SPEED, _parameters(model, degree, seed=degree), degree)
    h = 1e-5 / step.period  # in normalised time
    t = np.linspace(0.01, 0.99, 23)
    angles, rates, accels = evaluate(step, t)
    above, below = evaluate(step, t + h), evaluate(step, t - h)
    dt = 2e-5
    np.testing.assert_allclose((above[0] - below[0]) / dt, rates, atol=1e-7 * np.abs(rates).max())
    np.testing.assert_allclose((above[1] - below[1]) / dt, accels, atol=1e-6 * np.abs(accels).max())


def test_the_basis_sums_to_one_and_the_samples_are_the_curve():
    """The Bernstein polynomials are a partition of unity (their derivatives sum to 0), and
    ``sample``'s angles are ``evaluate``'s."""
    t = np.linspace(0.0, 1.0, 17)
    for n in (3, 8, MAX_DEGREE):
        values, rates, accels = bernstein(n, t)
        np.testing.assert_allclose(values.sum(axis=1), 1.0, atol=1e-14)
        np.testing.assert_allclose(rates.sum(axis=1), 0.0, atol=1e-9)
        np.testing.assert_allclose(accels.sum(axis=1), 0.0, atol=1e-7)
    model = _model()
    step = build_bezier_step(model, SPEED, _parameters(model, 6), 6)
    time, q, qd, qdd, *_ = sample(model, step, 16)
    angles, rates, accels = evaluate(step, t)
    np.testing.assert_allclose(time, t * step.period, atol=1e-15)
    np.testing.assert_allclose(q[:, 1:7], angles, atol=1e-14)
    np.testing.assert_allclose(qd[:, 1:7], rates, atol=1e-12)


def test_the_family_has_one_piece_and_its_own_samples_and_scales():
    """One piece of as many solver and check intervals as the paper's spline's two, the
    control points scaled and bounded as angles."""
    family = Bezier(7)
    assert SOLVER_SAMPLES[family] == 50 and CHECK_SAMPLES[family] == 200
    assert len(variable_names(family)) == len(scales(family)) == 33
    assert np.array_equal(scales(family)[:8], scales(1)[:8]) and scales(family)[-1] == scales(1)[-1]
    lower, upper = bounds(family)
    assert np.all(upper[8:-1] == np.pi) and np.all(lower[8:-1] == -np.pi)
    assert GaitProblem(_model(), SPEED, knots=family).describe().endswith("Bézier of degree 7")


@pytest.mark.parametrize("knee", biped.KNEES)
def test_the_graph_is_the_numeric_model(knee):
    """The CasADi graph of a Bézier gait gives the numeric model's torques, constraints and
    criteria to 1e-12 at random variables (clearance on: its between-sample rows too)."""
    safety = Safety(clearance=0.02)
    family = Bezier(6)
    problem = GaitProblem(_model(knee), SPEED, safety=safety, knots=family)
    assert_graph_is_the_model(problem, safety, family, seed=6)


def test_the_first_guess_is_the_papers_fitted():
    """The first guess's curves have the paper's first guess's ends, and fit its angles
    better as the degree grows (least squares over the step)."""
    model = _model()
    paper = GaitProblem(model, SPEED)
    reference = build_step(model, SPEED, paper.first_parameters())
    t = np.linspace(0.0, 1.0, 101)
    expected = np.concatenate(
        [evaluate_at(reference, t[:51], 0)[0], evaluate_at(reference, t[50:], 1)[0]]
    )
    errors = []
    for degree in (4, 6, 10):
        problem = GaitProblem(model, SPEED, knots=Bezier(degree))
        step = build_step(model, SPEED, problem.first_parameters(), Bezier(degree))
        np.testing.assert_allclose(step.start[1], reference.start[1], atol=1e-12)
        found = evaluate(step, np.concatenate([t[:51], t[50:]]))[0]
        errors.append(np.abs(found - expected).max())
    assert errors[0] >= errors[1] >= errors[2]


def test_an_optimum_is_certified_and_a_higher_degree_never_worse(tmp_path):
    """At 0.3 m/s the sthenic optimum of degree 7 is certified; degree 9 started from it
    (its curves raised, the same motion) is certified and no worse; its gait file reads
    back the family, and a file naming no family is refused."""
    model = _model("revolute")
    low = optimize(GaitProblem(model, SPEED, knots=Bezier(7)))
    high = optimize(GaitProblem(model, SPEED, knots=Bezier(9)), below=low)
    assert low.certified and high.certified
    assert BELOW_START in [s.kind for s in high.report.history]
    assert high.value <= low.value * (1 + 1e-9)
    path = Gait.from_optimum(high, model.robot).write(tmp_path / "gait.json")
    content = json.loads(path.read_text())
    assert content["knots"] == {"bezier": 9} and content["units"]["knots.bezier"] == "1"
    gait = Gait.read(path)
    assert gait.knots == Bezier(9) and gait.costs.sthenic == pytest.approx(high.value, rel=1e-12)
    from validate.walk.samples import GaitSamples

    samples = GaitSamples.from_gait(gait)  # one curve: one piece, each time once
    ((rows, t0, t1),) = samples.pieces()
    assert (t0, t1) == (0.0, pytest.approx(high.step.period, rel=1e-12))
    assert rows == slice(0, len(samples.t))
    spline = dataclasses.replace(samples, one_piece=False)  # a spline's samples need a knot
    with pytest.raises(biped.BipedError, match="has no knot"):
        spline.pieces()
    content["knots"] = {"bezier": 2}
    (tmp_path / "bad.json").write_text(json.dumps(content))
    with pytest.raises(biped.BipedError, match="degree = 2: allowed an integer from 3"):
        Gait.read(tmp_path / "bad.json")


def test_a_ladder_of_degrees_is_nested_or_refused():
    """Increasing degrees make a ladder; a repeated degree, or splines and Bézier curves
    mixed, do not."""
    ladder = (Bezier(3), Bezier(5), Bezier(9))
    assert check_ladder(ladder) == ladder
    for bad, why in (
        ([Bezier(5), Bezier(5)], "allowed increasing knots or degrees"),
        ([1, Bezier(5)], "does not hold the spline of 1"),
        ([Bezier(5), 3], "does not hold the Bézier of degree 5"),
    ):
        with pytest.raises(biped.BipedError, match=why):
            check_ladder(bad)


def _knee_rows(graph, values) -> dict:
    """The graph's constraint rows of each knee (``values``: the constraints' numbers), in
    order: first at the solver's samples, then at the check grid's between them."""
    names = np.array(graph.constraint_names)
    return {name: values[names == name] for name in KNEES}


def _between(family, samples_per_half) -> np.ndarray:
    """Which of the check grid's samples lie strictly inside the step and between the
    solver's."""
    t_check, _ = spline_basis(CHECK_SAMPLES[family], family)
    t_solver = np.concatenate(piece_grid(samples_per_half, family))
    apart = np.min(np.abs(t_check[:, None] - t_solver[None, :]), axis=1) > 1e-12
    return apart & (t_check > 0.0) & (t_check < 1.0)


@pytest.mark.parametrize("knee", biped.KNEES)
def test_the_knees_are_held_between_the_solvers_samples(knee):
    """A Bézier family's graph imposes the knees' Ψ4 (less the least stance bend) and Ψ5 at
    every sample of the check grid between its 51 own, each row the numeric check's value
    less ``KNEE_BETWEEN_SAMPLES_MARGIN`` (to 1e-12 at random variables); a spline family's
    graph imposes them at its own samples alone (its constraints unchanged)."""
    safety = Safety(knee_bend=0.01)
    family = Bezier(8)
    problem = GaitProblem(_model(knee), SPEED, safety=safety, knots=family)
    graph = StepGraph(problem.model, problem.samples_per_half, safety, knots=family)
    rng = np.random.default_rng(8)
    z = problem.first_guess() + 0.3 * scales(family) * rng.standard_normal(len(scales(family)))
    rows = _knee_rows(graph, graph.function()(z=z, speed=SPEED)["constraints"].full().ravel())
    step = build_step(problem.model, SPEED, problem.to_parameters(z), family)
    check = evaluate_step(problem.model, step, CHECK_SAMPLES[family], safety=safety)
    between = _between(family, problem.samples_per_half)
    assert between.sum() == 150
    for column, name in enumerate(KNEES, start=3):
        expected = check.constraints[between, column] - KNEE_BETWEEN_SAMPLES_MARGIN
        assert len(rows[name]) == 51 + 150
        np.testing.assert_allclose(rows[name][51:], expected, rtol=1e-12, atol=1e-12)
    for knots in (1, 3, 15):
        spline = StepGraph(problem.model, SOLVER_SAMPLES[knots], safety, knots=knots)
        samples = (knots + 1) * (SOLVER_SAMPLES[knots] + 1)
        counts = [spline.constraint_names.count(name) for name in KNEES]
        assert counts == [samples, samples], knots


# The atlas's cell of its best walking pay-off (walkable constraints, 0.2 m/s, 2 cm of
# clearance) at degree 11, where the rolling knee's optimum on the solver's samples alone
# dipped 1.05e-5 rad below the swing knee's stop between two of them.
DIPPED = dict(speed=0.2, clearance=0.02, degree=11)
# [rad] IPOPT's constraint tolerance on the knees (scale 1 rad).
SOLVER_TOLERANCE = 1e-9


def _dipped_optimum():
    safety = dataclasses.replace(WALKABLE, clearance=DIPPED["clearance"])
    family = Bezier(DIPPED["degree"])
    problem = GaitProblem(_model("rolling"), DIPPED["speed"], safety=safety, knots=family)
    return optimize(problem, starts=1)


def test_a_bezier_optimum_holds_its_knees_on_the_check_grid(monkeypatch):
    """The rolling knee's degree 11 optimum at 0.2 m/s with 2 cm (walkable) is certified: on
    the check grid its knees' Ψ4, Ψ5 keep the between-samples margin to the solver's
    tolerance, and the swing knee leans on it (its least value between the solver's
    samples, 1e-3 rad at them). On the solver's samples alone (the rows between them taken
    away) the same problem's optimum is infeasible there: Ψ5 < 0 between two samples."""
    held = _dipped_optimum()
    assert held.certified, held.evaluation.violations_line()
    psi = held.evaluation.constraints
    between = _between(held.problem.knots, held.problem.samples_per_half)
    knees = psi[:, 3:5]
    assert np.nanmin(knees) >= KNEE_BETWEEN_SAMPLES_MARGIN - SOLVER_TOLERANCE
    swing = psi[:, 4]
    assert np.nanmin(swing[between]) == pytest.approx(KNEE_BETWEEN_SAMPLES_MARGIN, abs=1e-8)
    assert np.nanmin(swing[~between]) >= MARGINS[4] - SOLVER_TOLERANCE
    monkeypatch.setattr(StepGraph, "_knees_between_samples", lambda self: [])
    forget_solvers()
    try:
        coarse = _dipped_optimum()
    finally:
        monkeypatch.undo()
        forget_solvers()
    assert coarse.report.converged and not coarse.feasible
    assert set(coarse.evaluation.violations()) == {"swing_knee"}
    worst = int(np.nanargmin(coarse.evaluation.constraints[:, 4]))
    assert between[worst]
