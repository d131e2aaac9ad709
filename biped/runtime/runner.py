"""Many independent computations, on local processes or on a Dask cluster, with one interface.

A sweep's points, a design map's radii: each task is one call ``function(task)`` that writes its
own output file whole (``biped.runtime.files``) and returns a short line of text saying what it did.
``run_tasks`` runs them all and yields each line as its task completes (in completion order):

- ``jobs=1``: one task after the other in this process;
- ``jobs=N`` (default: all cores, at most one per task): a pool of N worker processes started
  with ``spawn``;
- ``dask="tcp://HOST:PORT"``: on the workers of a running Dask scheduler (``jobs`` is then
  ignored: the cluster's workers decide). ``function`` and the tasks are pickled and sent to
  the workers, which must import this package (the same environment) and see the output
  folder at the same path (one machine, or a shared file system). Needs the ``cluster`` extra
  (``pip install .[cluster]``).

The numbers are the same either way: a task's result depends only on its argument and on the
files it reads, never on where or when it runs. numpy's floating-point warnings (overflow in
``expm1`` while an optimiser explores) stay off the terminal in every case.

Interrupts (the whole policy: ``biped.runtime.interrupts``): on Ctrl-C, SIGTERM or an error
of a task, the local workers are terminated (each removes the temporary file it was writing)
or the Dask futures cancelled and the client closed, and the exception goes on up. A task
already running on a Dask worker cannot be stopped there: it finishes and writes its file
whole, the file a rerun would write. So a run stopped at any moment leaves whole files only,
and a rerun that skips the tasks whose files exist ends with the files of an uninterrupted run.

    for line in run_tasks(solve_point, points, jobs=4, progress=bar):
        print(line, file=sys.stderr)

Within one task, the starts of one optimization may run on the cores left free
(``run_forked``: processes forked from this one, which inherit its built solvers): all cores
in a command's own process, none in a campaign's worker, whose siblings use them
(``free_cores``).
"""

from __future__ import annotations

import contextlib
import functools
import multiprocessing
import os
import sys
import warnings
from collections.abc import Callable, Iterable, Iterator
from typing import Protocol, TextIO

import numpy as np

from biped.errors import BipedError
from biped.runtime.interrupts import (
    deferred_signals,
    starting_workers,
    worker_signals,
    worker_task,
)

# How long to wait for a Dask scheduler to answer [s].
CONNECT_TIMEOUT = 10.0
MISSING_DASK = (
    "--dask needs dask.distributed, which is not installed: allowed after "
    "pip install 'biped-rolling-knee[cluster]' (or pip install '.[cluster]' in the source)"
)


class ProgressBar(Protocol):
    """What ``run_tasks`` needs of a progress bar (``biped_cli.progress.Progress`` is one)."""

    def advance(self, units: int = 1, note: str | None = None) -> None: ...

    def clear(self) -> None: ...


def check_dask(address: str | None = None) -> None:
    """Raise a one-line ``BipedError`` if dask.distributed is not installed or, given an
    ``address``, if no scheduler answers there (checked before a command writes anything)."""
    try:
        import dask.distributed  # noqa: F401
    except ImportError:
        raise BipedError(MISSING_DASK) from None
    if address is not None:
        _connect(address).close()


def run_tasks(
    function: Callable,
    tasks: Iterable,
    *,
    jobs: int | None = None,
    dask: str | None = None,
    stream: TextIO | None = sys.stderr,
    progress: ProgressBar | None = None,
) -> Iterator:
    """Run ``function(task)`` for every task; yield each result as its task completes.

    Args:
        function: a top-level function (picklable), one argument; it writes its own output
            file atomically and returns a short line of text.
        tasks: its arguments, each picklable.
        jobs: local worker processes (default: all cores); 1 runs in this process.
        dask: the address of a running Dask scheduler (``tcp://HOST:PORT``): run there.
        stream: where the runner says where it runs (the Dask scheduler and its workers);
            None says nothing.
        progress: a bar advanced after each task, cleared before each result is yielded (so
            the caller can print it).

    Raises:
        BipedError: dask.distributed is missing, or no scheduler answers at ``dask``.
    """
    tasks = list(tasks)
    if not tasks:
        return
    if dask is not None:
        results = _on_dask(function, tasks, dask, stream)
    else:
        jobs = max(1, min(jobs or os.cpu_count() or 1, len(tasks)))
        results = _in_process(function, tasks) if jobs == 1 else _on_pool(function, tasks, jobs)
    try:
        for result in results:
            if progress is not None:
                progress.clear()
            yield result
            if progress is not None:
                progress.advance()
    finally:
        results.close()  # stops the workers now, also when the caller stops early


# Whether this process is one of a campaign's workers (a pool's or a Dask worker): its
# siblings use the other cores (``free_cores``).
_IN_WORKER = False


def free_cores() -> int:
    """How many processes one computation of this process may run at once: the cores this
    process may use in a command's own process, 1 in a campaign's worker."""
    if _IN_WORKER:
        return 1
    try:
        return len(os.sched_getaffinity(0))
    except AttributeError:  # not on Linux
        return os.cpu_count() or 1


def _quietly(function: Callable, task):
    """``function(task)`` with numpy's floating-point warnings off (thread-safe: a Dask worker
    runs tasks in threads), in a worker (``free_cores``)."""
    global _IN_WORKER
    _IN_WORKER = True
    with np.errstate(all="ignore"):
        return function(task)


def _worker_init():
    """A worker's signals (``biped.runtime.interrupts.worker_signals``), and numpy's
    floating-point warnings off the terminal, as in the command line."""
    global _IN_WORKER
    _IN_WORKER = True
    worker_signals()
    np.seterr(all="ignore")
    warnings.simplefilter("ignore", RuntimeWarning)


def _in_process(function: Callable, tasks: list) -> Iterator:
    """The tasks one after the other in this process, each as in a worker (one core,
    ``free_cores``); this process is itself again between tasks and after them."""
    global _IN_WORKER
    for task in tasks:
        was = _IN_WORKER
        try:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore", RuntimeWarning)
                result = _quietly(function, task)
        finally:
            _IN_WORKER = was
        yield result


@contextlib.contextmanager
def _pool(method: str, jobs: int) -> Iterator:
    """A pool of ``jobs`` workers started by ``method`` ("spawn", "fork"), deaf to Ctrl-C from
    their first instruction (a Ctrl-C or SIGTERM received meanwhile takes effect once the pool
    is started: ``biped.runtime.interrupts.starting_workers``); on any exception in the block
    (Ctrl-C, SIGTERM, an error of a task, the caller stopping early) the workers are
    terminated, else the pool is closed; joined either way, a signal received meanwhile (a
    second Ctrl-C) taking effect once they are."""
    pools: list = []  # the pool, once started
    try:
        with starting_workers():
            pools.append(multiprocessing.get_context(method).Pool(jobs, _worker_init))
        yield pools[0]
    except BaseException:
        with deferred_signals():  # a second Ctrl-C must not cut the clean-up short
            for pool in pools:
                pool.terminate()
                pool.join()
        raise
    with deferred_signals():
        pools[0].close()
        pools[0].join()


def _on_pool(function: Callable, tasks: list, jobs: int) -> Iterator:
    with _pool("spawn", jobs) as pool:
        yield from pool.imap_unordered(functools.partial(_task, function), tasks)


def _task(function: Callable, task):
    """A pool worker's task (``biped.runtime.interrupts.worker_task``)."""
    with worker_task():
        return function(task)


# What the forked workers of ``run_forked`` call: (function, arguments), set before the fork.
_FORKED: tuple = (None, ())


def run_forked(function: Callable, arguments: list, jobs: int, first=()) -> list:
    """``[function(a) for a in arguments]``, on ``jobs`` processes forked from this one when
    ``jobs`` > 1 and the platform forks: they inherit this process's memory (a built solver),
    so ``function`` may be any callable and only the results are pickled. The results are
    those of the calls in this process, in order. On several processes the calls of the
    indices ``first`` (the longest, so that none starts last) are handed out before the
    others. Interrupts as ``run_tasks``' pool: the workers are terminated and the exception
    goes on up."""
    wrong = [i for i in first if not (isinstance(i, int) and 0 <= i < len(arguments))]
    if wrong:
        raise BipedError(
            f"first = {wrong!r}: allowed indices of the arguments, 0 to {len(arguments) - 1}"
        )
    jobs = max(1, min(jobs, len(arguments)))
    if jobs == 1 or "fork" not in multiprocessing.get_all_start_methods():
        return [function(a) for a in arguments]
    global _FORKED
    _FORKED = (function, arguments)
    order = list(dict.fromkeys([*first, *range(len(arguments))]))
    try:
        with _pool("fork", jobs) as pool:
            ends = pool.map(_call_forked, order, chunksize=1)
    finally:
        _FORKED = (None, ())
    results = [None] * len(arguments)
    for index, end in zip(order, ends, strict=True):
        results[index] = end
    return results


def _call_forked(index: int):
    function, arguments = _FORKED
    with worker_task():
        return function(arguments[index])


def _connect(address: str):
    check_dask()
    from dask.distributed import Client

    try:
        return Client(address, timeout=CONNECT_TIMEOUT, set_as_default=False)
    except (OSError, TimeoutError, ValueError, TypeError) as error:
        reason = " ".join(str(error).split()) or type(error).__name__
        raise BipedError(
            f"Dask scheduler {address!r} cannot be reached ({reason}): allowed the address of "
            "a running scheduler, tcp://HOST:PORT (start one with 'dask scheduler')"
        ) from None


def _on_dask(function: Callable, tasks: list, address: str, stream: TextIO | None) -> Iterator:
    from dask.distributed import as_completed

    client = _connect(address)
    futures = []
    try:
        workers = len(client.scheduler_info().get("workers", {}))
        if stream is not None:
            waiting = "" if workers else "; the tasks wait for workers ('dask worker ADDRESS')"
            print(
                f"dask: {len(tasks)} tasks on {address}, {workers} workers now{waiting}",
                file=stream,
                flush=True,
            )
        # pure=False: every task runs, even one the scheduler still holds from another run.
        futures = [client.submit(_quietly, function, task, pure=False) for task in tasks]
        for future in as_completed(futures, loop=client.loop):
            yield future.result()
    except BaseException:
        client.cancel(futures)
        raise
    finally:
        client.close()
