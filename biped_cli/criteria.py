"""``biped criteria``: each knee's optimum of each criterion, every criterion measured on
every optimum (``biped.studies.criteria_matrix``)."""

from __future__ import annotations

import sys
import time
from pathlib import Path

from biped_cli import args as types
from biped_cli import checks

DEFAULT_OUT = "logs/criteria"
# The outputs' name in the folder: criteria.json, criteria.png and criteria.md.
NAME = "criteria"


def add_parser(commands) -> None:
    help = "each knee's optimum of each criterion, every criterion measured on every optimum"
    parser = types.add_command(commands, "criteria", help, cmd_criteria)
    types.add_speed(parser)
    types.add_safety(parser)
    types.add_robot(parser)
    types.add_knots(parser)
    types.add_bezier(parser)
    checks.add_folder(parser, "--out", DEFAULT_OUT, "folder of the results",
                      f": {NAME}.json, its figure {NAME}.png and page {NAME}.md",
                      claims=(NAME,))  # fmt: skip
    types.add_options(
        parser,
        ("--starts", types.starts, 3, "N", "IPOPT's own starts of each optimization (default "
         "3), the sthenic optimum among the starts of the others; " + types.CERTIFIED_HELP),
        ("--seed", types.non_negative, 0, "N", "seed of the perturbed starts (default 0)"),
        ("--jobs", types.jobs, None, "N", types.JOBS_HELP),
    )  # fmt: skip


def cmd_criteria(args) -> int:
    """Each knee's optimal gait at --speed for each criterion (sthenic, energy-per-metre,
    electrical), in the family of --knots or --family bezier --degree, and every criterion
    measured on every optimum: a table per knee (rows: the criterion minimised; columns: the
    criteria measured, with units), what optimizing one criterion costs in another relative
    to that other's own optimum, and the knees' difference in each cell. An optimum lower in
    another criterion than that criterion's own optimum starts it again. Writes criteria.json,
    criteria.png and criteria.md in --out and prints the tables and a sentence. Exits 1 when
    an optimum is not certified or is not the least of its own criterion."""
    from biped.model.dynamics import Biped
    from biped.optimization.knees import KNEES
    from biped.optimization.problem import GaitProblem
    from biped.studies.criteria_matrix import optimize_criteria, study_of

    robot = types.robot_of(args)
    family = types.gait_family(args)
    safety = types.safety(args)
    problems = {
        knee: GaitProblem(Biped(robot, knee), args.speed, "sthenic", safety, knots=family)
        for knee in KNEES
    }
    print(f"optimizing each criterion of {problems['rolling'].describe()}...", file=sys.stderr)
    began = time.perf_counter()
    solved = {
        knee: optimize_criteria(problem, args.seed, args.starts, args.jobs, _progress(knee))
        for knee, problem in problems.items()
    }
    study = study_of(problems["revolute"], solved, robot, args.seed, args.starts)
    return _report(args, study, time.perf_counter() - began)


def _progress(knee: str):
    from biped.model.criteria import CRITERION_UNITS

    def say(optimum) -> None:
        report = optimum.report
        print(
            f"  {knee}, {optimum.criterion}: {optimum.value:.6g} "
            f"{CRITERION_UNITS[optimum.criterion]} ({report.status}, {report.seconds:.1f} s)",
            file=sys.stderr,
        )

    return say


def _report(args, study, seconds: float) -> int:
    from biped.pages.criteria_figures import criteria_figure
    from biped.pages.criteria_page import markdown, sentence, tables
    from biped.pages.style import save_with_json
    from biped.runtime.files import atomic_write_text

    folder = Path(args.out)
    save_with_json(folder, NAME, "criteria", study.to_dict(), criteria_figure(study))
    print(f"wrote {folder / f'{NAME}.json'} and {folder / f'{NAME}.png'}")
    page = markdown(study, f"{NAME}.png", seconds)
    print(f"wrote {atomic_write_text(folder / f'{NAME}.md', page)}")
    print("\n".join(tables(study)))
    print(f"time: {seconds:.1f} s (both knees, every criterion)")
    for line in sentence(study):
        print(line)
    return _verdict(study)


def _verdict(study) -> int:
    """0 when every optimum is certified and the least of its own criterion; else 1 after a
    line on stderr naming what is not."""
    failed = [
        f"{matrix.knee} {row.optimized} ({row.status})"
        for matrix in study.knees
        for row in matrix.rows
        if not row.certified
    ]
    if failed:
        print(
            f"biped criteria: NOT CERTIFIED: {', '.join(failed)}: those optima are not "
            "converged and feasible, their costs and differences are unknown",
            file=sys.stderr,
        )
        return 1
    beaten = [
        f"{matrix.knee}: the {a} optimum is lower in {b} than {b}'s own"
        for matrix in study.knees
        for a, b in matrix.exceptions()
    ]
    if beaten:
        print(
            f"biped criteria: an optimum is not the least of its own criterion ("
            f"{'; '.join(beaten)}), even started again from the lower one",
            file=sys.stderr,
        )
        return 1
    return 0
