"""Argument types of the ``biped`` command: each refuses a bad value with one line naming it."""

from __future__ import annotations

import argparse
import os

import numpy as np

from biped.criteria import MAX_CLEARANCE, MAX_ZMP_MARGIN, Safety
from biped.errors import BipedError

ROBOT_HELP = "robot parameters, .json or .toml; fields left out keep Table 1 (default: Table 1)"


def speed(text: str) -> float:
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"speed = {text!r} is not a number") from None
    if not (np.isfinite(value) and value > 0):
        raise argparse.ArgumentTypeError(f"speed = {text!r} m/s: allowed > 0")
    return value


def speeds(text: str) -> np.ndarray:
    """'0.15:0.45:13' (start:stop:count) or '0.2,0.3' (a list)."""
    try:
        if ":" in text:
            start, stop, count = text.split(":")
            values = np.linspace(float(start), float(stop), int(count))
        else:
            values = np.array([float(v) for v in text.split(",")])
    except ValueError:
        raise argparse.ArgumentTypeError(
            f"speeds = {text!r}: allowed START:STOP:COUNT or a comma-separated list"
        ) from None
    if values.size == 0 or not np.all(np.isfinite(values) & (values > 0)):
        raise argparse.ArgumentTypeError(f"speeds = {text!r}: allowed speeds > 0 m/s")
    return np.round(values, 6)


def check_output(path: str, option: str = "--out") -> None:
    """Fail before any work if ``path`` cannot become a file."""
    from pathlib import Path

    target = Path(path)
    if target.is_dir():
        raise BipedError(f"{option} {path!r} is a folder: allowed a file path")
    check_folder(str(target.parent), option, of=path)


def check_folder(path: str, option: str, of: str | None = None) -> None:
    """Fail before any work if ``path`` cannot be (or become) a writable folder."""
    from pathlib import Path

    folder = Path(path)
    named = of if of is not None else path
    existing = folder
    while not existing.exists():
        existing = existing.parent
    if not existing.is_dir():
        raise BipedError(f"{option} {named!r}: {str(existing)!r} is a file, allowed a folder")
    if not os.access(existing, os.W_OK):
        raise BipedError(f"{option} {named!r}: folder {str(existing)!r} is not writable")


def budget(args) -> dict:
    return {
        "max_restarts": args.restarts,
        "evaluations_per_run": args.evaluations,
        "polish_iterations": args.polish,
        "safety": Safety(clearance=args.clearance, zmp_margin=args.zmp_margin),
    }


def add_budget(parser):
    from biped.optimize import EVALUATIONS_PER_RUN, MAX_RESTARTS, POLISH_ITERATIONS

    parser.add_argument("--seed", type=int, default=0, help="orients the restarts (default 0)")
    parser.add_argument(
        "--restarts",
        type=non_negative,
        default=MAX_RESTARTS,
        help=f"Nelder-Mead restarts from the best point at most (default {MAX_RESTARTS})",
    )
    parser.add_argument(
        "--evaluations",
        type=positive,
        default=EVALUATIONS_PER_RUN,
        metavar="N",
        help=f"criterion evaluations per Nelder-Mead run (default {EVALUATIONS_PER_RUN})",
    )
    parser.add_argument(
        "--clearance",
        type=clearance,
        default=0.0,
        metavar="M",
        help="[m] height the swing foot must keep off the ground away from the ends of the "
        "step (default 0, the paper's z >= 0)",
    )
    parser.add_argument(
        "--zmp-margin",
        type=zmp_margin,
        default=0.0,
        metavar="M",
        help="[m] distance the ZMP must keep inside the sole's heel and toe (default 0)",
    )
    parser.add_argument(
        "--polish",
        type=non_negative,
        default=POLISH_ITERATIONS,
        metavar="N",
        help=f"SLSQP polish iterations at most, 0 for none (default {POLISH_ITERATIONS})",
    )


def margin(name: str, high: float):
    def parse(text: str) -> float:
        try:
            value = float(text)
        except ValueError:
            value = float("nan")
        if not (0.0 <= value <= high):
            raise argparse.ArgumentTypeError(f"{name} = {text!r} m: allowed 0 to {high}")
        return value

    return parse


clearance = margin("clearance", MAX_CLEARANCE)
zmp_margin = margin("zmp margin", MAX_ZMP_MARGIN)


def non_negative(text: str) -> int:
    try:
        value = int(text)
    except ValueError:
        value = -1
    if value < 0:
        raise argparse.ArgumentTypeError(f"{text!r}: allowed an integer >= 0")
    return value


def positive(text: str) -> int:
    try:
        value = int(text)
    except ValueError:
        value = 0
    if value < 1:
        raise argparse.ArgumentTypeError(f"{text!r}: allowed an integer >= 1")
    return value
