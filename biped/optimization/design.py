"""Knee co-design: the rolling knee's radii optimised together with the gait.

The paper fixes r1 = r2 = 5 cm and ends on "integrate the radii r1 and r2 in the parameter
vector". A ``DesignProblem`` minimises the criterion over the gait's variables and (r1, r2)
together, under the gait's constraints, with IPOPT on the graph of the step whose radii are
symbols (``StepGraph(..., design=True)``, ``Solver`` with ``radius_bounds``); every other
parameter of the robot stays as given.

Design bounds. The segment lengths l1, l2 include the radii (``biped.model.robot``), so a
radius moves length into the knee: l'1 = l1 − r1 from the ankle to the shank circle's centre
C1, l'2 = l2 − r2 from the hip to the thigh circle's centre C2. The centres of mass (s1 from
the knee, s2 from the hip) stay on their segments when

    0 <= r1 <= s1            (shank: s1 − r1 >= 0; then l'1 >= l1 − s1 > 0)
    0 <= r2 <= l2 − s2       (thigh: s2 <= l'2; then l'2 >= s2 > 0)

the bounds by default (``radius_limits``: 0.181 m and 0.236 m for Table 1); narrower upper
bounds may be given. At r1 = 0 or r2 = 0 the rolling knee is the revolute knee (a circle
rolling on a point turns about it), beside which every design is compared and which no
rolling knee's MJCF can hold: the radii are bounded below by ``MIN_RADIUS`` (1 mm), and a
design at that bound gains nothing by rolling there. The robot's own radii, the reference
design, are moved into the bounds where they lie beyond them (``moved_reference``).

Starts, solved by the gaits' multistart (``biped.optimization.optimize.multistart``): the
gait's first guesses at the robot's own radii, starts with radii drawn uniformly in the
bounds from ``numpy.random.default_rng(seed)`` (``DESIGN_STARTS``), given (gait, radii)
pairs, and for the energy criterion the sthenic design under both barriers. The best
converged start wins; when none converged the report carries IPOPT's status (and the
command line exits 1): never a silent fallback.
"""

from __future__ import annotations

import dataclasses
import functools
import math
import time
from dataclasses import dataclass

import numpy as np

from biped.errors import BipedError
from biped.model.criteria import CRITERION_UNITS, PAPER_SAFETY, WORK_CRITERIA, Safety
from biped.model.dynamics import Biped
from biped.model.robot import LENGTH_MIN, Robot
from biped.optimization.comparison import (
    DIFFERENCE_VS_REVOLUTE,
    GAINS,
    RADII,
    relative_change,
)
from biped.optimization.optimize import (
    DEFAULT_STARTS,
    GUESS_PERIODS,
    Candidate,
    Optimum,
    best_of,
    checked,
    multistart,
    optimize,
    perturbed,
    start_schedule,
    sthenic_starts,
)
from biped.optimization.problem import GaitProblem, check_criterion, check_speed
from biped.optimization.solver import Solver

# [m] Lower bound of a designed knee radius: the smallest length of a robot
# (``biped.model.robot.LENGTH_MIN``); at 0 the rolling knee is the revolute knee (module docstring).
MIN_RADIUS = LENGTH_MIN


def radius_limits(robot: Robot) -> tuple[float, float]:
    """[m] The largest radii (r1, r2) that keep the centres of mass on the shank and the
    thigh: r1 <= s1 (shank_com, measured from the knee), r2 <= l2 − s2 (thigh_com is
    measured from the hip)."""
    return robot.shank_com, robot.thigh_length - robot.thigh_com


def check_radii(robot: Robot, radii, what: str = "radii") -> tuple[float, float]:
    """``radii`` (r1, r2) [m] if each is a finite number within ``radius_limits``, else a
    clear error naming the bad one."""
    limits = radius_limits(robot)
    try:
        values = tuple(radii)
    except TypeError:
        raise BipedError(f"{what} = {radii!r}: allowed two numbers (r1, r2) [m]") from None
    if len(values) != 2:
        raise BipedError(f"{what} = {radii!r}: allowed two numbers (r1, r2) [m]")
    for name, value, limit in zip(RADII, values, limits, strict=True):
        number = isinstance(value, (int, float, np.floating)) and not isinstance(value, bool)
        if not (number and math.isfinite(value) and 0.0 <= value <= limit):
            raise BipedError(
                f"{name} = {value!r} m: allowed 0 to {limit:.4g} m (the "
                f"{'shank' if name == 'r1' else 'thigh'}'s centre of mass stays on the segment)"
            )
    return tuple(float(v) for v in values)


@dataclass(frozen=True)
class DesignProblem:
    """Minimise ``criterion`` over the gaits and the knee radii (r1, r2) of the rolling knee
    of ``robot`` at ``speed``.

    Attributes:
        robot: every parameter but the radii; its own radii (Table 1: 5 cm) are the
            reference design and the first start.
        speed: walking speed V [m/s].
        criterion: ``"sthenic"`` (eq. 30) or ``"energy"`` (eq. 31).
        safety: margins of ours beyond the paper's constraints.
        samples_per_half: samples per spline piece of the solver's constraints.
        upper: [m] upper bounds of (r1, r2); default ``radius_limits(robot)``; each within
            (``MIN_RADIUS``, its limit].
    """

    robot: Robot
    speed: float
    criterion: str = "sthenic"
    safety: Safety = PAPER_SAFETY
    samples_per_half: int = 25
    upper: tuple | None = None

    def __post_init__(self):
        if not isinstance(self.robot, Robot):
            raise BipedError(f"robot = {self.robot!r}: allowed a biped.model.robot.Robot")
        object.__setattr__(self, "speed", check_speed(Biped(self.robot, "rolling"), self.speed))
        check_criterion(self.criterion)
        if not isinstance(self.safety, Safety):
            raise BipedError(f"safety = {self.safety!r}: allowed a biped.model.criteria.Safety")
        upper = radius_limits(self.robot) if self.upper is None else self.upper
        upper = check_radii(self.robot, upper, "upper bounds of the radii")
        for name, value in zip(RADII, upper, strict=True):
            if value <= MIN_RADIUS:
                raise BipedError(
                    f"upper bound of {name} = {value!r} m: allowed > {MIN_RADIUS:g} m, the "
                    "lower bound of a designed radius (at 0 the knee is the revolute knee)"
                )
        object.__setattr__(self, "upper", upper)
        # the sample count is checked by the gait problem
        self.gait_problem(self.reference_radii)

    @property
    def lower(self) -> tuple[float, float]:
        return (MIN_RADIUS, MIN_RADIUS)

    @property
    def reference_radii(self) -> tuple[float, float]:
        """The robot's own radii, clipped into the bounds (``moved_reference``): the first
        start and the rolling knee every design is compared with."""
        own = (self.robot.r1, self.robot.r2)
        return tuple(
            float(np.clip(r, low, high))
            for r, low, high in zip(own, self.lower, self.upper, strict=True)
        )

    def moved_reference(self) -> list[str]:
        """A sentence per radius of the robot's own that lies beyond its bound, so that the
        reference design (``reference_radii``) has another: empty when none moved."""
        moved = []
        own = (self.robot.r1, self.robot.r2)
        radii = zip(RADII, own, self.reference_radii, self.upper, strict=True)
        for name, value, used, high in radii:
            if value == used:
                continue
            why = (
                f"its upper bound {high:.4g} m"
                if used == high
                else f"its lower bound {MIN_RADIUS:g} m (at 0 the knee is the revolute knee)"
            )
            moved.append(
                f"the robot's own {name} = {value:.4g} m lies beyond {why}: the rolling knee "
                f"of the robot's own radii is compared at {name} = {used:.4g} m"
            )
        return moved

    def robot_with(self, radii) -> Robot:
        """The robot with knee radii ``radii`` (r1, r2) [m]."""
        r1, r2 = check_radii(self.robot, radii)
        return dataclasses.replace(self.robot, r1=r1, r2=r2)

    def gait_problem(self, radii, knee: str = "rolling") -> GaitProblem:
        """The gait problem of the robot with radii ``radii`` (r1, r2) [m] (or of its
        revolute knee, whose radii are not used)."""
        model = Biped(self.robot_with(radii), knee)
        return GaitProblem(model, self.speed, self.criterion, self.safety, self.samples_per_half)

    def describe(self) -> str:
        text = self.gait_problem(self.reference_radii).describe().replace("rolling knee, ", "")
        return (
            f"rolling knee radii r1 <= {self.upper[0]:.4g} m, r2 <= {self.upper[1]:.4g} m, " + text
        )


@dataclass
class Design:
    """The optimal radii of a ``DesignProblem`` and the gait that goes with them.

    Attributes:
        problem: what was solved.
        optimum: the gait of the designed robot, checked on the fine grid as every optimum
            (``biped.optimization.optimize.checked``); its report is the design's (starts, status).
    """

    problem: DesignProblem
    optimum: Optimum

    report = property(lambda self: self.optimum.report)
    value = property(lambda self: self.optimum.value)
    certified = property(lambda self: self.optimum.certified)

    @property
    def robot(self) -> Robot:
        return self.optimum.problem.model.robot

    @property
    def radii(self) -> tuple[float, float]:
        """(r1, r2) [m] of the designed robot."""
        return self.robot.r1, self.robot.r2

    def at_bounds(self) -> list[str]:
        """The radii at a bound (within 1e-6 m), e.g. ``["r1 at its upper bound"]``."""
        found = []
        for name, value, low, high in zip(
            RADII, self.radii, self.problem.lower, self.problem.upper, strict=True
        ):
            for bound, side in ((low, "lower"), (high, "upper")):
                if abs(value - bound) <= 1e-6:
                    found.append(f"{name} at its {side} bound")
        return found

    def to_dict(self) -> dict:
        """The ``design`` block of a gait file."""
        return {
            "radii": {name: float(r) for name, r in zip(RADII, self.radii, strict=True)},
            "lower": dict(zip(RADII, self.problem.lower, strict=True)),
            "upper": dict(zip(RADII, self.problem.upper, strict=True)),
            "at_bounds": self.at_bounds(),
        }


@functools.lru_cache(maxsize=8)
def _solver(robot: Robot, criterion: str, safety: Safety, samples: int, upper) -> Solver:
    model = Biped(robot, "rolling")  # its radii are symbols in the graph
    lower = (MIN_RADIUS, MIN_RADIUS)
    return Solver(model, criterion, safety, samples, radius_bounds=(lower, upper))


def solver_for(problem: DesignProblem) -> Solver:
    """The design solver of ``problem``'s family, built once per process (every speed)."""
    if not isinstance(problem, DesignProblem):
        raise BipedError(
            f"problem = {problem!r}: allowed a biped.optimization.design.DesignProblem"
        )
    robot = dataclasses.replace(problem.robot, r1=0.0, r2=0.0)  # the radii are variables
    return _solver(
        robot, problem.criterion, problem.safety, problem.samples_per_half, problem.upper
    )


# Starts of a design, in order: first guesses of the gait at the robot's radii with these step
# periods [s] (``biped.optimization.optimize.GUESS_PERIODS``), or None for a random start
# (radii uniform in the bounds, the gait's first guess there perturbed); random starts after
# these. The short period comes late: from it IPOPT takes several times the iterations of
# the others (388 against 26-88 at 0.3 m/s) to the same design.
DESIGN_STARTS = (GUESS_PERIODS[0], GUESS_PERIODS[1], None, GUESS_PERIODS[2])


def design_starts(problem: DesignProblem, starts: int, seed: int) -> list[tuple]:
    """The ``starts`` starts (each a ``Candidate`` of (z, radii)) in the order of
    ``DESIGN_STARTS``."""
    schedule = start_schedule(starts, seed, DESIGN_STARTS)
    rng = np.random.default_rng(seed)
    reference = problem.reference_radii
    result = []
    for source, period in schedule:
        if period is not None:
            z = problem.gait_problem(reference).first_guess(period)
            result.append(Candidate(source, (z, reference)))
            continue
        radii = tuple(float(r) for r in rng.uniform(problem.lower, problem.upper))
        z = perturbed(problem.gait_problem(radii).first_guess(), rng)
        result.append(Candidate(source, (z, radii)))
    return result


def optimize_design(
    problem: DesignProblem, seed: int = 0, starts: int = DEFAULT_STARTS, given=()
) -> Design:
    """The best radii and gait of ``problem`` (``biped.optimization.optimize.multistart``).

    Args:
        seed: seed of the random starts; the same seed gives the same result.
        starts: the first guess at the robot's radii and ``starts − 1`` random starts.
        given: further starts, each (z (21,), (r1, r2)), e.g. the optimal gait at the
            Table 1 radii.
    """
    began = time.perf_counter()
    solver = solver_for(problem)  # which checks ``problem``
    candidates = design_starts(problem, starts, seed)
    for z, radii in given:
        start = (np.asarray(z, dtype=float), check_radii(problem.robot, radii))
        candidates.append(Candidate("given", start))
    if problem.criterion in WORK_CRITERIA and starts > 0:  # as for gaits: least torque first
        sthenic = optimize_design(dataclasses.replace(problem, criterion="sthenic"), seed, starts)
        candidates += sthenic_starts(sthenic.report, (sthenic.optimum.variables, sthenic.radii))

    def solve(start, barrier):
        return solver.solve(problem, *start, barrier=barrier)

    solver.prepare({start.barrier for start in candidates})
    best, report = multistart(candidates, solve, seed, began)
    # IPOPT may end a hair outside a bound (its bound_relax_factor): back inside
    radii = tuple(
        float(np.clip(r, low, high))
        for r, low, high in zip(best.radii, problem.lower, problem.upper, strict=True)
    )
    optimum = checked(problem.gait_problem(radii), best.variables, report)
    return Design(problem, optimum)


@dataclass(frozen=True)
class _HeldRadii:
    """The design graph of one criterion with the knee radii held: a gait solver for every
    radius without a new graph."""

    design: Solver
    radii: tuple

    def prepare(self, barriers) -> None:
        self.design.prepare(barriers)

    def solve(self, gait: GaitProblem, start, barrier: str = "adaptive"):
        return self.design.solve(gait, start, self.radii, hold_radii=True, barrier=barrier)


def optimize_at(
    problem: DesignProblem, radii, seed: int = 0, starts: int = DEFAULT_STARTS, given=()
) -> Optimum:
    """The optimal gait of ``problem``'s robot with the radii held at ``radii`` (r1, r2) [m]:
    ``biped.optimization.optimize.optimize`` (same starts, same report) on the design graph,
    so that a map of many radii builds one graph per process."""
    radii = check_radii(problem.robot, radii)

    def held(gait: GaitProblem) -> _HeldRadii:  # once per criterion and grid, not per start
        family = dataclasses.replace(
            problem, criterion=gait.criterion, samples_per_half=gait.samples_per_half
        )
        return _HeldRadii(solver_for(family), radii)

    gait = problem.gait_problem(radii)
    return optimize(gait, seed=seed, starts=starts, given=given, solvers=held)


@dataclass
class Comparison:
    """The designed knee beside the revolute knee and the rolling knee of the robot's own
    radii (Table 1's), each the optimal gait at the same speed, criterion and margins.

    Attributes:
        problem: the design problem.
        revolute: optimal gait of the revolute knee.
        reference: optimal gait of the rolling knee at the robot's own radii.
        design: optimal radii and gait.
    """

    problem: DesignProblem
    revolute: Optimum
    reference: Optimum
    design: Design

    def rows(self) -> list[tuple[str, tuple | None, Optimum]]:
        """(label, radii or None, optimum) of the three knees."""
        return [
            ("revolute", None, self.revolute),
            ("rolling, Table 1 radii", self.problem.reference_radii, self.reference),
            ("rolling, optimal radii", self.design.radii, self.design.optimum),
        ]

    @property
    def certified(self) -> bool:
        return all(optimum.certified for _, _, optimum in self.rows())

    def gains(self) -> dict:
        """[%] Change of the criterion (``comparison.relative_change``: negative, the first
        needs less): the design against the revolute knee and against the Table 1 radii, the
        Table 1 radii against the revolute knee."""
        design, revolute, reference = self.design.value, self.revolute.value, self.reference.value
        changes = ((design, revolute), (design, reference), (reference, revolute))
        return {name: relative_change(*pair) for name, pair in zip(GAINS, changes, strict=True)}

    def table(self) -> str:
        """The three knees in a text table: radii, both criteria of the gait optimal for
        the problem's criterion, its change against the revolute knee (the convention
        on the last line)."""
        criterion = self.problem.criterion
        title = f"{criterion} vs revolute"
        width = max(22, len(title) + 2)  # the longer criteria's names keep their space
        head = (
            f"{'knee':24}{'r1 [m]':>9}{'r2 [m]':>9}{'sthenic [N²·m·s]':>18}{'energy [J]':>12}"
            f"{title:>{width}}"
        )
        lines = [head]
        for label, radii, optimum in self.rows():
            r1, r2 = ("-", "-") if radii is None else (f"{radii[0]:.4f}", f"{radii[1]:.4f}")
            change = relative_change(optimum.value, self.revolute.value)
            status = "" if optimum.certified else "  NOT CERTIFIED"
            lines.append(
                f"{label:24}{r1:>9}{r2:>9}{optimum.evaluation.sthenic:18.4f}"
                f"{optimum.evaluation.energy:12.4f}"
                f"{'' if radii is None else f'{change:+.2f} %':>{width}}{status}"
            )
        lines.append(f"{criterion} vs revolute: {DIFFERENCE_VS_REVOLUTE}")
        return "\n".join(lines)

    def radii_line(self) -> str:
        """The optimal radii and criterion of the design, and its gains over the revolute
        knee and the Table 1 radii."""
        design, gains, bounds = self.design, self.gains(), self.design.at_bounds()
        criterion = self.problem.criterion
        return (
            f"optimal radii: r1 = {design.radii[0]:.4f} m, r2 = {design.radii[1]:.4f} m"
            f"{' (' + ', '.join(bounds) + ')' if bounds else ''}; "
            f"{criterion} {design.value:.6g} {CRITERION_UNITS[criterion]}: "
            f"{gains['design_vs_revolute']:+.2f} % vs revolute, "
            f"{gains['design_vs_table1']:+.2f} % vs Table 1 radii"
        )

    def uncertified(self) -> list[str]:
        """The knees compared that are not certified optima, each with why."""
        return [
            f"{label}: {optimum.report.status if not optimum.report.converged else 'infeasible'}"
            for label, _, optimum in self.rows()
            if not optimum.certified
        ]

    def to_dict(self) -> dict:
        """The comparison as JSON (``design`` block of a gait file)."""
        knees = []
        for label, radii, optimum in self.rows():
            knees.append(
                {
                    "knee": label,
                    "radii": None if radii is None else dict(zip(RADII, radii, strict=True)),
                    "sthenic": optimum.evaluation.sthenic,
                    "energy": optimum.evaluation.energy,
                    "status": optimum.report.status,
                    "certified": optimum.certified,
                }
            )
        return {
            **self.design.to_dict(),
            "compared": knees,
            "gains_percent": self.gains(),
            "reference_moved": self.problem.moved_reference(),
        }


def bound_notes(problem: DesignProblem, design: Design | None = None) -> list[str]:
    """What the design's bounds did: the robot's own radii moved into them (the reference
    design of the table), and a designed radius at its lower bound (``MIN_RADIUS``)."""
    notes = [f"note: {sentence}" for sentence in problem.moved_reference()]
    for bound in [] if design is None else design.at_bounds():
        if bound.endswith("lower bound"):
            notes.append(
                f"note: {bound} {MIN_RADIUS:g} m: the radii are bounded away from 0, where "
                "the rolling knee is the revolute knee (the first row); the design gains "
                "nothing by rolling on that side"
            )
    return notes


def compare(
    problem: DesignProblem,
    seed: int = 0,
    starts: int = DEFAULT_STARTS,
    revolute: Optimum | None = None,
    reference: Optimum | None = None,
) -> Comparison:
    """The optimal radii of ``problem`` beside the revolute knee and the robot's own radii.

    Each optimum also starts from the others' gaits (the variables mean the same for every
    knee): the Table 1 knee from the revolute optimum, the design from both, then the
    revolute and Table 1 knees again from the design's gait, so that each of the three is
    the best of every start. Optima given (``revolute``, ``reference``: e.g. gaits already
    written) are kept as they are.
    """
    ref = problem.reference_radii
    hinge, rolling = problem.gait_problem(ref, "revolute"), problem.gait_problem(ref)
    fixed = {"revolute": revolute is not None, "reference": reference is not None}
    if revolute is None:
        revolute = optimize(hinge, seed=seed, starts=starts)
    if reference is None:
        reference = optimize(rolling, seed=seed, starts=starts, given=[revolute.variables])
    given = [(o.variables, ref) for o in (reference, revolute) if np.all(np.isfinite(o.variables))]
    design = optimize_design(problem, seed=seed, starts=starts, given=given)
    again = [design.optimum.variables]
    if not fixed["revolute"]:
        more = optimize(hinge, seed=seed, starts=0, given=again + [reference.variables])
        revolute = best_of(hinge, [revolute, more])
    if not fixed["reference"]:
        reference = best_of(
            rolling, [reference, optimize(rolling, seed=seed, starts=0, given=again)]
        )
    return Comparison(problem, revolute, reference, design)
