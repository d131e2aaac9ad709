"""Checks declared with the options they check, run by ``biped_cli.main`` after parsing and
before the command, so that no command checks its options by hand.

- An output (``add_out``, ``declare_output``): a file, or a folder, refused before any work
  where it cannot be written (a folder, a device, a FIFO, a folder not writable) and claimed
  for the run (``biped.runtime.claims``: two runs on one output never both go on).
- A rule between options (``declare_rule``): options that exclude or need each other, a
  budget the method would not spend; it raises ``BipedError`` with its one line.

``run_checks`` runs a command's in a fixed order: the rules (nothing read), then the outputs'
checks (the file system looked at), then their claims, each kind in the order declared. What
a command writes under names derived from its inputs (a map per gait file) is claimed by the
command through ``claim_derived``, from the output's declaration.
"""

from __future__ import annotations

import argparse
import tempfile
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

from biped.errors import BipedError

# Where a command's parser keeps its declared checks: a default of its namespace.
DECLARED = "declared_checks"

# How an output is claimed for the run (``Output.claims``), besides the names of the files a
# folder holds (a tuple: ``("converge",)`` claims converge.json and converge.png):
WHOLE = "whole"  # the file, or the folder and all in it
DERIVED = "derived"  # outputs named from the inputs, claimed by the command (claim_derived)
WITH_ANOTHER = "with another output"  # named from an output claimed (the pipeline's --out)

FILE, FOLDER = "file", "folder"
# What an option naming an output says of its missing folders (the path written is printed).
FOLDERS_CREATED = "missing folders are created"
FOLDER_CREATED = "created if missing"
# Gait files whose outputs share a name (named from their folder and file names).
SAME_FOLDERS = "gait files in folders of the same name"


def distinct_outputs(names: list, what: str, gaits: str = SAME_FOLDERS) -> None:
    """Refuse ``gaits`` that would write the same output: ``what``, named ``names``."""
    repeated = sorted({str(name) for name in names if names.count(name) > 1})
    if repeated:
        raise BipedError(
            f"{gaits} would share the {what} {repeated[0]!r}: allowed gait files of distinct "
            "folder or file names"
        )


def check_folder(path: str, option: str, of: str | None = None) -> None:
    """Fail before any work if ``path`` cannot be (or become) a writable folder."""
    folder = Path(path)
    named = of if of is not None else path
    existing = folder
    while not existing.exists():
        existing = existing.parent
    if not existing.is_dir():
        raise BipedError(f"{option} {named!r}: {str(existing)!r} is a file, allowed a folder")
    try:  # what a writer will do there (permissions alone miss /proc, read-only mounts)
        with tempfile.TemporaryFile(dir=existing):
            pass
    except OSError as error:
        raise BipedError(
            f"{option} {named!r}: folder {str(existing)!r} is not writable "
            f"({error.strerror}): allowed a folder this user can write in"
        ) from None


@dataclass(frozen=True)
class Output:
    """An output an option names, checked and claimed before the command runs."""

    option: str  # the option naming it, in its messages: "--out"
    kind: str  # FILE or FOLDER
    claims: str | tuple[str, ...]  # WHOLE, DERIVED, WITH_ANOTHER, or the names in the folder
    # The paths it names in a run (none: the option not given); default the option's value.
    paths: Callable[[argparse.Namespace], list[str]] | None = None

    def given(self, args) -> list[str]:
        """The paths this output names in the run ``args``."""
        if self.paths is not None:
            return [str(path) for path in self.paths(args)]
        value = getattr(args, self.option.removeprefix("--").replace("-", "_"))
        return [] if value is None else [str(value)]

    def check(self, args) -> None:
        """Refuse (BipedError naming the option and path) a path that cannot be written."""
        from biped.runtime.files import special_kind

        for path in self.given(args):
            if self.kind == FOLDER:
                check_folder(path, self.option)
                continue
            kind = special_kind(Path(path))  # /dev/null, /dev/stdout: a rename would destroy it
            if kind is not None:
                raise BipedError(f"{self.option} {path!r} is {kind}: allowed a file path")
            if Path(path).is_dir():
                raise BipedError(f"{self.option} {path!r} is a folder: allowed a file path")
            check_folder(str(Path(path).parent), self.option, of=path)

    def claim(self, args) -> None:
        """Claim the outputs of this run until it ends (another run's refused, named)."""
        from biped.runtime.claims import hold

        for path in self.given(args):
            if self.claims == WHOLE:
                hold(path, self.option)
            elif isinstance(self.claims, tuple):
                for name in self.claims:
                    hold(Path(path) / name, self.option)


@dataclass(frozen=True)
class Rule:
    """A check between options: ``check(args)`` raises BipedError with its one line."""

    options: tuple[str, ...]  # the options it checks, first the one its message names
    check: Callable[[argparse.Namespace], None]


def declared(parser) -> tuple:
    """The checks declared on ``parser`` so far (``Output`` and ``Rule``), in order."""
    return parser.get_default(DECLARED) or ()


def declare_output(parser, output: Output) -> None:
    """Declare ``output`` on ``parser``: checked and claimed before its command runs."""
    parser.set_defaults(**{DECLARED: (*declared(parser), output)})


def declare_rule(parser, options: tuple[str, ...], check) -> None:
    """Declare a rule between ``options`` on ``parser``, checked before its command runs."""
    parser.set_defaults(**{DECLARED: (*declared(parser), Rule(tuple(options), check))})


def add_out(
    parser,
    option: str,
    kind: str,
    help: str,
    claims: str | tuple[str, ...] = WHOLE,
    paths: Callable[[argparse.Namespace], list[str]] | None = None,
    **kwargs,
) -> None:
    """The option naming an output (``--out FILE``, ``--recordings DIR``) declared with its
    check: ``kind`` FILE or FOLDER, ``claims`` how it is claimed and ``paths`` the paths it
    names (``Output``); ``kwargs`` argparse's (default, required, metavar). Its ``help`` says
    that missing folders are created."""
    if FOLDERS_CREATED not in help and FOLDER_CREATED not in help:
        raise ValueError(f"the help of {option} does not say that missing folders are created")
    kwargs.setdefault("metavar", "DIR" if kind == FOLDER else "FILE")
    parser.add_argument(option, help=help, **kwargs)
    declare_output(parser, Output(option, kind, claims, paths))


def add_folder(
    parser,
    option: str,
    default: str,
    what: str,
    files: str = "",
    claims: str | tuple[str, ...] = WHOLE,
) -> None:
    """An output folder, ``--out DIR`` or ``--recordings DIR``: ``what`` it holds, and the
    ``files`` written there (``": <folder>-<gait>.json"``), claimed as ``claims`` says."""
    help = f"{what}, {FOLDER_CREATED} (default {default}){files}"
    add_out(parser, option, FOLDER, help, claims, default=default)


def add_gait_out(parser) -> None:
    """``--out FILE``: the gait file a command writes."""
    help = f"gait file to write (JSON; {FOLDERS_CREATED})"
    add_out(parser, "--out", FILE, help, required=True)


def run_checks(args) -> None:
    """The checks declared on the command of ``args``: its rules, its outputs' checks, then
    their claims (cheap first: a refusal claims nothing)."""
    checks = getattr(args, DECLARED, ())
    for rule in checks:
        if isinstance(rule, Rule):
            rule.check(args)
    outputs = [output for output in checks if isinstance(output, Output)]
    for output in outputs:
        output.check(args)
    for output in outputs:
        output.claim(args)


def declaration(args, option: str) -> Output:
    """The output ``option`` declared on the command of ``args``."""
    for output in getattr(args, DECLARED, ()):
        if isinstance(output, Output) and output.option == option:
            return output
    raise ValueError(f"{option} is not a declared output of this command")


def claim_derived(args, option: str, paths: list, what: str, gaits: str = SAME_FOLDERS) -> None:
    """Check and claim the outputs of ``option`` named from the inputs (declared ``DERIVED``):
    ``paths``, files, or names in its folder standing for their files (``NAME.json``,
    ``NAME.png``); gait files that would write the same one are refused (``what``, named)."""
    from biped.runtime.claims import hold

    output = declaration(args, option)
    if output.claims != DERIVED:
        raise ValueError(f"{option} is not declared with outputs derived from the inputs")
    distinct_outputs(list(paths), what, gaits)
    for path in paths:
        if output.kind == FILE:
            named = Output(option, FILE, WHOLE, paths=lambda args, path=path: [path])
            named.check(args)
            named.claim(args)
        else:
            for folder in output.given(args):
                hold(Path(folder) / str(path), option)
