"""How a command ends: exit statuses, one line on stderr for every failure, interrupts.

- 0: done, every check passed.
- 1: done, but a result fails a check (an infeasible optimum, a gait that falls in MuJoCo).
- 2: the input is wrong (one line naming the value, the option or file, and what is
  allowed), or an unexpected internal error (one line; ``--debug`` shows the traceback).
- 130 / 143: interrupted by Ctrl-C (SIGINT) / terminated (SIGTERM), as a shell reports a
  process killed by those signals (128 + the signal's number): one line, no traceback (the
  whole policy of interrupts: ``biped.runtime.interrupts``).

Floating-point warnings of numpy (overflow in ``expm1`` while the optimiser explores) are
expected and handled where they matter; they never reach the terminal unless ``--debug``.
The package's own warnings (``biped.errors.BipedWarning``: derivatives interpreted, not
compiled; no viewer took a streamed recording) are one line on stderr each, as the failures
are; they leave the exit status to the results.
"""

from __future__ import annotations

import contextlib
import os
import sys
import traceback
import warnings
from collections.abc import Callable, Iterator

import numpy as np

from biped.errors import BipedError, BipedWarning
from biped.runtime.claims import release_held
from biped.runtime.interrupts import command_interrupts, exit_status, received_interrupt

EXIT_OK = 0
EXIT_CHECK_FAILED = 1
EXIT_BAD_INPUT = 2


@contextlib.contextmanager
def quiet_numerics(debug: bool = False) -> Iterator[None]:
    """Within the block, numpy's floating-point warnings are silent (shown with ``debug``)."""
    if debug:
        yield
        return
    with np.errstate(all="ignore"), warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)
        yield


@contextlib.contextmanager
def warnings_as_lines(say: Callable[[str], None]) -> Iterator[None]:
    """Within the block, the package's warnings (``BipedWarning``: no compiler, no viewer) are
    said as one line each."""
    shown = warnings.showwarning

    def show(message, category, filename, lineno, file=None, line=None):
        if issubclass(category, BipedWarning):
            say(f"warning: {one_line(message)}")
        else:
            shown(message, category, filename, lineno, file, line)

    warnings.showwarning = show
    try:
        yield
    finally:
        warnings.showwarning = shown


@contextlib.contextmanager
def claims() -> Iterator[None]:
    """The outputs a command claimed where it checked them (``biped.runtime.claims.hold``)
    are released when it ends, however it ends."""
    try:
        yield
    finally:
        release_held()


def one_line(text: str) -> str:
    """``text`` on one line: line breaks become spaces."""
    return " ".join(str(text).split("\n")).strip()


def _stdout_closed() -> None:
    """After a broken pipe (``biped demo | head -1``): send further output to nowhere, so that
    Python's final flush does not fail again."""
    with contextlib.suppress(OSError, ValueError, AttributeError):
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())


def run_guarded(name: str | Callable[[], str], run: Callable[[], int], debug: bool = False) -> int:
    """Run a command and turn how it ends into an exit status with at most one line on stderr.

    Args:
        name: the program and command, first on the line (``biped validate``), or a function
            that gives it when the line is printed.
        run: the command; returns 0 or 1.
        debug: print the traceback of an error before its line.
    """

    def say(text: str) -> None:
        print(f"{name() if callable(name) else name}: {text}", file=sys.stderr, flush=True)

    def fail(kind: str, error: BaseException | str, hint: str = "") -> int:
        if debug:
            traceback.print_exc()
        say(f"{kind}: {one_line(error)}{hint}")
        return EXIT_BAD_INPUT

    try:
        with command_interrupts(), quiet_numerics(debug), warnings_as_lines(say), claims():
            return run()
    except KeyboardInterrupt as interrupt:  # Ctrl-C, or SIGTERM (``Terminated``)
        status, signal_name = exit_status(interrupt)
        say(f"interrupted ({signal_name})")
        return status
    except BrokenPipeError as error:
        _stdout_closed()
        return fail("error", f"output closed early ({error.strerror})")
    except (BipedError, OSError) as error:
        return fail("error", error)
    except SystemExit as exit_:
        code = exit_.code
        return code if isinstance(code, int) else (EXIT_OK if code is None else EXIT_BAD_INPUT)
    except Exception as error:  # a bug: say so on one line, the traceback on demand
        interrupt = received_interrupt()  # a library may have turned it into its own error
        if interrupt is not None:
            status, signal_name = exit_status(interrupt)
            say(f"interrupted ({signal_name})")
            return status
        return fail(
            "internal error",
            f"{type(error).__name__}: {error}" if str(error) else type(error).__name__,
            " (rerun with --debug for the traceback)",
        )
