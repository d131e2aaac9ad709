"""Criteria (30)-(31) and the constraint penalties."""

import numpy as np
import pytest
from scipy.integrate import quad, simpson

import biped
from biped.model.criteria import (
    CONSTRAINTS,
    PENALTY_WEIGHT,
    constraints,
    evaluate_step,
    penalty_rate,
    simpson_weights,
)
from biped.model.gait import breakpoints, build_step, evaluate
from biped.optimization.problem import GaitProblem

SPEED = 0.3


def torques_at(model, step, t):
    """Torques at physical time t from the spline, one sample."""
    t_n = t / step.period
    piece = "left" if t_n <= 0.5 else "right"
    angles, rates, accel = evaluate(step, t_n, piece)
    q, qd, qdd = model.stance_state(angles, rates, accel)
    return model.inverse_dynamics(q, qd, qdd)[0], model.joint_angles(qd)


@pytest.mark.parametrize("knots", [1, 3, 5])
@pytest.mark.parametrize("samples", [1, 2, 3, 8, 9, 13, 25, 34, 50, 100])
def test_simpson_weights_are_scipys_rule_and_exact_where_simpson_is(knots, samples):
    """The written-out weights equal scipy's Simpson's rule on each piece (to the rounding
    of its sums), integrate every quadratic exactly (cubics too with an even number of
    intervals), and repeat on every piece."""
    n, length = samples + 1, breakpoints(knots)[1]
    weights = simpson_weights(samples, knots)
    x = np.linspace(0.0, length, n)
    reference = simpson(np.eye(n), x=x, axis=-1)
    assert weights.shape == (n * (knots + 1),)
    np.testing.assert_allclose(weights[:n], reference, rtol=0, atol=1e-14 * length)
    np.testing.assert_array_equal(
        weights.reshape(knots + 1, n), np.tile(weights[:n], (knots + 1, 1))
    )
    degrees = range(4 if samples % 2 == 0 else 3) if n > 2 else range(2)
    for degree in degrees:
        exact = length ** (degree + 1) / (degree + 1)
        assert weights[:n] @ x**degree == pytest.approx(exact, rel=1e-13), degree


def test_simpson_weights_refuse_an_empty_piece():
    with pytest.raises(biped.BipedError, match="samples per half = 0"):
        simpson_weights(0)


def test_criteria_match_adaptive_quadrature(model):
    """Simpson on the grid equals scipy's adaptive quadrature of ΓᵀΓ and Σ|Γ θ̇|."""
    step = build_step(model, SPEED, GaitProblem(model, SPEED).first_parameters())
    ev = evaluate_step(model, step, 100)
    half = step.period / 2
    squared = sum(
        quad(lambda t: (torques_at(model, step, t)[0] ** 2).sum(), a, b, epsabs=1e-9, limit=200)[0]
        for a, b in ((0.0, half), (half, step.period))
    )
    power = sum(
        quad(lambda t: np.abs(np.prod(torques_at(model, step, t), axis=0)).sum(), a, b, limit=200)[
            0
        ]
        for a, b in ((0.0, half), (half, step.period))
    )
    assert ev.sthenic == pytest.approx(squared / step.step_length, rel=1e-5)
    assert ev.energy == pytest.approx(power, rel=1e-4)


def test_each_constraint_flags_its_own_violation():
    """Hand-made samples: a ZMP behind the heel or past the toe, a knee bent backwards, a
    swing foot below the ground each make exactly the matching Ψ_i negative."""
    robot = biped.Robot.paper()
    weight = 700.0

    def psi(zmp=0.0, q1=-0.1, q2=0.1, q3=0.1, q4=-0.1, heel=0.02, toe=0.02, fz=weight):
        q = np.zeros((1, 9))
        q[0, 2:6] = q1, q2, q3, q4
        torques = np.zeros((1, 6))
        torques[0, 0] = zmp * fz  # Γ1 = x_ZMP Fz + h_p Fx with Fx = 0
        wrench = np.array([[0.0, fz, torques[0, 0]]])
        return dict(
            zip(CONSTRAINTS, constraints(robot, q, torques, wrench, [[heel, toe]])[0], strict=True)
        )

    assert all(v > 0 for v in psi().values())
    cases = {
        "zmp_heel": psi(zmp=-0.12),  # heel at -0.0935 m
        "zmp_toe": psi(zmp=0.18),  # toe at 0.1649 m
        "stance_knee": psi(q1=0.2, q2=0.1),
        "swing_knee": psi(q3=-0.2, q4=-0.1),
        "swing_heel": psi(heel=-0.001),
        "swing_toe": psi(toe=-0.001),
        "normal_force": psi(fz=-1.0, zmp=0.0),
    }
    for name, values in cases.items():
        assert [k for k, v in values.items() if v < 0] == [name], name
    assert psi(zmp=-0.12)["zmp_heel"] == pytest.approx(-0.12 + robot.foot_heel)
    assert psi(zmp=0.18)["zmp_toe"] == pytest.approx(robot.foot_length - robot.foot_heel - 0.18)


def test_penalty_rate_is_the_exponential_barrier():
    """k (e^(|Ψ|-Ψ) - 1) is 0 for Ψ >= 0 and k (e^(2|Ψ|) - 1) for Ψ < 0; unchecked ignored."""
    psi = np.array([[0.3, 0.0, -0.01], [-0.5, 2.0, -1.0]])
    checked = np.array([[True, True, True], [True, True, False]])
    expected = [PENALTY_WEIGHT * np.expm1(0.02), PENALTY_WEIGHT * np.expm1(1.0)]
    np.testing.assert_allclose(penalty_rate(psi, checked), expected, rtol=1e-12)


def test_infeasible_first_guess_reports_its_violations(model):
    """The first guess violates constraints: positive penalty, each violation negative."""
    step = build_step(model, SPEED, GaitProblem(model, SPEED).first_parameters())
    ev = evaluate_step(model, step, 100)
    violated = ev.violations()
    assert violated and ev.penalty > 0.0 and not ev.feasible
    for name, worst in violated.items():
        assert worst == np.nanmin(ev.constraints[:, CONSTRAINTS.index(name)]) < 0.0


def test_margins_only_make_the_penalty_larger(model):
    """The optimiser's margins raise the penalty; feasibility is judged without them."""
    step = build_step(model, SPEED, GaitProblem(model, SPEED).first_parameters())
    plain = evaluate_step(model, step, 40)
    strict = evaluate_step(model, step, 40, margins=True)
    assert strict.penalty >= plain.penalty
    assert strict.sthenic == plain.sthenic and strict.energy == plain.energy


@pytest.mark.parametrize("criterion", ["sthenic", "energy", "energy-per-metre", "electrical"])
def test_each_criterion_without_penalty_is_its_definition_and_what_the_polish_minimises(
    criterion,
):
    """C_Γ, C_E per step, C_E / S and E / S (the motors' energy per metre): ``value`` gives
    each, and the SLSQP polish of the paper's method minimises that one (it took the energy
    per step for the energy per metre)."""
    from biped.optimization.penalty import POLISH_SAMPLES_PER_HALF, _Polish

    model = biped.Biped(biped.Robot.paper(), "rolling")
    problem = GaitProblem(model, SPEED, criterion)
    parameters = problem.first_parameters()
    step = build_step(model, SPEED, parameters)
    ev = evaluate_step(model, step, POLISH_SAMPLES_PER_HALF, safety=problem.safety)
    length = step.step_length
    expected = {
        "sthenic": ev.sthenic,
        "energy": ev.energy,
        "energy-per-metre": ev.energy / length,
        "electrical": ev.electrical / length,
    }[criterion]
    assert ev.value(criterion, length) == expected
    assert ev.cost(criterion, length) >= expected  # the penalty is never negative
    polish = _Polish(problem, np.asarray(parameters, float), POLISH_SAMPLES_PER_HALF)
    assert polish._evaluate(np.zeros(len(parameters)))[0] == pytest.approx(expected, rel=1e-12)
