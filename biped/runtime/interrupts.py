"""Interrupts that survive the solver: Ctrl-C and SIGTERM during an IPOPT solve.

CasADi checks for signals while IPOPT iterates and stops the solver when a signal's Python
handler raises (KeyboardInterrupt for Ctrl-C, the command line's ``Terminated`` for SIGTERM),
but it swallows the exception: the solve returns with a status such as
``NonIpopt_Exception_Thrown`` and the program would go on to the next start, the next point,
as if nothing had been asked. It does the same while it builds a graph: CasADi asks Python for
each operand's shape, and a handler that raises during that call loses its exception there
(the build goes on to its end). ``kept_interrupts`` remembers the signal and, once the solver
has returned, calls its handler again, so the same exception goes up as it would anywhere
else:

    with kept_interrupts():
        result = nlp(x0=x0, ...)
"""

from __future__ import annotations

import contextlib
import signal
import sys
import threading
from collections.abc import Iterator

SIGNALS = (signal.SIGINT, signal.SIGTERM)
# CasADi's notice of the exception it swallowed (a line on stderr, through Python's sys.stderr):
# the interrupt goes up instead, and the command line says it in one line.
SOLVER_NOTICE = "KeyboardInterruptException"


class _WithoutSolverNotice:
    """``sys.stderr`` less CasADi's notice of an interrupt. CasADi writes a notice in pieces
    ("CasADi - ", the date, ' WARNING("', the text...): its lines are held until whole, then
    dropped if they are the notice, written otherwise."""

    PREFIX = "CasADi - "

    def __init__(self, stream):
        self.stream = stream
        self.held = ""

    def write(self, text):
        if not self.held and not text.startswith(self.PREFIX):
            return self.stream.write(text)
        self.held += text
        if "\n" in self.held:
            line, self.held = self.held.split("\n", 1)
            if SOLVER_NOTICE not in line:
                self.stream.write(line + "\n")
            if self.held:
                rest, self.held = self.held, ""
                self.write(rest)
        return len(text)

    def release(self):
        """Write what is still held (a line CasADi did not end)."""
        if self.held:
            self.stream.write(self.held)
            self.held = ""

    def __getattr__(self, name):
        return getattr(self.stream, name)


@contextlib.contextmanager
def kept_interrupts() -> Iterator[None]:
    """Within the block, a SIGINT or SIGTERM whose Python handler raises is remembered;
    after the block, that handler runs again (and raises again). Elsewhere than in the main
    thread, and for signals left to the system (the process ends at once), it does nothing."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    handlers = {s: signal.getsignal(s) for s in SIGNALS}
    handlers = {s: h for s, h in handlers.items() if callable(h)}
    caught: list[int] = []

    def remember(signum, frame):
        try:
            handlers[signum](signum, frame)  # a handler that returns lets the solver go on
        except BaseException:  # one that raises stops it: remember the signal
            caught.append(signum)
            raise

    for number in handlers:
        signal.signal(number, remember)
    stderr = sys.stderr
    sys.stderr = filtered = _WithoutSolverNotice(stderr)
    try:
        yield
    finally:
        sys.stderr = stderr
        filtered.release()
        for number, handler in handlers.items():
            signal.signal(number, handler)
    if caught:
        handlers[caught[0]](caught[0], None)
        raise KeyboardInterrupt
