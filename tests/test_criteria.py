"""Criteria (30)-(31) and the constraint penalties."""

import numpy as np
import pytest
from scipy.integrate import quad

from biped.criteria import CONSTRAINTS, PENALTY_WEIGHT, evaluate_step
from biped.gait import build_step, evaluate
from biped.optimize import initial_parameters

SPEED = 0.3


def torques_at(model, step, t):
    """Torques at physical time t from the spline, one sample."""
    t_n = t / step.period
    piece = "left" if t_n <= 0.5 else "right"
    angles, rates, accel = evaluate(step, t_n, piece)
    q, qd, qdd = model.stance_state(angles, rates, accel)
    return model.inverse_dynamics(q, qd, qdd)[0], model.joint_angles(qd)


def test_criteria_match_adaptive_quadrature(model):
    """Simpson on the grid equals scipy's adaptive quadrature of ΓᵀΓ and Σ|Γ θ̇|."""
    step = build_step(model, SPEED, initial_parameters(model, SPEED))
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


def test_penalty_counts_only_violations(model):
    """The penalty integrates k (e^(|Ψ|-Ψ) - 1) over time: zero iff every Ψ_i >= 0."""
    step = build_step(model, SPEED, initial_parameters(model, SPEED))
    ev = evaluate_step(model, step, 100)
    psi = ev.constraints
    barrier = PENALTY_WEIGHT * np.nansum(np.expm1(np.abs(psi) - psi), axis=1)
    expected = sum(np.trapezoid(barrier[i], ev.t[i]) for i in (slice(0, 101), slice(101, None)))
    assert ev.penalty == pytest.approx(expected, rel=1e-2)
    violated = ev.violations()
    assert set(violated) <= set(CONSTRAINTS)
    assert (ev.penalty > 0.0) == bool(violated)
    for name, worst in violated.items():
        assert worst == np.nanmin(psi[:, CONSTRAINTS.index(name)]) < 0.0


def test_margins_only_make_the_penalty_larger(model):
    """The optimiser's margins raise the penalty; feasibility is judged without them."""
    step = build_step(model, SPEED, initial_parameters(model, SPEED))
    plain = evaluate_step(model, step, 40)
    strict = evaluate_step(model, step, 40, margins=True)
    assert strict.penalty >= plain.penalty
    assert strict.sthenic == plain.sthenic and strict.energy == plain.energy
