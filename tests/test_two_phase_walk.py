"""MuJoCo's walk of a two-phase gait: the controller follows the single support, then the
double support with both feet on the floor, and each step ends at the rear foot's lift-off,
legs swapped; the checks read the double support as support, not as a scuff; a walk of a
gait of single support is the same walk as before."""

import dataclasses

import numpy as np
import pytest

from biped import Biped
from biped.errors import BipedError
from tests.conftest import gait_of, optimal_gait, two_phase_gait
from validate.checks.checks import MAX_SLIP, walk_causes, walk_figures
from validate.scene.mapping import other
from validate.scene.model import model_spec
from validate.walk import contact
from validate.walk.simulate import TOUCH_THRESHOLD, Walker, WalkSettings, phase_table

STEPS = 6
# A step's touchdown against the gait's T, as a share of it: the controller follows the
# hip's advance, not the clock, and the walk's speed varies by a few per cent from step to
# step (measured over the first six steps: touchdowns at 0.982-1.013 T).
EVENT_TOLERANCE = 0.05
# The median step against the period T + T_ds: the walk's timing (1.008 measured; the double
# support halved or doubled in the samples walks 1.061 and 0.922 of it).
PERIOD_TOLERANCE = 0.03
# Each step against the period: the step durations alternate, long and short, a mode of the
# walk's orbit that is not damped (docs/gaits.md, "The orbit of a two-phase walk"), so a
# step strays further than the median (0.987-1.076 over the first six steps). A step beyond
# it is a walk that has lost the gait's timing.
STEP_TOLERANCE = 0.10


@pytest.fixture(scope="module")
def gait():
    """The rolling knee's zero-speed landing at 0.3 m/s (the double support 0.1-0.2 of the
    step): its landing is held by the floor and its replay follows the file."""
    return two_phase_gait("rolling", "zero-speed")


@pytest.fixture(scope="module")
def walked(gait):
    walker = Walker(gait)
    return walker, walker.walk(STEPS)


def durations(sim) -> np.ndarray:
    """(steps,) each step's duration [s], from its start to its event."""
    return np.diff(sim.time[sim.step_starts].tolist() + [sim.time[-1]])


def test_two_phase_walk_runs_both_phases(gait, walked):
    """Every step lifts the rear foot, lands the front one at T ± 5 %, goes on through the
    double support with both feet carrying the robot (each more than a fifth of the weight
    on average) and ends at the rear foot's lift-off, the front foot on the floor; the legs
    then swap. The steps last the period T + T_ds: their median within 3 %, each within
    10 % (the undamped alternation of long and short steps)."""
    walker, sim = walked
    samples, weight = walker.samples, gait.robot.weight
    assert sim.double_support and all(sim.landed) and len(sim.stances) == STEPS
    assert sim.stances == ["left", "right"] * (STEPS // 2)
    steps = zip(sim.step_slices(), sim.stances, sim.touchdowns, strict=True)
    for rows, stance, down in steps:
        assert down is not None and rows.start < down < rows.stop
        landing = (sim.time[down] - sim.time[rows.start]) / samples.landing
        assert landing == pytest.approx(1.0, abs=EVENT_TOLERANCE)
        rear, front = (
            sim.touch(stance)[down : rows.stop],
            sim.touch(other(stance))[down : rows.stop],
        )
        assert rear.mean() > 0.2 * weight and front.mean() > 0.2 * weight
        assert front[-1] > TOUCH_THRESHOLD  # the step ends with the front foot down
    period = durations(sim) / samples.period
    np.testing.assert_allclose(period, 1.0, atol=STEP_TOLERANCE)
    assert np.median(period) == pytest.approx(1.0, abs=PERIOD_TOLERANCE)


def test_the_double_support_is_support_not_a_scuff(gait, walked):
    """The trailing foot on the floor in double support is no scuff, and the slip and tilt
    are each supporting foot's: the front foot's from its touchdown, the stance foot's from
    its touchdown in the step before to its lift-off. Its verdict is its slip's: "slipped"
    its only cause when a supporting foot slides 1 mm or more (the zero-speed optima slide
    0.8-1.05 mm with the load handed over: docs/gaits.md), none otherwise."""
    walker, sim = walked
    figures = walk_figures(walker.biped, walker.samples, sim, float("nan"))
    assert figures["scuff_steps"] == 0 and not figures["fell"]
    settle = int(contact.SETTLE * walker.period / sim.model.opt.timestep)
    for j, spans in enumerate(sim.supports(settle)):
        (stance, rows), (front, landed) = spans
        assert front == other(stance) and landed.start == sim.touchdowns[j] + settle
        if j:
            assert rows.start == min(sim.touchdowns[j - 1] + settle, sim.step_starts[j])
    slipped = figures["max_slip"] >= MAX_SLIP
    assert walk_causes(figures, STEPS) == ["slipped"] * slipped


def test_a_walk_of_single_support_has_no_double_support():
    """A gait of single support walks as before: its steps end at touchdown, its supports
    are the stance foot's after the landing settles, its slip that foot's travel there."""
    walker = Walker(gait_of(optimal_gait("rolling")))
    sim = walker.walk(3)
    assert not sim.double_support and sim.touchdowns == [] and all(sim.landed)
    settle = int(contact.SETTLE * walker.period / sim.model.opt.timestep)
    expected = []
    steps = zip(sim.step_slices(), sim.stances, sim.supports(settle), strict=True)
    for rows, stance, spans in steps:
        assert spans == [(stance, slice(rows.start + settle, rows.stop))]
        middle = 0.5 * (sim.heel(stance)[rows, 0] + sim.toe(stance)[rows, 0])
        expected.append(np.ptp(middle[settle:]))
    np.testing.assert_array_equal(sim.stance_foot_slip(settle), expected)
    assert walker.samples.landing_time == walker.period


def test_wrong_knee_model_is_refused(gait):
    """The rolling knee's two-phase gait on the revolute knee's model: no walk (the model
    has no rolling knee's joints)."""
    with pytest.raises(BipedError, match="does not compile"):
        Walker(gait, model_spec(Biped(gait.robot, "revolute")))


@pytest.mark.parametrize("stretch", [0.5, 2.0])
def test_double_support_of_another_duration_misses_the_period(gait, stretch):
    """The double support's duration halved or doubled in the samples (the same torques),
    walked on the file's references: the robot's steps, driven by its own hip, do not last
    the samples' period (median 1.061 and 0.922 of it measured, against 1.008): the median
    step tells the wrong timing from the walk's alternation of long and short steps."""
    walker = Walker(gait)
    samples = walker.samples
    t = samples.t.copy()
    later = t > samples.landing
    t[later] = samples.landing + stretch * (t[later] - samples.landing)
    walker.samples = dataclasses.replace(samples, t=t, period=float(t[-1]))
    walker.table = phase_table(walker.samples, walker.layout, walker.biped.radii)
    sim = walker.walk(STEPS, WalkSettings(close_chain=False))
    period = durations(sim) / walker.period
    assert abs(np.median(period) - 1.0) > PERIOD_TOLERANCE
