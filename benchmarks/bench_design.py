"""Knee co-design: one design optimization (radii and gait, default starts) at 0.3 m/s beside
one gait optimization at the Table 1 radii in the same process; then a 10 x 10 design map at
one speed on two local processes and on a local two-worker Dask cluster, with the same
numbers checked.

    python benchmarks/bench_design.py [--repeats N] [--grid N] [--no-map]
"""

import os

for _var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ[_var] = "1"  # one core per process, set before numpy loads its BLAS

import argparse  # noqa: E402
import io  # noqa: E402
import json  # noqa: E402
import logging  # noqa: E402
import tempfile  # noqa: E402
import time  # noqa: E402
from pathlib import Path  # noqa: E402

import numpy as np  # noqa: E402
from timing import median_time  # noqa: E402

import biped  # noqa: E402
from biped.optimization.design import DesignProblem, optimize_design, solver_for  # noqa: E402
from biped.optimization.optimize import optimize  # noqa: E402
from biped.optimization.solver import solver_for as gait_solver_for  # noqa: E402
from biped.studies.design_map import run_design_map  # noqa: E402

SPEED = 0.3
WORKERS = 2


def one_design(repeats: int) -> None:
    robot = biped.Robot.paper()
    problem = DesignProblem(robot, SPEED)
    gait = problem.gait_problem(problem.reference_radii)
    began = time.perf_counter()
    solver_for(problem)
    design_build = time.perf_counter() - began
    began = time.perf_counter()
    gait_solver_for(gait)
    gait_build = time.perf_counter() - began
    design_seconds, design = median_time(optimize_design, problem, repeats=repeats)
    gait_seconds, optimum = median_time(optimize, gait, repeats=repeats)
    print(f"one optimization at {SPEED} m/s, sthenic, default starts, median of {repeats}")
    print(f"{'':32}{'build [s]':>10}{'solve [s]':>11}{'iterations':>12}{'value':>12}{'starts':>8}")
    for label, build, seconds, result in (
        ("design (radii and gait)", design_build, design_seconds, design.optimum),
        ("gait at Table 1 radii", gait_build, gait_seconds, optimum),
    ):
        report = result.report
        iterations = sum(start.iterations for start in report.history)
        print(
            f"{label:32}{build:10.2f}{seconds:11.2f}{iterations:12d}{result.value:12.5f}"
            f"{f'{report.starts_at_best}/{report.starts}':>8}"
        )
    print(
        f"design / gait time: {design_seconds / gait_seconds:.2f}; optimal radii "
        f"r1 = {design.radii[0]:.4f} m, r2 = {design.radii[1]:.4f} m "
        f"(target: one design optimization <= 2 s once the graph is built)"
    )


def _values(folder: Path) -> dict:
    values = {}
    for path in sorted(folder.glob("*.json")):
        if path.name != "design-map.json":
            content = json.loads(path.read_text())
            values[path.name] = (content["value"], content["radii"], content["status"])
    return values


def design_map(grid: int) -> None:
    robot = biped.Robot.paper()
    r1 = np.linspace(0.0, robot.shank_com, grid)
    r2 = np.linspace(0.0, robot.thigh_length - robot.thigh_com, grid)
    optimizations = grid * grid + 3
    print(
        f"\n{grid} x {grid} design map at {SPEED} m/s ({optimizations} optimizations: the grid, "
        "revolute, Table 1, joint optimum)"
    )
    quiet = io.StringIO()
    with tempfile.TemporaryDirectory() as scratch:
        local, cluster_folder = Path(scratch) / "local", Path(scratch) / "dask"
        began = time.perf_counter()
        run_design_map(local, robot, [SPEED], r1, r2, jobs=WORKERS, stream=quiet)
        local_seconds = time.perf_counter() - began
        print(f"local, {WORKERS} processes:            {local_seconds:7.1f} s")
        try:
            from dask.distributed import LocalCluster
        except ImportError:
            print("dask.distributed is not installed (pip install '.[cluster]'): no Dask timing")
            return
        with LocalCluster(
            n_workers=WORKERS,
            threads_per_worker=1,
            processes=True,
            dashboard_address=None,
            silence_logs=logging.ERROR,
        ) as cluster:
            began = time.perf_counter()
            run_design_map(
                cluster_folder, robot, [SPEED], r1, r2, dask=cluster.scheduler_address, stream=quiet
            )
            dask_seconds = time.perf_counter() - began
        print(f"Dask LocalCluster, {WORKERS} workers:    {dask_seconds:7.1f} s")
        same = _values(local) == _values(cluster_folder)
        print(
            f"Dask / local time: {dask_seconds / local_seconds:.2f}; "
            f"same values, radii and statuses in every file: {'yes' if same else 'NO'}"
        )


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=3, help="design optimizations (median)")
    parser.add_argument("--grid", type=int, default=10, help="radii per axis of the map")
    parser.add_argument("--no-map", action="store_true", help="only the design optimization")
    args = parser.parse_args()
    one_design(args.repeats)
    if not args.no_map:
        design_map(args.grid)


if __name__ == "__main__":
    main()
