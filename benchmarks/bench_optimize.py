"""One optimisation, IPOPT with exact derivatives from several starts, beside the method of
an earlier version kept here ("before": CasADi's Hessian of the whole graph, IPOPT's
gradient scaling, the first guesses and, for the energy criterion, the sthenic optimum under
both barriers, one start after the other), in the same process: setup, solve, value, starts
at the best value, ratios; and beside today's method without its coarse search of the
sthenic starts ("fine grid alone": every start solved on the problem's grid), and beside
today's method with CasADi's interpreter for its derivatives instead of compiled code
("interpreted", ``biped.optimization.compiled``: the same optimum to the bit). ``biped
optimize`` is timed as a whole process; ``--sweep`` times the default sweep both ways,
``--pipeline`` the pipeline without videos.

    python benchmarks/bench_optimize.py [--repeats N] [--sweep] [--pipeline]
"""

import os

for _var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ[_var] = "1"  # one BLAS thread, set before numpy loads its BLAS

import argparse  # noqa: E402
import contextlib  # noqa: E402
import subprocess  # noqa: E402
import sys  # noqa: E402
import tempfile  # noqa: E402
import time  # noqa: E402
from unittest import mock  # noqa: E402

import numpy as np  # noqa: E402
from timing import median_time  # noqa: E402

import biped  # noqa: E402
from biped.optimization import compiled as compiled_module  # noqa: E402
from biped.optimization import optimize as optimize_module  # noqa: E402
from biped.optimization import solver as solver_module  # noqa: E402
from biped.optimization.optimize import (  # noqa: E402
    first_guesses,
    multistart,
    optimize,
    prepare,
    sthenic_starts,
)
from biped.optimization.problem import GaitProblem  # noqa: E402
from biped.runtime.runner import free_cores  # noqa: E402
from biped.studies.sweep import run_sweep, sweep_settings  # noqa: E402

SPEED = 0.3
TARGETS = {"sthenic": 0.5, "energy": 1.5}  # [s] of a solve once set up
BIPED = [sys.executable, "-m", "biped"]


class Before(solver_module.Solver):
    """The solver before: CasADi's Hessian of the whole graph, IPOPT scaling the gradients."""

    def ipopt_options(self, barrier):
        options = super().ipopt_options(barrier)
        for key in ("hess_lag", "jac_g", "grad_f"):
            options.pop(key, None)
        options["ipopt.nlp_scaling_method"] = "gradient-based"
        return options


def build_before(problem) -> Before:
    """The solver before, built without the sample-by-sample Hessian it does not use."""
    with mock.patch.object(solver_module, "lagrangian_hessian", lambda *args: None):
        return Before(problem.model, problem.criterion, problem.safety, problem.samples_per_half)


def optimize_before(problem, solvers: dict):
    """The starts before, one after the other: the first guesses; for the energy criterion
    also the sthenic optimum of the same problem (itself optimized so) under both barriers."""
    began = time.perf_counter()
    solver = solvers[problem.criterion]
    candidates = first_guesses(problem, 3, 0, by_table=False)
    if problem.criterion == "energy":
        twin = GaitProblem(problem.model, problem.speed, "sthenic", problem.safety)
        sthenic = optimize_before(twin, solvers)
        candidates += sthenic_starts(sthenic.report, sthenic.variables)
    best, report = multistart(
        candidates, lambda z, barrier: solver.solve(problem, z, barrier=barrier), 0, began, jobs=1
    )
    return optimize_module.checked(problem, best.variables, report)


def whole_process(knee: str, criterion: str, repeats: int) -> float:
    """Median wall time [s] of ``biped optimize`` as a process (imports included)."""
    with tempfile.TemporaryDirectory() as folder:
        argv = BIPED + ["optimize", "--knee", knee, "--criterion", criterion]
        argv += ["--speed", str(SPEED), "--out", f"{folder}/gait.json"]
        seconds, _ = median_time(
            lambda: subprocess.run(argv, check=True, capture_output=True), repeats=repeats
        )
    return seconds


def one_optimization(repeats: int) -> None:
    print(
        f"one optimisation at {SPEED} m/s, default starts, median of {repeats}; "
        f"{free_cores()} cores"
    )
    print(
        f"{'':18}{'setup [s]':>20}{'solve [s]':>20}{'value':>24}{'starts at best':>18}"
        f"{'process [s]':>13}{'fine grid alone [s]':>27}{'interpreted [s]':>24}"
    )
    print(
        f"{'knee, criterion':18}{'before':>10}{'now':>7}{'ratio':>6}{'before':>10}{'now':>7}"
        f"{'ratio':>6}{'before':>12}{'now':>12}{'before':>9}{'now':>9}{'now':>13}"
        f"{'solve':>9}{'ratio':>6}{'value':>12}{'solve':>9}{'ratio':>6}{'same bits':>10}"
    )
    for criterion in ("sthenic", "energy"):
        for knee in biped.KNEES:
            problem = GaitProblem(biped.Biped(biped.Robot.paper(), knee), SPEED, criterion)
            began = time.perf_counter()
            before = {
                c: build_before(GaitProblem(problem.model, SPEED, c))
                for c in ("sthenic", criterion)
            }
            for solver in before.values():
                solver.prepare(("adaptive", "monotone"))
            setup_before = time.perf_counter() - began
            with interpreted():
                prepare(problem)
                solve_interpreted, slow = median_time(optimize, problem, repeats=repeats)
            setup_now = prepare(problem)
            solve_before, old = median_time(optimize_before, problem, before, repeats=repeats)
            solve_now, new = median_time(optimize, problem, repeats=repeats)
            with mock.patch.object(optimize_module, "COARSE_CRITERIA", ()):
                solve_fine, fine = median_time(optimize, problem, repeats=repeats)
            process = whole_process(knee, criterion, repeats)
            print(
                f"{knee + ', ' + criterion:18}{setup_before:10.2f}{setup_now:7.2f}"
                f"{setup_now / setup_before:6.2f}{solve_before:10.2f}{solve_now:7.2f}"
                f"{solve_now / solve_before:6.2f}{old.report.value:12.6f}{new.report.value:12.6f}"
                f"{f'{old.report.starts_at_best}/{old.report.starts}':>9}"
                f"{f'{new.report.starts_at_best}/{new.report.starts}':>9}{process:13.2f}"
                f"{solve_fine:9.2f}{solve_now / solve_fine:6.2f}{fine.report.value:12.6f}"
                f"{solve_interpreted:9.2f}{solve_now / solve_interpreted:6.2f}"
                f"{str(np.array_equal(slow.variables, new.variables)):>10}"
            )
    print(
        "targets: a solve (all starts) <= "
        + ", ".join(f"{t} s {c}" for c, t in TARGETS.items())
        + " once set up; biped optimize <= 2 s as a process"
    )


@contextlib.contextmanager
def interpreted():
    """Within the block, solvers built anew with CasADi's interpreter for their derivatives;
    after it, built anew compiled."""
    before = os.environ.get(compiled_module.SWITCH)
    os.environ[compiled_module.SWITCH] = "0"
    solver_module.forget_solvers()
    try:
        yield
    finally:
        if before is None:
            del os.environ[compiled_module.SWITCH]
        else:
            os.environ[compiled_module.SWITCH] = before
        solver_module.forget_solvers()


@contextlib.contextmanager
def solvers_before():
    """Within the block, every optimization runs the method before (its solvers, its starts)."""
    cache = {}

    def before(problem):
        key = (problem.knee, problem.criterion, problem.safety, problem.samples_per_half)
        if key not in cache:
            cache[key] = build_before(problem)
        return cache[key]

    def optimize_old(problem, seed=0, starts=3, given=(), sthenic=None, **kwargs):
        began = time.perf_counter()
        solver = before(problem)
        candidates = first_guesses(problem, starts, seed, by_table=False)
        candidates += [("given", np.asarray(z, dtype=float)) for z in given]
        if problem.criterion == "energy" and starts > 0:
            if sthenic is None:
                twin = GaitProblem(problem.model, problem.speed, "sthenic", problem.safety)
                sthenic = optimize_old(twin, seed, starts)
            candidates += sthenic_starts(sthenic.report, sthenic.variables)
        best, report = multistart(
            candidates, lambda z, b: solver.solve(problem, z, barrier=b), seed, began, jobs=1
        )
        return optimize_module.checked(problem, best.variables, report)

    with mock.patch("biped.studies.sweep.optimize", optimize_old):
        yield


def sweep() -> None:
    """The default sweep (both knees, both criteria, 13 speeds) on all cores, both ways; the
    method before runs in this process (``--jobs 1``), so its time is given per core too."""
    cores = free_cores()  # the processes of the sweep now
    with tempfile.TemporaryDirectory() as folder:
        began = time.perf_counter()
        with open(os.devnull, "w") as null:
            run_sweep(f"{folder}/now", sweep_settings(biped.Robot.paper()), stream=null)
        now = time.perf_counter() - began
        began = time.perf_counter()
        with solvers_before(), open(os.devnull, "w") as null:
            run_sweep(f"{folder}/before", sweep_settings(biped.Robot.paper()), stream=null, jobs=1)
        before = time.perf_counter() - began
    print(
        f"\ndefault sweep (2 knees x 2 criteria x 13 speeds): now {now:.1f} s on {cores} "
        f"processes; before {before:.1f} s on one process, {before / cores:.1f} s per core of "
        f"{cores}; ratio {now / (before / cores):.2f} (target 60 s)"
    )


def pipeline(repeats: int) -> None:
    with tempfile.TemporaryDirectory() as folder:
        argv = BIPED + ["pipeline", "--no-video", "--out", folder, "--recordings", folder]
        seconds, _ = median_time(
            lambda: subprocess.run(argv, check=True, capture_output=True), repeats=repeats
        )
    print(f"\nbiped pipeline --no-video as a process: {seconds:.1f} s (target 25 s)")


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=3, help="runs per figure (median)")
    parser.add_argument("--sweep", action="store_true", help="also time the default sweep")
    parser.add_argument("--pipeline", action="store_true", help="also time the pipeline")
    args = parser.parse_args()
    one_optimization(args.repeats)
    if args.pipeline:
        pipeline(args.repeats)
    if args.sweep:
        sweep()


if __name__ == "__main__":
    main()
