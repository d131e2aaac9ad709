"""One optimum re-solved from given starts, to see which basin they reach: the checks behind two
README sentences, which no command of the package makes.

    python benchmarks/resolve_point.py other-knee SWEEP_FOLDER --criterion energy --speed 0.15
        the revolute knee's point of a sweep solved from the rolling knee's optimum there,
        under each barrier (does the revolute knee reach the rolling knee's basin?)
    python benchmarks/resolve_point.py kernels ATLAS_FOLDER [--kernels Haswell Sandybridge ...]
        the atlas's richer-family solve of the revolute knee at 1 m/s and 5 cm (from the final
        optima of both knees), in a process of its own under each OpenBLAS kernel set
        (OPENBLAS_CORETYPE, set before numpy loads): its status and value under each
    python benchmarks/resolve_point.py per-metre SWEEP_FOLDER
        each energy point of a sweep that one start alone reached, solved from the energy
        per metre's optimum at its speed under each barrier: how far above the best it ends
        (is the per-metre optimum a second start to its basin?)
    python benchmarks/resolve_point.py mumps [--repeats 2]
        the energy criterion's table starts at 0.3 m/s, both knees, solved under MUMPS's
        orderings and scalings, each option set in a process of its own, in turn: ms an
        IPOPT iteration, the iterations and the values (the same path, a cheaper KKT solve?);
        --ipopt '{"print_timing_statistics": "yes", "print_level": 5, "max_iter": 40}': where
        an iteration's time goes
    python benchmarks/resolve_point.py sweep OUT [--first-stage] [--ipopt JSON]
        the default sweep (`biped sweep --paper-seeds 0`) written to OUT and timed: with
        --first-stage its first stage alone (its own starts, no second stage), to set beside
        the whole sweep's time; with --ipopt more IPOPT options for every solve
        ('{"mumps_pivtol": 1e-8}'), its files to compare with compare_sweeps.py
"""

import argparse
import json
import os
import subprocess
import sys
from pathlib import Path

import numpy as np


def other_knee(folder: Path, criterion: str, speed: float) -> None:
    import biped
    from biped.optimization.problem import GaitProblem
    from biped.optimization.solver import BARRIERS, solver_for
    from biped.studies import campaign

    name = f"{criterion}-{speed:.3f}.json"
    values = {}
    for knee in biped.KNEES:
        gait = json.loads((folder / f"{knee}-{name}").read_text())
        values[knee] = gait["optimizer"]["value"]
    rolling = json.loads((folder / f"rolling-{name}").read_text())
    start = campaign.variables(rolling["optimizer"]["variables"])
    problem = GaitProblem(biped.Biped(biped.Robot.paper(), "revolute"), speed, criterion)
    solver = solver_for(problem)
    print(
        f"{criterion} at {speed} m/s, on the solver's samples: revolute {values['revolute']:.6f}, "
        f"rolling {values['rolling']:.6f}"
    )
    for barrier in BARRIERS:
        end = solver.solve(problem, start, barrier=barrier)
        print(
            f"  revolute from the rolling optimum, {barrier:8} barrier: {end.value:.6f} "
            f"({end.status})"
        )


RICHER_CORNER = """
import json, sys
import numpy as np
from pathlib import Path
from biped.optimization.optimize import optimize
from biped.studies import atlas
folder = Path(sys.argv[1])
settings = atlas.Settings.from_dict(json.loads((folder / atlas.MANIFEST).read_text()))
point = atlas.Point("richer", "revolute", "sthenic", atlas.Cell(1.0, 0.05, 0.0))
finals = [atlas.read(folder, point.at("final", knee)) for knee in ("revolute", "rolling")]
richer = settings.problem(point, knots=atlas.RICHER_KNOTS)
given = [richer.embedded(np.array(f.variables)) for f in finals]
best = optimize(richer, starts=0, given=given, jobs=1)
print(best.report.status, f"{best.report.value:.9f}")
"""


def kernels(folder: Path, names: list[str]) -> None:
    for name in names:
        env = {**os.environ, "OPENBLAS_CORETYPE": name}
        done = subprocess.run(
            [sys.executable, "-c", RICHER_CORNER, str(folder)],
            env=env,
            capture_output=True,
            text=True,
            check=True,
        )
        print(f"OPENBLAS_CORETYPE={name:12} {done.stdout.strip()}")


def per_metre(folder: Path) -> None:
    import biped
    from biped.optimization.optimize import optimize
    from biped.optimization.problem import GaitProblem
    from biped.optimization.solver import BARRIERS, solver_for

    for path in sorted(folder.glob("*-energy-*.json")):
        gait = json.loads(path.read_text())
        if gait["optimizer"]["starts_at_best"] >= 2:
            continue
        knee, speed, best = gait["knee"], gait["speed"], gait["optimizer"]["value"]
        model = biped.Biped(biped.Robot.paper(), knee)
        start = optimize(GaitProblem(model, speed, "energy-per-metre"), jobs=1).variables
        problem = GaitProblem(model, speed, "energy")
        solver = solver_for(problem)
        ends = {b: solver.solve(problem, start, barrier=b) for b in BARRIERS if b != "tight"}
        above = ", ".join(f"{b} {e.value / best - 1:+.2e} ({e.status})" for b, e in ends.items())
        print(f"{path.name}: best {best:.6f} J; from the per-metre optimum: {above}")


MUMPS_RUN = """
import json, sys, time
from biped.optimization import solver as S
S.IPOPT_OPTIONS.update(json.loads(sys.argv[1]))
import biped
from biped.optimization.problem import GaitProblem
from biped.optimization.optimize import table_starts
for knee in ("revolute", "rolling"):
    p = GaitProblem(biped.Biped(biped.Robot.paper(), knee), 0.3, "energy")
    s = S.solver_for(p)
    starts = table_starts(p, 1)
    s.prepare({start.barrier for start in starts})
    seconds, iterations, values = 0.0, 0, []
    for start in starts:
        began = time.perf_counter()
        end = s.solve(p, start.variables, barrier=start.barrier)
        seconds += time.perf_counter() - began
        iterations += end.iterations
        values.append(f"{end.value:.9f}")
    print(f"{knee:8} {1e3 * seconds / iterations:5.2f} ms an iteration, {iterations} "
          f"iterations, values {' '.join(values)}")
"""
MUMPS_OPTIONS = {
    "default": {},
    "AMD ordering": {"mumps_pivot_order": 0},
    "AMF ordering": {"mumps_pivot_order": 2},
    "METIS ordering": {"mumps_pivot_order": 5},
    "no scaling": {"mumps_permuting_scaling": 0, "mumps_scaling": 0},
    "pivot tolerance 1e-8": {"mumps_pivtol": 1e-8},
}


def mumps(repeats: int, ipopt: dict) -> None:
    for _ in range(repeats):
        for name, options in MUMPS_OPTIONS.items():
            done = subprocess.run(
                [sys.executable, "-c", MUMPS_RUN, json.dumps({**options, **ipopt})],
                capture_output=True,
                text=True,
                check=True,
            )
            for line in done.stdout.strip().splitlines():
                print(f"{name:21} {line}")


# More IPOPT options for every solve of ``sweep``, JSON: the sweep's workers are spawned and
# import this file again (as __mp_main__), so they take them from the environment here.
IPOPT_ENV = "RESOLVE_POINT_IPOPT"


def _more_ipopt_options() -> None:
    if os.environ.get(IPOPT_ENV):
        from biped.optimization import solver

        solver.IPOPT_OPTIONS.update(json.loads(os.environ[IPOPT_ENV]))


_more_ipopt_options()


def sweep(out: Path, first_stage: bool, ipopt: dict) -> None:
    import time

    import biped.studies.sweep as sweeps
    from biped_cli.main import main as biped_main

    os.environ[IPOPT_ENV] = json.dumps(ipopt)
    _more_ipopt_options()
    stages = sweeps.sweep_stages

    def own_starts_only(*args):  # each stage without its final tasks, in the same order
        own = sweeps.solve_independent
        return [[t for t in tasks if t.solve is own] for tasks in stages(*args)]

    if first_stage:
        sweeps.sweep_stages = own_starts_only
    began = time.perf_counter()
    code = biped_main(["sweep", "--paper-seeds", "0", "--out", str(out)])  # 1 without finals
    what = "first stage alone" if first_stage else "whole"
    print(f"the default sweep, {what}: {time.perf_counter() - began:.1f} s wall (exit {code})")


def _sweep_folder(text: str) -> Path:
    folder = Path(text)
    if not any(folder.glob("*-energy-*.json")):
        raise argparse.ArgumentTypeError(f"{text!r}: allowed a sweep folder with energy optima")
    return folder


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    sub = parser.add_subparsers(dest="check", required=True)
    one = sub.add_parser("other-knee")
    one.add_argument("folder", type=Path)
    one.add_argument("--criterion", default="energy")
    one.add_argument("--speed", type=float, default=0.15)
    two = sub.add_parser("kernels")
    two.add_argument("folder", type=Path)
    two.add_argument("--kernels", nargs="+", default=["Haswell", "Sandybridge", "Nehalem"])
    sub.add_parser("per-metre").add_argument("folder", type=_sweep_folder)
    solves = sub.add_parser("mumps")
    solves.add_argument("--repeats", type=int, default=2)
    solves.add_argument("--ipopt", type=json.loads, default={}, help="more IPOPT options, JSON")
    swept = sub.add_parser("sweep")
    swept.add_argument("out", type=Path)
    swept.add_argument("--first-stage", action="store_true", help="its first stage alone")
    swept.add_argument("--ipopt", type=json.loads, default={}, help="more IPOPT options, JSON")
    args = parser.parse_args()
    if args.check == "other-knee":
        other_knee(args.folder, args.criterion, args.speed)
    elif args.check == "kernels":
        kernels(args.folder, args.kernels)
    elif args.check == "per-metre":
        per_metre(args.folder)
    elif args.check == "mumps":
        mumps(args.repeats, args.ipopt)
    else:
        sweep(args.out, args.first_stage, args.ipopt)


if __name__ == "__main__":
    np.seterr(all="ignore")
    main()
