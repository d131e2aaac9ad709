"""One optimum re-solved from given starts, to see which basin they reach: the checks behind two
README sentences, which no command of the package makes.

    python benchmarks/resolve_point.py other-knee SWEEP_FOLDER --criterion energy --speed 0.15
        the revolute knee's point of a sweep solved from the rolling knee's optimum there,
        under each barrier (does the revolute knee reach the rolling knee's basin?)
    python benchmarks/resolve_point.py kernels ATLAS_FOLDER [--kernels Haswell Sandybridge ...]
        the atlas's richer-family solve of the revolute knee at 1 m/s and 5 cm (from the final
        optima of both knees), in a process of its own under each OpenBLAS kernel set
        (OPENBLAS_CORETYPE, set before numpy loads): its status and value under each
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
given = [richer.embedded(np.array(f["variables"])) for f in finals]
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
    args = parser.parse_args()
    if args.check == "other-knee":
        other_knee(args.folder, args.criterion, args.speed)
    else:
        kernels(args.folder, args.kernels)


if __name__ == "__main__":
    np.seterr(all="ignore")
    main()
