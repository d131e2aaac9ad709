"""One optimisation: IPOPT with exact derivatives from several starts, beside the previous
method in the same process (the paper's Nelder-Mead, then an SLSQP polish with finite
differences): value reached and seconds. ``--sweep`` also times the default sweep.

    python benchmarks/bench_optimize.py [--repeats N] [--sweep]
"""

import os

for _var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ[_var] = "1"  # one core, set before numpy loads its BLAS

import argparse  # noqa: E402
import tempfile  # noqa: E402
import time  # noqa: E402

import numpy as np  # noqa: E402
from timing import median_time  # noqa: E402

import biped  # noqa: E402
from biped.optimization.optimize import first_guesses, optimize  # noqa: E402
from biped.optimization.penalty import nelder_mead, polish  # noqa: E402
from biped.optimization.problem import GaitProblem  # noqa: E402
from biped.optimization.solver import solver_for  # noqa: E402
from biped.studies.sweep import run_sweep  # noqa: E402

SPEED = 0.3


def previous_method(problem):
    """Nelder-Mead (1500 evaluations, one restart) then SLSQP (200 iterations)."""
    start = problem.first_parameters()
    p, _, count, _ = nelder_mead(problem, start, np.random.default_rng(0))
    polished, more, message = polish(problem, p)
    from biped.optimization.optimize import Report, checked

    report = Report("nelder-mead+slsqp", message, 1, 1, count + more, np.nan, np.nan, 0.0, 0)
    return checked(problem, None, report, polished)


def _function_seconds(stats: dict):
    """Seconds IPOPT spent in each of CasADi's functions (criterion, constraints and their
    derivatives) in the last solve."""
    return [value for key, value in stats.items() if key.startswith("t_wall_nlp")]


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=5, help="optimisations per case (median)")
    parser.add_argument("--sweep", action="store_true", help="also time the default sweep")
    args = parser.parse_args()
    print(f"one optimisation at {SPEED} m/s, default starts, median of {args.repeats}")
    print(
        f"{'knee':10}{'criterion':10}{'build [s]':>10}{'IPOPT [s]':>11}{'value':>12}"
        f"{'starts at best':>16}{'previous [s]':>14}{'value':>12}{'ratio':>8}"
    )
    hessians = []
    for criterion in ("sthenic", "energy"):
        for knee in biped.KNEES:
            problem = GaitProblem(biped.Biped(biped.Robot.paper(), knee), SPEED, criterion)
            began = time.perf_counter()
            solver_for(problem)
            build = time.perf_counter() - began
            seconds, optimum = median_time(optimize, problem, repeats=args.repeats)
            report = optimum.report
            nlp = solver_for(problem).nlp
            hessian = nlp.get_function("nlp_hess_l").n_instructions()
            shares = []  # of each first-guess start's solve, in derivatives and functions
            for _, start in first_guesses(problem, 3, 0):
                solution = solver_for(problem).solve(problem, start)
                spent = sum(_function_seconds(nlp.stats()))
                shares.append(spent / solution.seconds)
            stats = nlp.stats()  # of the last of them
            calls = max(stats["n_call_nlp_hess_l"], 1)
            hessians.append(
                f"{knee:10}{criterion:10}{hessian / 1e6:9.2f} M SX instructions"
                f"{stats['t_wall_nlp_hess_l'] / calls * 1e3:8.2f} ms a call; the last start: "
                f"{stats['iter_count']} iterations, Hessians {stats['t_wall_nlp_hess_l']:.2f} s, "
                f"all derivatives and functions {sum(_function_seconds(stats)):.2f} s; "
                f"derivatives and functions over the 3 first guesses: "
                f"{min(shares):.0%}-{max(shares):.0%} of a solve"
            )
            began = time.perf_counter()
            old = previous_method(problem)
            old_seconds = time.perf_counter() - began
            print(
                f"{knee:10}{criterion:10}{build:10.2f}{seconds:11.2f}"
                f"{optimum.value:12.5f}{f'{report.starts_at_best}/{report.starts}':>16}"
                f"{old_seconds:14.2f}{old.value:12.5f}{old.value / optimum.value:8.3f}"
            )
    print("target: one optimisation (all starts) <= 0.5 s median once the graph is built")
    print("\nIPOPT's exact Hessian of the Lagrangian (CasADi SX virtual machine)")
    print("\n".join(hessians))
    if args.sweep:
        began = time.perf_counter()
        with tempfile.TemporaryDirectory() as folder:
            run_sweep(folder, biped.Robot.paper(), stream=open(os.devnull, "w"))  # noqa: SIM115
        print(
            f"\ndefault sweep (2 knees x 2 criteria x 13 speeds, all cores): "
            f"{time.perf_counter() - began:.1f} s (target 60 s)"
        )


if __name__ == "__main__":
    main()
