"""``biped design`` and ``biped design-map``: the rolling knee's radii optimised with the gait
(``biped.optimization.design``) and mapped over a grid of radii (``biped.studies.design_map``); the
design stage
of ``biped pipeline --design``."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

from biped.errors import BipedError
from biped_cli import args as types

DEFAULT_MAP = "logs/design-map"
# Most grid values per radius: a map is an optimization per (r1, r2) and speed.
MAX_GRID = 100
CRITERION_UNITS = {"sthenic": "N²·m·s", "energy": "J"}


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
    parser.add_argument(
        "--starts",
        type=types.positive,
        default=DEFAULT_STARTS,
        metavar="N",
        help="IPOPT starts of each optimization: the first guess (at the robot's radii) and "
        f"N-1 random ones (default {DEFAULT_STARTS}); {types.CERTIFIED_HELP}",
    )
    parser.add_argument(
        "--seed",
        type=types.non_negative,
        default=0,
        metavar="N",
        help="seed of the random starts (default 0)",
    )
    parser.add_argument(
        "--clearance",
        type=types.clearance,
        default=0.0,
        metavar="M",
        help="[m] height the swing foot must keep off the ground away from the ends of the "
        "step (default 0, the paper's z >= 0)",
    )
    parser.add_argument(
        "--zmp-margin",
        type=types.zmp_margin,
        default=0.0,
        metavar="M",
        help="[m] distance the ZMP must keep inside the sole's heel and toe (default 0)",
    )
    for name, segment, limit in (
        ("r1", "shank", "s1, the shank's centre of mass from the knee"),
        ("r2", "thigh", "l2 - s2, the thigh's centre of mass from the knee"),
    ):
        parser.add_argument(
            f"--max-{name}",
            type=types.metres,
            default=None,
            metavar="M",
            help=f"[m] upper bound of {name}, the {segment} circle's radius (default {limit}: "
            f"the centre of mass stays on the segment)",
        )
    parser.add_argument("--robot", metavar="FILE", help=types.ROBOT_HELP)


def add_parsers(commands) -> None:
    """Register ``design`` and ``design-map`` on the ``biped`` subcommands."""
    design = commands.add_parser(
        "design",
        help="optimal rolling-knee radii with the gait at one speed",
        description=cmd_design.__doc__,
    )
    design.add_argument(
        "--speed", type=types.speed, required=True, metavar="V", help=types.SPEED_HELP
    )
    design.add_argument(
        "--out",
        required=True,
        metavar="FILE",
        help=f"gait file to write (JSON; {types.FOLDERS_CREATED})",
    )
    _add_common(design)
    design.set_defaults(run=cmd_design)

    grid = commands.add_parser(
        "design-map",
        help="optimal gait over a grid of knee radii, and the optimal radii, per speed",
        description=cmd_design_map.__doc__,
    )
    grid.add_argument(
        "--speeds",
        type=types.speeds,
        default=np.array([0.3]),
        metavar="S",
        help="START:STOP:COUNT or a list V1,V2,... [m/s] (default 0.3)",
    )
    for name in ("r1", "r2"):
        grid.add_argument(
            f"--{name}",
            type=radii,
            default=None,
            metavar="GRID",
            help=f"{name} values [m]: START:STOP:COUNT or a list (default 10 from 0 to its "
            "upper bound)",
        )
    grid.add_argument(
        "--out",
        default=DEFAULT_MAP,
        metavar="DIR",
        help=f"folder of the map, {types.FOLDER_CREATED} (default {DEFAULT_MAP})",
    )
    grid.add_argument("--jobs", type=types.jobs, default=None, metavar="N", help=types.JOBS_HELP)
    types.add_dask(grid)
    _add_common(grid)
    grid.set_defaults(run=cmd_design_map)


def _upper(args, robot) -> tuple:
    """The upper bounds of the radii given on the command line (default the limits)."""
    from biped.optimization.design import MIN_RADIUS, radius_limits

    limits = radius_limits(robot)
    upper = []
    for name, limit in zip(("r1", "r2"), limits, strict=True):
        value = getattr(args, f"max_{name}", None)  # the pipeline has none
        if value is None:
            upper.append(limit)
        elif not MIN_RADIUS < value <= limit:
            raise BipedError(
                f"--max-{name} {value:g} m: allowed > {MIN_RADIUS:g} m (the radii's lower "
                f"bound) and <= {limit:.4g} m (beyond, the "
                f"{'shank' if name == 'r1' else 'thigh'}'s centre of mass leaves the segment)"
            )
        else:
            upper.append(value)
    return tuple(upper)


def _robot(path):
    from biped.model.robot import Robot

    return Robot.paper() if path is None else Robot.from_file(path)


def _problem(args, robot, speed):
    from biped.optimization.design import DesignProblem

    return DesignProblem(
        robot, speed, args.criterion, types.safety(args), upper=_upper(args, robot)
    )


def _radii_line(comparison) -> str:
    design = comparison.design
    unit = CRITERION_UNITS[comparison.problem.criterion]
    gains = comparison.gains()
    bounds = design.at_bounds()
    return (
        f"optimal radii: r1 = {design.radii[0]:.4f} m, r2 = {design.radii[1]:.4f} m"
        f"{' (' + ', '.join(bounds) + ')' if bounds else ''}; "
        f"{comparison.problem.criterion} {design.value:.6g} {unit}: "
        f"{gains['design_vs_revolute']:+.2f} % vs revolute, "
        f"{gains['design_vs_table1']:+.2f} % vs Table 1 radii"
    )


def _bound_notes(problem, design=None) -> list[str]:
    """What the design's bounds did: the robot's own radii moved into them (the reference
    design of the table), and a designed radius at its lower bound (``MIN_RADIUS``)."""
    from biped.optimization.design import MIN_RADIUS

    notes = [f"note: {sentence}" for sentence in problem.moved_reference()]
    for bound in [] if design is None else design.at_bounds():
        if bound.endswith("lower bound"):
            notes.append(
                f"note: {bound} {MIN_RADIUS:g} m: the radii are bounded away from 0, where "
                "the rolling knee is the revolute knee (the first row); the design gains "
                "nothing by rolling on that side"
            )
    return notes


def _uncertified(comparison) -> list[str]:
    return [
        f"{label}: {optimum.report.status if not optimum.report.converged else 'infeasible'}"
        for label, _, optimum in comparison.rows()
        if not optimum.certified
    ]


def _gait(comparison, seed: int) -> dict:
    from biped.records import gait_file

    design = comparison.design
    content = gait_file.to_dict(design.optimum, design.robot, seed)
    content["design"] = comparison.to_dict()
    return content


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
    from biped.optimization.design import compare
    from biped.records import gait_file

    robot = _robot(args.robot)
    problem = _problem(args, robot, args.speed)
    types.check_output(args.out)
    print(f"designing the {problem.describe()} (seed {args.seed})...", file=sys.stderr)
    comparison = compare(problem, seed=args.seed, starts=args.starts)
    design = comparison.design
    print(comparison.table())
    for note in _bound_notes(problem, design):
        print(note)
    print(_radii_line(comparison))
    print(f"design: {design.report.summary()}")
    if design.report.converged and not design.report.confirmed:
        print(
            "warning: the best design was reached by a single start; more --starts may find "
            "a better one",
            file=sys.stderr,
        )
    if not design.report.converged or not design.optimum.feasible:
        reason = (
            f"the solver did not converge ({design.report.status})"
            if not design.report.converged
            else "the design's gait is infeasible ("
            + ", ".join(f"{k} = {v:.3g}" for k, v in design.optimum.evaluation.violations().items())
            + ")"
        )
        print(f"biped design: {reason}; no file written", file=sys.stderr)
        return 1
    path = gait_file.write_json(args.out, _gait(comparison, args.seed))
    print(f"wrote {path}")
    bad = _uncertified(comparison)
    if bad:
        print(
            "biped design: compared with knees that are not certified optima ("
            + "; ".join(bad)
            + "): the changes in % are not between certified optima",
            file=sys.stderr,
        )
        return 1
    return 0


def cmd_design_map(args) -> int:
    """The optimal gait's criterion over a grid of knee radii (r1, r2) at each speed, the
    revolute knee, the Table 1 radii and the jointly optimal radii; then the figures
    (map-<speed>.png, speeds.png with several speeds) and summary.csv in --out.

    Every optimization is saved as it completes (one JSON each); run the same command again
    to resume. Runs on all cores, or on a Dask cluster with --dask tcp://HOST:PORT. Exits 1
    when an optimization is not certified (converged and feasible).
    """
    from biped.records.comparison import DIFFERENCE_VS_REVOLUTE
    from biped.runtime.runner import check_dask
    from biped.studies.design_map import MANIFEST, draw, load, run_design_map, speed_summaries
    from biped_cli.progress import Progress

    robot = _robot(args.robot)
    problem = _problem(args, robot, float(args.speeds[0]))
    types.check_folder(args.out, "--out")
    for note in _bound_notes(problem):
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
        jobs=args.jobs,
        dask=args.dask,
        progress=lambda total: Progress(total, "design map"),
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


def pipeline_design(args, robot, optima: dict, out: Path, recordings: Path) -> bool:
    """The design stage of ``biped pipeline --design``: the radii optimised at the
    pipeline's speed, the table of the revolute knee, the Table 1 radii and the optimal
    radii (the pipeline's own optima where certified), and the designed gait written and
    validated in MuJoCo as the knees' are. Returns whether every step passed."""
    from biped.optimization.design import compare
    from biped.records import gait_file
    from biped_cli.commands import _validate_and_record
    from biped_cli.outputs import check_owner, recording_lines

    problem = _problem(args, robot, args.speed)
    name = f"design-{args.criterion}-{args.speed:.3f}"
    check_owner(recordings / f"{name}.rrd", out / f"{name}.json", "--recordings")
    print(f"[design] optimizing the knee radii at {args.speed} m/s ({args.criterion})...")
    given = {
        name: optima[knee] if knee in optima and optima[knee].certified else None
        for name, knee in (("revolute", "revolute"), ("reference", "rolling"))
    }
    comparison = compare(problem, seed=args.seed, starts=args.starts, **given)
    design = comparison.design
    for line in comparison.table().splitlines() + _bound_notes(problem, design):
        print(f"[design] {line}")
    print(f"[design] {_radii_line(comparison)}")
    print(f"[design] {design.report.summary()}")
    if not design.certified:
        print(f"[design] FAIL  the design is not certified: {design.report.status}")
        return False
    gait_path = gait_file.write_json(out / f"{name}.json", _gait(comparison, args.seed))
    print(f"[design] validating {args.steps} steps in MuJoCo...", flush=True)
    video = None if args.no_video else recordings / f"{name}.mp4"
    result, report = _validate_and_record(
        gait_file.read(gait_path), args.steps, recordings / f"{name}.rrd", video, source=gait_path
    )
    for check in result.checks:
        print("[design]   " + check.line())
    report_path = gait_file.write_json(
        out / f"{name}.report.json", {**report, "gait": str(gait_path)}
    )
    print(f"[design] gait {gait_path}, report {report_path}")  # every file written, once
    for line in recording_lines(report["recording"]):
        print(f"[design] {line}")
    for written in report.get("video", []):
        print(f"[design] video {written}")
    return result.passed and not _uncertified(comparison)
