"""A ``biped`` command run as a script's background job (a POSIX shell starts it with Ctrl-C
ignored: ``biped sweep ... &``), stopped by a real signal while its worker processes run:
Ctrl-C as a terminal sends it (to the whole process group, workers included) or to the
command's process alone, SIGTERM as ``kill`` does."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import time
from dataclasses import dataclass
from pathlib import Path

# `biped` as its console script runs it (`python -m biped` loads the package first).
PROGRAM = "import sys; from biped_cli import main; sys.exit(main())"
# [s] How soon a stopped command and every process it started must have ended: "within
# seconds" (a solve in a worker is terminated, not waited for).
PROMPTLY = 10.0
# [s] How long a command may take to start its workers (loading, building its solvers).
STARTING = 120.0


def as_a_background_job() -> None:
    """In the child: Ctrl-C ignored, as a POSIX shell starts a script's background job."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)


def workers(pid: int) -> list[int]:
    """The worker processes a process has started (its children but multiprocessing's
    resource tracker, which ends with its last user)."""
    found = []
    for task in Path(f"/proc/{pid}/task").glob("*"):
        try:
            found += [int(c) for c in (task / "children").read_text().split()]
        except OSError:
            continue
    return [c for c in found if b"resource_tracker" not in _cmdline(c)]


def _cmdline(pid: int) -> bytes:
    try:
        return Path(f"/proc/{pid}/cmdline").read_bytes()
    except OSError:
        return b""


def _group_alive(pgid: int) -> bool:
    try:
        os.killpg(pgid, 0)
    except ProcessLookupError:
        return False
    return True


@dataclass(frozen=True)
class Stopped:
    """How a command stopped by a signal ended."""

    status: int  # its exit status (130 Ctrl-C, 143 SIGTERM)
    stderr: str  # what it wrote on stderr
    seconds: float  # [s] from the signal until it and every process it started had ended


def stop_while_workers_run(
    argv: list[str], signum: int, to_group: bool = True, least_workers: int = 2
) -> Stopped:
    """Run ``biped ARGV`` as a background job; once it runs ``least_workers`` worker processes
    (and half a second more), send ``signum`` to its process group (``to_group``) or to it
    alone; return how it ended. Whatever happens, no process of it is left behind."""
    process = subprocess.Popen(
        [sys.executable, "-c", PROGRAM, *argv],
        stdout=subprocess.DEVNULL,
        stderr=subprocess.PIPE,
        text=True,
        start_new_session=True,
        preexec_fn=as_a_background_job,
    )
    try:
        deadline = time.monotonic() + STARTING
        while len(workers(process.pid)) < least_workers:
            assert process.poll() is None, f"ended before its workers ran: {process.stderr.read()}"
            assert time.monotonic() < deadline, "its workers did not start"
            time.sleep(0.05)
        time.sleep(0.5)  # the workers in their tasks
        sent = time.monotonic()
        (os.killpg if to_group else os.kill)(process.pid, signum)
        _, err = process.communicate(timeout=PROMPTLY)
        while _group_alive(process.pid) and time.monotonic() < sent + PROMPTLY:
            time.sleep(0.05)
        assert not _group_alive(process.pid), "a worker outlived the command"
        return Stopped(process.returncode, err, time.monotonic() - sent)
    finally:
        if _group_alive(process.pid):
            os.killpg(process.pid, signal.SIGKILL)
        process.wait()


def numbers(folder: Path) -> dict:
    """Every JSON file under ``folder`` by its relative path, without what differs from run to
    run (wall times, the command line and versions)."""

    def without_times(value):
        if isinstance(value, dict):
            return {
                k: without_times(v) for k, v in value.items() if k not in ("seconds", "provenance")
            }
        if isinstance(value, list):
            return [without_times(v) for v in value]
        return value

    return {
        str(path.relative_to(folder)): without_times(json.loads(path.read_bytes()))
        for path in sorted(folder.rglob("*.json"))
    }


def stopped_twice_then_resumed(argv: list[str], out: Path) -> list[Stopped]:
    """``biped ARGV --out OUT`` stopped while its workers run, by Ctrl-C to its process group
    then by SIGTERM to its process, then run again to its end (exit 0); returns the stops."""
    stops = [
        stop_while_workers_run([*argv, "--out", str(out)], signum, to_group)
        for signum, to_group in ((signal.SIGINT, True), (signal.SIGTERM, False))
    ]
    done = subprocess.run(
        [sys.executable, "-c", PROGRAM, *argv, "--out", str(out)],
        capture_output=True,
        text=True,
        timeout=600,
    )
    assert done.returncode == 0, done.stderr
    assert not [p for p in out.rglob("*") if p.name.endswith(".tmp")]
    return stops
