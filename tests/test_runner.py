"""The runner of many independent optimizations (``biped.runtime.runner``): the same results in this
process, on a pool of processes and on a Dask cluster; a sweep on a two-worker Dask cluster
writes the files of a local sweep; a progress bar on a terminal only; numpy's warnings off the
terminal; errors and unreachable schedulers are one line."""

import io
import json
import os
import queue
import random
import re
import signal
import subprocess
import sys
import threading
import time
import warnings
from pathlib import Path

import numpy as np
import pytest

import biped
from biped.runtime import interrupts, runner
from biped.runtime.files import atomic_write_text
from biped.studies.sweep import INDEPENDENT, run_sweep, sweep_settings
from biped_cli import main, progress
from tests.background import PROGRAM, as_a_background_job

SPEEDS = (0.275, 0.3)
# A small sweep: one knee, one criterion, two speeds, one start (4 optimizations).
SMALL = dict(knees=("revolute",), criteria=("sthenic",))
SETTINGS = sweep_settings(biped.Robot.paper(), SPEEDS, starts=1)


def overflowing_task(task):
    """A task in the manner of a sweep's: writes its file whole, returns a line. numpy
    overflows in ``expm1`` on the way (as the optimiser's exploration does)."""
    folder, x = task
    value = float(np.expm1(np.float64(x) * 1000.0))  # x > 0.71: inf, with a RuntimeWarning
    atomic_write_text(Path(folder) / f"{x}.txt", f"{x * x!r} {value!r}")
    return f"{x}: {x * x!r}"


def failing_task(task):
    if task == 2:
        raise ValueError("task 2 fails")
    return str(task)


@pytest.fixture(scope="module")
def cluster():
    """A Dask cluster of two worker processes of one thread each, on this machine."""
    from dask.distributed import LocalCluster

    with LocalCluster(
        n_workers=2, processes=True, threads_per_worker=1, dashboard_address=":0"
    ) as local:
        yield local.scheduler_address


def _outputs(folder):
    return {p.name: p.read_text() for p in sorted(Path(folder).iterdir())}


@pytest.mark.parametrize("mode", ["in-process", "pool", "dask"])
def test_every_mode_gives_the_same_results_and_no_warning(mode, tmp_path, capfd, request):
    """The same lines and files in this process, on two processes and on Dask, each result
    once; numpy's overflow warnings stay off stderr (the workers' stderr too)."""
    tasks = [(str(tmp_path), x) for x in (0.5, 1.0, 1.5, 2.0, 2.5)]
    where = {"in-process": dict(jobs=1), "pool": dict(jobs=2)}.get(mode)
    if where is None:
        where = dict(dask=request.getfixturevalue("cluster"))
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        lines = list(runner.run_tasks(overflowing_task, tasks, stream=None, **where))
    assert sorted(lines) == [f"{x}: {x * x!r}" for _, x in tasks]
    with np.errstate(over="ignore"):
        expected = {f"{x}.txt": f"{x * x!r} {float(np.expm1(x * 1000.0))!r}" for _, x in tasks}
    assert _outputs(tmp_path) == expected
    assert not [w for w in caught if issubclass(w.category, RuntimeWarning)]
    assert "RuntimeWarning" not in capfd.readouterr().err


def test_the_task_does_overflow(tmp_path):
    """Called bare, the task makes numpy warn (so the test above can fail)."""
    with pytest.warns(RuntimeWarning, match="overflow"):
        overflowing_task((str(tmp_path), 1.0))


class RecordingBar:
    """A progress bar that records what is done to it, and what the consumer saw when."""

    def __init__(self):
        self.events = []

    def advance(self, units=1, note=None):
        self.events.append("advance")

    def clear(self):
        self.events.append("clear")


def test_the_bar_is_cleared_before_each_result_and_advanced_after(tmp_path):
    """Each result is yielded with the bar cleared (so it prints on a clean line), and the
    bar advances once per task."""
    bar = RecordingBar()
    tasks = [(str(tmp_path), x) for x in (0.1, 0.2, 0.3)]
    for _ in runner.run_tasks(overflowing_task, tasks, jobs=1, progress=bar):
        bar.events.append("result")
    assert bar.events == ["clear", "result", "advance"] * 3


@pytest.mark.parametrize("jobs", [1, 2])
def test_a_failing_task_stops_the_run_with_its_error(jobs):
    """An error of one task goes up to the caller (local workers are stopped)."""
    with pytest.raises(ValueError, match="task 2 fails"):
        list(runner.run_tasks(failing_task, range(6), jobs=jobs))


def sleeping_task(seconds):
    time.sleep(seconds)
    return f"slept {seconds} s"


def test_a_failing_task_on_dask_stops_the_run_with_its_error(cluster):
    with pytest.raises(ValueError, match="task 2 fails"):
        list(runner.run_tasks(failing_task, range(6), dask=cluster, stream=None))


def _scheduler_tasks(dask_scheduler):
    return len(dask_scheduler.tasks)


def test_an_interrupted_dask_run_cancels_its_tasks(cluster):
    """Stopped after its first result (as by Ctrl-C in the caller), a run on Dask cancels
    the tasks it submitted and closes its client: the scheduler forgets them all."""
    from dask.distributed import Client

    tasks = [0.0, 3.0, 3.0, 3.0, 3.0, 3.0]
    with Client(cluster) as observer:
        results = runner.run_tasks(sleeping_task, tasks, dask=cluster, stream=None)
        assert next(results) == "slept 0.0 s"
        assert observer.run_on_scheduler(_scheduler_tasks) > 0  # the others wait or run
        results.close()  # what a KeyboardInterrupt in the caller's loop does
        for _ in range(100):
            if observer.run_on_scheduler(_scheduler_tasks) == 0:
                break
            time.sleep(0.1)
        assert observer.run_on_scheduler(_scheduler_tasks) == 0


def test_an_unreachable_scheduler_is_one_error_naming_it(monkeypatch):
    """No scheduler at the address: a BipedError naming the address and what is allowed."""
    monkeypatch.setattr(runner, "CONNECT_TIMEOUT", 1.0)
    with pytest.raises(biped.BipedError) as error:
        list(runner.run_tasks(failing_task, [1], dask="tcp://127.0.0.1:9", stream=None))
    message = str(error.value)
    assert "'tcp://127.0.0.1:9' cannot be reached" in message and "dask scheduler" in message
    assert "\n" not in message


@pytest.mark.parametrize("command", ["sweep", "design-map"])
def test_an_unreachable_scheduler_is_refused_before_anything_is_written(
    command, tmp_path, capsys, monkeypatch
):
    """No scheduler at --dask: exit 2 with one line, and no output folder is made."""
    monkeypatch.setattr(runner, "CONNECT_TIMEOUT", 1.0)
    argv = [command, "--dask", "tcp://127.0.0.1:9", "--out", str(tmp_path / "s")]
    assert main(argv) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "'tcp://127.0.0.1:9' cannot be reached" in err[0]
    assert not (tmp_path / "s").exists()


@pytest.mark.parametrize(
    "address", ["localhost:8786", "tcp://:8786", "tcp://host:99999", "http://host:80", "tcp://h"]
)
def test_a_malformed_address_is_refused_naming_it(address, tmp_path, capsys):
    """--dask takes tcp://HOST:PORT (or tls://): anything else exits 2 with one line."""
    assert main(["sweep", "--dask", address, "--out", str(tmp_path / "s")]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and repr(address) in err[0] and "tcp://HOST:PORT" in err[0]
    assert not (tmp_path / "s").exists()


def test_dask_missing_is_one_line_naming_the_extra(tmp_path, capsys, monkeypatch):
    """--dask without dask.distributed installed: exit 2, one line naming the extra."""
    monkeypatch.setitem(sys.modules, "dask.distributed", None)  # import fails
    argv = ["sweep", "--dask", "tcp://127.0.0.1:8786", "--out", str(tmp_path / "s")]
    assert main(argv) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "[cluster]" in err[0] and "dask.distributed" in err[0]
    assert not (tmp_path / "s").exists()


@pytest.fixture(scope="module")
def local_sweep(tmp_path_factory):
    """The small sweep on one process of this machine."""
    folder = tmp_path_factory.mktemp("local")
    run_sweep(folder, SETTINGS, jobs=1, stream=io.StringIO(), **SMALL)
    return folder


def every_file(folder) -> dict:
    """Every file of a sweep folder by relative path; gait files without what differs from
    run to run (the solver's time, the provenance: versions and command line)."""
    files = {}
    for path in sorted(p for p in Path(folder).rglob("*") if p.is_file()):
        name = str(path.relative_to(folder))
        if path.name == "sweep.json":
            files[name] = path.read_bytes()
            continue
        gait = json.loads(path.read_bytes())
        gait["optimizer"].pop("seconds")
        gait.pop("provenance")
        files[name] = gait
    return files


def test_a_sweep_on_dask_writes_the_files_of_a_local_sweep(local_sweep, cluster, tmp_path):
    """The same files, every number identical (JSON keeps every bit), both stages."""
    log = io.StringIO()
    run_sweep(tmp_path, SETTINGS, dask=cluster, stream=log, **SMALL)
    expected = every_file(local_sweep)
    assert sorted(expected) == sorted(every_file(tmp_path))
    assert len([n for n in expected if n.startswith(INDEPENDENT)]) == 2
    assert every_file(tmp_path) == expected
    assert f"dask: 2 tasks on {cluster}, 2 workers now" in log.getvalue()
    assert "2 of 2 points certified" in log.getvalue()


class Terminal(io.StringIO):
    """stderr as a terminal shows it."""

    def isatty(self):
        return True


def screen(text: str) -> list[str]:
    """The lines a terminal shows after ``text``: a carriage return goes back to the start of
    the line, ESC [K erases to its end."""
    lines = []
    for raw in text.split("\n"):
        line, column = "", 0
        for i, part in enumerate(raw.split("\r")):
            column = 0 if i else column
            for j, piece in enumerate(part.split("\x1b[K")):
                if j:
                    line = line[:column]
                line = line[:column] + piece + line[column + len(piece) :]
                column += len(piece)
        lines.append(line)
    return lines


def test_screen_renders_a_bar_left_behind():
    """A bar not erased stays on the screen (so the test below can fail)."""
    assert screen("\rsweep  1/3 [#]\n") == ["sweep  1/3 [#]", ""]
    assert screen("\rsweep  1/3 [#]\r\x1b[Kdone\n") == ["done", ""]


class Clock:
    """A clock read by ``biped_cli.progress``, set by the test [s]."""

    def __init__(self):
        self.now = 1000.0

    def monotonic(self):
        return self.now


@pytest.fixture
def clock(monkeypatch):
    from biped_cli import progress

    clock = Clock()
    monkeypatch.setattr(progress, "time", clock)
    return clock


def test_the_bar_shows_the_time_elapsed_and_left_on_a_terminal(clock):
    """On a terminal the bar says the time elapsed and, once a unit is done, the estimate of
    the time left (mean time per unit so far times the units left), each with its unit."""
    from biped_cli.progress import Progress

    terminal = Terminal()
    with Progress(4, "sweep", stream=terminal) as bar:
        assert bar.line().endswith("0 %  elapsed 0 s")
        clock.now += 75.0
        bar.advance()
        assert bar.line().endswith("25 %  elapsed 1 min 15 s  ETA 3 min 45 s")
        assert screen(terminal.getvalue())[-1] == bar.line()
        clock.now += 3 * 3600.0
        bar.advance(2)
        assert bar.line().endswith("75 %  elapsed 3 h 01 min  ETA 1 h 00 min")


def test_not_on_a_terminal_a_line_per_completed_unit_at_most_every_interval(clock):
    """Piped, the progress is a plain line per completed unit (no carriage return, no
    escape), at most one every ``interval`` seconds, with the time elapsed and left; the
    last unit's line closes a log that has one, and a short run, or one of a single unit,
    writes nothing."""
    from biped_cli.progress import Progress

    piped = io.StringIO()
    with Progress(5, "validate", stream=piped, interval=10.0) as bar:
        for seconds in (4.0, 8.0, 1.0, 30.0, 2.0):  # done at 4, 12, 13, 43, 45 s
            clock.now += seconds
            bar.advance()
    assert piped.getvalue().splitlines() == [
        "validate: 2/5 done (40 %), elapsed 12 s, ETA 18 s",
        "validate: 4/5 done (80 %), elapsed 43 s, ETA 11 s",
        "validate: 5/5 done (100 %), elapsed 45 s",
    ]
    short = io.StringIO()
    with Progress(3, "validate", stream=short, interval=10.0) as bar:
        for _ in range(3):
            clock.now += 3.0
            bar.advance()
    with Progress(1, "validate", stream=short, interval=10.0) as bar:
        clock.now += 30.0
        bar.advance()
    assert short.getvalue() == ""


def test_sweep_progress_bar_on_a_terminal_only(local_sweep, tmp_path, monkeypatch, capsys):
    """On a terminal, `biped sweep` draws a bar from 0 to every optimization done and erases
    it before each line of the log and at the end: the screen keeps the log alone. Piped, it
    writes no bar (no carriage return, no escape) but lines of the optimizations done, with
    the time elapsed."""
    for name in ("sweep.json", ".independent/revolute-sthenic-0.300.json"):
        (tmp_path / name).parent.mkdir(exist_ok=True)
        (tmp_path / name).write_bytes((local_sweep / name).read_bytes())
    argv = ["sweep", "--out", str(tmp_path), "--knees", "revolute", "--criteria", "sthenic"]
    argv += ["--paper-seeds", "0"]
    argv += ["--speeds", "0.275,0.3", "--starts", "1", "--jobs", "1"]
    terminal = Terminal()
    monkeypatch.setattr(sys, "stderr", terminal)
    assert main(argv) == 0
    monkeypatch.undo()
    shown = terminal.getvalue()
    assert "\rsweep  0/3 [" in shown and "\rsweep  3/3 [" in shown  # 1 + 2 optimizations
    assert "100 %  elapsed " in shown
    log = screen(shown)
    assert not [line for line in log if "sweep  " in line and "/3 [" in line]
    assert [line[:13] for line in log if line.startswith("[")] == ["[own starts, "] + [
        "[final, stage"
    ] * 2
    assert log[-2].startswith("sweep: done") and log[-1] == ""
    capsys.readouterr()
    for path in tmp_path.glob("*-*.json"):
        path.unlink()
    monkeypatch.setattr(progress, "LOG_INTERVAL", 0.0)  # a line per optimization
    assert main(argv) == 0
    piped = capsys.readouterr().err
    assert "[final" in piped and "\r" not in piped and "\x1b" not in piped
    logged = [line for line in piped.splitlines() if line.startswith("sweep: ") and "/2 " in line]
    assert len(logged) == 2
    assert re.fullmatch(r"sweep: 1/2 done \(50 %\), elapsed \d+ s, ETA \d+ s", logged[0])
    assert re.fullmatch(r"sweep: 2/2 done \(100 %\), elapsed \d+ s", logged[1])


SIGNALS = {signal.SIGINT: "Ctrl-C", signal.SIGTERM: "SIGTERM"}


def _lines(stream, into: queue.Queue):
    for line in stream:
        into.put(line)
    into.put(None)


def test_signals_at_random_moments_leave_whole_files_and_resume_to_the_same(local_sweep, tmp_path):
    """`biped sweep --jobs 2`, started as a script's background job (Ctrl-C ignored), stopped
    by real signals at seeded random moments (while it loads, in either stage, while it sums
    up): Ctrl-C as a terminal sends it (to the whole process group, workers included) and
    SIGTERM as `kill` does (to the program). Each stop
    exits 130 / 143 with one line and no traceback, leaves no temporary file, and the run
    that follows ends with every file of an uninterrupted sweep."""
    out = tmp_path / "sweep"
    argv = [sys.executable, "-c", PROGRAM, "sweep", "--out", str(out), "--jobs", "2"]
    argv += ["--paper-seeds", "0"]
    argv += ["--knees", "revolute", "--criteria", "sthenic", "--speeds", "0.275,0.3"]
    argv += ["--starts", "1"]
    rng = random.Random(20260611)
    stopped = 0
    for signum in (signal.SIGINT, signal.SIGTERM, signal.SIGINT, signal.SIGTERM):
        # The moment: after a random number of the run's lines (0: while it loads), a random
        # fraction of a second later.
        after_lines, delay = rng.randrange(0, 4), rng.uniform(0.0, 1.5)
        process = subprocess.Popen(
            argv,
            stdout=subprocess.DEVNULL,
            stderr=subprocess.PIPE,
            text=True,
            start_new_session=True,
            preexec_fn=as_a_background_job,
        )
        lines: queue.Queue = queue.Queue()
        reader = threading.Thread(target=_lines, args=(process.stderr, lines), daemon=True)
        reader.start()
        seen = []
        while len(seen) < after_lines and (line := lines.get(timeout=120)) is not None:
            seen.append(line)
        time.sleep(delay)
        if process.poll() is None:
            if signum == signal.SIGINT:
                os.killpg(process.pid, signal.SIGINT)
            else:
                process.send_signal(signal.SIGTERM)
        try:
            process.wait(timeout=120)
        finally:  # a run that does not stop fails the test, and leaves no process behind
            if process.poll() is None:
                os.killpg(process.pid, signal.SIGKILL)
        reader.join(timeout=10)
        while not lines.empty() and (line := lines.get_nowait()) is not None:
            seen.append(line)
        err = "".join(seen)
        assert "Traceback" not in err and "Error" not in err and "Warning" not in err, err
        if process.returncode == -signum:  # ended by the signal's own default action:
            assert "sweep: done" in err, err  # only after the work, while Python shuts down
        elif process.returncode != 0:  # stopped before the end
            stopped += 1
            assert process.returncode == 128 + signum, err
            last = err.strip().splitlines()[-1]
            assert re.fullmatch(rf"biped( sweep)?: interrupted \({SIGNALS[signum]}\)", last), err
        assert not [p for p in tmp_path.rglob("*") if p.name.endswith(".tmp")]
    assert stopped >= 2  # the signals did stop runs
    done = subprocess.run(argv, capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr
    assert every_file(out) == every_file(local_sweep)


def test_the_solver_runs_blas_on_one_thread():
    """IPOPT's linear solver uses CasADi's OpenBLAS on one thread once a solver is built, so
    this process, pool workers and Dask workers (OPENBLAS_NUM_THREADS=1) sum alike."""
    import ctypes

    import casadi

    from biped.optimization.problem import GaitProblem
    from biped.optimization.solver import solver_for

    solver_for(GaitProblem(biped.Biped(biped.Robot.paper(), "revolute"), 0.3))
    library = ctypes.CDLL(str(Path(casadi.__file__).parent / "libcasadi-tp-openblas.so.0"))
    assert library.openblas_get_num_threads() == 1


def _swallowing_worker(lock, ready):
    """A pool worker whose code swallows the SIGTERM's SystemExit (as CasADi does while it
    calls back into Python), then waits for a task that never comes."""
    runner._worker_init()
    with interrupts.worker_task():
        ready.set()
        try:
            while True:
                time.sleep(0.01)
        except BaseException:
            pass
    with lock:
        pass


@pytest.mark.skipif(not hasattr(signal, "setitimer"), reason="no interval timers")
def test_a_worker_that_swallows_its_sigterm_still_ends():
    """The pool terminates its workers with SIGTERM and waits for each; a worker that
    swallowed the SystemExit and went on to wait for its next task kept `biped sweep` from
    ending after Ctrl-C. The exit is raised again until the worker ends, with its status."""
    import multiprocessing

    context = multiprocessing.get_context("spawn")
    lock, ready = context.Lock(), context.Event()
    lock.acquire()  # held, as the pool holds its task queue's lock while it terminates
    worker = context.Process(target=_swallowing_worker, args=(lock, ready))
    worker.start()
    try:
        assert ready.wait(60)
        worker.terminate()
        worker.join(10 * interrupts.EXIT_AGAIN_AFTER)
        assert not worker.is_alive()
        assert worker.exitcode == 143
    finally:
        if worker.is_alive():
            worker.kill()
            worker.join()


def test_forked_runs_give_the_results_in_order_and_raise_errors():
    """``run_forked`` calls any callable (a closure: nothing but the results is pickled) on
    forked processes and returns its results in the order of the arguments, as one process
    would; an error of a call goes up; in a campaign's worker there is one core to use."""
    from biped.runtime import runner

    offset = 10
    assert runner.run_forked(lambda x: (x + offset, os.getpid()), [], 2) == []
    results = runner.run_forked(lambda x: (x + offset, os.getpid()), list(range(6)), 2)
    assert [r for r, _ in results] == list(range(10, 16))
    assert {pid for _, pid in results} - {os.getpid()}  # forked
    with pytest.raises(ZeroDivisionError):
        runner.run_forked(lambda x: 1 / (x - 3), list(range(5)), 2)
    assert runner.free_cores() >= 1

    # the calls named first are handed out first, the results still in order
    def timed(x):
        began = time.monotonic()
        time.sleep(0.05)
        return x * x, began

    results = runner.run_forked(timed, list(range(6)), 2, first=[5, 4])
    assert [r for r, _ in results] == [x * x for x in range(6)]
    began = [b for _, b in results]
    assert max(began[4], began[5]) < min(began[:4])
    for wrong in ([6], [-1], [0.5]):
        with pytest.raises(biped.BipedError, match=r"first = .*allowed indices"):
            runner.run_forked(timed, list(range(6)), 2, first=wrong)
    # a campaign run in this process: each task on one core, this process itself afterwards
    cores = runner.free_cores()
    seen = list(runner.run_tasks(lambda _: runner.free_cores(), [0, 1], jobs=1, stream=None))
    assert seen == [1, 1] and runner.free_cores() == cores
    runner._IN_WORKER, before = True, runner._IN_WORKER
    try:
        assert runner.free_cores() == 1
    finally:
        runner._IN_WORKER = before


def test_a_second_ctrl_c_during_the_clean_up_still_ends_the_pool(monkeypatch, tmp_path):
    """A forked run stopped by Ctrl-C whose second Ctrl-C comes while the pool is being
    terminated (two forked starts each signalled the command) ends with KeyboardInterrupt,
    its workers ended; without deferring it the termination stopped half-way and the pool's
    join raised "Pool is still running" (or waited for ever)."""
    import multiprocessing.pool

    terminate, calls = multiprocessing.pool.Pool.terminate, []

    def terminate_after_a_second_ctrl_c(self):
        calls.append(self)
        if len(calls) == 1:
            signal.raise_signal(signal.SIGINT)  # its handler runs here
        terminate(self)

    def interrupted(x):
        if x == 0:
            os.kill(os.getppid(), signal.SIGINT)  # the first Ctrl-C, to the command
        time.sleep(5)

    monkeypatch.setattr(multiprocessing.pool.Pool, "terminate", terminate_after_a_second_ctrl_c)
    previous = signal.signal(signal.SIGINT, signal.default_int_handler)
    # A pool that never ends: pytest's faulthandler_timeout (pyproject) ends the test run.
    try:
        with pytest.raises(KeyboardInterrupt):
            runner.run_forked(interrupted, [0, 1], 2)
    finally:
        signal.signal(signal.SIGINT, previous)
    assert len(calls) == 1
    assert all(p.exitcode is not None for p in calls[0]._pool)


# A command's pool stopped while its workers are still starting (their initializer made slow),
# in a process of its own: it prints its workers' exit statuses once the pool is terminated.
_TERMINATED_WHILE_STARTING = """
import time
from biped.runtime import interrupts, runner

start = runner._worker_init
runner._worker_init = lambda: (time.sleep(1.0), start())
pools = []
with interrupts.command_interrupts():  # as every command
    try:
        with runner._pool("fork", 2) as pool:
            pools.append(pool)
            raise RuntimeError("stopped at once")
    except RuntimeError:
        print(sorted(worker.exitcode for worker in pools[0]._pool))
"""


@pytest.mark.skipif(
    "fork" not in __import__("multiprocessing").get_all_start_methods(), reason="no fork"
)
def test_a_pool_terminated_while_its_workers_start_ends():
    """A forked worker inherits the handlers of the process starting it (which only note a
    signal until the pool is started): terminated before its initializer ran, it swallowed
    its SIGTERM, then waited for a task for ever, and the pool's termination with it (a
    Ctrl-C just after `biped optimize` forked its starts). Now each worker ends by its
    SIGTERM once its initializer has run."""
    command = [sys.executable, "-c", _TERMINATED_WHILE_STARTING]
    process = subprocess.Popen(command, stdout=subprocess.PIPE, text=True, start_new_session=True)
    try:
        out, _ = process.communicate(timeout=30)
    except subprocess.TimeoutExpired:
        os.killpg(process.pid, signal.SIGKILL)  # the command and its workers
        process.communicate()
        pytest.fail("the pool's termination waited for a worker terminated while starting")
    assert process.returncode == 0
    assert out.split() == [f"[{-signal.SIGTERM},", f"{-signal.SIGTERM}]"]


def _signalled_worker(moment: str):
    """A pool worker sent SIGTERM at ``moment``: waiting for a task, in one, or as one ends
    (the signal held until then), then waiting for the next task."""
    interrupts.worker_signals()
    if moment == "idle":
        os.kill(os.getpid(), signal.SIGTERM)
    else:
        with interrupts.worker_task():
            if moment == "task":
                os.kill(os.getpid(), signal.SIGTERM)
            else:
                signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGTERM})
                os.kill(os.getpid(), signal.SIGTERM)
    time.sleep(5)
    os._exit(0)


@pytest.mark.skipif(
    "fork" not in __import__("multiprocessing").get_all_start_methods(), reason="no fork"
)
@pytest.mark.parametrize(
    "moment, status",
    [("idle", -signal.SIGTERM), ("task", interrupts.EXIT_TERMINATED), ("ending", -signal.SIGTERM)],
)
def test_a_sigterm_ends_a_worker_at_any_moment(moment, status):
    """A worker waiting for a task ends at a SIGTERM by the system's default action: with a
    Python handler, a SIGTERM that came just before the worker blocked on the task queue's
    lock (held by the pool terminating it) left its handler waiting to run, and the pool's
    termination waiting for the worker (1 in 6 runs of the second-Ctrl-C test). In a task
    the SIGTERM raises SystemExit(143), so the task's files are cleaned up; one that comes as
    the task ends ends the worker there."""
    import multiprocessing

    worker = multiprocessing.get_context("fork").Process(target=_signalled_worker, args=(moment,))
    worker.start()
    worker.join(30)
    if worker.is_alive():
        worker.kill()
        worker.join()
    assert worker.exitcode == status
