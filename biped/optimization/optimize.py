"""Certified optimal gaits: IPOPT with exact derivatives from several starts.

``optimize(problem)`` solves a ``GaitProblem`` with IPOPT (``biped.optimization.solver``) from
several first guesses and keeps the best converged one (``multistart``, which the knee's
design, ``biped.optimization.design``, shares):

- the default first guess (``GaitProblem.first_guess``);
- perturbed first guesses, drawn from ``numpy.random.default_rng(seed)``;
- optionally the paper's Nelder-Mead from a few seeds (``nelder_mead_starts``);
- any given guesses, e.g. the optimum at a neighbouring speed in a sweep (``given``);
- for the energy criterion, the sthenic optimum of the same problem, solved under IPOPT's
  adaptive and under its monotone barrier (``MONOTONE_START``).

The optimum is certified when IPOPT converged from its start, and confirmed when at least
two starts reach the same value (within ``AGREEMENT``, relative). A solver that did not
converge is reported as such (``Report.status``), never replaced by a silent fallback; the
command line exits 1 on it.

Every optimum is then checked on a fine grid (``CHECK_SAMPLES_PER_HALF`` samples per spline
piece, where the solver imposed the constraints with margins at ``samples_per_half``): it is
feasible only if every constraint holds there with zero penalty.

``method="nelder-mead"`` runs the paper's method alone (``biped.optimization.penalty``) so that its
results can be set beside certified optima.
"""

from __future__ import annotations

import dataclasses
import time
from dataclasses import dataclass

import numpy as np

from biped.errors import BipedError
from biped.model.criteria import WORK_CRITERIA, StepEvaluation, evaluate_step
from biped.model.gait import Step, build_step
from biped.optimization import table
from biped.optimization.penalty import EVALUATIONS_PER_RUN, MAX_RESTARTS, nelder_mead
from biped.optimization.problem import (  # noqa: F401 (re-exported)
    CHECK_SAMPLES,
    CHECK_SAMPLES_PER_HALF,
    FIRST_GUESS_PERIOD,
    SCALES,
    GaitProblem,
    bounds,
    check_criterion,
    check_speed,
    max_walking_speed,
    scales,
)
from biped.optimization.report import Report, Start  # noqa: F401 (re-exported)
from biped.optimization.solver import BARRIERS, CONVERGED, solver_for
from biped.optimization.table import OTHER_KNEE_START, TABLE_START
from biped.runtime.runner import free_cores, run_forked

METHODS = ("ipopt", "nelder-mead")
# Starts of IPOPT by default (``first_guesses``).
DEFAULT_STARTS = 3
# Step periods [s] of the first guesses, in order; starts beyond these are perturbations.
GUESS_PERIODS = (FIRST_GUESS_PERIOD, 0.8, 0.45)
# Standard deviation of the perturbed starts, in units of ``SCALES``.
PERTURBATION = 1.0
# Two starts reach the same optimum when their values agree to this, relative.
AGREEMENT = 1e-6


@dataclass(frozen=True, eq=False)
class Candidate:
    """A start of a multistart: where it comes from (``source``: "first guess", "given",
    ``TABLE_START``, ``STHENIC_START``, ...), what it starts from (``variables``: the solver's
    variables, or what a design's solver takes, such as (z, radii)) and the barrier it is
    solved under (one of ``biped.optimization.solver.BARRIERS``). A report's history names
    it by its ``kind``: the source, then the barrier's ending (``BARRIER_ENDINGS``)."""

    source: str
    variables: object
    barrier: str = "adaptive"

    def __post_init__(self):
        if self.barrier not in BARRIERS:
            raise BipedError(f"barrier = {self.barrier!r}: allowed one of {', '.join(BARRIERS)}")

    @property
    def kind(self) -> str:
        """The start's name in a report's history: "sthenic optimum, monotone barrier"."""
        return self.source + ENDINGS.get(self.barrier, "")

    def under(self, barrier: str) -> Candidate:
        """The same start solved under ``barrier``."""
        return dataclasses.replace(self, barrier=barrier)


@dataclass
class Optimum:
    """A solution of a ``GaitProblem`` with its solver report.

    Attributes:
        problem: what was solved.
        variables: the solvers' variables (``biped.optimization.problem.VARIABLES``).
        parameters: the paper's 21 parameters (``biped.model.gait.PARAMETERS``).
        step: the step they build.
        evaluation: on the fine check grid.
        value: the criterion there (penalty included: equal to the criterion when feasible).
        report: how it was found.
    """

    problem: GaitProblem
    variables: np.ndarray
    parameters: np.ndarray
    step: Step
    evaluation: StepEvaluation
    value: float
    report: Report

    knee = property(lambda self: self.problem.knee)
    criterion = property(lambda self: self.problem.criterion)
    speed = property(lambda self: self.problem.speed)
    safety = property(lambda self: self.problem.safety)
    seconds = property(lambda self: self.report.seconds)

    @property
    def feasible(self) -> bool:
        return self.evaluation.feasible

    @property
    def certified(self) -> bool:
        """Converged, feasible on the fine grid."""
        return self.report.converged and self.feasible

    def rank(self) -> tuple:
        """Sort key: certified first, then feasible, then lower criterion."""
        return (not self.certified, not self.feasible, self.value)

    def costs(self) -> dict:
        """Both criteria of the paper and the motors' energy per metre (no penalty)."""
        ev = self.evaluation
        return {c: ev.value(c, self.step.step_length) for c in ("sthenic", "energy", "electrical")}


def check_method(method: str) -> str:
    if method not in METHODS:
        raise BipedError(f"method = {method!r}: allowed {', '.join(map(repr, METHODS))}")
    return method


def start_schedule(starts: int, seed: int, periods) -> list[tuple[str, float | None]]:
    """(source, period) of ``starts`` starts: the first guesses of the step periods [s]
    ``periods`` in order (None: a random start), random starts after them."""
    if isinstance(starts, bool) or not isinstance(starts, int) or starts < 0:
        raise BipedError(f"starts = {starts!r}: allowed an integer >= 0")
    if isinstance(seed, bool) or not isinstance(seed, (int, np.integer)) or seed < 0:
        raise BipedError(f"seed = {seed!r}: allowed an integer >= 0")
    periods = list(periods[:starts]) + [None] * (starts - len(periods))
    return [
        ("perturbed" if p is None else f"first guess T = {p:g} s" if k else "first guess", p)
        for k, p in enumerate(periods)
    ]


def first_guesses(
    problem: GaitProblem, starts: int, seed: int, by_table: bool = True
) -> list[Candidate]:
    """``starts`` first guesses in the bounds: the default first guess, then first guesses of
    other step periods (``GUESS_PERIODS``: the step length a gait settles on is its largest
    choice, and the basins of the optima follow it), then perturbations of the default. For
    the energy criterion per step, the family of short steps ``ENERGY_GUESS_LENGTHS`` under
    the monotone barrier instead (``energy_first_guesses``); the energy per metre takes steps
    of the sthenic criterion's lengths (0.18 m at 0.3 m/s), which these first guesses reach.
    ``by_table``: the energy criterion's default first guesses are replaced by the table's
    starts where it covers the problem (``energy_first_guesses``; False: all solved)."""
    if problem.criterion == "energy":
        return energy_first_guesses(problem, starts, seed, by_table)
    schedule = start_schedule(starts, seed, GUESS_PERIODS)
    guess, rng = problem.first_guess(), np.random.default_rng(seed)
    return [
        Candidate(
            source,
            perturbed(guess, rng, problem.knots) if period is None else problem.first_guess(period),
        )
        for source, period in schedule
    ]


# Step lengths [m] of the energy criterion's first guesses, in order. Its optima take short
# steps (0.06-0.11 m at 0.15-0.45 m/s, against 0.13-0.25 m for the sthenic criterion), and
# from a first guess of the sthenic criterion's periods, or under the adaptive barrier from
# any first guess, IPOPT ends in a basin of 2-7 times the least energy at every speed of the
# default sweep; under the monotone barrier from these lengths it reaches the least at some.
ENERGY_GUESS_LENGTHS = (0.1, 0.08, 0.12)


def energy_first_guesses(
    problem: GaitProblem, starts: int, seed: int, by_table: bool = True
) -> list:
    """``starts`` first guesses of the energy criterion, each solved under the monotone
    barrier: steps of the lengths ``ENERGY_GUESS_LENGTHS`` at the problem's speed, then
    perturbations of the first. Where the table of optima covers the problem
    (``biped.optimization.table.covers``) its starts (``table_starts``) take the place of
    the first guesses of those lengths, and only the perturbations beyond are solved: over
    the default sweep the table's starts and the sthenic optimum's reach every optimum the
    first guesses reached, and one lower, in 0.64 times the iterations
    (``benchmarks/energy_starts.py``)."""
    covered = by_table and table.covers(problem)
    skipped = min(len(ENERGY_GUESS_LENGTHS), starts) if covered else 0
    return _energy_guesses(problem, starts, seed)[skipped:]


def _energy_guesses(problem: GaitProblem, starts: int, seed: int) -> list:
    lengths = ENERGY_GUESS_LENGTHS[:starts]
    guesses = [
        Candidate(
            f"first guess S = {length:g} m", problem.first_guess(length / problem.speed), "monotone"
        )
        for length in lengths
    ]
    rng = np.random.default_rng(seed)
    base = guesses[0].variables if guesses else problem.first_guess()
    guesses += [
        Candidate("perturbed", perturbed(base, rng, problem.knots), "monotone")
        for _ in range(starts - len(lengths))
    ]
    return guesses


def perturbed(guess, rng: np.random.Generator, knots: int = 1) -> np.ndarray:
    """``guess`` (variables of the family of ``knots``) perturbed by ``PERTURBATION`` x its
    scales (``biped.optimization.problem.scales``), in the bounds."""
    lower, upper = bounds(knots)
    z = guess + PERTURBATION * scales(knots) * rng.standard_normal(np.shape(guess))
    z[:2] = np.abs(z[:2])  # the knee bends stay bends
    return np.clip(z, lower, upper)


def multistart(candidates, solve, seed: int, began: float, jobs: int | None = None, search=None):
    """The best solution from the starts ``candidates`` and its ``Report``: the multistart of
    gaits (``optimize``) and designs (``biped.optimization.design``), each giving its starts
    and what solves one.

    Args:
        candidates: the starts (``Candidate``: each its barrier).
        solve: ``solve(start, barrier)`` -> ``biped.optimization.solver.Solution``.
        seed: recorded in the report.
        began: ``time.perf_counter()`` when the search began, for the report's seconds.
        jobs: processes solving the starts at once (``biped.runtime.runner.run_forked``;
            default ``biped.runtime.runner.free_cores()``); the result is the same.
        search: ``search(start, barrier)`` -> ``Solution`` on a coarser grid: each start
            is searched there, then polished by ``solve`` (``coarse_to_fine``); None: each
            start solved by ``solve`` alone.

    Returns:
        (best, report): the converged solution of least value (of every solution when none
        converged; a NaN value ranks last).
    """
    if not candidates:
        raise BipedError("no start: allowed starts >= 1 or given starts")
    jobs = free_cores() if jobs is None else jobs
    if search is None:

        def solve_start(candidate: Candidate):
            return solve(candidate.variables, candidate.barrier)

        ends = run_forked(solve_start, list(candidates), jobs, _far_first(candidates))
    else:
        ends = coarse_to_fine(list(candidates), search, solve, jobs)
    solutions = list(zip([c.kind for c in candidates], ends, strict=True))
    converged = [s for _, s in solutions if s.converged]
    pool = converged or [s for _, s in solutions]
    best = min(pool, key=lambda s: s.value if np.isfinite(s.value) else np.inf)
    history = tuple(Start(kind, s.value, s.status, s.iterations) for kind, s in solutions)
    report = Report(
        method="ipopt",
        status="converged" if best.converged else best.status,
        starts=len(solutions),
        starts_at_best=starts_at_value(history, best.value),
        iterations=best.iterations,
        constraint_violation=best.constraint_violation,
        dual_infeasibility=best.dual_infeasibility,
        seconds=time.perf_counter() - began,
        seed=int(seed),
        history=history,
        value=best.value,
    )
    return best, report


def _far_first(candidates) -> list[int]:
    """The indices of the starts from the sthenic optimum (of a criterion of work), to be
    solved first: far from the criterion's optima, they are the longest at most points (at
    0.3 m/s 89-169 IPOPT iterations, where the table's starts take 29-114), and a long
    solve started last keeps one process busy alone."""
    return [i for i, c in enumerate(candidates) if c.source == STHENIC_START]


def coarse_to_fine(candidates, search, solve, jobs: int) -> list:
    """The end of each start (``Candidate``) of ``candidates``: searched on the coarse grid
    (``search``), then polished from there on the problem's own (``solve``, IPOPT's adaptive
    barrier). Starts whose searches end at one value (within ``AGREEMENT``) are one coarse
    optimum, polished once: they share its end. A search that did not converge is solved on
    the problem's grid from its start instead. Each end counts the iterations and seconds of
    both grids."""
    searched = run_forked(lambda c: search(c.variables, c.barrier), candidates, jobs)
    groups = []  # [index of the search polished, indices of the starts sharing it]
    for index, end in enumerate(searched):
        shared = next(
            (
                g
                for g in groups
                if end.converged
                and searched[g[0]].converged
                and abs(end.value - searched[g[0]].value) <= AGREEMENT * abs(end.value)
            ),
            None,
        )
        if shared is None:
            groups.append([index, [index]])
        else:
            shared[1].append(index)

    def polish(group):
        first = searched[group[0]]
        if first.converged:
            return solve(first.variables, "adaptive")
        start = candidates[group[0]]
        return solve(start.variables, start.barrier)

    polished = run_forked(polish, groups, jobs)
    ends = [None] * len(candidates)
    for (_, members), end in zip(groups, polished, strict=True):
        for index in members:
            ends[index] = dataclasses.replace(
                end,
                iterations=searched[index].iterations + end.iterations,
                seconds=searched[index].seconds + end.seconds,
            )
    return ends


# Samples per spline piece of the coarse grid a sthenic optimum is searched on before it is
# polished on the problem's (``coarse_to_fine``): an iteration there costs about half, and
# from its optimum the polish takes 17-19 iterations, where a start takes 35-100 on the fine
# grid alone (``benchmarks/bench_optimize.py``). The energy criteria's landscape has close
# local minima that a polish from the coarse optimum does not keep: solved on their own grid.
COARSE_SAMPLES_PER_HALF = 8
COARSE_CRITERIA = ("sthenic",)


def coarse_problem(problem: GaitProblem) -> GaitProblem | None:
    """The problem on the coarse grid its starts are searched on, or None: it is solved on
    its own (another criterion than ``COARSE_CRITERIA``, a richer family than the paper's
    spline, or a grid that is not the default)."""
    if problem.criterion not in COARSE_CRITERIA or problem.knots != 1:
        return None
    if not problem.on_default_grid:  # a grid asked for is solved on as it is
        return None
    return dataclasses.replace(problem, samples_per_half=COARSE_SAMPLES_PER_HALF)


def prepare(problem: GaitProblem) -> float:
    """Build the solvers an optimization of ``problem`` needs (``solver_for``, once per
    process: the energy criterion's sthenic twin's too, and the coarse grid's of a sthenic
    search, ``coarse_problem``) with the barriers its starts are solved with
    (``barriers_of``); returns the seconds it took (0 when they were built already)."""
    began = time.perf_counter()
    criteria = (
        {problem.criterion, "sthenic"}
        if problem.criterion in WORK_CRITERIA
        else {problem.criterion}
    )
    for criterion in sorted(criteria):
        for knots in dict.fromkeys((1, problem.knots)):  # the paper's spline first
            family = dataclasses.replace(
                problem, criterion=criterion, knots=knots, samples_per_half=None
            )
            solver_for(family).prepare(barriers_of(family))
            coarse = coarse_problem(family)
            if coarse is not None:
                solver_for(coarse).prepare(barriers_of(coarse))
    return time.perf_counter() - began


def barriers_of(problem: GaitProblem) -> tuple[str, ...]:
    """The barriers (``Candidate.barrier``) the starts of an optimization of ``problem`` are solved
    with: the adaptive one, and for the criteria of work the monotone one too (their table
    start, ``table_starts``, and the energy per step's first guesses), for the energy per
    step also the one from mu = 1e-4 (its table start, ``NEAR``)."""
    if problem.criterion not in WORK_CRITERIA:
        return ("adaptive",)
    if problem.criterion == "energy":
        return ("adaptive", "monotone", "near")
    return ("adaptive", "monotone")


def optimize(
    problem: GaitProblem,
    seed: int = 0,
    starts: int = DEFAULT_STARTS,
    given=(),
    nelder_mead_starts: int = 0,
    method: str = "ipopt",
    max_restarts: int = MAX_RESTARTS,
    evaluations_per_run: int = EVALUATIONS_PER_RUN,
    solvers=None,
    sthenic: Optimum | None = None,
    jobs: int | None = None,
    below: Optimum | None = None,
) -> Optimum:
    """The best gait of ``problem``.

    Args:
        seed: seed of the perturbed starts and of Nelder-Mead; the same seed gives the
            same result.
        starts: IPOPT's own starts (``first_guesses``): first guesses of several step
            periods (of step lengths for the energy criterion), then perturbations; the
            table's starts come with them (``table_starts``; with ``starts`` = 0, none),
            and for the energy criterion replace its first guesses where the table covers
            the problem.
        given: further starts, each the solvers' variables (21,) (e.g. the optimum at a
            neighbouring speed).
        nelder_mead_starts: IPOPT also starts from the paper's Nelder-Mead run with seeds
            ``seed``, ``seed + 1``, ...
        method: ``"ipopt"`` or ``"nelder-mead"`` (the paper's method alone, with
            ``max_restarts`` and ``evaluations_per_run``, from the first guess with seed 0
            and from the seed's perturbation of it otherwise).
        solvers: ``solvers(problem)`` gives what solves a problem from a start,
            ``.solve(problem, z, barrier=...)`` (default ``biped.optimization.solver.solver_for``;
            ``barrier`` one of ``biped.optimization.solver.BARRIERS``; ``biped.optimization.design``
            gives its graph with the knee radii held, which serves every radius); asked for
            the coarse grid's problem too (``coarse_problem``).
        sthenic: for the energy criterion, the sthenic optimum of the same problem with
            the same ``seed`` and ``starts``, if already known (a sweep's): it starts the
            energy criterion as the one this call would compute (None: computed here).
        jobs: processes solving the starts at once (default: the cores free,
            ``biped.runtime.runner.free_cores``); the optimum is the same.
        below: for a richer family, the optimum of the same problem in a family it holds
            (the rung below on a ladder, ``biped.optimization.ladder``), its start in place of
            the paper's spline's optimum (None: that optimum, computed here).
    """
    check_method(method)
    if not isinstance(problem, GaitProblem):
        raise BipedError(f"problem = {problem!r}: allowed a biped.optimization.problem.GaitProblem")
    began = time.perf_counter()
    if problem.knots != 1 and (method == "nelder-mead" or nelder_mead_starts):
        raise BipedError(
            f"knots = {problem.knots} with the paper's Nelder-Mead: allowed knots = 1 (its "
            "method optimizes the paper's spline)"
        )
    if method == "nelder-mead":
        return _nelder_mead_only(problem, seed, max_restarts, evaluations_per_run, began)
    solver = (solver_for if solvers is None else solvers)(problem)
    candidates = first_guesses(problem, starts, seed) + table_starts(problem, starts)
    if starts > 0:  # the table's starts are among these: a given one of them is that start
        given = apart_from_table(problem, given)
    candidates += [Candidate("given", np.asarray(z, dtype=float)) for z in given]
    if problem.knots != 1 and starts > 0:
        candidates += _paper_start(problem, seed, starts, solvers, jobs, below)
    if problem.criterion in WORK_CRITERIA and starts > 0:
        candidates += _sthenic_start(problem, seed, starts, solvers, sthenic, jobs)
    candidates += _nelder_mead_starts(
        problem, seed, nelder_mead_starts, max_restarts, evaluations_per_run
    )
    barriers = {c.barrier for c in candidates}
    solver.prepare(barriers)
    best, report = multistart(
        candidates,
        lambda z, barrier: solver.solve(problem, z, barrier=barrier),
        seed,
        began,
        jobs,
        _coarse_search(problem, barriers, solvers),
    )
    return checked(problem, best.variables, report)


def _nelder_mead_starts(problem, seed, count, max_restarts, evaluations_per_run) -> list:
    """The ends of the paper's Nelder-Mead from the first guess with the seeds ``seed``,
    ``seed + 1``, ... (``count`` runs), as IPOPT's starts."""
    starts = []
    for k in range(count):
        parameters, *_ = nelder_mead(
            problem,
            problem.to_parameters(problem.first_guess()),
            np.random.default_rng(seed + k),
            max_restarts,
            evaluations_per_run,
        )
        try:
            starts.append(Candidate("nelder-mead", problem.from_parameters(parameters)))
        except BipedError:
            continue  # a Nelder-Mead point out of reach starts nothing
    return starts


def _coarse_search(problem: GaitProblem, barriers, solvers=None):
    """``search(z, barrier)`` on the coarse grid of ``problem`` (``coarse_problem``), its
    solver (``solvers``' of the coarse problem, as ``optimize``'s) built with ``barriers``;
    None when the problem is solved on its own grid."""
    coarse = coarse_problem(problem)
    if coarse is None:
        return None
    coarse_solver = (solver_for if solvers is None else solvers)(coarse)
    coarse_solver.prepare(barriers)
    return lambda z, barrier: coarse_solver.solve(coarse, z, barrier=barrier)


def table_starts(problem: GaitProblem, starts: int) -> list:
    """The start of the table of optima at the neighbouring speeds
    (``biped.optimization.table``) and the other knee's, with ``starts`` > 0, when the
    table has the problem's knee and criterion. The criteria of work have close local
    minima, and from one start each barrier may end in another: the neighbours' start is
    solved under the monotone barrier too; for the energy criterion per step where the
    table covers the problem (``biped.optimization.table.covers``: its starts then replace
    the first guesses), from mu = 1e-4 (``NEAR``) instead, and the other knee's start under
    the monotone barrier and from mu = 1e-4 too: with the sthenic optimum's, the starts
    that reach every optimum of the default sweep, and a lower one (revolute knee,
    0.15 m/s: from the rolling knee's optimum, from mu = 1e-4 alone)."""
    if starts == 0:
        return []
    found = [
        Candidate(TABLE_START, _embedded(problem, table.start(problem))),
        Candidate(OTHER_KNEE_START, _embedded(problem, table.other_knee_start(problem))),
    ]
    found = [start for start in found if start.variables is not None]
    if problem.criterion not in WORK_CRITERIA:
        return found
    twins = {TABLE_START: ("monotone",)}
    if problem.criterion == "energy" and table.covers(problem):
        twins = {TABLE_START: ("near",), OTHER_KNEE_START: ("monotone", "near")}
    return [
        twin
        for start in found
        for twin in [start] + [start.under(barrier) for barrier in twins.get(start.source, ())]
    ]


# Two starts are one when their variables differ by less than this, in units of their
# scales (``biped.optimization.problem.scales``): from both IPOPT ends at the same point.
SAME_START = 1e-5


def apart_from_table(problem: GaitProblem, given) -> list[np.ndarray]:
    """The starts of ``given`` (variables) that are none of the table's (``table_starts``),
    to ``SAME_START``. A campaign's other-knee optimum is the table's other-knee start when
    the table was made from such a campaign (in the default sweep at 49 of its 52 points,
    ``benchmarks/given_starts.py``): it is one of the point's own starts already, and
    solved again it would reach the same end and count as a second start."""
    own = [start.variables for start in table_starts(problem, 1)]
    scale = scales(problem.knots)

    def known(z):
        return any(np.max(np.abs((z - t) / scale)) < SAME_START for t in own)

    given = [np.asarray(z, dtype=float) for z in given]
    return [z for z in given if not known(z)]


def _embedded(problem: GaitProblem, variables):
    """The paper spline's ``variables`` in the problem's family (None stays None)."""
    return None if variables is None else problem.embedded(variables, exact=False)


# A richer family's start from the optimum of the paper's spline (its family holds it), or
# of the family below it on a ladder (``BELOW_START``).
PAPER_START = "optimum of the paper's spline"
BELOW_START = "optimum of the family below"


def _paper_start(
    problem: GaitProblem, seed, starts, solvers=None, jobs=None, below: Optimum | None = None
) -> list:
    """The optimum of the same problem with the paper's spline (``below``, the optimum of a
    family the problem's holds, when given), the same gait in the problem's richer family:
    from it the richer family's optimum is never worse. A family that does not hold the
    paper's (an even number of knots) starts from the spline through its angles and rates at
    the knots."""
    if below is None:
        paper = dataclasses.replace(problem, knots=1, samples_per_half=None)
        below = optimize(paper, seed, starts, solvers=solvers, jobs=jobs)
        kind = PAPER_START
    else:
        _check_below(problem, below)
        kind = PAPER_START if below.problem.knots == 1 else BELOW_START
    if not below.report.converged:
        return []
    odd = isinstance(problem.knots, int) and problem.knots % 2 == 1
    exact = below.problem.knots != 1 or odd  # else fitted: a Bézier, or an even K
    start = problem.embedded(below.variables, below.problem.knots, exact=exact)
    return [Candidate(kind, start)]


def _check_below(problem: GaitProblem, below) -> None:
    """Refuse a ``below`` that is not an optimum of the same problem in a family the
    problem's holds."""
    if not isinstance(below, Optimum):
        raise BipedError(f"below = {below!r}: allowed a biped.optimization.optimize.Optimum")
    same = dataclasses.replace(below.problem, knots=problem.knots, samples_per_half=None)
    if _family(same)[:-2] != _family(problem)[:-2]:
        raise BipedError(
            f"below: an optimum of {below.problem.describe()}: allowed one of "
            f"{problem.describe()} in a family it holds"
        )


# The energy criterion's starts from the sthenic optimum, under IPOPT's adaptive and its
# monotone barrier: from the same point they may end in different local minima (0.1 % apart
# for the revolute knee at 0.3 m/s, tests/test_optimize.py), and either may be the lower.
STHENIC_START = "sthenic optimum"
# A start solved under the monotone barrier is named as its twin under the adaptive one, then
# this; the two are one start when both reach a value (``starts_at_value``).
MONOTONE = ", monotone barrier"
MONOTONE_START = STHENIC_START + MONOTONE


def _sthenic_start(
    problem: GaitProblem, seed, starts, solvers=None, sthenic: Optimum | None = None, jobs=None
) -> list:
    """The sthenic optimum of the same problem (``sthenic``, or computed), a start of the
    energy criterion: its landscape has basins of short fast steps (3-7 times the minimum)
    that no first guess escapes, and the gait of least torque lies in the basin of least
    energy."""
    twin = dataclasses.replace(problem, criterion="sthenic")
    if sthenic is not None and not isinstance(sthenic, Optimum):
        raise BipedError(
            f"sthenic = {sthenic!r}: allowed a biped.optimization.optimize.Optimum or None"
        )
    if sthenic is None:
        sthenic = optimize(twin, seed, starts, solvers=solvers, jobs=jobs)
    elif _family(sthenic.problem) != _family(twin):
        raise BipedError(
            f"sthenic = the optimum of {sthenic.problem.criterion} at {sthenic.problem.speed} "
            f"m/s ({sthenic.problem.knee} knee): allowed the sthenic optimum of this problem"
        )
    return sthenic_starts(sthenic.report, sthenic.variables)


def sthenic_starts(report: Report, start) -> list[Candidate]:
    """The energy criterion's starts ``start`` from a sthenic optimum found as ``report``
    says, under both barriers (``STHENIC_START``, ``MONOTONE_START``): none unless it
    converged."""
    if not report.converged:
        return []
    return [Candidate(STHENIC_START, start), Candidate(STHENIC_START, start, "monotone")]


# A start solved to a tighter tolerance (``biped.optimization.solver.BARRIERS["tight"]``).
TIGHT = ", tight tolerance"
# A start solved under the monotone barrier from mu = 1e-3 (``BARRIERS["confirm"]``,
# ``confirm``).
CONFIRM = ", monotone barrier from 1e-3"
# A start near an optimum solved under the monotone barrier from mu = 1e-4
# (``BARRIERS["near"]``, ``table_starts``).
NEAR = ", monotone barrier from 1e-4"
# The ending of a start's kind in a report's history for the barrier it was solved under
# (``Candidate.kind``); none: the adaptive one.
BARRIER_ENDINGS = {TIGHT: "tight", MONOTONE: "monotone", CONFIRM: "confirm", NEAR: "near"}
ENDINGS = {barrier: ending for ending, barrier in BARRIER_ENDINGS.items()}


def _ending(kind: str) -> str:
    """The ending of ``BARRIER_ENDINGS`` a recorded start's kind has, or ""."""
    return next((end for end in BARRIER_ENDINGS if kind.endswith(end)), "")


def start_of(kind: str) -> str:
    """The start a recorded kind (a report's history, as read from a file) names, without the
    barrier it was solved with (``BARRIER_ENDINGS``)."""
    return kind[: len(kind) - len(_ending(kind))]


def refine(problem: GaitProblem, start, barrier: str = "adaptive", seed: int = 0) -> Optimum:
    """``problem`` solved from the one start ``start`` (variables, "given"), under ``barrier``
    (``"tight"``: to a tighter tolerance): an optimum re-solved on a finer grid or more
    tightly, for its error bar."""
    began = time.perf_counter()
    solver = solver_for(problem)
    best, report = multistart(
        [Candidate("given", np.asarray(start, dtype=float), barrier)],
        lambda z, barrier: solver.solve(problem, z, barrier=barrier),
        seed,
        began,
        jobs=1,
    )
    return checked(problem, best.variables, report)


def _family(problem: GaitProblem) -> tuple:
    """What makes two problems one (``Biped`` compares by identity)."""
    return (
        problem.model.robot,
        problem.knee,
        problem.speed,
        problem.criterion,
        problem.safety,
        problem.samples_per_half,
        problem.knots,
    )


def starts_at_value(history, value: float) -> int:
    """Converged starts within ``AGREEMENT`` of ``value``; one point solved under several barriers
    (kinds "X", "X, monotone barrier", "X, monotone barrier from 1e-3", "X, monotone barrier
    from 1e-4") is one start: it does not confirm itself. Of a kind several starts may reach the
    value (the given ones): a start counts as many as the most of its barriers."""
    kinds = [
        s.kind
        for s in history
        if s.status in CONVERGED and abs(s.value - value) <= AGREEMENT * abs(value)
    ]
    most: dict[str, int] = {}
    for kind in set(kinds):
        start = start_of(kind)
        most[start] = max(most.get(start, 0), kinds.count(kind))
    return sum(most.values())


def confirm(problem: GaitProblem, optimum: Optimum, given=(), jobs: int | None = None):
    """``optimum``, or, when IPOPT reached its best value of a criterion of work from a single
    start, the best of it and of more starts, each near an optimum: the table's and the other
    knee's (``table_starts``) and ``given`` (e.g. the optima at the neighbouring speeds), under
    the monotone barrier from mu = 1e-3 (``CONFIRM``), the other knee's also from mu = 1e-2; a
    start the optimum's history holds already (the energy criterion's other knee's from 1e-2) is
    not solved again, as it would count its own value twice. The energy criteria's local minima
    lie 0.01-0.1 % apart, and from the same start these barriers follow other paths among them
    than the first starts' (at 0.25 m/s the revolute knee's least energy per step, reached by
    the other knee's start under the monotone barrier alone, is reached again from the
    neighbours' and the other knee's optima from mu = 1e-3); they may also reach a lower
    optimum, which replaces ``optimum`` only when lower on the solver's samples too (the problem
    IPOPT solves; ``best_of`` ranks by the check grid): a confirmation never leaves a higher
    optimum. An optimum whose solver did not converge is returned as it is (there is nothing to
    confirm). The starts run on ``jobs`` processes (``multistart``)."""
    if not isinstance(problem, GaitProblem):
        raise BipedError(f"problem = {problem!r}: allowed a biped.optimization.problem.GaitProblem")
    if not isinstance(optimum, Optimum):
        raise BipedError(f"optimum = {optimum!r}: allowed a biped.optimization.optimize.Optimum")
    report = optimum.report
    settled = report.method != "ipopt" or not report.converged or report.confirmed
    if settled or problem.criterion not in WORK_CRITERIA:
        return optimum
    near = [start for start in table_starts(problem, 1) if start.barrier == "adaptive"]
    candidates = [start.under("confirm") for start in near]
    candidates += [start.under("monotone") for start in near if start.source == OTHER_KNEE_START]
    solved = {start.kind for start in report.history}  # the same start again adds nothing
    candidates = [start for start in candidates if start.kind not in solved]
    given = apart_from_table(problem, given)
    candidates += [Candidate("given", np.asarray(z, dtype=float), "confirm") for z in given]
    if not candidates:
        return optimum
    began = time.perf_counter()
    solver = solver_for(problem)
    solver.prepare({start.barrier for start in candidates})
    best, again = multistart(
        candidates,
        lambda z, barrier: solver.solve(problem, z, barrier=barrier),
        report.seed,
        began,
        jobs,
    )
    found = checked(problem, best.variables, again)
    lower = again.converged and again.value < report.value * (1 - AGREEMENT)
    return best_of(problem, [optimum, found], None if lower else optimum)


def next_optimum(report: Report) -> float | None:
    """Where one start alone reached the best value of ``report``: the relative distance
    from it to the next optimum its other converged starts reached (the spread of the
    starts), None where none of them converged; 0 where at least two starts reached it."""
    if report.starts_at_best >= 2:
        return 0.0
    best = report.value
    above = [
        s.value
        for s in report.history
        if s.status in CONVERGED and np.isfinite(s.value) and s.value > best * (1 + AGREEMENT)
    ]
    return min(above) / best - 1.0 if above else None


def single_start_note(report: Report) -> str:
    """Why the best value of ``report`` counts one start: the start that reached it, and the
    next optimum the starts reached, how far above and by how many starts ("by the optima
    table at neighbouring speeds alone; the next optimum +0.096 %, by 4 starts"): the
    energy criterion's local minima lie close together, and one start may find a lower
    one than the others all reach."""
    best = report.value
    converged = [s for s in report.history if s.status in CONVERGED and np.isfinite(s.value)]
    at = [s.kind for s in converged if abs(s.value - best) <= AGREEMENT * abs(best)]
    text = f"by {_named_starts(at) or 'the best start'} alone"
    others = sorted(s.value for s in converged if s.value > best * (1 + AGREEMENT))
    if others:
        count = starts_at_value(converged, others[0])
        starts = "start" if count == 1 else "starts"
        text += f"; the next optimum {100 * (others[0] / best - 1):+.3g} %, by {count} {starts}"
    return text


GIVEN_NAME = "a given start (another problem's optimum, or an earlier stage's)"


def _named_starts(kinds) -> str:
    """Starts named once each, with the barriers they reached the value under: "the sthenic
    optimum under the adaptive barrier and the monotone barrier from 1e-4"."""
    barriers: dict[str, list[str]] = {}
    for kind in dict.fromkeys(kinds):
        barriers.setdefault(start_of(kind), []).append(_ending(kind).removeprefix(", "))
    names = []
    for start, endings in barriers.items():
        name = GIVEN_NAME if start == "given" else f"the {start}"
        if endings != [""]:
            under = ", under " if "," in start else " under "  # "the optima table, other knee"
            name += under + " and ".join(f"the {e or 'adaptive barrier'}" for e in endings)
        names.append(name)
    return " and ".join(names)


def best_of(problem: GaitProblem, optima, best: Optimum | None = None) -> Optimum:
    """The best of several optima of ``problem`` (certified first, then the lowest value;
    or ``best``, one of them), its report counting the starts of all."""
    optima = list(optima)
    best = min(optima, key=lambda o: o.rank()) if best is None else best
    history = tuple(s for o in optima for s in o.report.history)
    report = dataclasses.replace(
        best.report,
        starts=len(history),
        starts_at_best=starts_at_value(history, best.report.value),
        seconds=sum(o.report.seconds for o in optima),
        history=history,
    )
    return dataclasses.replace(best, report=report)


def _nelder_mead_only(problem, seed, max_restarts, evaluations_per_run, began) -> Optimum:
    # seed 0 starts from the first guess, seed k > 0 from its perturbation number k (as a
    # designer would try a few first guesses); the seed drives the restarts too.
    guess = problem.first_guess()
    if seed != 0:
        guess = perturbed(guess, np.random.default_rng(seed))
    start = problem.to_parameters(guess)
    parameters, history, count, converged = nelder_mead(
        problem, start, np.random.default_rng(seed), max_restarts, evaluations_per_run
    )
    report = Report(
        method="nelder-mead",
        status="converged" if converged else "budget exhausted",
        starts=1,
        starts_at_best=1,
        iterations=count,
        constraint_violation=float("nan"),
        dual_infeasibility=float("nan"),
        seconds=time.perf_counter() - began,
        seed=int(seed),
        history=(Start("first guess", history[-1], "converged" if converged else "budget", count),),
        value=history[-1],
    )
    return checked(problem, None, report, parameters)


def checked(problem: GaitProblem, variables, report: Report, parameters=None) -> Optimum:
    """An ``Optimum`` of ``variables`` (or the paper's ``parameters``), evaluated on the fine
    check grid."""
    if parameters is None:
        parameters = problem.to_parameters(variables)
    elif variables is None:
        try:
            variables = problem.from_parameters(parameters)
        except BipedError:
            variables = np.full(len(parameters), np.nan)
    step = build_step(problem.model, problem.speed, parameters, problem.knots)
    samples = CHECK_SAMPLES[problem.knots]
    evaluation = evaluate_step(problem.model, step, samples, safety=problem.safety)
    return Optimum(
        problem=problem,
        variables=np.asarray(variables, dtype=float),
        parameters=np.asarray(parameters, dtype=float),
        step=step,
        evaluation=evaluation,
        value=evaluation.cost(problem.criterion, step.step_length),
        report=report,
    )
