"""Ctrl-C and SIGTERM, in one place: what they do at each moment of a command.

A command stopped by Ctrl-C (SIGINT) or SIGTERM ends with one line on stderr, ``biped
COMMAND: interrupted (Ctrl-C)`` or ``(SIGTERM)``, no traceback, exit status 130 or 143 (128 +
the signal's number, as a shell reports it), and whole files only: every output is written
to a temporary file, renamed into place (``biped.runtime.files``) or removed on the way out.
A campaign saves each optimization as it completes: run again, it skips the files written
and ends with the files of an uninterrupted run. Moment by moment:

- loading (numpy, CasADi: a second or two): the program ends at once, nothing written yet
  (``biped_cli/__init__.py``: it must act before ``biped`` loads numpy);
- a Ctrl-C the shell had the program ignore (a script's background job, ``biped sweep &``)
  stops it all the same (``taken_over``);
- a command, in the main thread: Ctrl-C raises ``KeyboardInterrupt``, SIGTERM ``Terminated``
  (one, ``command_interrupts``), so the same clean-up runs (``finally`` blocks, temporary
  files, worker pools); ``biped_cli.guard`` prints the line and exits with ``exit_status``;
- CasADi building a graph or IPOPT solving: CasADi stops at the signal but swallows the
  exception; ``kept_interrupts`` raises it again once CasADi has returned;
- a worker pool starting: the signal takes effect once the pool is started
  (``starting_workers``), never between a worker's start and its first instruction; a worker
  terminated while it starts ends once its initializer has run;
- a worker process (``worker_signals``): Ctrl-C is left to the main process; SIGTERM (the
  main process terminating its pool) ends a worker waiting for a task at once (the system's
  default), and in a task (``worker_task``) raises ``SystemExit(143)``, again every
  ``EXIT_AGAIN_AFTER`` seconds until the worker has ended;
- a Dask cluster: the futures are cancelled; a task already running on a worker finishes
  and writes its file whole (``biped.runtime.runner``).
"""

from __future__ import annotations

import contextlib
import signal
import sys
import threading
from collections.abc import Iterator
from multiprocessing import resource_tracker

SIGNALS = (signal.SIGINT, signal.SIGTERM)
EXIT_INTERRUPTED = 128 + signal.SIGINT  # 130
EXIT_TERMINATED = 128 + signal.SIGTERM  # 143
# How long a worker that swallowed its SIGTERM's SystemExit runs on before it is raised again [s].
EXIT_AGAIN_AFTER = 1.0


class Terminated(KeyboardInterrupt):
    """SIGTERM received: raised in the main thread as Ctrl-C raises KeyboardInterrupt, so the
    same clean-up runs (``finally`` blocks, temporary files removed, worker pools closed)."""


def exit_status(interrupt: KeyboardInterrupt) -> tuple[int, str]:
    """The exit status of a command an interrupt stopped, and the signal's name."""
    if isinstance(interrupt, Terminated):
        return EXIT_TERMINATED, "SIGTERM"
    return EXIT_INTERRUPTED, "Ctrl-C"


# The signals received in a ``command_interrupts`` block, first first.
_received: list[int] = []


def _interrupt(signum, frame):
    """Ctrl-C raises ``KeyboardInterrupt``, SIGTERM ``Terminated``; each is remembered."""
    _received.append(signum)
    raise Terminated if signum == signal.SIGTERM else KeyboardInterrupt


def _main_thread() -> bool:
    return threading.current_thread() is threading.main_thread()


def taken_over(handler) -> bool:
    """Whether a command handles a signal whose handler is ``handler``: Python's own (Ctrl-C's
    ``KeyboardInterrupt``), the system's default, or ignored. A POSIX shell starts a script's
    background job (``biped sweep ... &``) with Ctrl-C ignored: the command stops at it all the
    same, as ``kill -INT`` and a terminal's Ctrl-C to its process group mean it to. A handler
    of the program's own (a library calling ``main``) is left in place."""
    return handler in (signal.default_int_handler, signal.SIG_DFL, signal.SIG_IGN)


@contextlib.contextmanager
def command_interrupts() -> Iterator[None]:
    """Within the block, SIGTERM raises ``Terminated`` and Ctrl-C ``KeyboardInterrupt`` in the
    main thread (elsewhere: no-op), each remembered for ``received_interrupt``; a Ctrl-C the
    shell had the command ignore is handled too (``taken_over``)."""
    if not _main_thread():
        yield
        return
    _received.clear()
    handled = [signal.SIGTERM]
    if taken_over(signal.getsignal(signal.SIGINT)):
        handled.append(signal.SIGINT)
    with _replaced({number: signal.getsignal(number) for number in handled}, _interrupt):
        yield


def received_interrupt() -> KeyboardInterrupt | None:
    """The interrupt of the first signal the current ``command_interrupts`` block received,
    if any. A library may turn the exception a signal raised into one of its own, the
    interrupt lost (ctypes: ``ArgumentError: argument 1: Terminated``; a pybind11 module
    loading: ``ImportError: initialization failed``): the command ends as interrupted all
    the same."""
    if not _received:
        return None
    return Terminated() if _received[0] == signal.SIGTERM else KeyboardInterrupt()


def _python_handlers() -> dict:
    """The handlers of SIGINT and SIGTERM that are Python's (not those left to the system)."""
    return {s: h for s in SIGNALS if callable(h := signal.getsignal(s))}


@contextlib.contextmanager
def _replaced(handlers: dict, replacement) -> Iterator[None]:
    """Within the block, ``replacement`` handles the signals of ``handlers``; they are back
    after it."""
    for number in handlers:
        signal.signal(number, replacement)
    try:
        yield
    finally:
        for number, handler in handlers.items():
            signal.signal(number, handler)


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
    if not _main_thread():
        yield
        return
    handlers, caught = _python_handlers(), []

    def remember(signum, frame):
        try:
            handlers[signum](signum, frame)  # a handler that returns lets the solver go on
        except BaseException:  # one that raises stops it: remember the signal
            caught.append(signum)
            raise

    stderr = sys.stderr
    with _replaced(handlers, remember):
        sys.stderr = filtered = _WithoutSolverNotice(stderr)
        try:
            yield
        finally:
            sys.stderr = stderr
            filtered.release()
    if caught:
        handlers[caught[0]](caught[0], None)
        raise KeyboardInterrupt


@contextlib.contextmanager
def deferred_signals() -> Iterator[None]:
    """Ctrl-C and SIGTERM received in the block take effect when it ends (their handlers run
    then), so that what the block starts is not cut in the middle. Main thread only."""
    if not _main_thread():
        yield
        return
    handlers, received = _python_handlers(), []
    with _replaced(handlers, lambda signum, frame: received.append(signum)):
        yield
    for number in received[:1]:
        handlers[number](number, None)


@contextlib.contextmanager
def starting_workers() -> Iterator[None]:
    """Around the start of worker processes (``worker_signals`` in their initializer): they start
    deaf to Ctrl-C from their first instruction, a SIGTERM that reaches one before its
    initializer ends it once the initializer has run, and a signal received meanwhile (by any
    thread of this process) takes effect once the block is done.

    A new process inherits the signal mask of the thread that starts it, so the workers start
    with SIGINT and SIGTERM blocked. A terminal's Ctrl-C reaches every process of its group, and
    a worker still importing would print a traceback: ``worker_signals`` ignores SIGINT. A
    forked worker inherits this process's handlers too, this block's among them, which only
    note a signal: a pool terminated (SIGTERM) while a worker was still starting would have
    that worker swallow its SIGTERM and then wait for a task for ever, the pool's termination
    with it. Blocked, the SIGTERM waits until ``worker_signals`` has put the worker's own
    handler in place.
    """
    with deferred_signals():
        if not hasattr(signal, "pthread_sigmask"):
            yield
            return
        # The pool's locks start multiprocessing's resource tracker, which unblocks SIGINT and
        # SIGTERM after starting: start it first.
        resource_tracker.ensure_running()
        previous = signal.pthread_sigmask(signal.SIG_BLOCK, set(SIGNALS))
        try:
            yield
        finally:
            signal.pthread_sigmask(signal.SIG_SETMASK, previous)


def worker_signals():
    """In a worker process: Ctrl-C is left to the main process, and SIGTERM (the main process
    terminating its workers) ends a worker waiting for a task at once, by the system's
    default action: nothing is being written then. A Python handler would run only once the
    worker is back in Python code, and a SIGTERM that reaches a worker just before it blocks on
    the task queue's lock (which the terminating pool holds) would leave it waiting for ever,
    the pool's termination with it. A SIGTERM received while the worker was starting
    (``starting_workers`` blocked it) takes effect here."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    signal.signal(signal.SIGTERM, signal.SIG_DFL)
    if hasattr(signal, "pthread_sigmask"):
        signal.pthread_sigmask(signal.SIG_UNBLOCK, {signal.SIGTERM})


@contextlib.contextmanager
def worker_task() -> Iterator[None]:
    """Around a worker's task: SIGTERM raises ``SystemExit`` (``_end_worker``), so a file being
    written is removed, never left half-written. After it the system's default is back; a
    SIGTERM received as the task ended, whose handler had yet to run, ends the worker there
    (blocked meanwhile, a later one waits for the default)."""
    if not _main_thread():
        yield
        return
    signal.signal(signal.SIGTERM, _end_worker)
    try:
        yield
    finally:
        masks = hasattr(signal, "pthread_sigmask")
        if masks:
            signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGTERM})
        try:
            _handlers_run()  # a SIGTERM noted by the C handler runs _end_worker here
            signal.signal(signal.SIGTERM, signal.SIG_DFL)
        finally:
            if masks:
                signal.pthread_sigmask(signal.SIG_UNBLOCK, {signal.SIGTERM})


def _handlers_run() -> None:
    """Nothing: calling a Python function runs the Python handlers of the signals received
    (the interpreter checks for them on entering a function)."""


def _end_worker(signum, frame):
    """SIGTERM in a worker: SystemExit. Code that calls back into Python can swallow it
    (CasADi does, while it asks an operand's shape), and the worker would go on, then wait
    for its next task forever: the pool's termination never ends. So the exit is raised
    again every ``EXIT_AGAIN_AFTER`` seconds (SIGALRM) until the worker has ended."""
    if hasattr(signal, "setitimer"):
        signal.signal(signal.SIGALRM, _end_worker)
        signal.setitimer(signal.ITIMER_REAL, EXIT_AGAIN_AFTER, EXIT_AGAIN_AFTER)
    sys.exit(EXIT_TERMINATED)
