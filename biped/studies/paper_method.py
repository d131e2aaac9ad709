"""The paper's own method over several seeds, beside the certified optima of a sweep.

The paper minimises the criterion plus an exponential penalty of the constraints with
Nelder-Mead (§4), a method that stops where its evaluation budget ends. To show what that does
to a comparison of two knees, ``run_paper_method`` runs it (``biped.optimization.optimize`` with
``method="nelder-mead"``: the paper's kind of budget, a first run then restarts) at one speed,
for each knee and criterion, from several seeds (seed 0 starts from the first guess, seed k
from a perturbation of it, the way a designer tries a few first guesses). The gait files go to
the sweep's folder ``paper-method/``, beside its own ``settings.json``; like a sweep, the run
resumes and refuses a folder made with other settings.

``spread_lines`` sets the results beside the sweep's certified optimum at that speed: the
spread of the paper's method over the seeds, and the rolling-vs-revolute difference each seed
would have reported.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from biped.errors import BipedError
from biped.model.criteria import CRITERIA, CRITERION_UNITS, PAPER_SAFETY, Safety
from biped.model.dynamics import Biped
from biped.model.kinematics import KNEES
from biped.model.robot import Robot
from biped.optimization.comparison import DIFFERENCE, relative_change
from biped.optimization.optimize import optimize
from biped.optimization.penalty import EVALUATIONS_PER_RUN, MAX_RESTARTS
from biped.optimization.problem import GaitProblem, check_speed
from biped.records import gait_file
from biped.records.provenance import version
from biped.runtime.claims import claimed
from biped.studies import campaign
from biped.studies.campaign import Task

FOLDER = "paper-method"
SETTINGS = "settings.json"
PAPER = campaign.Campaign(
    "paper's method",
    SETTINGS,
    "record of the paper's method",
    "these runs of the paper's method were",
)
# The speed of the comparison: the paper's optimal speeds are 0.27 and 0.30 m/s.
SPEED = 0.3
DEFAULT_SEEDS = 5


@dataclass(frozen=True)
class PaperMethod(campaign.Settings):
    """What shapes the paper-method runs of a sweep folder."""

    # 2: a robot without actuators has the catalog's default set (biped-gait/3)
    FORMAT = "biped-paper-method/2"
    robot: Robot
    safety: Safety
    speed: float  # [m/s]
    seeds: int  # runs from seeds 0 .. seeds − 1

    def stamp(self) -> dict:
        """The method's budget and the version (not an IPOPT campaign's)."""
        return {
            "evaluations_per_run": EVALUATIONS_PER_RUN,
            "max_restarts": MAX_RESTARTS,
            "version": version(),
        }


@dataclass(frozen=True)
class Run:
    knee: str
    criterion: str
    speed: float  # [m/s]
    seed: int  # 0: from the first guess, k: from its perturbation number k

    def filename(self) -> str:
        return f"{self.knee}-{self.criterion}-{self.speed:.3f}-seed{self.seed}.json"


def _solve(task: Task) -> str:
    settings, run = task.settings, task.point
    problem = GaitProblem(
        Biped(settings.robot, run.knee), run.speed, run.criterion, settings.safety
    )
    optimum = optimize(problem, seed=run.seed, method="nelder-mead")
    gait_file.Gait.from_optimum(optimum, settings.robot).write(task.path)
    return (
        f"[paper method {run.knee:8} {run.criterion:7}] {run.speed:.3f} m/s seed "
        f"{run.seed}: C = {optimum.value:12.6f} {CRITERION_UNITS[run.criterion]} on the check "
        f"grid, penalty included: {optimum.report.status}"
    )


def paper_settings(
    robot: Robot, speed: float = SPEED, seeds: int = DEFAULT_SEEDS, safety: Safety = PAPER_SAFETY
) -> PaperMethod:
    """The settings of runs of the paper's method, each checked (BipedError naming a bad
    one): ``seeds`` (0 .. seeds − 1) at ``speed`` [m/s], walkable by either knee."""
    if isinstance(seeds, bool) or not isinstance(seeds, int) or seeds < 1:
        raise BipedError(f"seeds = {seeds!r}: allowed an integer >= 1")
    for knee in KNEES:
        check_speed(Biped(robot, knee), speed)
    return PaperMethod(robot, safety, float(speed), seeds)


def check_paper_method(sweep_folder: str | Path, settings: PaperMethod) -> None:
    """Raise the BipedError ``run_paper_method`` would raise on the folder's record before
    running, writing nothing (so that a sweep is refused before it starts, not after)."""
    PAPER.check(Path(sweep_folder) / FOLDER, settings.to_dict())


def run_paper_method(
    sweep_folder: str | Path, settings: PaperMethod, knees=KNEES, criteria=CRITERIA, **where
) -> list[Path]:
    """The paper's Nelder-Mead from the seeds of ``settings`` (``paper_settings``) for every
    knee and criterion, into ``sweep_folder``/paper-method/ (runs already there are kept);
    returns the gait files. ``where`` they run: as ``campaign.Campaign.run`` says."""
    with claimed(Path(sweep_folder) / FOLDER):  # one run at a time on the folder
        folder = PAPER.claim(Path(sweep_folder) / FOLDER, settings)  # checked before it is made
        speed, seeds = settings.speed, settings.seeds
        runs = [Run(k, c, speed, s) for c in criteria for k in knees for s in range(seeds)]
        todo = [Task(_solve, settings, r, str(folder)) for r in runs]
        todo = [task for task in todo if not task.path.exists()]
        plan = (
            f"paper's method: {len(runs)} Nelder-Mead runs at {speed:.3f} m/s in {folder}: "
            f"{len(runs) - len(todo)} already done, {len(todo)} to run"
        )
        PAPER.run(plan if todo else None, [todo], **where)
    return [folder / r.filename() for r in runs]


def read_runs(sweep_folder: str | Path) -> dict:
    """{(knee, criterion): [value of each seed, in seed order]} and the speed, from the
    paper-method folder of a sweep ({} and None if it has none)."""
    folder = Path(sweep_folder) / FOLDER
    settings = PAPER.read(folder)
    if settings is None:
        return {}, None
    try:
        speed, seeds = float(settings["speed"]), int(settings["seeds"])
    except (ValueError, KeyError, TypeError) as error:
        raise BipedError(f"{folder / SETTINGS}: unreadable {PAPER.what} ({error})") from None
    runs = {}
    for knee in KNEES:
        for criterion in CRITERIA:
            values = []
            for seed in range(seeds):
                file = folder / Run(knee, criterion, speed, seed).filename()
                if not file.exists():
                    break
                gait = gait_file.read(file)
                values.append(float(gait.costs.criterion(criterion)))
            if len(values) == seeds:
                runs[(knee, criterion)] = values
    return runs, speed


def spread_lines(sweep_folder: str | Path, certified: dict) -> list[str]:
    """Markdown lines: the paper's method over its seeds beside the certified optima.

    Args:
        certified: {(knee, criterion): {speed: value}} of the sweep's certified optima.
    """
    runs, speed = read_runs(sweep_folder)
    if not runs:
        return []
    lines = [
        f"## The paper's method (Nelder-Mead, penalty) over seeds, at {speed:.3f} m/s",
        "",
        f"Generated by `biped sweep` (`--paper-seeds`): Nelder-Mead on the penalised "
        f"criterion, a run of {EVALUATIONS_PER_RUN} evaluations then up to {MAX_RESTARTS} "
        "restart(s) from the best point, as in the paper's §4; seed 0 starts from the first "
        "guess, seed k from a perturbation of it.",
        "",
        "| knee, criterion | certified optimum | paper's method: best / median / worst "
        "| worst / certified |",
        "|---|---|---|---|",
    ]
    for (knee, criterion), values in sorted(runs.items()):
        optimum = certified.get((knee, criterion), {}).get(round(speed, 6))
        v = np.asarray(values)
        found = "none certified" if optimum is None else f"{optimum:.4g}"
        worst = "n/a" if optimum is None else f"{v.max() / optimum:.2f}"
        lines.append(
            f"| {knee}, {criterion} | {found} | {v.min():.4g} / {np.median(v):.4g} / "
            f"{v.max():.4g} | {worst} |"
        )
    lines += ["", f"Differences, rolling vs revolute: {DIFFERENCE}.", ""]
    for criterion in CRITERIA:
        if ("revolute", criterion) not in runs or ("rolling", criterion) not in runs:
            continue
        diff = np.array(
            [
                relative_change(rolling, revolute)
                for rolling, revolute in zip(
                    runs[("rolling", criterion)], runs[("revolute", criterion)], strict=True
                )
            ]
        )
        seeds = "the paper's method, seed by seed: " + ", ".join(f"{d:+.1f} %" for d in diff)
        a = certified.get(("revolute", criterion), {}).get(round(speed, 6), float("nan"))
        b = certified.get(("rolling", criterion), {}).get(round(speed, 6), float("nan"))
        true = relative_change(b, a)
        if not np.isfinite(true):
            lines.append(f"- {criterion}: no certified optimum of both knees here; {seeds}.")
            continue
        lines.append(
            f"- {criterion}: rolling vs revolute, certified optima {true:+.1f} %; {seeds}."
        )
        if np.ptp(diff) > abs(true):
            lines.append(
                f"  The seeds alone move the paper's method's answer over a range of "
                f"{np.ptp(diff):.0f} %, more than the certified difference ({abs(true):.1f} %)."
            )
        flips = int(np.sum(np.sign(diff) != np.sign(true)))
        if flips:
            lines.append(f"  {flips} of {len(diff)} seeds report the wrong knee as the better one.")
    lines.append("")
    return lines
