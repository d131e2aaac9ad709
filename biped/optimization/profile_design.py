"""Knee profiles designed with the gait: the surfaces of ``biped.model.profile`` (family
"linear": each radius of curvature ρ_i = r_i + k_i ψ) optimised together with the gait.

A ``ProfileProblem`` is a circles' ``DesignProblem`` (robot, speed, criterion, margins, the
radii's upper bounds) and a family. IPOPT minimises the criterion over the gait's variables
and (r1, r2, k1, k2) on the step's graph with the four as symbols
(``StepGraph(..., design=True, profile=True)``), within

    MIN_RADIUS <= r_i <= upper_i,   |k_i| <= ``RATE_BOUND``,
    ρ_i >= ``MIN_CURVATURE_RADIUS`` and |K − C_i| <= upper_i over the knee's range

(``biped.model.profile.surface_margins``: convex, and inside the disc the circles' bound
gives each segment; at k = 0 these are the circles' bounds exactly).

The family contains the circles (k1 = k2 = 0), so the best circles are a profile: the design
starts from the circles' design (``biped.optimization.design.optimize_design``), under the
adaptive barrier and under the monotone one from 1e-3 (which keeps near it), and from
``RANDOM_STARTS`` profiles about it. Its result is never worse than those circles: when no
start ends below them (a relative ``NEVER_WORSE`` of the criterion), the circles are the
design (``ProfileDesign.kept_circles``) and the gait file says so. When no start converged
the report carries IPOPT's status: never a silent fallback.
"""

from __future__ import annotations

import dataclasses
import functools
import time
from dataclasses import dataclass

import numpy as np

from biped.errors import BipedError
from biped.model.dynamics import Biped
from biped.model.profile import (
    FAMILIES,
    MARGINS,
    PARAMETERS,
    PROFILE_RANGE,
    KneeProfile,
    surface_margins,
)
from biped.model.robot import Robot
from biped.optimization.comparison import (  # noqa: F401 (re-exported)
    PROFILE_DESIGN_UNITS,
    PROFILE_GAINS,
    relative_change,
)
from biped.optimization.design import MIN_RADIUS, Comparison, Design, DesignProblem
from biped.optimization.optimize import Candidate, Optimum, Report, checked, multistart
from biped.optimization.problem import GaitProblem
from biped.optimization.solver import Solver

# [m/rad] Bound of |k_i|, the box IPOPT needs: 20 m a radian, beyond what the surfaces'
# bounds allow (at 0.3 m/s with a 2 cm clearance the thigh's k2 = 8.1 m/rad is held by its
# convexity at the extension stop and its distance at full flexion; at 0.5, 2 or 5 m/rad the
# box bound it first, each lower the criterion).
RATE_BOUND = 20.0
# Profiles drawn about the circles' design as further starts: k_i uniform in
# ±``RANDOM_RATE`` [m/rad], the radii the circles'.
RANDOM_STARTS = 2
RANDOM_RATE = 0.05
# A profile replaces the circles when its criterion is below theirs by more than this
# (relative): the family contains them, so equal is the circles.
NEVER_WORSE = 1e-9


@dataclass(frozen=True)
class ProfileProblem:
    """Minimise ``circles.criterion`` over the gaits and the knee profiles of ``family``
    (module docstring).

    Attributes:
        circles: the circles' design problem: robot, speed, criterion, margins, the radii's
            upper bounds (each also the bound of its surface's distance from its centre).
        family: one of ``biped.model.profile.FAMILIES``.
    """

    circles: DesignProblem
    family: str = "linear"

    def __post_init__(self):
        if not isinstance(self.circles, DesignProblem):
            raise BipedError(
                f"circles = {self.circles!r}: allowed a biped.optimization.design.DesignProblem"
            )
        if self.family not in FAMILIES:
            raise BipedError(f"profile family {self.family!r}: allowed {', '.join(FAMILIES)}")

    @property
    def speed(self) -> float:
        """[m/s] The walking speed."""
        return self.circles.speed

    @property
    def lower(self) -> tuple:
        return (MIN_RADIUS, MIN_RADIUS, -RATE_BOUND, -RATE_BOUND)

    @property
    def upper(self) -> tuple:
        return (*self.circles.upper, RATE_BOUND, RATE_BOUND)

    def robot_with(self, parameters) -> Robot:
        """The robot with the profile ``parameters`` (r1, r2 [m], k1, k2 [m/rad])."""
        values = dict(zip(PARAMETERS, map(float, parameters), strict=True))
        return dataclasses.replace(self.circles.robot, **values)

    def gait_problem(self, parameters) -> GaitProblem:
        circles = self.circles
        model = Biped(self.robot_with(parameters), "rolling")
        return GaitProblem(
            model, circles.speed, circles.criterion, circles.safety, circles.samples_per_half
        )

    def margins(self, parameters) -> dict:
        """The surfaces' bounds (``biped.model.profile.MARGINS``) of ``parameters``, >= 0 when
        met: ρ_i − 1 mm [m], upper_i² − |K − C_i|² [m²]."""
        values = surface_margins(tuple(parameters), self.circles.upper)
        return {name: float(v) for name, v in zip(MARGINS, values, strict=True)}

    def describe(self) -> str:
        return f"{self.family} knee profile, " + self.circles.describe()


@functools.lru_cache(maxsize=4)
def _solver(robot: Robot, criterion: str, safety, samples: int, upper: tuple) -> Solver:
    lower = (MIN_RADIUS, MIN_RADIUS, -RATE_BOUND, -RATE_BOUND)
    return Solver(Biped(robot, "rolling"), criterion, safety, samples, radius_bounds=(lower, upper))


def solver_for(problem: ProfileProblem) -> Solver:
    """The profile design's solver, built once per process (every speed)."""
    circles = problem.circles
    robot = dataclasses.replace(circles.robot, r1=0.05, r2=0.05, k1=0.0, k2=0.0)
    samples = circles.samples_per_half
    return _solver(robot, circles.criterion, circles.safety, samples, problem.upper)


@dataclass
class ProfileDesign:
    """The optimal profile of a ``ProfileProblem``, its gait and the circles it started from.

    Attributes:
        problem: what was solved.
        optimum: the gait of the designed robot (checked on the fine grid).
        circles: the best circles (``biped.optimization.design.Design``), the first start.
        kept_circles: no profile ended below the circles: the design is the circles (their
            optimum as it is).
        search: the profile starts' report (``biped.optimization.optimize.multistart``).
    """

    problem: ProfileProblem
    optimum: Optimum
    circles: Design
    kept_circles: bool
    search: Report

    report = property(lambda self: self.search)
    value = property(lambda self: self.optimum.value)
    certified = property(lambda self: self.optimum.certified)

    @property
    def robot(self) -> Robot:
        return self.optimum.problem.model.robot

    @property
    def parameters(self) -> tuple:
        """(r1, r2, k1, k2) [m, m, m/rad, m/rad]."""
        return KneeProfile.of(self.robot).vector

    @property
    def gain(self) -> float:
        """[%] The profile's criterion against the circles' (``relative_change``)."""
        return relative_change(self.value, self.circles.value)

    def at_bounds(self) -> list[str]:
        """The parameters at a bound (within 1e-6) and the surfaces' bounds that are met
        with equality (within 1e-9 of their scale)."""
        found = []
        problem = self.problem
        pairs = zip(PARAMETERS, self.parameters, problem.lower, problem.upper, strict=True)
        for name, value, low, high in pairs:
            for bound, side in ((low, "lower"), (high, "upper")):
                if abs(value - bound) <= 1e-6:
                    found.append(f"{name} at its {side} bound")
        for name, margin in self.problem.margins(self.parameters).items():
            if abs(margin) <= 1e-9 and not self.kept_circles:
                found.append(f"{name} (bound met)")
        return found


def profile_starts(problem: ProfileProblem, circles: Design, seed: int) -> list[tuple]:
    """The starts (each a ``Candidate`` of (z, parameters); module docstring)."""
    z = np.asarray(circles.optimum.variables, dtype=float)
    base = (*circles.radii, 0.0, 0.0)
    starts = [Candidate("circles", (z, base)), Candidate("circles", (z, base), "confirm")]
    rng = np.random.default_rng(seed)
    for _ in range(RANDOM_STARTS):
        rates = rng.uniform(-RANDOM_RATE, RANDOM_RATE, 2)
        starts.append(Candidate("perturbed", (z, (*circles.radii, *map(float, rates)))))
    return starts


def optimize_profile(problem: ProfileProblem, circles: Design, seed: int = 0) -> ProfileDesign:
    """The best profile of ``problem`` from the circles' design ``circles`` (module
    docstring); never worse than them."""
    began = time.perf_counter()
    solver = solver_for(problem)
    candidates = profile_starts(problem, circles, seed)

    def solve(start, barrier):
        return solver.solve(problem, *start, barrier=barrier)

    solver.prepare({"adaptive", "confirm"})
    best, report = multistart(candidates, solve, seed, began)
    lower, upper = problem.lower, problem.upper
    parameters = tuple(
        float(np.clip(p, low, high)) for p, low, high in zip(best.radii, lower, upper, strict=True)
    )
    optimum = checked(problem.gait_problem(parameters), best.variables, report)
    better = optimum.certified and optimum.value < circles.value * (1.0 - NEVER_WORSE)
    if not better and circles.certified and report.converged:
        return ProfileDesign(problem, circles.optimum, circles, True, report)
    return ProfileDesign(problem, optimum, circles, False, report)


# The changes of a profile comparison, by name (``ProfileComparison.gains``).


@dataclass
class ProfileComparison:
    """The designed profile beside the circles' comparison (``design.Comparison``: the
    revolute knee, the robot's own circles and the designed circles)."""

    circles: Comparison
    profile: ProfileDesign

    @property
    def problem(self) -> ProfileProblem:
        return self.profile.problem

    def rows(self) -> list[tuple[str, tuple | None, Optimum]]:
        """(label, parameters (r1, r2, k1, k2) or None, optimum) of the four knees."""
        rows = [
            (label, None if radii is None else (*radii, 0.0, 0.0), optimum)
            for label, radii, optimum in self.circles.rows()
        ]
        label = f"rolling, {self.problem.family} profile"
        return rows + [(label, self.profile.parameters, self.profile.optimum)]

    @property
    def certified(self) -> bool:
        return all(optimum.certified for _, _, optimum in self.rows())

    def gains(self) -> dict:
        """[%] The profile against the designed circles and the revolute knee, the circles
        against the revolute knee (``relative_change``: negative, the first needs less)."""
        profile, circles = self.profile.value, self.circles.design.value
        revolute = self.circles.revolute.value
        pairs = ((profile, circles), (profile, revolute), (circles, revolute))
        return {name: relative_change(*p) for name, p in zip(PROFILE_GAINS, pairs, strict=True)}

    def table(self) -> str:
        """The four knees: profile parameters, both criteria, the change against the
        revolute knee."""
        criterion = self.problem.circles.criterion
        title = f"{criterion} vs revolute"
        head = (
            f"{'knee':28}{'r1 [m]':>9}{'r2 [m]':>9}{'k1 [m/rad]':>12}{'k2 [m/rad]':>12}"
            f"{'sthenic [N²·m·s]':>18}{'energy [J]':>12}{title:>24}"
        )
        lines = [head]
        for label, p, optimum in self.rows():
            shown = ["-"] * 4 if p is None else [f"{v:.4f}" for v in p]
            change = relative_change(optimum.value, self.circles.revolute.value)
            status = "" if optimum.certified else "  NOT CERTIFIED"
            lines.append(
                f"{label:28}{shown[0]:>9}{shown[1]:>9}{shown[2]:>12}{shown[3]:>12}"
                f"{optimum.evaluation.sthenic:18.4f}{optimum.evaluation.energy:12.4f}"
                f"{'' if p is None else f'{change:+.2f} %':>24}{status}"
            )
        return "\n".join(lines)

    def profile_line(self) -> str:
        """The designed profile, its criterion and its gains."""
        design, gains = self.profile, self.gains()
        r1, r2, k1, k2 = design.parameters
        bounds = design.at_bounds()
        kept = " (no profile below the circles: the circles kept)" if design.kept_circles else ""
        return (
            f"optimal profile: r1 = {r1:.4f} m, r2 = {r2:.4f} m, k1 = {k1:+.4f} m/rad, "
            f"k2 = {k2:+.4f} m/rad{kept}{' (' + ', '.join(bounds) + ')' if bounds else ''}; "
            f"{self.problem.circles.criterion} {design.value:.6g}: "
            f"{gains['profile_vs_circles']:+.3f} % vs the designed circles, "
            f"{gains['profile_vs_revolute']:+.2f} % vs revolute"
        )

    def to_dict(self) -> dict:
        """The ``design`` block of the profile's gait file: the circles' block
        (``Comparison.to_dict``, its radii the profile's), the profile and the four knees."""
        block = self.circles.to_dict()
        design = self.profile
        names = dict(zip(PARAMETERS, design.parameters, strict=True))
        block["radii"] = {name: names[name] for name in ("r1", "r2")}
        block["at_bounds"] = design.at_bounds()
        block["compared"] = [
            {
                "knee": label,
                "radii": None if p is None else dict(zip(("r1", "r2"), p[:2], strict=True)),
                "rates": None if p is None else dict(zip(("k1", "k2"), p[2:], strict=True)),
                "sthenic": optimum.evaluation.sthenic,
                "energy": optimum.evaluation.energy,
                "status": optimum.report.status,
                "certified": optimum.certified,
            }
            for label, p, optimum in self.rows()
        ]
        block["gains_percent"] = {**block["gains_percent"], **self.gains()}
        block["profile"] = {
            "family": self.problem.family,
            "rates": {name: names[name] for name in ("k1", "k2")},
            "rate_bound": RATE_BOUND,
            "range": list(PROFILE_RANGE),
            "kept_circles": design.kept_circles,
            "surface_margins": self.problem.margins(design.parameters),
        }
        return block


# Units of a profile design's block beyond the circles' (``DESIGN_UNITS``).


def compare_profile(
    problem: ProfileProblem, seed: int = 0, starts: int = 3, circles: Comparison | None = None
) -> ProfileComparison:
    """The circles' comparison (``biped.optimization.design.compare``, unless given) and the
    profile designed from its circles."""
    from biped.optimization.design import compare

    if circles is None:
        circles = compare(problem.circles, seed=seed, starts=starts)
    return ProfileComparison(circles, optimize_profile(problem, circles.design, seed))
