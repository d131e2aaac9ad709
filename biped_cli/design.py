"""``biped design`` and ``biped design-map``: the rolling knee's radii optimised with the gait
(``biped.optimization.design``) and mapped over a grid of radii (``biped.studies.design_map``);
the design problem of ``biped pipeline --design`` (``validate.workflows``)."""

from __future__ import annotations

import argparse
import sys

import numpy as np

from biped.errors import BipedError
from biped_cli import args as types
from biped_cli import checks

DEFAULT_MAP = "logs/design-map"
# Most grid values per radius: a map is an optimization per (r1, r2) and speed.
MAX_GRID = 100


def circles_of(args) -> list:
    """The designed circles' gait file of ``--profile``, beside --out's (none without it)."""
    from biped_cli.profile import circles_path

    return [] if args.profile is None else [str(circles_path(args.out))]


def radii(text: str) -> np.ndarray:
    """Grid radii [m]: 'START:STOP:COUNT' or 'R1,R2,...', each >= 0 (the bounds of the
    robot are checked later)."""
    values = types.number_list(text, "radii", MAX_GRID, " [m]")
    if values.size == 0 or values.size > MAX_GRID or not np.all(np.isfinite(values)):
        raise argparse.ArgumentTypeError(
            f"radii = {text!r}: allowed 1 to {MAX_GRID} finite radii [m]"
        )
    if np.any(values < 0.0):
        raise argparse.ArgumentTypeError(f"radii = {text!r}: allowed radii >= 0 m")
    return np.round(values, 6)


def _add_common(parser) -> None:
    from biped.optimization.optimize import DEFAULT_STARTS

    types.add_criterion(parser)
    types.add_options(
        parser,
        ("--starts", types.starts, DEFAULT_STARTS, "N", "IPOPT starts of each optimization, 1 "
         f"to {types.MAX_STARTS}: the first guess (at the robot's radii) and N-1 random ones "
         f"(default {DEFAULT_STARTS}); {types.CERTIFIED_HELP}"),
        ("--seed", types.non_negative, 0, "N", "seed of the random starts (default 0)"),
    )  # fmt: skip
    types.add_safety(parser)
    types.add_options(
        parser,
        *(
            (f"--max-{name}", types.metres, None, "M", f"[m] upper bound of {name}, the "
             f"{segment} circle's radius (default {limit}: the centre of mass stays on the "
             "segment)")
            for name, segment, limit in (
                ("r1", "shank", "s1, the shank's centre of mass from the knee"),
                ("r2", "thigh", "l2 - s2, the thigh's centre of mass from the knee"),
            )
        ),
    )  # fmt: skip
    types.add_robot(parser)


def add_parsers(commands) -> None:
    help = "optimal rolling-knee radii with the gait at one speed"
    design = types.add_command(commands, "design", help, cmd_design)
    types.add_speed(design)
    checks.add_gait_out(design)
    from biped.model.profile import FAMILIES

    design.add_argument(
        "--profile",
        choices=FAMILIES,
        default=None,
        metavar="FAMILY",
        help="design the knee's two surfaces as profiles of FAMILY ("
        + ", ".join(FAMILIES)
        + ": each radius of curvature r + k ψ of its tangent angle ψ), started from the "
        "optimal circles and never worse than them; the gait file's robot holds r1, r2, "
        "k1, k2 (default: circles)",
    )
    # the designed circles' gait file, beside the profile's
    checks.declare_output(design, checks.Output("--out", checks.FILE, checks.WHOLE, circles_of))
    _add_common(design)

    help = "optimal gait over a grid of knee radii, and the optimal radii, per speed"
    grid = types.add_command(commands, "design-map", help, cmd_design_map)
    types.add_speeds(grid, np.array([0.3]), "0.3")
    for name in ("r1", "r2"):
        grid.add_argument(
            f"--{name}",
            type=radii,
            default=None,
            metavar="GRID",
            help=f"{name} values [m]: START:STOP:COUNT or a list (default 10 from 0 to its "
            "upper bound)",
        )
    checks.add_folder(grid, "--out", DEFAULT_MAP, "folder of the map")
    types.add_jobs(grid)
    types.add_dask(grid)
    _add_common(grid)


def _upper(args, robot) -> tuple:
    """The upper bounds of the radii given on the command line (default the limits)."""
    from biped.optimization.design import MIN_RADIUS, radius_limits

    upper = []
    for name, limit in zip(("r1", "r2"), radius_limits(robot), strict=True):
        value = getattr(args, f"max_{name}", None)  # the pipeline has none
        if value is not None and not MIN_RADIUS < value <= limit:
            raise BipedError(
                f"--max-{name} {value:g} m: allowed > {MIN_RADIUS:g} m (the radii's lower "
                f"bound) and <= {limit:.4g} m (beyond, the "
                f"{'shank' if name == 'r1' else 'thigh'}'s centre of mass leaves the segment)"
            )
        upper.append(limit if value is None else value)
    return tuple(upper)


def _check_own_radii(args, robot, upper: tuple) -> None:
    """Refuse a robot whose own radii, the rolling knee every design is compared with, lie
    beyond the design's bounds: compared at the bound instead, the row would not be the
    robot's knee."""
    from biped.optimization.design import MIN_RADIUS, RADII, radius_limits

    source = f"--robot {args.robot!r}" if args.robot else "Table 1's robot"
    radii = zip(RADII, (robot.r1, robot.r2), upper, radius_limits(robot), strict=True)
    for name, value, high, limit in radii:
        if not MIN_RADIUS <= value <= high:
            wider = high < value <= limit and hasattr(args, f"max_{name}")
            option = f" or --max-{name} {value:g}" if wider else ""
            raise BipedError(
                f"{source}: its own {name} = {value:g} m lies beyond the design's bounds "
                f"{MIN_RADIUS:g} to {high:.4g} m, so its knee cannot be compared: allowed a "
                f"robot whose radii lie within them{option}"
            )


def design_problem(args, robot, speed):
    """The knee design of the command line at ``speed`` (``biped.optimization.design``); a
    robot whose own radii lie beyond its bounds is refused (``_check_own_radii``)."""
    from biped.optimization.design import DesignProblem

    upper = _upper(args, robot)
    _check_own_radii(args, robot, upper)
    return DesignProblem(robot, speed, args.criterion, types.safety(args), upper=upper)


def cmd_design(args) -> int:
    """Optimise the rolling knee's radii (r1, r2) together with the gait at one speed and
    write the gait file of the designed robot (its ``robot`` holds the radii, so
    ``biped validate FILE`` walks it on the MJCF of those radii).

    The radii stay within design bounds that keep the centres of mass on the shank and the
    thigh (r1 <= s1, r2 <= l2 - s2; narrower with --max-r1, --max-r2). Prints the optimal
    radii and criterion beside the revolute knee and the rolling knee of the robot's own
    radii (Table 1: 5 cm) at the same speed and margins, with the changes in %. Exits 1 when
    the design's solver did not converge or its gait is infeasible (no file), or when a
    knee it is compared with is not certified.
    """
    from biped.optimization.design import bound_notes, compare
    from biped.records.gait_file import Gait
    from biped_cli.profile import check_profile_options, run_profile

    robot = types.robot_of(args)
    check_profile_options(args)
    problem = design_problem(args, robot, args.speed)
    if args.profile is not None:
        return run_profile(args, problem)
    print(f"designing the {problem.describe()} (seed {args.seed})...", file=sys.stderr)
    comparison = compare(problem, seed=args.seed, starts=args.starts)
    design = comparison.design
    print(comparison.table())
    for note in bound_notes(problem, design):
        print(note)
    print(comparison.radii_line())
    print(f"design: {design.report.summary()}")
    if design.report.converged and not design.report.confirmed:
        print(
            "warning: the best design was reached by a single start; more --starts may find "
            "a better one",
            file=sys.stderr,
        )
    if not design.certified:
        reason = (
            f"the solver did not converge ({design.report.status})"
            if not design.report.converged
            else f"the design's gait is infeasible ({design.optimum.evaluation.violations_line()})"
        )
        print(f"biped design: {reason}; no file written", file=sys.stderr)
        return 1
    path = Gait.from_design(comparison).write(args.out)
    print(f"wrote {path}")
    return certified_exit(comparison.uncertified())


def certified_exit(bad) -> int:
    """0 when every knee compared is a certified optimum; else 1, after one line on stderr
    naming the others (``bad``, a design comparison's ``uncertified()``)."""
    if not bad:
        return 0
    print(
        "biped design: compared with knees that are not certified optima ("
        + "; ".join(bad)
        + "): the changes in % are not between certified optima",
        file=sys.stderr,
    )
    return 1


def cmd_design_map(args) -> int:
    """The optimal gait's criterion over a grid of knee radii (r1, r2) at each speed, the
    revolute knee, the Table 1 radii and the jointly optimal radii; then the figures
    (map-<speed>.png, speeds.png with several speeds) and summary.csv in --out.

    Every optimization is saved as it completes (one JSON each); run the same command again
    to resume. Runs on all cores, or on a Dask cluster with --dask tcp://HOST:PORT. Exits 1
    when an optimization is not certified (converged and feasible).
    """
    from biped.model.criteria import CRITERION_UNITS
    from biped.optimization.comparison import DIFFERENCE_VS_REVOLUTE
    from biped.optimization.design import bound_notes
    from biped.pages.design_map_figures import draw
    from biped.runtime.runner import check_dask
    from biped.studies.design_map import MANIFEST, load, run_design_map, speed_summaries

    robot = types.robot_of(args)
    problem = design_problem(args, robot, float(args.speeds[0]))
    for note in bound_notes(problem):
        print(note)
    if args.dask is not None:
        check_dask(args.dask)
    run_design_map(
        args.out,
        robot,
        args.speeds,
        args.r1,
        args.r2,
        criterion=args.criterion,
        safety=problem.safety,
        upper=problem.upper,
        seed=args.seed,
        starts=args.starts,
        **types.campaign(args, "design map"),
    )
    for path in draw(args.out):
        print(f"wrote {path}")
    settings, results = load(args.out)
    print(  # the folder's other files, once: a file per optimization is too many to name
        f"design map results in {args.out}: {MANIFEST}, {len(results)} optimizations, one JSON each"
    )
    unit = CRITERION_UNITS[settings.criterion]
    print(
        f"{'speed [m/s]':>12}{'r1 [m]':>9}{'r2 [m]':>9}{f'design [{unit}]':>18}"
        f"{'vs revolute':>13}{'Table 1 vs revolute':>21}"
    )
    for s in speed_summaries(settings, results):
        r1, r2 = ("n/a", "n/a") if s.radii is None else (f"{s.radii[0]:.4f}", f"{s.radii[1]:.4f}")
        design = "n/a" if s.design is None else f"{s.design:.4f}"
        gain, table1 = s.gain(s.design), s.gain(s.table1)
        print(
            f"{s.speed:12.3f}{r1:>9}{r2:>9}{design:>18}"
            f"{'n/a' if gain is None else f'{gain:+.2f} %':>13}"
            f"{'n/a' if table1 is None else f'{table1:+.2f} %':>21}"
        )
    print(f"vs revolute: {DIFFERENCE_VS_REVOLUTE}")
    certified = all(content["certified"] for content in results.values())
    return 0 if certified else 1
