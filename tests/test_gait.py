"""Gait parametrisation: the conditions of §3.2 hold exactly, through the impact and swap."""

import numpy as np
import pytest

import biped
from biped.model.gait import PARAMETERS, build_step, evaluate, sample
from biped.model.kinematics import QP2, XH, ZH
from biped.optimization.problem import GaitProblem

SPEED = 0.3


def perturbed_parameters(model, seed):
    """The first guess with seeded perturbations of every parameter."""
    rng = np.random.default_rng(seed)
    p = GaitProblem(model, SPEED).first_parameters()
    scale = np.array([0.02, 0.01, 0.05] + [0.3] * 5 + [3.0] * 12 + [0.1])
    return p + scale * rng.uniform(-1, 1, len(p))


@pytest.fixture(params=[0, 1, 2])
def step(model, request):
    return build_step(model, SPEED, perturbed_parameters(model, request.param))


def test_there_are_21_parameters():
    """The paper's parameter vector has 21 entries."""
    assert len(PARAMETERS) == 21


def test_parameters_are_reproduced(model, step):
    """Start hip, trunk, end rates, start and end accelerations and T come out as given."""
    seed = [
        s
        for s in range(3)
        if np.allclose(build_step(model, SPEED, perturbed_parameters(model, s)).a, step.a)
    ][0]
    p = perturbed_parameters(model, seed)
    q0, _ = step.start
    assert q0[XH] == pytest.approx(p[0], abs=1e-12)
    assert q0[ZH] == pytest.approx(p[1], abs=1e-12)
    assert q0[6] == pytest.approx(p[2], abs=1e-12)
    _, rates_end, _ = evaluate(step, 1.0, "right")
    np.testing.assert_allclose(rates_end[1:], p[3:8], atol=1e-12)
    _, _, acc0 = evaluate(step, 0.0, "left")
    _, _, acc1 = evaluate(step, 1.0, "right")
    np.testing.assert_allclose(acc0, p[8:14], atol=1e-10)
    np.testing.assert_allclose(acc1, p[14:20], atol=1e-10)
    assert step.period == p[20] and step.step_length == pytest.approx(SPEED * p[20])


def test_swing_foot_flat_on_the_ground_at_both_ends(model, step):
    """qp2 = 0 at 0 and T, q̇p2(T) = 0; heel and toe at z = 0; ankles one step apart."""
    t, q, qd, *_ = sample(model, step, 20)
    for i in (0, -1):
        assert q[i, QP2] == pytest.approx(0.0, abs=1e-12)
        np.testing.assert_allclose(model.point(q[i], "swing_heel")[1], 0.0, atol=1e-12)
        np.testing.assert_allclose(model.point(q[i], "swing_toe")[1], 0.0, atol=1e-12)
    assert qd[-1, QP2] == pytest.approx(0.0, abs=1e-12)
    assert model.point(q[0], "swing_ankle")[0] == pytest.approx(-step.step_length, abs=1e-12)
    assert model.point(q[-1], "swing_ankle")[0] == pytest.approx(step.step_length, abs=1e-12)
    assert q[-1, XH] - q[0, XH] == pytest.approx(step.step_length, abs=1e-12)
    assert t[0] == 0.0 and t[-1] == pytest.approx(step.period)


def test_end_posture_is_the_start_posture_with_legs_swapped(model, step):
    """Thighs and shanks 2T-periodic, trunk and feet T-periodic."""
    _, q, *_ = sample(model, step, 20)
    start, end = q[0], q[-1]
    swapped = biped.swap_legs(model, end)
    np.testing.assert_allclose(swapped, start, atol=1e-12)
    assert end[3] == pytest.approx(start[4]) and end[4] == pytest.approx(start[3])  # thighs
    assert end[2] == pytest.approx(start[5]) and end[5] == pytest.approx(start[2])  # shanks


def test_spline_is_c1_at_the_knot(step):
    """Values and rates of both pieces agree at t_n = 0.5; accelerations may jump."""
    left = evaluate(step, 0.5, "left")
    right = evaluate(step, 0.5, "right")
    np.testing.assert_allclose(left[0], right[0], atol=1e-12)
    np.testing.assert_allclose(left[1], right[1], atol=1e-11)


def test_start_velocities_are_the_impact_of_the_end_velocities(model, step):
    """q̇(0⁺) = swap(impact(q̇(T⁻))): the gait is periodic through the impact."""
    _, q, qd, *_ = sample(model, step, 20)
    qd_plus, impulse = model.impact(q[-1], qd[-1])
    _, qd_next = biped.swap_legs(model, q[-1], qd_plus)
    np.testing.assert_allclose(qd[0], qd_next, atol=1e-12)
    np.testing.assert_allclose(impulse, step.impulse, atol=1e-12)
    # ... and the new stance foot is at rest.
    np.testing.assert_allclose(model.contact_jacobian(q[0]) @ qd[0], 0.0, atol=1e-12)


def test_out_of_reach_hip_is_a_graded_error(model):
    """A hip out of the legs' reach raises StepBuildError with how far it is."""
    p = GaitProblem(model, SPEED).first_parameters()
    p[1] = 1.2
    with pytest.raises(biped.model.gait.StepBuildError) as error:
        build_step(model, SPEED, p)
    p[1] = 1.4
    with pytest.raises(biped.model.gait.StepBuildError) as further:
        build_step(model, SPEED, p)
    assert further.value.excess > error.value.excess > 0.0
