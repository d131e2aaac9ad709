"""Sweeps of optimal gaits over walking speed, both knees and both criteria.

Each point is one optimisation, run on all cores; its gait file is written atomically as soon
as it completes, so an interrupted sweep resumes with the points still missing. Infeasible
points are saved too (``feasible: false``) and are not optimised again.
"""

from __future__ import annotations

import multiprocessing
import os
import sys
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from biped import gait_file
from biped.criteria import CRITERIA
from biped.dynamics import Biped
from biped.errors import BipedError
from biped.kinematics import KNEES
from biped.optimize import optimize
from biped.robot import Robot

DEFAULT_SPEEDS = np.round(np.linspace(0.15, 0.45, 13), 6)  # [m/s], every 0.025 m/s


@dataclass(frozen=True)
class Point:
    knee: str
    criterion: str
    speed: float

    def filename(self) -> str:
        return f"{self.knee}-{self.criterion}-{self.speed:.3f}.json"


def run_point(point: Point, robot: Robot, seed: int, folder: Path, budget: dict) -> tuple:
    """Optimise one point and save it; returns (point, value, feasible, seconds)."""
    model = Biped(robot, point.knee)
    optimum = optimize(model, point.speed, point.criterion, seed=seed, **budget)
    gait_file.write_json(folder / point.filename(), gait_file.to_dict(optimum, robot, seed))
    return point, optimum.value, optimum.feasible, optimum.seconds


def _run_point(args):
    return run_point(*args)


def pending_points(points, folder: Path):
    """Points whose gait file is missing or unreadable."""
    todo = []
    for point in points:
        path = folder / point.filename()
        try:
            gait_file.read(path)
        except BipedError:
            todo.append(point)
    return todo


def run_sweep(
    folder: Path,
    robot: Robot,
    speeds=DEFAULT_SPEEDS,
    knees=KNEES,
    criteria=CRITERIA,
    seed: int = 0,
    jobs: int | None = None,
    stream=sys.stderr,
    **budget,
) -> list[Point]:
    """Optimise every (knee, criterion, speed) not yet in ``folder``; returns all points.

    ``budget`` goes to ``biped.optimize.optimize`` (``max_restarts``, ``evaluations_per_run``).
    """
    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    points = [Point(k, c, float(s)) for c in criteria for k in knees for s in speeds]
    todo = pending_points(points, folder)
    done = len(points) - len(todo)
    print(
        f"sweep: {len(points)} points in {folder}, {done} already done, {len(todo)} to run",
        file=stream,
    )
    jobs = jobs or os.cpu_count() or 1
    began = time.perf_counter()
    tasks = [(point, robot, seed, folder, budget) for point in todo]
    if jobs == 1 or len(tasks) <= 1:
        results = map(_run_point, tasks)
        pool = None
    else:
        pool = multiprocessing.get_context("spawn").Pool(min(jobs, len(tasks)))
        results = pool.imap_unordered(_run_point, tasks)
    try:
        for count, (point, value, feasible, seconds) in enumerate(results, start=1):
            status = "feasible" if feasible else "INFEASIBLE"
            print(
                f"[{done + count:3d}/{len(points)}] {point.knee:8} {point.criterion:7} "
                f"{point.speed:.3f} m/s  C = {value:12.4f}  {status}  {seconds:5.1f} s  "
                f"(elapsed {time.perf_counter() - began:6.1f} s)",
                file=stream,
                flush=True,
            )
    finally:
        if pool is not None:
            pool.terminate()
    return points
