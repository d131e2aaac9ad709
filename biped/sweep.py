"""Sweeps of optimal gaits over walking speed, both knees and both criteria.

Each (knee, criterion) pair is a series over increasing speeds, and the series run in
parallel on all cores. The first speed is optimised from the default first guess
(Nelder-Mead, then SLSQP); each next one by continuation, polishing the optimum of the
previous speed (same step length, period scaled to the new speed), and from the default first
guess too if the continuation ends infeasible or with a jump of the criterion.
Nelder-Mead and SLSQP find local minima, and continuation keeps a series in the basin it
found instead of letting neighbouring speeds fall into unrelated ones.

Each point's gait file is written atomically as soon as it completes, so an interrupted
sweep resumes with the points still missing (a saved point also seeds the continuation).
Infeasible points are saved too (``feasible: false``) and are not optimised again.
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
from biped.criteria import CRITERIA, PAPER_SAFETY, Safety
from biped.dynamics import Biped
from biped.errors import BipedError
from biped.kinematics import KNEES
from biped.optimize import check_speed, initial_parameters, optimize
from biped.robot import Robot

DEFAULT_SPEEDS = np.round(np.linspace(0.15, 0.45, 13), 6)  # [m/s], every 0.025 m/s


@dataclass(frozen=True)
class Point:
    knee: str
    criterion: str
    speed: float

    def filename(self) -> str:
        return f"{self.knee}-{self.criterion}-{self.speed:.3f}.json"


def _saved(path: Path, point: Point, robot: Robot, safety: Safety = PAPER_SAFETY):
    """The gait saved for ``point`` at ``path``, or None if missing or unreadable.

    Raises:
        BipedError: the file holds another robot's or another point's gait.
    """
    try:
        gait = gait_file.read(path)
    except BipedError:
        return None
    found = (gait["knee"], gait["criterion"], gait["speed"])
    same_problem = gait["robot"] == robot and gait["safety"] == safety
    if found != (point.knee, point.criterion, point.speed) or not same_problem:
        raise BipedError(
            f"{path} holds a gait of another robot, safety or point ({found[0]}, "
            f"{found[1]}, {found[2]} m/s): allowed only this sweep's, choose another --out folder"
        )
    return gait


def _continued(model, criterion, speed, source, seed, budget):
    """Polish the optimum ``source`` = (speed, parameters, value) of a neighbouring speed at
    ``speed``: same step length, period scaled to the new speed, so the posture stays in reach."""
    last_speed, warm, _ = source
    warm = warm.copy()
    warm[-1] *= last_speed / speed
    return optimize(model, speed, criterion, seed=seed, starts=[], polish_starts=[warm], **budget)


def run_series(knee, criterion, speeds, robot, seed, folder, budget, stream=sys.stderr):
    """Optimise one (knee, criterion) series over increasing speeds; returns points run.

    Forward pass: each speed continues from the previous one (or starts from the first
    guess). Backward pass, once every speed is done: where a speed's criterion lies above the
    next speed's by more than ``CONTINUATION_GROWTH``, it sat in a worse basin and is polished
    again from the next speed's optimum, kept if better. An interrupted sweep resumes in the
    same pass with the same inputs, so it ends with the numbers of an uninterrupted one.
    """
    model = Biped(robot, knee)
    speeds = sorted(speeds)
    found: list = [None] * len(speeds)  # (speed, parameters, value) of feasible optima
    ran = 0

    def save(i, optimum, note=""):
        point = Point(knee, criterion, float(speeds[i]))
        gait_file.write_json(
            Path(folder) / point.filename(), gait_file.to_dict(optimum, robot, seed)
        )
        status = "feasible" if optimum.feasible else "INFEASIBLE"
        print(
            f"[{knee:8} {criterion:7} {i + 1:2d}/{len(speeds)}] {point.speed:.3f} m/s  "
            f"C = {optimum.value:12.4f}  {status}  {optimum.seconds:5.1f} s{note}",
            file=stream,
            flush=True,
        )
        found[i] = (point.speed, optimum.parameters, optimum.value) if optimum.feasible else None

    for i, speed in enumerate(speeds):
        point = Point(knee, criterion, float(speed))
        saved = _saved(
            Path(folder) / point.filename(), point, robot, budget.get("safety", PAPER_SAFETY)
        )
        if saved is not None:
            if saved["feasible"]:
                found[i] = (point.speed, gait_file.parameters(saved), saved["costs"][criterion])
            continue
        previous = next((f for f in reversed(found[:i]) if f is not None), None)
        optimum = None
        if previous is not None:
            optimum = _continued(model, criterion, point.speed, previous, seed, budget)
        if optimum is None or not _continues(optimum, previous):
            start = initial_parameters(model, point.speed)
            fresh = optimize(model, point.speed, criterion, seed=seed, starts=[start], **budget)
            if optimum is None or fresh.rank() < optimum.rank():
                optimum = fresh
        save(i, optimum)
        ran += 1
        j = i
        while (
            j > 0
            and found[j]
            and found[j - 1]
            and found[j - 1][2] > CONTINUATION_GROWTH * found[j][2]
        ):
            again = _continued(model, criterion, speeds[j - 1], found[j], seed, budget)
            if not again.feasible or again.value >= found[j - 1][2]:
                break
            save(j - 1, again, "  (again, from the next speed)")
            j -= 1
    return ran


# A continued optimum is trusted if feasible and its criterion at most this factor above the
# previous speed's (the criteria change by tens of percent between grid speeds).
CONTINUATION_GROWTH = 1.5


def _continues(optimum, previous) -> bool:
    """Whether the continued optimum is plausible: feasible, no jump of the criterion."""
    return optimum.feasible and optimum.value <= CONTINUATION_GROWTH * previous[2]


def _run_series(args):
    return run_series(*args)


def pending_points(points, folder: Path, robot: Robot, safety: Safety = PAPER_SAFETY):
    """Points whose gait file is missing or unreadable."""
    folder = Path(folder)
    return [p for p in points if _saved(folder / p.filename(), p, robot, safety) is None]


def check_speeds(robot: Robot, speeds, knees) -> list[float]:
    """Sorted speeds, each walkable and with its own file name; raise a clear error if not."""
    speeds = sorted(float(s) for s in speeds)
    for knee in knees:
        model = Biped(robot, knee)
        for speed in speeds:
            check_speed(model, speed)
    names = [f"{s:.3f}" for s in speeds]
    for a, b in zip(names, names[1:], strict=False):
        if a == b:
            raise BipedError(f"speeds {a} m/s appear twice at 1 mm/s resolution: allowed distinct")
    return speeds


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

    ``budget`` goes to ``biped.optimize.optimize`` (``max_restarts``, ``evaluations_per_run``,
    ``polish_iterations``, ``safety``).
    """
    speeds = check_speeds(robot, speeds, knees)
    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    points = [Point(k, c, s) for c in criteria for k in knees for s in speeds]
    todo = pending_points(points, folder, robot, budget.get("safety", PAPER_SAFETY))
    print(
        f"sweep: {len(points)} points in {folder}, {len(points) - len(todo)} already done, "
        f"{len(todo)} to run",
        file=stream,
        flush=True,
    )
    series = [
        (k, c)
        for c in criteria
        for k in knees
        if any(p.knee == k and p.criterion == c for p in todo)
    ]
    tasks = [(k, c, speeds, robot, seed, folder, budget) for k, c in series]
    jobs = min(jobs or os.cpu_count() or 1, max(len(tasks), 1))
    began = time.perf_counter()
    if jobs == 1:
        for task in tasks:
            run_series(*task, stream=stream)
    else:
        with multiprocessing.get_context("spawn").Pool(jobs) as pool:
            for _ in pool.imap_unordered(_run_series, tasks):
                pass
    print(f"sweep: done in {time.perf_counter() - began:.1f} s", file=stream, flush=True)
    return points
