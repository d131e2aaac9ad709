"""Which starts reach the energy criterion's optima: at every point of the default sweep (both
knees, 13 speeds), each start near an optimum (the table's neighbours, the other knee's, the
sthenic optimum) solved under each barrier, and the default first guesses, one by one; then,
for the start set of ``biped.optimization.optimize`` and for the one before it, the points
where the set reaches the best value found, the points it confirms (two starts or more, a
start's barriers counted once) and its IPOPT iterations in all.

    python benchmarks/energy_starts.py [--jobs N] [--points revolute:0.15 ...]

The best value of a point is the least any start reached (solver's samples); a set reaches it
within ``AGREEMENT``. Takes 2 min 14 s on a 2-core AMD EPYC.
"""

import argparse

import numpy as np

import biped
from biped.optimization import table
from biped.optimization.optimize import (
    AGREEMENT,
    MONOTONE,
    STHENIC_START,
    Candidate,
    Start,
    first_guesses,
    optimize,
    starts_at_value,
    table_starts,
)
from biped.optimization.problem import GaitProblem
from biped.optimization.solver import CONVERGED, solver_for
from biped.runtime.runner import free_cores, run_forked
from biped.studies.sweep import DEFAULT_SPEEDS

# The barriers each start near an optimum is solved under: the adaptive, then monotone from
# 1e-2, 1e-3 and 1e-4.
NEAR_BARRIERS = ("adaptive", "monotone", "confirm", "near")
NEAR_STARTS = (table.TABLE_START, table.OTHER_KNEE_START, STHENIC_START)
FIRST_GUESSES = "first guesses"
STHENIC_STARTS = [STHENIC_START, STHENIC_START + MONOTONE]
# The energy criterion's starts before the table replaced its first guesses (``Start.kind``).
BEFORE = [FIRST_GUESSES, table.TABLE_START, table.TABLE_START + MONOTONE]
BEFORE += [table.OTHER_KNEE_START, *STHENIC_STARTS]


def problem_of(knee: str, speed: float) -> GaitProblem:
    return GaitProblem(biped.Biped(biped.Robot.paper(), knee), speed, "energy")


def starts_now(problem: GaitProblem) -> list[str]:
    """The kinds of the energy criterion's starts of ``optimize`` today at ``problem``."""
    kinds = [start.kind for start in table_starts(problem, 1)] + STHENIC_STARTS
    return kinds if table.covers(problem) else [FIRST_GUESSES, *kinds]


def solve_point(point) -> list[Start]:
    """Every start of one point (knee, speed) solved alone: (kind, value, status, iterations)."""
    problem = problem_of(*point)
    solver = solver_for(problem)
    sthenic = optimize(GaitProblem(problem.model, problem.speed, "sthenic"), jobs=1)
    near = {start.source: start.variables for start in table_starts(problem, 1)}
    near[STHENIC_START] = sthenic.variables
    runs = [
        Candidate(f"{FIRST_GUESSES}: {guess.source}", guess.variables, guess.barrier)
        for guess in first_guesses(problem, 3, 0, False)
    ]
    runs += [Candidate(s, near[s], barrier) for s in NEAR_STARTS for barrier in NEAR_BARRIERS]
    found = []
    for run in runs:
        end = solver.solve(problem, run.variables, barrier=run.barrier)
        found.append(Start(run.kind, end.value, end.status, end.iterations))
    return found


def of_set(starts: list[Start], kinds: list[str]) -> list[Start]:
    """The starts of a set: its kinds, the first guesses as one kind."""
    return [
        s
        for s in starts
        if s.kind in kinds or (FIRST_GUESSES in kinds and s.kind.startswith(FIRST_GUESSES))
    ]


def point_of(text: str) -> tuple[str, float]:
    """(knee, speed [m/s]) of "KNEE:SPEED"; an argparse error naming the text otherwise."""
    knee, _, speed = text.partition(":")
    try:
        if knee in biped.KNEES:
            return knee, float(speed)
    except ValueError:
        pass
    raise argparse.ArgumentTypeError(f"{text!r}: allowed KNEE:SPEED, KNEE one of {biped.KNEES}")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--jobs", type=int, default=free_cores())
    parser.add_argument(
        "--points", nargs="*", type=point_of, default=None, help="KNEE:SPEED, default the sweep's"
    )
    args = parser.parse_args()
    points = args.points or [(k, float(v)) for k in biped.KNEES for v in DEFAULT_SPEEDS]
    results = run_forked(solve_point, points, args.jobs)
    totals = {name: [0, 0, 0] for name in ("now", "before")}
    for (knee, speed), starts in zip(points, results, strict=True):
        converged = [s.value for s in starts if s.status in CONVERGED]
        best = min(converged, default=np.inf)
        line = []
        for name, kinds in (("now", starts_now(problem_of(knee, speed))), ("before", BEFORE)):
            chosen = of_set(starts, kinds)
            value = min((s.value for s in chosen if s.status in CONVERGED), default=np.inf)
            reached = value <= best * (1 + AGREEMENT)
            count = starts_at_value(chosen, value)
            totals[name][0] += reached
            totals[name][1] += reached and count >= 2
            totals[name][2] += sum(s.iterations for s in chosen)
            line.append(f"{name} {value:.9f} ({count} starts){'' if reached else ' ABOVE'}")
        at_best = [s.kind for s in starts if abs(s.value - best) <= AGREEMENT * best]
        print(f"{knee:8} {speed:.3f} best {best:.9f}: {'; '.join(line)}")
        print(f"    at best: {', '.join(at_best)}")
    for name, (reached, confirmed, iterations) in totals.items():
        print(
            f"{name}: reaches the best at {reached} of {len(points)} points, by two starts or "
            f"more at {confirmed}, {iterations} IPOPT iterations"
        )
    print(f"iterations now / before: {totals['now'][2] / totals['before'][2]:.2f}")


if __name__ == "__main__":
    np.seterr(all="ignore")
    main()
