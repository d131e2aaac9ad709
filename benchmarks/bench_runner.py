"""One small sweep run three ways through ``biped.runtime.runner``: in this process, on a local pool
of worker processes, and on a local Dask cluster of as many single-thread worker processes;
seconds of each and the ratio to the in-process run, and whether the gait files are the same.

    python benchmarks/bench_runner.py [--workers 2] [--speeds 0.25,0.275,0.3,0.325]

The pool and the Dask workers start fresh processes (their imports and CasADi graphs are part
of the time); the Dask cluster's own start-up is timed apart.
"""

import os

for _var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ[_var] = "1"  # one core per process, set before numpy loads its BLAS

import argparse  # noqa: E402
import io  # noqa: E402
import json  # noqa: E402
import tempfile  # noqa: E402
import time  # noqa: E402
from pathlib import Path  # noqa: E402

import biped  # noqa: E402
from biped.studies.sweep import run_sweep, sweep_settings  # noqa: E402


def _gaits(folder: Path) -> dict:
    """Gait files without the solver's time and the provenance."""
    files = {}
    for path in sorted(folder.rglob("*-*.json")):
        gait = json.loads(path.read_text())
        gait["optimizer"].pop("seconds")
        gait.pop("provenance")
        files[str(path.relative_to(folder))] = gait
    return files


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--speeds", default="0.25,0.275,0.3,0.325")
    args = parser.parse_args()
    speeds = [float(v) for v in args.speeds.split(",")]
    sweep = dict(knees=("revolute",), criteria=("sthenic",), stream=io.StringIO())
    settings = sweep_settings(biped.Robot.paper(), speeds, starts=1)
    points = len(speeds)
    print(f"sweep: revolute knee, sthenic, {points} speeds, 1 start: {2 * points} optimizations")
    with tempfile.TemporaryDirectory() as root:
        root = Path(root)
        began = time.perf_counter()
        run_sweep(root / "in-process", settings, jobs=1, **sweep)
        reference = time.perf_counter() - began
        print(f"in this process           {reference:7.1f} s   1.00 x")
        began = time.perf_counter()
        run_sweep(root / "pool", settings, jobs=args.workers, **sweep)
        pool = time.perf_counter() - began
        print(f"pool of {args.workers} processes        {pool:7.1f} s   {reference / pool:.2f} x")

        from dask.distributed import LocalCluster

        began = time.perf_counter()
        with LocalCluster(
            n_workers=args.workers, processes=True, threads_per_worker=1, dashboard_address=":0"
        ) as cluster:
            start = time.perf_counter() - began
            began = time.perf_counter()
            run_sweep(root / "dask", settings, dask=cluster.scheduler_address, **sweep)
            dask = time.perf_counter() - began
        print(
            f"Dask, {args.workers} workers          {dask:7.1f} s   {reference / dask:.2f} x"
            f"   (cluster start-up {start:.1f} s apart)"
        )
        same = _gaits(root / "in-process") == _gaits(root / "pool") == _gaits(root / "dask")
        print(f"gait files identical in the three runs: {same}")


if __name__ == "__main__":
    main()
