"""One run at a time on an output: a command claims the files and folders it writes before any
work, and a second run on one of them is refused while the first holds it.

A claim is a lock (``fcntl.flock``) on a file named after the output's absolute path, in a
folder of this user's (``claims_folder``), not beside the output: a refused run writes nothing
there, and no lock file is left in the user's folders. The system releases a lock when its
process ends, however it ends (a SIGKILL, a power loss), so no claim outlives its run. A run
claims an output exclusively and every folder above it shared: a sweep's folder and a gait file
inside it are one output, two files in one folder are two. Within one process a claim is
taken once (a command's folder, then its campaign); a process forked from it (a start solved
in a worker) shares its locks.

Claims hold among the processes of one machine (a Dask cluster's workers write the files of
one run, which holds the claim on its own machine); where ``fcntl`` is missing (Windows),
nothing is claimed.

    with claimed(folder, "--out"):
        ...  # a second run on ``folder``, or on a file in it, raises BipedError meanwhile
"""

from __future__ import annotations

import contextlib
import hashlib
import os
import sys
import tempfile
from collections.abc import Iterator
from pathlib import Path

from biped.errors import BipedError

try:
    import fcntl
except ImportError:  # not on POSIX: nothing is claimed
    fcntl = None

EXCLUSIVE, SHARED = "exclusive", "shared"


def claims_folder() -> Path:
    """Where the lock files are: ``$XDG_RUNTIME_DIR/biped-claims`` (this user's, emptied at
    log-out), else ``biped-claims-<uid>`` in the system's temporary folder."""
    runtime = os.environ.get("XDG_RUNTIME_DIR")
    if runtime and Path(runtime).is_dir():
        return Path(runtime) / "biped-claims"
    user = os.getuid() if hasattr(os, "getuid") else os.getlogin()
    return Path(tempfile.gettempdir()) / f"biped-claims-{user}"


class _Lock:
    """A lock file held open by this process, in one mode."""

    def __init__(self, fd: int, mode: str):
        self.fd, self.mode, self.count = fd, mode, 0


# The locks this process holds, by the absolute path they stand for.
_held: dict[str, _Lock] = {}


def _lock_file(path: str) -> Path:
    return claims_folder() / (hashlib.sha256(path.encode()).hexdigest()[:32] + ".lock")


def _acquire(path: str, mode: str) -> _Lock | None:
    """The lock standing for ``path`` in ``mode`` (taken now, or held already by this process
    in that mode or a stronger one); None where another process holds it."""
    lock = _held.get(path)
    if lock is not None and (lock.mode == EXCLUSIVE or mode == SHARED):
        return lock
    if lock is None:
        folder = claims_folder()
        folder.mkdir(mode=0o700, parents=True, exist_ok=True)
        fd = os.open(_lock_file(path), os.O_RDWR | os.O_CREAT, 0o600)
        lock = _Lock(fd, mode)
    operation = fcntl.LOCK_EX if mode == EXCLUSIVE else fcntl.LOCK_SH
    try:
        fcntl.flock(lock.fd, operation | fcntl.LOCK_NB)
    except OSError:
        if path not in _held:
            os.close(lock.fd)
        return None
    lock.mode = mode
    _held[path] = lock
    return lock


def _holder(path: str) -> str:
    """Who holds the claim on ``path``, as its lock file says (" (pid 123: biped sweep ...)"),
    if that process still runs; "" if unknown (a folder above an output, claimed shared,
    names no one)."""
    try:
        text = _lock_file(path).read_text(encoding="utf-8", errors="replace").strip()
        pid = int(text.partition(":")[0].removeprefix("pid "))
        os.kill(pid, 0)
    except (OSError, ValueError):
        return ""
    return f" ({text})"


def _release(paths: list[str]) -> None:
    for path in reversed(paths):
        lock = _held[path]
        lock.count -= 1
        if lock.count == 0:
            del _held[path]
            os.close(lock.fd)  # releases the lock


@contextlib.contextmanager
def claimed(path: str | Path, option: str = "--out") -> Iterator[Path]:
    """Within the block, ``path`` (a file or a folder, made or not) is this run's: claimed
    exclusively, the folders above it shared.

    Raises:
        BipedError: another run holds ``path``, a folder above it or a path within it.
    """
    target = Path(path).resolve()  # one output under every name (a link, a relative path)
    if fcntl is None:
        yield target
        return
    wanted = [(str(target), EXCLUSIVE), *((str(p), SHARED) for p in target.parents)]
    taken: list[str] = []
    try:
        for name, mode in wanted:
            lock = _acquire(name, mode)
            if lock is None:
                raise BipedError(
                    f"{option} {str(path)!r} is in use by another run{_holder(name)}: allowed "
                    "one run at a time on an output; wait for it to end or choose another path"
                )
            lock.count += 1
            taken.append(name)
        _sign(str(target))
        yield target
    finally:
        _release(taken)


def _sign(path: str) -> None:
    """Write this process and its command into the lock file it holds exclusively, for the
    message of a run refused meanwhile."""
    lock = _held[path]
    text = f"pid {os.getpid()}: {' '.join(os.path.basename(a) for a in sys.argv[:1])}"
    text += "".join(f" {a}" for a in sys.argv[1:])
    with contextlib.suppress(OSError):
        os.ftruncate(lock.fd, 0)
        os.pwrite(lock.fd, text.encode("utf-8", errors="replace"), 0)


# The claims a command holds until it ends (``hold``, ``release_held``).
_command: contextlib.ExitStack | None = None


def hold(path: str | Path, option: str = "--out") -> None:
    """Claim ``path`` (as ``claimed``) until ``release_held``: a command's outputs, claimed
    where they are checked, before any work."""
    global _command
    if _command is None:
        _command = contextlib.ExitStack()
    _command.enter_context(claimed(path, option))


def release_held() -> None:
    """Release what ``hold`` claimed (a command has ended)."""
    global _command
    if _command is not None:
        stack, _command = _command, None
        stack.close()
