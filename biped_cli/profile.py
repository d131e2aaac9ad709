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
    from biped_cli import args as types

    out = Path(args.out)
    circles_path = out.with_name(f"{out.stem}{CIRCLES_SUFFIX}")
    types.check_output(str(circles_path))
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
    design = {**gait.design, "circles_gait": circles_path.name}
    path = dataclasses.replace(gait, design=design).write(out)
    print(f"wrote {path}")
    written = Gait.from_design(comparison.circles).write(circles_path)
    print(f"wrote {written} (the designed circles' gait, which the page draws beside)")
    bad = comparison.circles.uncertified()
    if bad:
        print(
            "biped design: compared with knees that are not certified optima ("
            + "; ".join(bad)
            + "): the changes in % are not between certified optima",
            file=sys.stderr,
        )
        return 1
    return 0


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
