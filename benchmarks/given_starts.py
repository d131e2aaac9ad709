"""Does a sweep's second stage solve a start its first stage solved already? For every point of
a sweep folder, its neighbours' first-stage optima (the second stage's "given" starts:
``biped.studies.sweep.neighbours``) beside the table's starts of the point (among its own
starts): how many of them are one of the table's starts (to ``SAME_START`` of the variables'
scales), and how many given starts the point's history holds.

    python benchmarks/given_starts.py SWEEP_FOLDER

A sweep of this version leaves those out (``biped.optimization.optimize.apart_from_table``):
its histories hold only the others. Before, each was solved again and counted as a second
start: at the edge speeds the table's start is the neighbouring speed's optimum itself, and
the table's other-knee start is the other knee's optimum when the table was made from a sweep.
"""

import argparse
import json
from pathlib import Path

import numpy as np

import biped
from biped.optimization.optimize import SAME_START, table_starts
from biped.optimization.problem import GaitProblem, scales
from biped.studies import campaign
from biped.studies.sweep import INDEPENDENT, MANIFEST, Point, neighbours


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("folder", type=Path)
    folder = parser.parse_args().folder
    if not (folder / MANIFEST).is_file():
        parser.error(f"{folder}: no {MANIFEST}: allowed a folder biped sweep wrote")
    speeds = json.loads((folder / MANIFEST).read_text())["speeds"]
    counted = same = solved = 0
    for criterion in ("sthenic", "energy"):
        for knee in biped.KNEES:
            for speed in speeds:
                point = Point(knee, criterion, speed)
                problem = GaitProblem(biped.Biped(biped.Robot.paper(), knee), speed, criterion)
                own = [start.variables for start in table_starts(problem, 1)]
                for other in neighbours(point, speeds, biped.KNEES):
                    first = json.loads((folder / INDEPENDENT / other.filename()).read_text())
                    z = campaign.variables(first["optimizer"]["variables"])
                    gaps = [np.max(np.abs((z - t) / scales())) for t in own]
                    counted += 1
                    same += min(gaps) < SAME_START
                report = json.loads((folder / point.filename()).read_text())["optimizer"]
                solved += sum(s["kind"] == "given" for s in report["history"])
    print(
        f"{counted} neighbours' optima started the second stage's points; {same} of them are "
        f"one of the point's table starts (to {SAME_START:g} of the scales); the histories hold "
        f"{solved} given starts"
    )


if __name__ == "__main__":
    main()
