"""The orbit of a two-phase walk: its section in the single support after the rear foot's
lift-off, crossed once per step with the swing foot in the air, where the stance foot is at
rest (not at 0.1 T: there it still rocks from the double support, and the map of the 12
coordinates is not the walk's); the fixed point and its residual as stated; a section in the
double support refused."""

import numpy as np
import pytest

from biped.errors import BipedError
from tests.conftest import two_phase_gait
from validate.checks import orbit as o
from validate.scene.mapping import other
from validate.walk.simulate import TOUCH_THRESHOLD, Walker


@pytest.fixture(scope="module")
def walker():
    return Walker(two_phase_gait("rolling", "zero-speed"))


@pytest.fixture(scope="module")
def found(walker):
    return o.orbit(walker)


def test_the_section_is_crossed_once_per_step_after_the_lift_off(walker):
    """Each step of the walk (from the rear foot's lift-off to the next) crosses the section
    once, before its touchdown, with the swing foot off the floor, at ``LANDING`` of the
    single support's T in the gait (not of the whole step T + T_ds)."""
    samples = walker.samples
    assert o.section_time(walker) == pytest.approx(o.LANDING * samples.landing)
    assert o.section_time(walker) < o.LANDING * samples.period  # the single support's T
    advance = o.section_advance(walker)
    sim = walker.walk(8, o.NOMINAL)
    assert all(sim.landed)
    for k, rows in enumerate(sim.step_slices()):
        ahead = sim.hip_x()[rows] - sim.ankle_x(sim.stances[k])[rows] - advance
        crossings = np.flatnonzero((ahead[:-1] < 0.0) & (ahead[1:] >= 0.0))
        assert len(crossings) == 1, f"step {k + 1} crosses the section {len(crossings)} times"
        row = rows.start + int(crossings[0]) + 1
        assert row == o.crossing(sim, advance, k)
        assert rows.start < row < sim.touchdowns[k], f"step {k + 1}: not before its touchdown"
        swing = other(sim.stances[k])
        assert sim.touch(swing)[row - 1 : row + 1].max() <= TOUCH_THRESHOLD
        o.swing_aloft(sim, advance, k)  # says nothing


def test_the_fixed_point_is_the_maps_to_its_stated_residual(found):
    """The orbit is found (a verdict of ρ and its spread, the walk's period within 5 %), and
    the map walked again from the fixed point x* returns F̄(x*) - x* as the check states it:
    the residual is the map's, reproduced bit for bit, and smaller than the first
    chord-Newton step's, from the walk's mean state."""
    assert found.failure is None and np.isfinite(found.multipliers.spread)
    assert abs(found.period_ratio - 1.0) <= o.PERIOD_TOLERANCE
    returns, x = found.returns, found.fixed_point
    images = returns.at_phases(x, found.steps.phases)
    np.testing.assert_array_equal(images.mean(axis=0) - x, found.residual)
    figures = o.orbit_figures(found)
    assert figures.residual_rate == pytest.approx(np.abs(found.residual[6:]).max())
    settled = o.settle(returns.walker, found.settings, returns.advance)
    start = returns.at_phases(settled.mean, found.steps.phases).mean(axis=0) - settled.mean
    scale = found.steps.vector()
    assert np.linalg.norm(found.residual / scale) <= np.linalg.norm(start / scale)


def test_a_section_in_the_double_support_is_refused(walker):
    """A section placed as a single support's (just after the touchdown: here in the double
    support, both feet held) is refused by name before any walk; given as an advance, the
    walk finds the swing foot on the floor there and says there is no section of 12
    coordinates."""
    samples = walker.samples
    tau = samples.landing + o.LANDING * samples.landing  # a single support's section
    with pytest.raises(BipedError, match="in the double support"):
        o.section_advance(walker, tau)
    with pytest.raises(BipedError, match="not in the swing"):
        o.section_advance(walker, 0.0)  # the lift-off itself: the rear foot still down
    advance = float(samples.at("q", [tau])[0, o.XH])
    with pytest.raises(o.OrbitFailure, match="on the floor on the section"):
        o.settle(walker, o.NOMINAL, advance)


def test_the_section_is_where_the_stance_foot_is_at_rest(walker, found):
    """At 0.1 T the stance foot still rocks from the double support (its tilt rate spreads
    beyond ``HELD_RATE_SPREAD`` over the walk's steps: 0.0085 rad/s) and the return map
    restarted from the walk's own states there misses the walk's next state: the nearest of
    the map's images over MuJoCo's grid lies beyond ``RESTART_MISS`` (``restart_miss`` over
    three states: 1.25 central-difference steps), the 12 coordinates not holding the walk's
    state. The orbit's section is the first of ``SECTION_PHASES`` where the foot is at rest
    (0.3 T: 2e-5 rad/s), and there the restarted map is the walk (0.33 of a step).
    Asked for 0.1 T, the orbit is not measured: undecided, said, and the check fails."""
    landing = walker.samples.landing_time
    early = o.settle(walker, o.NOMINAL, o.section_advance(walker, o.LANDING * landing))
    assert early.held_rate_spread > o.HELD_RATE_SPREAD
    assert found.phase in o.SECTION_PHASES and found.phase > o.LANDING
    at_rest = o.settle(walker, o.NOMINAL, found.advance)
    assert at_rest.held_rate_spread < o.HELD_RATE_SPREAD
    for settled, advance, follows in ((early, None, False), (at_rest, found.advance, True)):
        returns = o.ReturnMap(walker, o.NOMINAL, settled.reference, settled.flow, advance)
        miss = o.restart_miss(returns, settled.states, (3, 8, 12))
        assert (miss < o.RESTART_MISS) == follows, miss
    asked = o.orbit(walker, tau=o.LANDING * landing)
    assert asked.unsettled and asked.multipliers is None and asked.verdict == "undecided"
    assert "not at rest on the section" in o.notes(asked)[0]
    check = o.orbit_check(asked)
    assert not check.passed and check.causes == ["unstable orbit"]
