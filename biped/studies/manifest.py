"""The record of the settings that shaped a folder of results (a sweep, a design map, the
paper's method over seeds): written when the folder is first used, compared on every resume,
so results of other settings are never mixed into it."""

from __future__ import annotations

import json
from dataclasses import dataclass
from pathlib import Path

from biped.errors import BipedError
from biped.runtime.files import atomic_write_text


@dataclass(frozen=True)
class Manifest:
    """How one kind of folder names its record and itself in messages.

    Attributes:
        name: the record's file name in the folder ("sweep.json").
        record: what the record is, for an unreadable one ("sweep record").
        made: the subject of "... made with KEY = VALUE" ("this folder's sweep was").
        owner: whose folder it is ("a sweep's"); None: a folder of its own, not checked for
            other files.
        contents: what other files in a folder without the record are ("gait files").
    """

    name: str
    record: str
    made: str
    owner: str | None = None
    contents: str = "JSON files"

    def claim(self, folder: str | Path, wanted: dict) -> None:
        """Write the folder's record of ``wanted`` settings, or check those it holds.

        The folder (and its missing parents) is created only once the check has passed: a
        refused run leaves nothing behind. Call it before anything else is written there.

        Raises:
            BipedError: as ``check``.
        """
        folder = Path(folder)
        if self.check(folder, wanted):
            return
        folder.mkdir(parents=True, exist_ok=True)
        atomic_write_text(folder / self.name, json.dumps(wanted, indent=1))

    def check(self, folder: str | Path, wanted: dict) -> bool:
        """Whether the folder's record holds ``wanted`` settings (False: it has none yet, a
        run may claim it); writes nothing.

        Raises:
            BipedError: the record is unreadable or holds other settings, or (with an
                ``owner``) the folder holds JSON files but no record.
        """
        folder = Path(folder)
        path = folder / self.name
        if path.exists():
            try:
                found = json.loads(path.read_text())
            except (OSError, ValueError, UnicodeDecodeError) as error:
                raise BipedError(f"{path}: unreadable {self.record} ({error})") from None
            for key, value in wanted.items():
                if found.get(key) != value:
                    raise BipedError(
                        f"{path}: {self.made} made with {key} = {found.get(key)!r}, this run "
                        f"has {value!r}: allowed only the same settings, choose another "
                        "--out folder"
                    )
            return True
        if self.owner is not None and any(folder.glob("*.json")):
            raise BipedError(
                f"{folder} holds {self.contents} but no {self.name}: allowed an empty folder "
                f"or {self.owner}, choose another --out folder"
            )
        return False
