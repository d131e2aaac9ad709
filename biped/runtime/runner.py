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
"""

from __future__ import annotations

import multiprocessing
import os
import sys
import warnings
from collections.abc import Callable, Iterable, Iterator
from typing import Protocol, TextIO

import numpy as np

from biped.errors import BipedError
from biped.runtime.interrupts import starting_workers, worker_signals

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


def _quietly(function: Callable, task):
    """``function(task)`` with numpy's floating-point warnings off (thread-safe: a Dask worker
    runs tasks in threads)."""
    with np.errstate(all="ignore"):
        return function(task)


def _worker_init():
    """A worker's signals (``biped.runtime.interrupts.worker_signals``), and numpy's
    floating-point warnings off the terminal, as in the command line."""
    worker_signals()
    np.seterr(all="ignore")
    warnings.simplefilter("ignore", RuntimeWarning)


def _in_process(function: Callable, tasks: list) -> Iterator:
    for task in tasks:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", RuntimeWarning)
            result = _quietly(function, task)
        yield result


def _start_pool(jobs: int, pools: list) -> None:
    """Append to ``pools`` a pool of ``jobs`` spawned workers deaf to Ctrl-C from their first
    instruction; a Ctrl-C or SIGTERM received meanwhile takes effect once the pool is started
    and in ``pools`` (``biped.runtime.interrupts.starting_workers``)."""
    context = multiprocessing.get_context("spawn")
    with starting_workers():
        pools.append(context.Pool(jobs, initializer=_worker_init))


def _on_pool(function: Callable, tasks: list, jobs: int) -> Iterator:
    pools: list = []  # the pool, once started
    try:
        _start_pool(jobs, pools)
        yield from pools[0].imap_unordered(function, tasks)
        pools[0].close()
    except BaseException:  # Ctrl-C, SIGTERM, an error of a task, the caller stopping early
        for pool in pools:
            pool.terminate()
        raise
    finally:
        for pool in pools:
            pool.join()


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
