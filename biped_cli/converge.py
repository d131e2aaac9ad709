"""``biped converge``: both knees' optima over a ladder of nested gait families, until the
comparison no longer moves (``biped.studies.converge``)."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from biped_cli import args as types
from biped_cli import checks

DEFAULT_LADDER = (1, 3, 7, 15)
# The Bézier family's (``--family bezier``): degrees, each holding the one below.
DEFAULT_BEZIER_LADDER = (5, 7, 9, 13)
DEFAULT_OUT = "logs/converge"
# The outputs' name in the folder: converge.json and converge.png.
NAME = "converge"


def ladder(text: str) -> tuple:
    """'1,3,7,15': the sizes of each rung (interior knots, or a Bézier family's degrees),
    integers; ``ladder_of`` checks them with the family."""
    try:
        return tuple(int(part) for part in text.split(","))
    except ValueError:
        raise argparse.ArgumentTypeError(
            f"ladder = {text!r}: not integers; allowed increasing knots, each family holding "
            "the one before, such as 1,3,7,15 (or degrees with --family bezier, such as 5,7,9)"
        ) from None


def ladder_of(args) -> tuple:
    """The families of ``--ladder`` in ``--family`` (its default ladder when not given),
    each holding the one before; a clear error otherwise."""
    from biped.errors import BipedError
    from biped.model.bezier import Bezier
    from biped.optimization.ladder import check_ladder

    bezier = args.family == "bezier"
    sizes = args.ladder or (DEFAULT_BEZIER_LADDER if bezier else DEFAULT_LADDER)
    try:
        return check_ladder(tuple(Bezier(n) for n in sizes) if bezier else sizes)
    except BipedError as error:
        allowed = "increasing degrees from 3 to 20" if bezier else "increasing knots"
        raise BipedError(
            f"ladder = {','.join(map(str, sizes))}: {error}; allowed {allowed}, each family "
            "holding the one before, such as " + ("5,7,9" if bezier else "1,3,7,15")
        ) from None


def add_parser(commands) -> None:
    help = "both knees' optima over nested gait families, until the comparison converges"
    parser = types.add_command(commands, "converge", help, cmd_converge)
    types.add_speed(parser)
    types.add_criterion(parser)
    types.add_safety(parser)
    types.add_robot(parser)
    types.add_family(parser, then="--ladder's degrees")
    checks.add_folder(parser, "--out", DEFAULT_OUT, "folder of the results",
                      f": {NAME}.json and its figure {NAME}.png", claims=(NAME,))  # fmt: skip
    types.add_options(
        parser,
        ("--ladder", ladder, None, "K1,K2,...", "interior knots of each rung, each "
         "family holding the one before (default 1,3,7,15: 21, 45, 93, 189 parameters); with "
         "--family bezier the degrees (default 5,7,9,13: 21, 33, 45, 69 parameters)"),
        ("--starts", types.starts, 3, "N", "IPOPT's own starts at each rung (default 3), the "
         "rung below's optimum among them; " + types.CERTIFIED_HELP),
        ("--seed", types.non_negative, 0, "N", "seed of the perturbed starts (default 0)"),
        ("--jobs", types.jobs, None, "N", types.JOBS_HELP),
    )  # fmt: skip
    checks.declare_rule(parser, ("--ladder", "--family"), ladder_of)


def cmd_converge(args) -> int:
    """Each knee's optimal gait at --speed in each family of --ladder (1, 3, 7, 15 interior
    knots, or with --family bezier the Bézier degrees 5, 7, 9, 13: each family holds the one
    below, and each rung starts from the rung below's
    optimum), the knees compared at each rung with the difference's error bar and each
    optimum's uncertainty (finer grid, tighter tolerance, starts). The comparison has
    converged at the first rung where each optimum and the difference changed by less than
    its error bar. Writes converge.json and converge.png in --out, prints a sentence. Exits 1
    when a rung is not certified or a rung's optimum is worse than the one below's."""
    from biped.model.dynamics import Biped
    from biped.model.gait import family_label
    from biped.optimization.knees import KNEES
    from biped.optimization.ladder import climb
    from biped.optimization.problem import GaitProblem
    from biped.studies.converge import convergence, rung_record

    robot = types.robot_of(args)
    safety = types.safety(args)
    problems = {
        knee: GaitProblem(Biped(robot, knee), args.speed, args.criterion, safety) for knee in KNEES
    }
    families = ladder_of(args)
    shown = ", ".join(map(family_label, families))
    print(f"converging {problems['rolling'].describe()} over {shown}...", file=sys.stderr)
    rungs = {}
    for knee, problem in problems.items():
        rungs[knee] = climb(problem, families, args.seed, args.starts, args.jobs, _progress(knee))
    records = []
    for i, _ in enumerate(families):
        records.append(rung_record({knee: rungs[knee][i] for knee in KNEES}))
        print(f"  {family_label(records[-1].knots)}: compared", file=sys.stderr)
    verdict = convergence(records)
    return _report(args, problems["rolling"], records, verdict, robot)


def _progress(knee: str):
    from biped.model.gait import family_label

    def say(rung) -> None:
        print(
            f"  {knee}, {family_label(rung.knots)}: {rung.value:.6g} "
            f"({rung.optimum.report.status}, "
            f"{rung.seconds:.1f} s)",
            file=sys.stderr,
        )

    return say


def _report(args, problem, records, verdict, robot) -> int:
    from biped.model.criteria import CRITERION_UNITS
    from biped.model.gait import family_label
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
    failed = [family_label(r.knots) for r in records if not r.certified]
    worse = [
        family_label(r.knots) for r in records if not all(k.monotone for k in r.knees.values())
    ]
    if failed:
        print(
            f"biped converge: NOT CERTIFIED at {', '.join(failed)}: those rungs' "
            "optima are not converged and feasible, their figures are not an answer",
            file=sys.stderr,
        )
    if worse:
        print(
            f"biped converge: at {', '.join(worse)} an optimum is worse than the "
            "rung below's embedded in its family (1e-9 relative)",
            file=sys.stderr,
        )
    return 1 if failed or worse else 0
