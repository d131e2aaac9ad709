"""One step of two phases: continuity at the landing and at lift-off, the landings."""

import numpy as np
import pytest

from biped.errors import BipedError
from biped.model import double_support as ds
from biped.model import two_phase as tp
from biped.model.gait import evaluate
from biped.model.kinematics import swap_legs

SPEED = 0.3  # [m/s]
# A rough two-phase step (not an optimum): 0.7 s of single support, 0.3 s of double support,
# the hip 0.84 m above the ground at lift-off and at landing [m, rad, m/s, rad/s, rad/s², s].
GUESS = {
    "x_hip": -0.02,
    "z_hip": 0.84,
    "trunk": 0.02,
    "lift_rate_x_hip": 0.3,
    "lift_rate_z_hip": 0.02,
    "lift_rate_trunk": -0.05,
    "landing_x_hip": 0.16,
    "landing_z_hip": 0.84,
    "landing_trunk": 0.02,
    "end_rate_q1": 0.5,
    "end_rate_q2": 0.6,
    "end_rate_q3": 0.4,
    "end_rate_q4": 0.2,
    "landing_rate_x_hip": 0.3,
    "landing_rate_z_hip": -0.01,
    "landing_rate_trunk": 0.05,
    "start_accel_q3": 2.0,
    "end_accel_q4": -3.0,
    "period": 0.7,
    "double_support": 0.3,
}


def guess_parameters(landing: str) -> np.ndarray:
    """``GUESS`` in the order of ``parameter_names(landing)``, zero where not given."""
    return np.array([GUESS.get(name, 0.0) for name in tp.parameter_names(landing)])


def guess_step(model, landing: str) -> tp.TwoPhaseStep:
    """The two-phase step of ``GUESS`` at 0.3 m/s."""
    return tp.build_two_phase(model, SPEED, guess_parameters(landing), landing)


def chain_at(model, phase, t):
    """q, q̇ (9,) of the double support ``phase`` at time t [s], from its cubics."""
    q, qd, _ = ds.chain_state(model, phase.step_length, *ds.phase_coordinates(phase, t))
    return q, qd


@pytest.mark.parametrize("landing", tp.LANDINGS)
def test_step_length_is_the_hips_advance_over_both_phases(model, landing):
    """S = V (T + T_ds): the rear ankle at 0, the landing ankle at S."""
    step = guess_step(model, landing)
    assert step.step_length == pytest.approx(SPEED * 1.0, rel=1e-15)
    assert step.duration == pytest.approx(1.0, rel=1e-15)
    np.testing.assert_allclose(
        model.point(step.single.end[0], "swing_ankle"), [step.step_length, 0.0663], atol=1e-12
    )


@pytest.mark.parametrize("landing", tp.LANDINGS)
def test_double_support_starts_where_the_landing_leaves(model, landing):
    """At the landing the single support's spline ends at the landing posture and rates, and
    the double support's cubics start at the state after the landing (position and velocity,
    1e-12)."""
    step = guess_step(model, landing)
    angles, rates, _ = evaluate(step.single, 1.0, "right")
    q_end, qd_end = step.single.end
    np.testing.assert_allclose(angles, q_end[1:7], atol=1e-12)
    np.testing.assert_allclose(rates, qd_end[1:7], atol=1e-12)
    q, qd = chain_at(model, step.double, 0.0)
    np.testing.assert_allclose(q, q_end, atol=1e-12)
    np.testing.assert_allclose(qd, step.double.start[1], atol=1e-12)


@pytest.mark.parametrize("landing", tp.LANDINGS)
def test_single_support_starts_where_double_support_ends(model, landing):
    """At lift-off the double support's cubics end at the lift-off state, and after the leg
    swap the single support's spline starts there with the same rates (no jump: the rear foot
    leaves the ground at rest), its stance chain putting the hip at the same place."""
    step = guess_step(model, landing)
    q, qd = chain_at(model, step.double, step.double.duration)
    np.testing.assert_allclose(q, step.double.end[0], atol=1e-12)
    np.testing.assert_allclose(qd, step.double.end[1], atol=1e-12)
    angles, rates, _ = evaluate(step.single, 0.0, "left")
    q_start, qd_start, _ = model.stance_state(angles, rates)
    swapped_q, swapped_qd = swap_legs(model, q, qd)
    np.testing.assert_allclose(q_start, swapped_q, atol=1e-12)
    np.testing.assert_allclose(qd_start, swapped_qd, atol=1e-12)
    # The swing foot (the old rear foot) is at rest as the single support starts.
    rows = model.contact_jacobian(q_start, "swing")
    np.testing.assert_allclose(rows @ qd_start, 0.0, atol=1e-12)


def test_impact_landing_stops_both_feet_and_loses_the_energy_of_the_jump(model):
    """With the impact landing both feet are at rest after it, and the kinetic energy lost is
    that of the velocity jump, ½ Δq̇ᵀ D Δq̇ (Carnot's theorem for a plastic impact)."""
    step = guess_step(model, "impact")
    q_end, qd_end = step.single.end
    qd_after = step.double.start[1]
    np.testing.assert_allclose(ds.contact_rows(model, q_end) @ qd_after, 0.0, atol=1e-12)
    loss = model.kinetic_energy(q_end, qd_end) - model.kinetic_energy(q_end, qd_after)
    jump = qd_end - qd_after
    assert loss == pytest.approx(0.5 * jump @ model.mass_matrix(q_end) @ jump, rel=1e-9)
    assert loss > 1e-3


def test_zero_speed_landing_has_no_jump(model):
    """With the zero-speed landing the swing foot arrives at rest: the velocities before and
    after are the same and the impulse is zero."""
    step = guess_step(model, "zero-speed")
    q_end, qd_end = step.single.end
    np.testing.assert_array_equal(step.double.start[1], qd_end)
    np.testing.assert_allclose(model.contact_jacobian(q_end, "swing") @ qd_end, 0.0, atol=1e-12)
    assert not np.any(step.impulse)


def test_bad_parameters_are_refused(model):
    """A wrong shape, a non-positive duration and an unknown landing are refused by name."""
    p = guess_parameters("impact")
    with pytest.raises(BipedError, match="allowed \\(28,\\)"):
        tp.build_two_phase(model, SPEED, p[:-1])
    bad = p.copy()
    bad[-1] = 0.0
    with pytest.raises(BipedError, match="double_support = 0 s"):
        tp.build_two_phase(model, SPEED, bad)
    with pytest.raises(BipedError, match="landing = 'soft'"):
        tp.build_two_phase(model, SPEED, p, "soft")
