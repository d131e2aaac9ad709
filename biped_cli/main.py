"""The ``biped`` program: its parser, one subcommand per job, and the top-level guard.

Errors in the input print one line on stderr and exit with status 2; exit statuses are those
of ``biped_cli.guard``.
"""

from __future__ import annotations

import argparse
import re
import sys

from biped.model.kinematics import KNEES
from biped.records.provenance import command_line, version
from biped.studies.sweep import DEFAULT_SPEEDS
from biped_cli import args as types
from biped_cli import design, report, robustness
from biped_cli.commands import (
    DEFAULT_FIGURES,
    DEFAULT_PIPELINE,
    DEFAULT_RECORDINGS,
    DEFAULT_SPEED,
    DEFAULT_SWEEP,
    cmd_demo,
    cmd_figures,
    cmd_optimize,
    cmd_pipeline,
    cmd_sweep,
    cmd_validate,
)
from biped_cli.guard import EXIT_BAD_INPUT, run_guarded
from validate import DEFAULT_STEPS

ROBOT_HELP = types.ROBOT_HELP
DEBUG_HELP = "on an error, print its traceback before the one-line message"


# An argument argparse must hand to its option as a value, not read as an option: a number
# with a minus sign, alone or first of a list or range (-1, -.5, -1e-3, -0.1,0.2, -0.1:0.3:3,
# -inf). argparse's own pattern takes only -1 and -0.1, so `--speeds -0.1,0.2` failed with
# "expected one argument" before the speeds' check could name the value. No option of the
# program starts like a number.
NEGATIVE_NUMBER = re.compile(r"^-(\.?\d|inf|nan)", re.IGNORECASE)


class _Parser(argparse.ArgumentParser):
    """argparse with one-line errors: 'biped optimize: error: ...' and exit status 2, and
    negative numbers read as values (``NEGATIVE_NUMBER``)."""

    def __init__(self, *args, **kwargs):
        super().__init__(*args, **kwargs)
        self._negative_number_matcher = NEGATIVE_NUMBER

    def error(self, message):
        self.exit(EXIT_BAD_INPUT, f"{self.prog}: error: {message}\n")


def build_parser() -> argparse.ArgumentParser:
    parser = _Parser(
        prog="biped",
        description="Quasi-optimal gaits of planar bipeds with revolute or rolling knees.",
        epilog="Exit status: 0 done, 1 a result fails a check, 2 bad input (one line on "
        "stderr), 130 / 143 interrupted (Ctrl-C / SIGTERM).",
    )
    parser.add_argument("--version", action="version", version=f"%(prog)s {version()}")
    parser.add_argument("--debug", action="store_true", help=DEBUG_HELP)
    commands = parser.add_subparsers(
        dest="command", required=True, metavar="COMMAND", parser_class=_Parser
    )
    demo = commands.add_parser(
        "demo",
        help="torques, ground wrench and ZMP of a one-leg posture",
        description=cmd_demo.__doc__,
    )
    demo.add_argument(
        "--knee", choices=KNEES, help=f"one knee kinematic; {types.KNEE_HELP} (default: both)"
    )
    demo.add_argument("--robot", metavar="FILE", help=ROBOT_HELP)
    demo.add_argument(
        "--hip-ahead",
        type=types.metres,
        default=0.05,
        metavar="M",
        help="[m] hip ahead of the stance ankle (default 0.05)",
    )
    demo.add_argument(
        "--hip-height",
        type=types.metres,
        default=0.86,
        metavar="M",
        help="[m] hip above the ground (default 0.86)",
    )
    demo.set_defaults(run=cmd_demo)

    opt = commands.add_parser(
        "optimize", help="optimal gait at one speed", description=cmd_optimize.__doc__
    )
    types.add_knee(opt, required=True)
    types.add_criterion(opt)
    opt.add_argument("--speed", type=types.speed, required=True, metavar="V", help=types.SPEED_HELP)
    opt.add_argument(
        "--out",
        required=True,
        metavar="FILE",
        help=f"gait file to write (JSON; {types.FOLDERS_CREATED})",
    )
    types.add_budget(opt)
    opt.add_argument("--robot", metavar="FILE", help=ROBOT_HELP)
    opt.set_defaults(run=cmd_optimize)

    sweep = commands.add_parser(
        "sweep", help="optimal gaits over speeds, knees, criteria", description=cmd_sweep.__doc__
    )
    sweep.add_argument(
        "--speeds",
        type=types.speeds,
        default=DEFAULT_SPEEDS,
        metavar="S",
        help="START:STOP:COUNT or a list V1,V2,... [m/s] (default 0.15:0.45:13)",
    )
    types.add_knee(sweep, several=True)
    types.add_criterion(sweep, several=True)
    sweep.add_argument(
        "--out",
        default=DEFAULT_SWEEP,
        metavar="DIR",
        help=f"folder of the sweep, {types.FOLDER_CREATED} (default {DEFAULT_SWEEP})",
    )
    sweep.add_argument("--jobs", type=types.jobs, default=None, metavar="N", help=types.JOBS_HELP)
    types.add_budget(sweep, sweep=True)
    sweep.add_argument("--robot", metavar="FILE", help=ROBOT_HELP)
    types.add_dask(sweep)
    sweep.add_argument(
        "--paper-seeds",
        type=types.bounded(0, 100),
        default=5,
        metavar="N",
        help="also run the paper's Nelder-Mead from N seeds at the speed nearest 0.3 m/s, "
        "for every knee and criterion, for comparison.md (default 5; 0: none)",
    )
    sweep.set_defaults(run=cmd_sweep)

    val = commands.add_parser(
        "validate",
        help="cross-check a gait in MuJoCo and record it",
        description=cmd_validate.__doc__,
    )
    val.add_argument(
        "gait", metavar="GAIT.json", nargs="+", help="gait files from optimize, sweep, pipeline"
    )
    val.add_argument(
        "--steps", type=types.steps, default=DEFAULT_STEPS, metavar="N", help=types.STEPS_HELP
    )
    val.add_argument(
        "--rrd",
        metavar="PATH",
        help=f"recording of a single gait (default {DEFAULT_RECORDINGS}/<folder>-<gait>.rrd, "
        "named from the gait file's folder and name; another gait's recording is refused; "
        f"{types.FOLDERS_CREATED})",
    )
    val.add_argument(
        "--json",
        action="store_true",
        help="print the report as JSON (several gaits: an object keyed by file)",
    )
    val.add_argument(
        "--video",
        metavar="FILE.mp4",
        help="also render MuJoCo's walk of a single gait to an H.264 MP4 video, a path "
        f"ending in .mp4 ({types.FOLDERS_CREATED}; MUJOCO_GL=egl without a display; default: "
        "no video)",
    )
    val.add_argument(
        "--gif", action="store_true", help="with --video, also an animated GIF beside it"
    )
    viewer = val.add_mutually_exclusive_group()
    viewer.add_argument(
        "--spawn",
        action="store_true",
        help="also stream the recording to a rerun viewer started for it",
    )
    viewer.add_argument(
        "--connect",
        metavar="URL",
        nargs="?",
        const="",
        default=None,
        type=types.viewer_url,
        help="also stream the recording to the rerun viewer running at URL (URL left out: its "
        "local address; default: no stream)",
    )
    val.add_argument(
        "--model",
        metavar="PATH",
        help="MJCF to play the gaits on (default: mjcf/scene_<knee>.xml when the gait's robot is "
        "Table 1, the model generated from the gait's robot otherwise)",
    )
    val.set_defaults(run=cmd_validate)

    pipe = commands.add_parser(
        "pipeline",
        help="optimize, validate and record both knees at one speed",
        description=cmd_pipeline.__doc__,
    )
    pipe.add_argument(
        "--speed",
        type=types.speed,
        default=DEFAULT_SPEED,
        metavar="V",
        help=f"{types.SPEED_HELP} (default %(default)s)",
    )
    types.add_knee(pipe, several=True)
    types.add_criterion(pipe)
    pipe.add_argument(
        "--steps", type=types.steps, default=DEFAULT_STEPS, metavar="N", help=types.STEPS_HELP
    )
    pipe.add_argument(
        "--out",
        default=DEFAULT_PIPELINE,
        metavar="DIR",
        help=f"folder of the gait files and reports, {types.FOLDER_CREATED} "
        f"(default {DEFAULT_PIPELINE})",
    )
    pipe.add_argument(
        "--recordings",
        default=DEFAULT_RECORDINGS,
        metavar="DIR",
        help=f"folder of the rerun recordings and videos, {types.FOLDER_CREATED} "
        f"(default {DEFAULT_RECORDINGS})",
    )
    pipe.add_argument(
        "--no-video",
        action="store_true",
        help="skip the videos of the walks (<recordings>/<gait>.mp4)",
    )
    types.add_budget(pipe)
    pipe.add_argument("--robot", metavar="FILE", help=ROBOT_HELP)
    pipe.add_argument(
        "--design",
        action="store_true",
        help="also optimise the rolling knee's radii with the gait, validate the designed "
        "gait and compare revolute, Table 1 radii and optimal radii in one table",
    )
    pipe.set_defaults(run=cmd_pipeline)

    fig = commands.add_parser(
        "figures", help="figures and table of the comparison", description=cmd_figures.__doc__
    )
    fig.add_argument(
        "--sweep",
        default=DEFAULT_SWEEP,
        metavar="DIR",
        help="folder of a sweep's results, as biped sweep --out writes it (default %(default)s)",
    )
    fig.add_argument(
        "--out",
        default=DEFAULT_FIGURES,
        metavar="DIR",
        help=f"folder of the figures and comparison.md, {types.FOLDER_CREATED} "
        f"(default {DEFAULT_FIGURES})",
    )
    fig.set_defaults(run=cmd_figures)
    design.add_parsers(commands)
    report.add_parser(commands)
    robustness.add_parser(commands)
    for command in commands.choices.values():  # after the command too: biped demo --debug
        command.add_argument(
            "--debug", action="store_true", default=argparse.SUPPRESS, help=DEBUG_HELP
        )
    parser.command_parsers = commands.choices  # each command's own parser, by name
    return parser


def main(argv: list[str] | None = None) -> int:
    """Run the ``biped`` command with ``argv`` (default: ``sys.argv[1:]``); returns the exit
    status (``biped_cli.guard``), printing at most one line on stderr when it is not 0 or 1."""
    argv = sys.argv[1:] if argv is None else [str(a) for a in argv]
    name = ["biped"]  # the command, once parsed, names the error lines

    def run() -> int:
        parser = build_parser()
        try:
            args, unknown = parser.parse_known_args(argv)
            if unknown:  # named by the command's own parser, which would have taken them
                parser.command_parsers[args.command].error(
                    f"unrecognized arguments: {' '.join(unknown)} (see biped {args.command} "
                    "--help for what is allowed)"
                )
        except SystemExit as exit_:  # --help, --version, or a one-line argparse error
            return exit_.code if isinstance(exit_.code, int) else EXIT_BAD_INPUT
        name[0] = f"biped {args.command}"
        with command_line(["biped", *argv]):
            return args.run(args)

    return run_guarded(lambda: name[0], run, debug="--debug" in argv)
