"""``biped design --profile FAMILY``: the rolling knee's surfaces designed as profiles of a
family (``biped.model.profile``) with the gait, from the best circles
(``biped.optimization.profile_design``)."""

from __future__ import annotations

import dataclasses
import sys
from pathlib import Path

from biped.errors import BipedError

# The designed circles' gait file, beside the profile's: ``<stem>-circles.json``.
CIRCLES_SUFFIX = "-circles.json"


def run_profile(args, problem) -> int:
    """The profile design of ``problem`` (a circles' ``DesignProblem``): the circles'
    comparison, then the profile from its circles; prints the four knees and writes the gait
    file of the designed profile and, beside it, the designed circles' (``CIRCLES_SUFFIX``,
    named in the profile's design block as ``circles_gait``). Exits 1 when the profile's
    search or a knee compared is not certified (no file when the design itself is not)."""
    from biped.optimization.design import bound_notes
    from biped.optimization.profile_design import ProfileProblem, compare_profile
    from biped.records.gait_file import Gait
    from biped_cli.design import certified_exit

    out = Path(args.out)
    circles = circles_path(out)  # checked and claimed with --out (biped_cli.design)
    profiled = ProfileProblem(problem, args.profile)
    print(f"designing the {profiled.describe()} (seed {args.seed})...", file=sys.stderr)
    comparison = compare_profile(profiled, seed=args.seed, starts=args.starts)
    design = comparison.profile
    print(comparison.table())
    for note in bound_notes(problem, comparison.circles.design):
        print(note)
    print(comparison.circles.radii_line())
    print(comparison.profile_line())
    print(f"circles: {comparison.circles.design.report.summary()}")
    print(f"profile: {design.search.summary()}")
    if not design.search.converged or not design.certified:
        reason = (
            f"the profile's solver did not converge ({design.search.status})"
            if not design.search.converged
            else f"the design's gait is infeasible ({design.optimum.evaluation.violations_line()})"
        )
        print(f"biped design: {reason}; no file written", file=sys.stderr)
        return 1
    gait = Gait.from_profile_design(comparison)
    design = {**gait.design, "circles_gait": circles.name}
    path = dataclasses.replace(gait, design=design).write(out)
    print(f"wrote {path}")
    written = Gait.from_design(comparison.circles).write(circles)
    print(f"wrote {written} (the designed circles' gait, which the page draws beside)")
    return certified_exit(comparison.circles.uncertified())


def circles_path(out: str | Path) -> Path:
    """The designed circles' gait file beside the profile's, ``out``."""
    out = Path(out)
    return out.with_name(f"{out.stem}{CIRCLES_SUFFIX}")


def check_profile_options(args) -> None:
    """Refuse options a profile design does not take."""
    if getattr(args, "profile", None) is not None and args.robot is not None:
        from biped_cli import args as types

        robot = types.robot_of(args)
        if robot.profiled:
            raise BipedError(
                f"--robot {args.robot!r} has a profiled knee (k1 = {robot.k1:g}, "
                f"k2 = {robot.k2:g}): allowed a robot of circles (k1 = k2 = 0), the design's "
                "first start"
            )


def add_parser(commands) -> None:
    from biped.studies.sweep import DEFAULT_SPEEDS
    from biped_cli import args as types
    from biped_cli import checks

    help = "a designed knee profile over the speeds, against circles designed at each"
    parser = types.add_command(commands, "profile-speeds", help, cmd_profile_speeds)
    parser.add_argument("gait", metavar="GAIT.json", help="gait file of biped design --profile")
    types.add_speeds(parser, DEFAULT_SPEEDS, "the sweep's, 0.15:0.45:13")
    help = f"JSON of the rows to write (its figure beside it, .png; {types.FOLDERS_CREATED})"
    checks.add_out(parser, "--out", checks.FILE, help, paths=with_figure, required=True)
    types.add_options(
        parser,
        ("--starts", types.starts, 3, "N", "IPOPT starts of each optimization (default 3); "
         + types.CERTIFIED_HELP),
        ("--seed", types.non_negative, 0, "N", "seed of the random starts (default 0)"),
    )  # fmt: skip


def with_figure(args) -> list:
    """The rows' JSON --out names and its figure beside it, .png."""
    return [args.out, str(Path(args.out).with_suffix(".png"))]


def cmd_profile_speeds(args) -> int:
    """The knee profile of a gait file (``biped design --profile``: its robot's r1, r2, k1,
    k2), machined once, at each speed of --speeds: its optimal gait beside the circles
    designed at that speed and the revolute knee, for the file's criterion and margins
    (``biped.studies.profile_speeds``). Prints the table, writes it as JSON and its figure
    (.png beside). Exits 1 when a knee at a speed is not certified."""
    from biped.model.criteria import CRITERION_UNITS
    from biped.pages.profile_figures import speeds_figure
    from biped.pages.style import save
    from biped.records.gait_file import Gait, write_json
    from biped.studies.profile_speeds import content_of, machined_circles, row_at, table

    gait = Gait.read(args.gait, consistent=True)
    if gait.knee != "rolling" or not gait.robot.profiled:
        raise BipedError(
            f"gait file {args.gait!r} has a {gait.knee} knee of circles: allowed the gait file "
            "of a knee profile (biped design --profile)"
        )
    out = Path(args.out)
    figure_path = out.with_suffix(".png")  # checked and claimed with --out (with_figure)
    machined = machined_circles(gait, args.gait)
    rows = []
    for speed in args.speeds:
        print(f"at {speed:.3f} m/s ...", file=sys.stderr)
        settings = (gait.criterion, gait.safety, args.seed, args.starts)
        rows.append(row_at(gait.robot, machined, float(speed), *settings))
    print(table(rows, CRITERION_UNITS[gait.criterion]))
    content = content_of(str(args.gait), gait, machined, rows)
    print(f"wrote {write_json(out, content)}")
    save(speeds_figure(rows, gait.criterion, gait.speed), figure_path)
    print(f"wrote {figure_path}")
    bad = [row.speed for row in rows if not row.all_certified]
    if bad:
        print(
            f"biped profile-speeds: not certified at {', '.join(f'{v:.3f}' for v in bad)} m/s "
            "(their changes are unknown)",
            file=sys.stderr,
        )
        return 1
    return 0
