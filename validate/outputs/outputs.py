"""Where a gait's outputs go, and which gait a recording belongs to.

A gait file's recording, video and page are named from the gait file's own path, its folder
and its name (``logs/sweep/rolling-sthenic-0.300.json`` -> ``sweep-rolling-sthenic-0.300``),
so gait files of the same name in two folders do not share them. Beside each recording, its
validation report ``<recording's stem>.report.json`` (``report_path``) and its owner record
``<recording>.source.json``, which names the gait file it was made from (absolute path)
and the SHA-256 of that file's content; a recording owned by another gait file is never
overwritten (``check_owner``), and a page links a recording only if it is its gait's.

Every file a command writes is printed once, the owner record of a recording on the line
after it (``recording_lines``); the command that opens a recording is this environment's own
rerun viewer (``open_command``), which works as printed without activating the environment.
"""

from __future__ import annotations

import hashlib
import json
import shlex
import shutil
import sys
from pathlib import Path

from biped.errors import BipedError
from biped.runtime.files import atomic_write_text

OWNER_SUFFIX = ".source.json"


def output_name(gait_path: str | Path) -> str:
    """The name of a gait file's outputs: '<folder>-<name>' of its absolute path."""
    path = Path(gait_path).resolve()
    return f"{path.parent.name}-{path.stem}" if path.parent.name else path.stem


def report_path(recording: str | Path) -> Path:
    """The validation report ``biped validate`` writes beside a recording:
    ``<recording's stem>.report.json``."""
    recording = Path(recording)
    return recording.with_name(f"{recording.stem}.report.json")


def owner_path(recording: str | Path) -> Path:
    """The owner record of a recording: ``<recording>.source.json`` beside it."""
    recording = Path(recording)
    return recording.with_name(recording.name + OWNER_SUFFIX)


def digest(path: str | Path) -> str:
    """SHA-256 (hex) of a file's content."""
    return hashlib.sha256(Path(path).read_bytes()).hexdigest()


def owner(recording: str | Path) -> dict | None:
    """The owner record of a recording ({"gait": path, "sha256": hex}), None if it has none
    or it cannot be read."""
    try:
        content = json.loads(owner_path(recording).read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return None
    return content if isinstance(content, dict) and isinstance(content.get("gait"), str) else None


def check_owner(recording: str | Path, gait_path: str | Path, option: str = "--rrd") -> None:
    """Refuse (BipedError) to write ``recording`` for ``gait_path`` when it exists and belongs
    to another gait file. A recording without an owner record may be overwritten."""
    recording = Path(recording)
    record = owner(recording) if recording.exists() else None
    if record is not None and record["gait"] != str(Path(gait_path).resolve()):
        raise BipedError(
            f"{option} {str(recording)!r} is the recording of another gait file, "
            f"{record['gait']!r}: allowed a path that is free or that gait file's own "
            "(remove the recording to replace it)"
        )


def claim(recording: str | Path, gait_path: str | Path) -> Path:
    """Write the owner record of ``recording``: made from ``gait_path`` as it is now."""
    gait_path = Path(gait_path)
    content = {"gait": str(gait_path.resolve()), "sha256": digest(gait_path)}
    return atomic_write_text(owner_path(recording), json.dumps(content, indent=1))


def belongs_to(recording: str | Path, gait_path: str | Path) -> bool | None:
    """Whether ``recording`` was made from ``gait_path`` as it is now: True, False (another
    gait file, or an earlier content of this one), or None (no owner record)."""
    record = owner(recording)
    if record is None:
        return None
    gait_path = Path(gait_path)
    return record["gait"] == str(gait_path.resolve()) and record.get("sha256") == digest(gait_path)


def rerun_command() -> str:
    """The rerun viewer of this environment, as a command that works as printed: the
    ``rerun`` beside this Python (a virtual environment's ``bin/``, on the PATH only once
    activated), else the one on the PATH, else this Python's ``-m rerun``."""
    beside = Path(sys.executable).parent / ("rerun.exe" if sys.platform == "win32" else "rerun")
    if beside.is_file():
        return shlex.quote(str(beside))
    found = shutil.which("rerun")
    return shlex.quote(found) if found else f"{shlex.quote(sys.executable)} -m rerun"


def open_command(recording: str | Path) -> str:
    """The command line that opens ``recording`` in this environment's rerun viewer."""
    return f"{rerun_command()} {shlex.quote(str(recording))}"


def recording_lines(recording: str | Path) -> list[str]:
    """What a command prints of a recording it wrote: the recording and how to open it, then
    its owner record (a file written too)."""
    return [
        f"recording {recording}  (open with: {open_command(recording)})",
        f"owner record {owner_path(recording)} (the gait file it was made from)",
    ]
