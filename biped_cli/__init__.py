"""The ``biped`` command line: optimize, sweep, validate and compare gaits.

Kept apart from the ``biped`` package, which holds the analytical models and never imports
the MuJoCo validation (``validate``); this package may import both.

The command line's modules (numpy, scipy, CasADi) take a second or two to load: a Ctrl-C or
SIGTERM meanwhile ends the program as it would later (the policy of
``biped.runtime.interrupts``, not imported here: ``biped`` loads numpy), with one line on
stderr and exit status 130 / 143, no traceback. Nothing is written yet then, so the program
ends at once (an exception raised in the middle of an extension module's loading would turn
into an ImportError).
"""

import os
import signal
import sys
import threading

# Exit status and name of an interrupt while the command line loads (as later: interrupts).
_INTERRUPTS = {
    signal.SIGINT: (128 + signal.SIGINT, "Ctrl-C"),
    signal.SIGTERM: (128 + signal.SIGTERM, "SIGTERM"),
}


def _end_while_loading(signum, frame):
    status, name = _INTERRUPTS[signum]
    os.write(2, f"biped: interrupted ({name})\n".encode())
    os._exit(status)


# Not in another thread, nor in a worker process of a pool (spawned, it loads the program too:
# a pool terminates its workers with SIGTERM, and they end without a word).
_handled = (
    "--multiprocessing-fork" not in sys.orig_argv
    and threading.current_thread() is threading.main_thread()
)
# Also where the shell had the program ignore Ctrl-C (a script's background job: ``biped sweep
# &``): it stops at Ctrl-C as later (``biped.runtime.interrupts.taken_over``).
_previous = {
    number: signal.signal(number, _end_while_loading) for number in _INTERRUPTS if _handled
}
try:
    from biped_cli.main import build_parser, main
finally:
    for _number, _handler in _previous.items():
        signal.signal(_number, _handler)

__all__ = ["build_parser", "main"]
