"""The words and the sign with which results are compared, written once.

- A difference between two knees (or two designs) is ``relative_change(value, reference)``:
  (value − reference) / reference in %, with the revolute knee as the reference. Negative:
  the knee compared needs less than the revolute knee (``DIFFERENCE`` says it in words).
- A gait file holds its criterion twice: ``optimizer.value``, on the solver's samples
  (``SOLVER_GRID``), which ranks the starts of one optimization, and ``costs.<criterion>``,
  on the finer check grid (``CHECK_GRID``), which every comparison, table and figure uses.
- ``certified`` (``CERTIFIED`` in words): the final optimum of a point, the best of several
  starts (in a sweep, its own and its neighbours' optima), whose solver converged and which
  is feasible on the check grid; how many starts reached it is printed beside it, and a best
  that only one start reached is flagged (``SINGLE_START``): it is the best found, not yet
  confirmed. A stage before the final one is never called certified.
"""

from __future__ import annotations

import math

from biped.model.profile import MARGINS, PARAMETER_UNITS
from biped.optimization.penalty import OPTIMIZE_SAMPLES_PER_HALF
from biped.optimization.problem import CHECK_SAMPLES_PER_HALF, SOLVER_SAMPLES_PER_HALF

# The knee radii a design names, and the changes of its comparison (``biped.optimization.design
# .Comparison.gains``), by name.
RADII = ("r1", "r2")
GAINS = ("design_vs_revolute", "design_vs_table1", "table1_vs_revolute")
# The changes of a profile design's comparison (``biped.optimization.profile_design``), and
# the units of its block in a gait file.
PROFILE_GAINS = ("profile_vs_circles", "profile_vs_revolute", "circles_vs_revolute")
PROFILE_DESIGN_UNITS = {
    **{f"design.profile.rates.{name}": PARAMETER_UNITS[name] for name in ("k1", "k2")},
    "design.profile.rate_bound": "m/rad",
    "design.profile.range": "rad",
    **{
        f"design.profile.surface_margins.{name}": "m" if "convex" in name else "m²"
        for name in MARGINS
    },
    "design.compared[].rates": "m/rad",
    **{f"design.compared[].rates.{name}": "m/rad" for name in ("k1", "k2")},
    **{f"design.gains_percent.{name}": "%" for name in PROFILE_GAINS},
}
# Convention of every difference between knees, in words (pages, figures, command lines).
DIFFERENCE = "(rolling − revolute) / revolute; negative: the rolling knee needs less"
# The same for any knee or design against the revolute knee.
DIFFERENCE_VS_REVOLUTE = "(knee − revolute) / revolute; negative: the knee needs less"

# Samples per step of the two grids a criterion is computed on.
SOLVER_SAMPLES_PER_STEP = 2 * (SOLVER_SAMPLES_PER_HALF + 1)  # IPOPT's
NELDER_MEAD_SAMPLES_PER_STEP = 2 * (OPTIMIZE_SAMPLES_PER_HALF + 1)  # the paper's method's
CHECK_SAMPLES_PER_STEP = 2 * (CHECK_SAMPLES_PER_HALF + 1)
SOLVER_GRID = (
    f"the solver's samples ({SOLVER_SAMPLES_PER_STEP} per step; the paper's Nelder-Mead: "
    f"{NELDER_MEAD_SAMPLES_PER_STEP}, penalties included)"
)
CHECK_GRID = f"the check grid of {CHECK_SAMPLES_PER_STEP} samples per step"
# What each of a gait file's two values of its criterion is, and is for.
SOLVER_VALUE = f"the criterion on {SOLVER_GRID}, which ranks the starts"
CHECKED_VALUE = f"the criterion on {CHECK_GRID}, which the comparisons use"

# What "certified" means wherever it is printed.
CERTIFIED = (
    "the final optimum of a point (not an intermediate stage's), the best of several starts, "
    "whose solver converged and which is feasible on the check grid; the starts that reached "
    "its value are printed beside it, and a value reached by one start only is flagged"
)
# The flag of a certified optimum whose value one start alone reached.
SINGLE_START = "reached by a single start"


def relative_change(value: float, reference: float) -> float:
    """[%] (value − reference) / reference: negative when ``value`` is the smaller; NaN
    when either is not a finite number or the reference is 0 (never printed: callers
    leave out what they cannot compare)."""
    if not (math.isfinite(value) and math.isfinite(reference)) or reference == 0.0:
        return float("nan")
    return 100.0 * (value - reference) / reference
