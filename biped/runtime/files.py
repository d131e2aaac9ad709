"""Files written whole or not at all.

Every output of the project (gait files, reports, figures, MJCF models, recordings) is written
to a temporary file in the destination's folder, flushed to disk, then renamed over the
destination (``os.replace``, atomic on POSIX and Windows). A destination that a rename would
destroy, a device, FIFO, socket or symbolic link, is refused (``refuse_special``). A reader,
or a run interrupted at any moment, sees the old file or the new one, never a part. The
temporary file is named ``.<name>.<random>.tmp``; it is removed on any exception,
``KeyboardInterrupt`` included. A process killed outright (SIGKILL, power loss) can leave one
behind: ``clean_stale_temporaries`` removes them before a run writes into the folder again.

A set of files that belong together (the figures of a sweep, a page and its images) is written
through ``atomic_set``: every file is written into a hidden staging folder first and moved into
place only once all of them are written, so a failure or an interrupt while writing leaves the
earlier set as it was.
"""

from __future__ import annotations

import contextlib
import os
import shutil
import stat
import tempfile
from collections.abc import Iterator
from pathlib import Path

from biped.errors import BipedError

TEMPORARY_SUFFIX = ".tmp"


def _umask() -> int:
    """The process's umask (read by setting it, so read once)."""
    global _UMASK
    if _UMASK is None:
        _UMASK = os.umask(0o022)
        os.umask(_UMASK)
    return _UMASK


_UMASK: int | None = None


def _fsync_folder(folder: Path) -> None:
    """Make a rename in ``folder`` durable (a no-op where folders cannot be opened)."""
    try:
        fd = os.open(folder, os.O_RDONLY)
    except OSError:
        return
    try:
        os.fsync(fd)
    except OSError:
        pass
    finally:
        os.close(fd)


@contextlib.contextmanager
def atomic_path(path: str | Path) -> Iterator[Path]:
    """A temporary path to write ``path`` through, for writers that take a file name.

    The body writes the temporary file (``figure.savefig(tmp)``, ``recording.save(tmp)``);
    when it returns, the file is flushed to disk and renamed to ``path``. If the body raises,
    nothing is renamed and the temporary file is removed. The folder of ``path`` must exist.

        with atomic_path("logs/figures/fig4.png") as tmp:
            figure.savefig(tmp, format="png")
    """
    path = Path(path)
    refuse_special(path)
    try:
        fd, name = tempfile.mkstemp(
            dir=path.parent, prefix=f".{path.name}.", suffix=TEMPORARY_SUFFIX
        )
    except OSError as error:  # named by the file asked for, not its temporary one
        raise OSError(error.errno, f"cannot write {str(path)!r}: {error.strerror}") from None
    tmp = Path(name)
    try:
        os.close(fd)
        os.chmod(tmp, 0o666 & ~_umask())  # as a plain open() would create it
        yield tmp
        with open(tmp, "rb+") as handle:
            os.fsync(handle.fileno())
        os.replace(tmp, path)
    except BaseException:
        tmp.unlink(missing_ok=True)
        raise
    _fsync_folder(path.parent)


def special_kind(path: Path) -> str | None:
    """What ``path`` is when a rename over it would destroy it: "a symbolic link"
    (``/dev/stdout``; the rename replaces the link) or "a device, a FIFO or a socket"
    (``/dev/null``); None when it is a regular file, a folder or nothing yet."""
    try:
        mode = path.lstat().st_mode
    except OSError:  # none yet (or unreadable: the rename says why)
        return None
    if stat.S_ISLNK(mode):
        return "a symbolic link"
    if not (stat.S_ISREG(mode) or stat.S_ISDIR(mode)):
        return "a device, a FIFO or a socket"
    return None


def refuse_special(path: Path) -> None:
    """Refuse a destination that a rename would destroy (``special_kind``): the system's
    ``/dev/null`` was replaced by a regular file."""
    kind = special_kind(path)
    if kind is not None:
        raise BipedError(
            f"cannot write {str(path)!r}: it is {kind}; allowed a regular file or a new path"
        )


def atomic_write_bytes(path: str | Path, data: bytes) -> Path:
    """Write ``data`` to ``path`` whole or not at all; returns ``path``. Its folder must exist."""
    path = Path(path)
    with atomic_path(path) as tmp, open(tmp, "wb") as handle:
        handle.write(data)
    return path


def atomic_write_text(path: str | Path, text: str, encoding: str = "utf-8") -> Path:
    """Write ``text`` to ``path`` whole or not at all; returns ``path``. Its folder must exist."""
    return atomic_write_bytes(path, text.encode(encoding))


def is_temporary(path: str | Path) -> bool:
    """Whether ``path`` is named as a temporary file of ``atomic_path`` (``.<name>.<x>.tmp``)."""
    name = Path(path).name
    return name.startswith(".") and name.endswith(TEMPORARY_SUFFIX) and name.count(".") >= 3


def clean_stale_temporaries(folder: str | Path) -> list[Path]:
    """Remove the temporary files a killed run left in ``folder``; returns those removed.

    Call it before any writer starts in ``folder``: a temporary file being written at the
    same moment would be removed too. A missing folder has none.
    """
    folder = Path(folder)
    if not folder.is_dir():
        return []
    removed = []
    for path in sorted(folder.iterdir()):
        if is_temporary(path) and path.is_file() and not path.is_symlink():
            path.unlink(missing_ok=True)
            removed.append(path)
    return removed


@contextlib.contextmanager
def atomic_set(folder: str | Path, name: str = "set") -> Iterator[Path]:
    """A staging folder to write a set of files through, all or none.

    The body writes its files (and subfolders) into the staging folder, a hidden folder
    ``.<name>.<random>.tmp`` inside ``folder``; when it returns, each file is flushed and
    renamed to the same relative path under ``folder``. If the body raises, nothing is moved.
    The staging folder is removed either way; staging folders of the same ``name`` left by a
    killed run are removed first. ``folder`` is created if missing.

    Only the renames, microseconds long, are not all-or-none: a process killed outright
    between two of them leaves the set mixed.

        with atomic_set("logs/figures", "figures") as staging:
            figure.savefig(staging / "fig4.png")
    """
    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    for stale in folder.glob(f".{name}.*{TEMPORARY_SUFFIX}"):
        if stale.is_dir() and not stale.is_symlink():
            shutil.rmtree(stale, ignore_errors=True)
    staging = Path(tempfile.mkdtemp(dir=folder, prefix=f".{name}.", suffix=TEMPORARY_SUFFIX))
    try:
        os.chmod(staging, 0o777 & ~_umask())
        yield staging
        files = sorted(p for p in staging.rglob("*") if p.is_file())
        for path in files:
            with open(path, "rb+") as handle:
                os.fsync(handle.fileno())
        for path in files:
            target = folder / path.relative_to(staging)
            target.parent.mkdir(parents=True, exist_ok=True)
            os.replace(path, target)
    finally:
        shutil.rmtree(staging, ignore_errors=True)
    _fsync_folder(folder)


def distinct_values(values, name: str, unit: str, decimals: int, resolution: str) -> list[float]:
    """``values`` sorted, each distinct in the file names that write it with ``decimals``
    decimals (``resolution`` says that step in words, e.g. "1 mm/s"); otherwise an error that
    names the value given twice, or the two values that share a name."""
    values = sorted(float(v) for v in values)
    for a, b in zip(values, values[1:], strict=False):
        shown = f"{a:.{decimals}f}"
        if shown != f"{b:.{decimals}f}":
            continue
        what = f"{a:g} {unit} given twice" if a == b else f"{a:g} and {b:g} {unit} are both {shown}"
        raise BipedError(
            f"{name}: {what}: allowed values distinct at the files' {resolution} resolution"
        )
    return values
