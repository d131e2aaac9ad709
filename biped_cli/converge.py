"""``biped converge``: both knees' optima over a ladder of nested gait families, until the
comparison no longer moves (``biped.studies.converge``)."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from biped_cli import args as types

DEFAULT_LADDER = (1, 3, 7, 15)
DEFAULT_OUT = "logs/converge"
# The outputs' name in the folder: converge.json and converge.png.
NAME = "converge"


def ladder(text: str) -> tuple:
    """'1,3,7,15': the interior knots of each rung, each family holding the one before."""
    from biped.errors import BipedError
    from biped.optimization.ladder import check_ladder

    try:
        knots = tuple(int(part) for part in text.split(","))
        return check_ladder(knots)
    except (ValueError, BipedError) as error:
        why = str(error) if isinstance(error, BipedError) else "not integers"
        raise argparse.ArgumentTypeError(
            f"ladder = {text!r}: {why}; allowed increasing knots, each family holding the one "
            "before, such as 1,3,7,15"
        ) from None


def add_parser(commands) -> None:
    help = "both knees' optima over nested gait families, until the comparison converges"
    parser = types.add_command(commands, "converge", help, cmd_converge)
    types.add_speed(parser)
    types.add_criterion(parser)
    types.add_safety(parser)
    types.add_robot(parser)
    types.add_folder(parser, "--out", DEFAULT_OUT, "folder of the results",
                     f": {NAME}.json and its figure {NAME}.png")  # fmt: skip
    types.add_options(
        parser,
        ("--ladder", ladder, DEFAULT_LADDER, "K1,K2,...", "interior knots of each rung, each "
         "family holding the one before (default 1,3,7,15: 21, 45, 93, 189 parameters)"),
        ("--starts", types.starts, 3, "N", "IPOPT's own starts at each rung (default 3), the "
         "rung below's optimum among them; " + types.CERTIFIED_HELP),
        ("--seed", types.non_negative, 0, "N", "seed of the perturbed starts (default 0)"),
        ("--jobs", types.jobs, None, "N", types.JOBS_HELP),
    )  # fmt: skip


def cmd_converge(args) -> int:
    """Each knee's optimal gait at --speed in each family of --ladder (1, 3, 7, 15 interior
    knots: each family holds the one below, and each rung starts from the rung below's
    optimum), the knees compared at each rung with the difference's error bar and each
    optimum's uncertainty (finer grid, tighter tolerance, starts). The comparison has
    converged at the first rung where each optimum and the difference changed by less than
    its error bar. Writes converge.json and converge.png in --out, prints a sentence. Exits 1
    when a rung is not certified or a rung's optimum is worse than the one below's."""
    from biped.model.dynamics import Biped
    from biped.optimization.knees import KNEES
    from biped.optimization.ladder import climb
    from biped.optimization.problem import GaitProblem
    from biped.studies.converge import convergence, rung_record

    robot = types.robot_of(args)
    safety = types.safety(args)
    problems = {
        knee: GaitProblem(Biped(robot, knee), args.speed, args.criterion, safety) for knee in KNEES
    }
    types.check_folder(args.out, "--out")
    types.claim_outputs(args.out, [NAME])
    print(f"converging {problems['rolling'].describe()} over K = {args.ladder}...", file=sys.stderr)
    rungs = {}
    for knee, problem in problems.items():
        rungs[knee] = climb(
            problem, args.ladder, args.seed, args.starts, args.jobs, _progress(knee)
        )
    records = []
    for i, _ in enumerate(args.ladder):
        records.append(rung_record({knee: rungs[knee][i] for knee in KNEES}))
        print(f"  K = {records[-1].knots}: compared", file=sys.stderr)
    verdict = convergence(records)
    return _report(args, problems["rolling"], records, verdict, robot)


def _progress(knee: str):
    def say(rung) -> None:
        print(
            f"  {knee}, K = {rung.knots}: {rung.value:.6g} ({rung.optimum.report.status}, "
            f"{rung.seconds:.1f} s)",
            file=sys.stderr,
        )

    return say


def _report(args, problem, records, verdict, robot) -> int:
    from biped.model.criteria import CRITERION_UNITS
    from biped.pages.converge_figures import converge_figure
    from biped.pages.style import save
    from biped.records.gait_file import write_json
    from biped.studies.converge import content_of, sentence

    folder = Path(args.out)
    unit = CRITERION_UNITS[args.criterion]
    content = content_of(problem, records, verdict, robot, unit)
    print(f"wrote {write_json(folder / f'{NAME}.json', content)}")
    figure = converge_figure(records, args.criterion, args.speed, verdict.converged_at)
    print(f"wrote {save(figure, folder / f'{NAME}.png')}")
    for line in sentence(records, verdict, unit):
        print(line)
    failed = [r.knots for r in records if not r.certified]
    worse = [r.knots for r in records if not all(k.monotone for k in r.knees.values())]
    if failed:
        print(
            f"biped converge: NOT CERTIFIED at K = {', '.join(map(str, failed))}: those rungs' "
            "optima are not converged and feasible, their figures are not an answer",
            file=sys.stderr,
        )
    if worse:
        print(
            f"biped converge: at K = {', '.join(map(str, worse))} an optimum is worse than the "
            "rung below's embedded in its family (1e-9 relative)",
            file=sys.stderr,
        )
    return 1 if failed or worse else 0
