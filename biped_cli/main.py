"""The ``biped`` program: its parser, one subcommand per job, and the top-level guard.

Errors in the input print one line on stderr and exit with status 2; exit statuses are those
of ``biped_cli.guard``.
"""

from __future__ import annotations

import argparse
import sys

from biped.records.provenance import command_line, version
from biped_cli import (
    atlas,
    commands,
    converge,
    criteria,
    design,
    orbit,
    profile,
    report,
    robustness,
    size,
)
from biped_cli.args import Commands, complete_later, numbers_as_values
from biped_cli.checks import run_checks
from biped_cli.guard import EXIT_BAD_INPUT, run_guarded

DEBUG_HELP = "on an error, print its traceback before the one-line message"


class _Parser(argparse.ArgumentParser):
    """argparse with one-line errors: 'biped optimize: error: ...' and exit status 2,
    negative numbers read as values (``biped_cli.args.numbers_as_values``), no abbreviated
    option (``--start 2`` is refused, not read as ``--starts 2``), and arguments that may be
    added when the parser is first used (``complete_later``)."""

    def __init__(self, *args, **kwargs):
        self.takes = {}  # option string -> its nargs, for the options that take values
        self.pending = []  # what adds the rest of the arguments, in order (complete_later)
        kwargs.setdefault("allow_abbrev", False)
        super().__init__(*args, **kwargs)

    def note(self, action: argparse.Action) -> argparse.Action:
        """Keep which option strings of ``action`` take values (``takes``); returns it."""
        if action.option_strings and action.nargs != 0:
            self.takes.update(dict.fromkeys(action.option_strings, action.nargs))
        return action

    def add_argument(self, *args, **kwargs):
        return self.note(super().add_argument(*args, **kwargs))

    def add_mutually_exclusive_group(self, **kwargs):
        group = super().add_mutually_exclusive_group(**kwargs)
        add = group.add_argument
        group.add_argument = lambda *args, **kwargs: self.note(add(*args, **kwargs))
        return group

    def complete_later(self, complete) -> None:
        """Add arguments by ``complete(self)`` when the parser is first used."""
        self.pending.append(complete)

    def complete(self) -> _Parser:
        """The parser with every argument (``complete_later``)."""
        while self.pending:
            self.pending.pop(0)(self)
        return self

    def parse_known_args(self, args=None, namespace=None):
        self.complete()
        args = sys.argv[1:] if args is None else list(args)
        return super().parse_known_args(numbers_as_values(args, self.takes), namespace)

    def format_usage(self):
        self.complete()
        return super().format_usage()

    def format_help(self):
        self.complete()
        return super().format_help()

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
    for add in (
        commands.add_demo,
        commands.add_optimize,
        commands.add_sweep,
        commands.add_validate,
        commands.add_pipeline,
        commands.add_figures,
        commands.add_table,
        atlas.add_parser,
        atlas.add_compare_parser,
        converge.add_parser,
        criteria.add_parser,
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
    parser.command_parsers = Commands(subcommands.choices)  # each command's, by name
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
            run_checks(args)  # those declared with its options: rules, outputs, claims
            return args.run(args)

    return run_guarded(lambda: name[0], run, debug="--debug" in argv)
