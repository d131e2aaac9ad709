"""Criterion evaluations per second and the time of one optimisation.

Reference, in the same process: the same criterion with the torques computed sample by
sample (a Python loop over the time grid) instead of vectorised over it.

    python benchmarks/bench_optimize.py [--repeats N]
"""

import os

for _var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ[_var] = "1"  # one core, set before numpy loads its BLAS

import argparse  # noqa: E402
import time  # noqa: E402

import numpy as np  # noqa: E402

import biped  # noqa: E402
from biped.gait import build_step, sample  # noqa: E402
from biped.optimize import OPTIMIZE_SAMPLES_PER_HALF, cost, initial_parameters, optimize  # noqa: E402

SPEED = 0.3


def per_sample_cost(model, p):
    """Sthenic criterion with one inverse-dynamics call per sample (the reference)."""
    step = build_step(model, SPEED, p)
    t, q, qd, qdd, *_ = sample(model, step, OPTIMIZE_SAMPLES_PER_HALF)
    squared = np.array(
        [(model.inverse_dynamics(*x)[0] ** 2).sum() for x in zip(q, qd, qdd, strict=True)]
    )
    n = OPTIMIZE_SAMPLES_PER_HALF + 1
    return (np.trapezoid(squared[:n], t[:n]) + np.trapezoid(squared[n:], t[n:])) / step.step_length


def rate(function, seconds=2.0):
    count, began = 0, time.perf_counter()
    while time.perf_counter() - began < seconds:
        function()
        count += 1
    return count / (time.perf_counter() - began)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=3, help="optimisations per knee (median)")
    args = parser.parse_args()
    print(
        f"criterion evaluations at {SPEED} m/s, "
        f"{2 * (OPTIMIZE_SAMPLES_PER_HALF + 1)} samples per step"
    )
    print(f"{'knee':10}{'vectorised':>14}{'per sample':>14}{'speed-up':>10}")
    for knee in biped.KNEES:
        model = biped.Biped(biped.Robot.paper(), knee)
        p = initial_parameters(model, SPEED)
        fast = rate(lambda: cost(model, SPEED, "sthenic", p, OPTIMIZE_SAMPLES_PER_HALF))  # noqa: B023
        slow = rate(lambda: per_sample_cost(model, p), seconds=1.0)  # noqa: B023
        print(f"{knee:10}{fast:10.0f} /s {slow:10.0f} /s {fast / slow:9.1f}x")
    print(f"\none optimisation (sthenic, {SPEED} m/s, default budget), median of {args.repeats}")
    for knee in biped.KNEES:
        model = biped.Biped(biped.Robot.paper(), knee)
        runs = []
        for seed in range(args.repeats):
            began = time.perf_counter()
            optimum = optimize(model, SPEED, "sthenic", seed=seed)
            runs.append((time.perf_counter() - began, optimum.evaluations, optimum.value))
        seconds = float(np.median([r[0] for r in runs]))
        evaluations = int(np.median([r[1] for r in runs]))
        values = ", ".join(f"{r[2]:.2f}" for r in runs)
        print(f"{knee:10}{seconds:6.1f} s  {evaluations} evaluations  criterion {values}")
    print("target: one optimisation within 10 s median")
    print(
        "\nNelder-Mead alone (the paper's method, same budget) against Nelder-Mead + SLSQP polish"
    )
    for knee in biped.KNEES:
        model = biped.Biped(biped.Robot.paper(), knee)
        alone = optimize(model, SPEED, "sthenic", polish_iterations=0)
        polished = optimize(model, SPEED, "sthenic")
        status = "feasible" if alone.feasible else "infeasible"
        print(
            f"{knee:10}criterion {alone.value:9.2f} ({status}) -> {polished.value:7.2f} with the"
            f" polish, {alone.value / polished.value:5.1f}x lower"
        )


if __name__ == "__main__":
    main()
