"""The recording of a two-phase walk read back: each foot's ground force, the gait's beside
MuJoCo's, and the feet on the floor, in their own plots; the swing foot carries the robot only
from its touchdown, both feet together its weight through the double support."""

import numpy as np
import pytest
import rerun.chunk

from tests.conftest import two_phase_gait
from tests.test_record import _views, column

FEET = [
    f"/feet/{force}/{role}_{source}"
    for force in ("Fx", "Fz")
    for role in ("stance", "swing")
    for source in ("analytic", "mujoco")
]


@pytest.fixture(scope="module")
def recorded(tmp_path_factory):
    """Four steps of the rolling knee's zero-speed two-phase gait, validated and recorded."""
    from validate.checks.validation import validate
    from validate.outputs.record import record

    folder = tmp_path_factory.mktemp("record")
    result = validate(two_phase_gait("rolling", "zero-speed"), steps=4)
    path = record(folder / "two.rrd", result)
    return result, rerun.chunk.RrdReader(path).stream().to_chunks(), path


def series(chunks, entity):
    """(times [s], values) of a time series."""
    values, times = column(chunks, entity, "Scalars:scalars", timeless=False)
    return times, np.array([row[0] for row in values], dtype=float)


def test_the_recording_holds_both_feet_and_the_supports(recorded):
    """Each foot's Fx and Fz, the gait's and MuJoCo's, and the supports are recorded, with a
    plot each beside the single support's ground reaction and the orbit's multipliers."""
    _, chunks, path = recorded
    paths = {chunk.entity_path for chunk in chunks}
    for entity in FEET + ["/support/analytic", "/support/mujoco", "/ground/Fz/mujoco"]:
        assert entity in paths, entity
    assert {"feet/Fx", "feet/Fz", "support", "ground/Fz", "orbit"} <= set(_views(path))
    assert "spectral_radius" in next(c.figures for c in recorded[0].checks if c.name == "orbit")


def test_the_swing_foot_carries_from_its_touchdown(recorded):
    """In the gait and in MuJoCo's walk the swing foot has no force in single support (its
    swing: a foot in the air) and carries the robot in double support; MuJoCo's supports
    are two from each touchdown to the step's end, the gait's from its landing τ = T."""
    result, chunks, _ = recorded
    sim, samples = result.simulation, result.samples
    t, supports = series(chunks, "/support/mujoco")
    np.testing.assert_allclose(t, sim.time, atol=1e-9)  # the recording's times in ns
    for rows, down in zip(sim.step_slices(), sim.touchdowns, strict=True):
        assert np.all(supports[rows.start : down] == 1.0) and np.all(
            supports[down : rows.stop] == 2
        )
    _, gait_supports = series(chunks, "/support/analytic")
    np.testing.assert_array_equal(gait_supports == 2.0, sim.phase >= samples.landing)
    t, swing = series(chunks, "/feet/Fz/swing_mujoco")
    rows = np.searchsorted(sim.time, t - 1e-7)
    aloft = (sim.phase[rows] > 0.2 * samples.landing) & (sim.phase[rows] < 0.8 * samples.landing)
    assert np.all(swing[aloft] == 0.0)
    double = supports[rows] == 2.0
    assert np.mean(swing[double]) > 0.2 * result.gait.robot.weight
    _, gait_swing = series(chunks, "/feet/Fz/swing_analytic")
    assert np.all(gait_swing[sim.phase < samples.landing] == 0.0)
    assert np.all(gait_swing[sim.phase > samples.landing] > 0.0)


def test_both_feet_hold_the_weight_in_double_support(recorded):
    """Over MuJoCo's double supports the two feet's Fz together average the robot's weight
    within 15 % (the hip's vertical acceleration is small), as the gait's do: the feet's
    forces are MuJoCo's contact on each foot, not one foot counted twice or missed."""
    result, chunks, _ = recorded
    weight, sim = result.gait.robot.weight, result.simulation
    t, stance = series(chunks, "/feet/Fz/stance_mujoco")
    _, swing = series(chunks, "/feet/Fz/swing_mujoco")
    _, supports = series(chunks, "/support/mujoco")
    double = supports[np.searchsorted(sim.time, t - 1e-7)] == 2.0
    total = stance[double] + swing[double]
    assert abs(total.mean() - weight) < 0.15 * weight, (total.mean(), weight)
    _, gait_stance = series(chunks, "/feet/Fz/stance_analytic")
    _, gait_swing = series(chunks, "/feet/Fz/swing_analytic")
    both = (gait_stance + gait_swing)[sim.phase > result.samples.landing]
    assert abs(both.mean() - weight) < 0.15 * weight, (both.mean(), weight)
