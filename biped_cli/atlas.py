"""``biped atlas``: where the rolling knee pays off, over speed x clearance (x a least knee bend),
each difference with its error bar (``biped.studies.atlas``), under the walkable constraints
or the paper's; every certified optimum walked in MuJoCo (``validate.studies.atlas_walks``); then
its CSV, figures and ``atlas.md`` (``biped.pages.atlas``). ``biped compare-atlas``: two atlases
of one problem in two gait families, cell by cell (``biped.studies.atlas_families``)."""

from __future__ import annotations

import argparse

import numpy as np

from biped.model.criteria import MAX_CLEARANCE, MAX_KNEE_BEND
from biped_cli import args as types
from biped_cli import checks

DEFAULT_ATLAS = "logs/atlas"
DEFAULT_FAMILIES = "logs/atlas-families"
FAMILIES = "families"  # the comparison's files' name (``biped.pages.atlas_families.NAME``)
MAX_VALUES = 100


def _values(name: str, unit: str, high: float):
    """A list or range of values from 0 to ``high`` (``types.number_list``)."""

    def parse(text: str) -> np.ndarray:
        values = types.number_list(text, name, MAX_VALUES, f" [{unit}]")
        if values.size == 0 or not np.all(np.isfinite(values) & (values >= 0) & (values <= high)):
            raise argparse.ArgumentTypeError(
                f"{name} = {text!r}: allowed values from 0 to {high:g} {unit}"
            )
        return np.round(values, 6)

    return parse


clearances = _values("clearances", "m", MAX_CLEARANCE)
knee_bends = _values("knee bends", "rad", MAX_KNEE_BEND)


def cmd_atlas(args) -> int:
    """Certified optimal gaits of both knees over a grid of speed x swing-foot clearance (x a
    least stance-knee bend), for each criterion asked, under the walkable constraints (the
    cells' clearances and knee bends replace the preset's; --paper-constraints: the paper's
    problem); each difference between the knees, (rolling − revolute) / revolute, with its
    uncertainty: the change on a grid of twice the samples, at ten times tighter tolerance
    and the spread of the starts; a difference no larger than it is not distinguishable. At
    the corner cells the gait is also optimized with 3 interior knots: how the difference
    moves with a richer gait. Then every certified optimum is walked in MuJoCo (unless
    --no-walks): the forward walk with contact and the feedforward replay everywhere, every
    check of biped validate at the corners and at each criterion's best pay-off; a gait
    walks when every check run on it passes. Writes the optima, the walks' records,
    atlas.csv, atlas-<criterion>.png and atlas.md (the pay-off among walking gaits beside
    the pay-off over all certified cells) in --out. Run again to resume. Exits 0 when every
    final optimum is certified, every re-solve measured what it is for and every walk was
    measured (a gait that does not walk is a finding, not a failure), 1 otherwise (a
    re-solve that did not converge leaves its term unknown: the run's last line and
    atlas.md say which and why). With --double-support, then each knee's two-phase optimum at
    every cell where it is built, from the cell's single-support optimum, in
    OUT/double-support/; exits 1 also when one is missing."""
    from biped.model.criteria import PAPER_SAFETY, WALKABLE
    from biped.pages import atlas as pages
    from biped.runtime.runner import check_dask
    from biped.studies import atlas

    settings = atlas.check_settings(
        atlas.Settings(
            types.robot_of(args),
            tuple(float(v) for v in args.speeds),
            tuple(float(v) for v in args.clearances),
            tuple(float(v) for v in args.knee_bends),
            tuple(args.criteria),
            types.gait_family(args),
            args.seed,
            args.starts,
            actuator_limits=args.actuator_limits,
            safety=PAPER_SAFETY if args.paper_constraints else WALKABLE,
        )
    )
    atlas.check_folder(args.out, settings)
    two = None
    if args.double_support is not None:  # refused before the atlas runs, not after
        from biped.studies import atlas_two_phase

        two = atlas_two_phase.of_atlas(settings, args.double_support, args.landing)
        atlas_two_phase.check_two_phase(args.out, two)
    if args.dask is not None:
        check_dask(args.dask)
    atlas.run_atlas(args.out, settings, **types.campaign(args, "atlas"))
    unwalked = []
    if not args.no_walks:
        from validate.studies import atlas_walks

        atlas_walks.run_walks(args.out, settings, **types.campaign(args, "walks"))
        unwalked = atlas_walks.unmeasured(args.out, settings)
    for path in pages.write(args.out, walked=not args.no_walks):
        print(f"wrote {path}")
    certified = all(
        (content := atlas.read(args.out, atlas.Point("final", k, c, cell))) is not None
        and content.certified
        for c in settings.criteria
        for cell in settings.cells()
        for k in ("revolute", "rolling")
    )
    status = 0 if certified and not atlas.unmeasured(args.out, settings) and not unwalked else 1
    if two is not None:  # from the atlas's single-support optima, those certified
        status = max(status, cmd_atlas_double_support(args, settings, two))
    return status


def cmd_atlas_double_support(args, settings, two) -> int:
    """The atlas's two-phase optima (``biped.studies.atlas_two_phase``), their summary and
    figure printed and written; 1 when a knee at a built cell has no two-phase optimum."""
    from pathlib import Path

    from biped.pages.atlas_two_phase import atlas_two_phase_figure
    from biped.studies import atlas_two_phase as study

    where = types.campaign(args, "double support")
    summary = study.run_two_phase(args.out, settings, two, **where)
    folder = Path(args.out) / study.FOLDER
    figure = atlas_two_phase_figure(summary, folder / study.FIGURE)
    print(summary.table())
    print(
        f"double support results in {folder}: {study.RECORD}, {study.SUMMARY}, {figure.name}, "
        "a two-phase gait file (or its failure record) <knee>-sthenic-<cell>.json per built "
        f"cell and knee; {len(summary.not_built)} cell(s) and criteria not built"
    )
    missing = summary.missing()
    if missing:
        print(f"double support: {len(missing)} of {len(summary.points)} two-phase optima "
              "NOT CERTIFIED (above: why)")  # fmt: skip
    return 1 if missing else 0


def add_parser(commands) -> None:
    from biped.optimization.optimize import DEFAULT_STARTS
    from biped.studies.atlas import DEFAULT_CLEARANCES, DEFAULT_CRITERIA, DEFAULT_SPEEDS

    help = "where the rolling knee pays off: speed x clearance, with error bars"
    parser = types.add_command(commands, "atlas", help, cmd_atlas)
    shown = f"{DEFAULT_SPEEDS[0]:g}:{DEFAULT_SPEEDS[-1]:g}:{len(DEFAULT_SPEEDS)}"
    types.add_speeds(parser, np.array(DEFAULT_SPEEDS), shown)
    types.add_options(
        parser,
        ("--clearances", clearances, np.array(DEFAULT_CLEARANCES), "C",
         f"[m] swing-foot clearances, START:STOP:COUNT or a list C1,C2,..., 0 to "
         f"{MAX_CLEARANCE:g} m (default {','.join(f'{c:g}' for c in DEFAULT_CLEARANCES)})"),
        ("--knee-bends", knee_bends, np.array([0.0]), "B",
         f"[rad] least stance-knee bends, a list or START:STOP:COUNT, 0 to {MAX_KNEE_BEND:g} "
         "rad (default 0: the paper's knee, not inverted)"),
        ("--starts", types.starts, DEFAULT_STARTS, "N",
         f"IPOPT's own starts per point, 1 to {types.MAX_STARTS} (default {DEFAULT_STARTS}); "
         f"{types.CERTIFIED_HELP}"),
        ("--seed", types.non_negative, 0, "N", "seed of the perturbed starts (default 0)"),
    )  # fmt: skip
    types.add_criterion(parser, several=True, default=DEFAULT_CRITERIA)
    types.add_knots(parser)
    types.add_bezier(parser)
    checks.add_folder(parser, "--out", DEFAULT_ATLAS, "folder of the atlas")
    parser.add_argument(
        "--no-walks", action="store_true", help="skip walking the certified optima in MuJoCo"
    )
    parser.add_argument(
        "--paper-constraints",
        action="store_true",
        help="the paper's problem (its constraints alone, the cells' clearances and knee bends "
        "aside) instead of the walkable constraints",
    )
    parser.add_argument("--actuator-limits", action="store_true", help=types.ACTUATOR_LIMITS_HELP)
    types.add_robot(parser)
    types.add_jobs(parser)
    types.add_dask(parser)
    add_double_support(parser)


def add_double_support(parser) -> None:
    """``--double-support LOW:HIGH`` and ``--landing``, and the rule of what they combine
    with."""
    types.add_double_support(
        parser,
        "after the atlas, at every cell where the gait of two phases is built (sthenic "
        "criterion, the paper's spline and constraints: --paper-constraints), each knee's "
        "optimum of single then double support, its double support a share of the step from "
        "LOW to HIGH (0 <= LOW <= HIGH < 0.5; one number: that share), started from the "
        "cell's single-support optimum; written with a summary and a figure in "
        "OUT/double-support/ (docs/atlas.md); the other cells listed as not built, with why "
        "(default: the atlas alone)",
    )
    types.add_landing(parser)
    options = ("--double-support", "--criteria", "--paper-constraints", "--actuator-limits",
               "--knots", "--family")  # fmt: skip
    checks.declare_rule(parser, options, _check_double_support)


def _check_double_support(args) -> None:
    """--double-support where at least one cell builds the two-phase problem: sthenic among
    the criteria, the paper's constraints and spline, no actuator limits."""
    from biped.errors import BipedError

    if args.double_support is None:
        return
    if "sthenic" not in args.criteria:
        raise BipedError(
            f"--criteria {' '.join(args.criteria)} with --double-support: allowed sthenic among "
            "them (the two-phase problem's only criterion)"
        )
    if not args.paper_constraints:
        raise BipedError(
            "--double-support without --paper-constraints: allowed the paper's problem (the "
            "two-phase problem is not built under the walkable constraints)"
        )
    if args.actuator_limits:
        raise BipedError("--actuator-limits with --double-support: allowed neither (the "
                         "two-phase problem has no actuator limits)")  # fmt: skip
    if args.knots != 1 or args.family != "spline":
        raise BipedError(
            f"--knots {args.knots} --family {args.family} with --double-support: allowed the "
            "paper's spline (--knots 1, --family spline)"
        )


def cmd_compare(args) -> int:
    """Two atlases of the same problem (robot, margins, knee bends) in two gait families,
    on their common cells and criteria: per cell and criterion the difference between the knees
    in each family with its error bar, the shift (rich less base) and whether the base family
    hides or invents a pay-off of the rolling knee (a shift beyond both error bars), agrees
    within them, or is unknown (an error bar not measured). Writes families.json,
    families.png and families.md in --out; prints a sentence per criterion. Exits 0 when
    every cell is compared, 1 when one is unknown, 2 for atlases that do not compare."""
    from biped.pages import atlas_families as pages
    from biped.studies.atlas_families import compare_atlases

    comparison = compare_atlases(args.base, args.rich)
    for path in pages.write(comparison, args.out):
        print(f"wrote {path}")
    for criterion in comparison.criteria:
        print(pages.sentence(comparison, criterion))
    unknown = sum(comparison.counts(c)["unknown"] for c in comparison.criteria)
    if unknown:
        print(f"{unknown} cells unknown (an error bar not measured): see families.md")
    return 1 if unknown else 0


def add_compare_parser(commands) -> None:
    help = "two atlases in two gait families, cell by cell"
    parser = types.add_command(commands, "compare-atlas", help, cmd_compare)
    parser.add_argument(
        "base",
        metavar="BASE_DIR",
        help="folder of the base atlas (biped atlas --out), e.g. the paper's spline",
    )
    parser.add_argument(
        "rich",
        metavar="RICH_DIR",
        help="folder of the atlas of the same problem in a richer family (biped atlas "
        "--family bezier --degree N --out)",
    )
    checks.add_folder(
        parser, "--out", DEFAULT_FAMILIES, "folder of the comparison", claims=(FAMILIES,)
    )
