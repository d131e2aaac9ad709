"""The ``biped`` program: its parser, one subcommand per job, and the top-level guard.

Errors in the input print one line on stderr and exit with status 2; exit statuses are those
of ``biped_cli.guard``.
"""

from __future__ import annotations

import argparse
import re
import sys

from biped.records.provenance import command_line, version
from biped_cli import atlas, commands, design, orbit, profile, report, robustness, size
from biped_cli.args import complete_later, lazy_commands
from biped_cli.guard import EXIT_BAD_INPUT, run_guarded

DEBUG_HELP = "on an error, print its traceback before the one-line message"


# An argument argparse must hand to its option as a value, not read as an option: a number
# with a minus sign, alone or first of a list or range (-1, -.5, -1e-3, -0.1,0.2, -0.1:0.3:3,
# -inf). argparse's own pattern takes only -1 and -0.1, so `--speeds -0.1,0.2` failed with
# "expected one argument" before the speeds' check could name the value. No option of the
# program starts like a number.
NEGATIVE_NUMBER = re.compile(r"^-(\.?\d|inf|nan)", re.IGNORECASE)


class _Parser(argparse.ArgumentParser):
    """argparse with one-line errors: 'biped optimize: error: ...' and exit status 2,
    negative numbers read as values (``NEGATIVE_NUMBER``), and no abbreviated option:
    ``--start 2`` is refused, not read as ``--starts 2``."""

    def __init__(self, *args, **kwargs):
        kwargs.setdefault("allow_abbrev", False)
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
    subcommands = parser.add_subparsers(
        dest="command", required=True, metavar="COMMAND", parser_class=_Parser
    )
    lazy_commands(subcommands)
    for add in (
        commands.add_demo,
        commands.add_optimize,
        commands.add_sweep,
        commands.add_validate,
        commands.add_pipeline,
        commands.add_figures,
        commands.add_table,
        atlas.add_parser,
        design.add_parsers,
        profile.add_parser,
        report.add_parser,
        robustness.add_parser,
        orbit.add_parser,
        size.add_parser,
    ):
        add(subcommands)
    for name in subcommands.choices:  # after the command too: biped demo --debug
        complete_later(subcommands, name, _add_debug)
    parser.command_parsers = subcommands.choices  # each command's own parser, by name
    return parser


def _add_debug(command: argparse.ArgumentParser) -> None:
    command.add_argument("--debug", action="store_true", default=argparse.SUPPRESS, help=DEBUG_HELP)


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
