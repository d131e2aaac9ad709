"""The knees compared from their orbits (``validate.studies.orbit_files``), on orbits made up
for the test: no walk, so in the fast tier."""

import numpy as np
import pytest

from validate.checks.units import OrbitFigures
from validate.studies.orbit_files import knee_means, knee_pairs
from validate.studies.orbit_study import OrbitStudy, StudiedOrbit


def studied(knee: str, speed: float, rho: float | None, spread: float = 0.01) -> OrbitStudy:
    """A gait's study under the validation's controller, its orbit's ρ and spread (None: the
    walk fell, no orbit)."""
    if rho is None:
        figures = OrbitFigures("unstable")
    else:
        figures = OrbitFigures("stable", spectral_radius=rho, spectral_radius_spread=spread)
    orbit = StudiedOrbit(None, figures, ())
    return OrbitStudy(f"{knee}-{speed}.json", knee, "sthenic", speed, orbits=(orbit,))


def test_the_knees_are_compared_where_both_have_an_orbit():
    """The knees side by side: ρ's difference (rolling − revolute) / revolute at each speed
    both have an orbit, distinct only beyond two spreads; a speed where a walk falls is shown
    but left out of the mean, and a speed of one knee only is not a pair."""
    studies = [
        studied("revolute", 0.3, 0.5), studied("rolling", 0.3, 0.6),  # +20 %, ± 2.8 % a spread
        studied("revolute", 0.4, 0.5), studied("rolling", 0.4, 0.51, spread=0.1),  # +2 %, wide
        studied("revolute", 0.5, 0.5), studied("rolling", 0.5, None),  # the rolling walk falls
        studied("revolute", 0.6, 0.5),  # no rolling gait at 0.6 m/s
    ]  # fmt: skip
    pairs = knee_pairs(studies)
    assert [p.speed for p in pairs] == [0.3, 0.4, 0.5]
    assert pairs[0].difference == pytest.approx(20.0) and pairs[0].distinct
    assert pairs[1].difference == pytest.approx(2.0) and not pairs[1].distinct
    assert pairs[2].difference is None and not pairs[2].distinct
    (mean,) = knee_means(pairs)
    assert (mean.criterion, mean.speeds, mean.distinct) == ("sthenic", 2, 1)
    assert mean.mean == pytest.approx(11.0)
    assert mean.spread == pytest.approx(np.hypot(pairs[0].spread, pairs[1].spread) / 2)
