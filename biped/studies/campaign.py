"""One mechanism for campaigns of optimizations (a sweep, a design map, the paper's method),
which differ only in their science: their points (frozen records, each with the
``filename()`` of its result), the solve of a point, the stages that order the solves, the
summary. The rest is here: ``Settings`` recorded in the folder and read back;
``Campaign.claim`` of the folder (its record written on first use and compared on every
resume, so results of other settings are never mixed in; a killed run's temporaries removed);
a ``Task`` per solve, which writes its file whole and returns its line; ``Campaign.run``: the
stages one after the other, the tasks of each in parallel (``biped.runtime.runner``: local
processes or Dask), their lines, a progress bar, the summary. A campaign resumes by solving
the points whose file is not whole yet, so it ends with the files of an uninterrupted run.
"""

from __future__ import annotations

import dataclasses
import json
import sys
import time
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any, ClassVar

import numpy as np

from biped.errors import BipedError
from biped.model.criteria import Safety, safety_dict
from biped.model.gait import family_json
from biped.model.robot import Robot
from biped.optimization import table
from biped.optimization.problem import FAMILIES, variable_names
from biped.records.gait_file import family_of
from biped.records.provenance import version
from biped.runtime.files import atomic_write_text, clean_stale_temporaries, distinct_values
from biped.runtime.runner import ProgressBar, run_tasks

# How each type of a settings field is read back from its record.
_READ = {
    "Robot": lambda value: Robot.from_mapping(value, source="robot"),
    "Safety": lambda value: Safety(**value),
    "tuple": tuple,
    "int": int,
    "bool": bool,
    "float": float,
    "str": lambda value: value,
    # a gait family: K interior knots, or {"bezier": degree} (``family_of``)
    "int | Bezier": family_of,
}


class Settings:
    """What shapes a campaign's numbers (a frozen dataclass deriving from this), recorded as
    ``FORMAT``, every field in order (tuples as lists), then ``stamp()``."""

    FORMAT: ClassVar[str]

    def stamp(self) -> dict:
        """The method, the versions and the table of optima that starts every optimization
        (``biped.optimization.table``): what made the numbers (an IPOPT campaign's)."""
        return {
            "method": "ipopt",
            "version": version(),
            "casadi": version("casadi"),
            "optima_table": table.digest(),
        }

    def to_dict(self) -> dict:
        content = {"format": self.FORMAT}
        for field in dataclasses.fields(self):
            value = getattr(self, field.name)
            if isinstance(value, Robot):
                value = value.to_dict()
            elif isinstance(value, Safety):  # what is asked (as the records before)
                value = safety_dict(value, kept=("knee_bend",))
            elif field.name == "knots":  # a gait family: K, or {"bezier": degree}
                value = family_json(value)
            content[field.name] = list(value) if isinstance(value, tuple) else value
        return {**content, **self.stamp()}

    @classmethod
    def from_dict(cls, content: dict):
        fields = {f.name: getattr(f.type, "__name__", f.type) for f in dataclasses.fields(cls)}
        return cls(**{name: _READ[kind](content[name]) for name, kind in fields.items()})


@dataclass(frozen=True)
class Task:
    """One solve, run on a worker: ``solve(task)`` writes the point's file whole and returns its
    line; ``given``: the points whose results start it (a sweep's neighbours)."""

    solve: Callable[[Task], str]
    settings: Any
    point: Any
    folder: str
    given: tuple = ()

    @property
    def path(self) -> Path:
        return Path(self.folder) / self.point.filename()


def perform(task: Task) -> str:
    return task.solve(task)


def failure(status: str, feasible: bool) -> str | None:
    """Why an optimum is not certified, as a campaign's line says it; None if it is (its
    solver converged, it is feasible on the check grid)."""
    if status != "converged":
        return "NOT CONVERGED: " + status
    return None if feasible else "INFEASIBLE"


def variables(named: dict) -> np.ndarray | None:
    """The solver's variables from {name: value} in the order of its family
    (``biped.optimization.problem.variable_names``), None if it ended without them."""
    names = tuple(named)
    if not any(names == variable_names(knots) for knots in FAMILIES):
        raise BipedError(f"variables {', '.join(names[:3])}, ...: allowed a gait family's")
    values = list(named.values())
    return None if any(v is None for v in values) else np.array(values, float)


def distinct_speeds(speeds) -> list[float]:
    """Sorted speeds [m/s], distinct at the 1 mm/s of the points' file names."""
    return distinct_values(speeds, "speeds", "m/s", 3, "1 mm/s")


def tally(points, why_not: Callable, counted: str, note: str = "", most: int | None = None):
    """ "N of M ``counted``", ``note``, then "; NOT: " and each point not certified with
    ``why_not(point)`` (None for a certified point), at most ``most`` of them."""
    bad = [f"{p.filename()} {why}" for p in points if (why := why_not(p)) is not None]
    text = f"{len(points) - len(bad)} of {len(points)} {counted}{note}"
    if bad:
        shown = bad[:most]
        text += "; NOT: " + ", ".join(shown) + (" ..." if len(shown) < len(bad) else "")
    return text


@dataclass(frozen=True)
class Campaign:
    """A kind of campaign: its name in its lines and the record that claims its folder.

    Attributes:
        name: the campaign in its closing line ("sweep").
        record: the record's file name in the folder ("sweep.json").
        what: what the record is, for an unreadable one ("sweep record").
        made: the subject of "... made with KEY = VALUE" ("this folder's sweep was").
        owner: whose folder it is ("a sweep's"); None: a folder of its own, not checked for
            other files.
        contents: what other files in a folder without the record are ("gait files").
    """

    name: str
    record: str
    what: str
    made: str
    owner: str | None = None
    contents: str = "JSON files"

    def claim(self, folder, settings: Settings, *inner: str) -> Path:
        """The folder, its record of ``settings`` checked (a refused run writes nothing, raising
        as ``check``) or written, its ``inner`` folders made, a killed run's temporaries gone."""
        folder = Path(folder)
        wanted = settings.to_dict()
        if not self.check(folder, wanted):
            folder.mkdir(parents=True, exist_ok=True)
            atomic_write_text(folder / self.record, json.dumps(wanted, indent=1))
        for place in (folder, *(folder / name for name in inner)):
            place.mkdir(exist_ok=True)
            clean_stale_temporaries(place)
        return folder

    def read(self, folder) -> dict | None:
        """The folder's record, None if it has none; a BipedError if it is unreadable."""
        path = Path(folder) / self.record
        if not path.exists():
            return None
        try:
            return json.loads(path.read_text())
        except (OSError, ValueError, UnicodeDecodeError) as error:
            raise BipedError(f"{path}: unreadable {self.what} ({error})") from None

    def check(self, folder, wanted: dict) -> bool:
        """Whether the folder's record holds ``wanted`` settings (False: it has none yet, a
        run may claim it); writes nothing.

        Raises:
            BipedError: the record is unreadable or holds other settings, or (with an
                ``owner``) the folder holds JSON files but no record.
        """
        folder = Path(folder)
        found = self.read(folder)
        if found is not None:
            for key, value in wanted.items():
                if found.get(key) != value:
                    raise BipedError(
                        f"{folder / self.record}: {self.made} made with {key} = "
                        f"{found.get(key)!r}, this run has {value!r}: allowed only the same "
                        "settings, choose another --out folder"
                    )
            return True
        if self.owner is not None and any(folder.glob("*.json")):
            raise BipedError(
                f"{folder} holds {self.contents} but no {self.record}: allowed an empty folder "
                f"or {self.owner}, choose another --out folder"
            )
        return False

    def run(
        self,
        plan: str | None,
        stages: list[list[Task]],
        summary: Callable[[], str] | None = None,
        *,
        jobs: int | None = None,
        dask: str | None = None,
        stream=None,
        progress: Callable[[int], ProgressBar] | None = None,
    ) -> None:
        """Print ``plan``, run the stages (each a list of tasks independent of each other,
        reading only the files of the stages before) on ``jobs`` processes or ``dask``, print
        each task's line to ``stream`` (default: the call's ``sys.stderr``) with the bar of
        ``progress(total)``, then "NAME: done in T s; ``summary()``"."""
        stream = sys.stderr if stream is None else stream
        if plan is not None:
            print(plan, file=stream, flush=True)
        began = time.perf_counter()
        total = sum(map(len, stages))
        bar = progress(total) if progress is not None and total else None
        if bar is not None:
            bar.advance(0)  # drawn from the start
        try:
            for tasks in stages:
                for line in run_tasks(
                    perform, tasks, jobs=jobs, dask=dask, stream=stream, progress=bar
                ):
                    print(line, file=stream, flush=True)
        finally:
            if bar is not None:
                bar.clear()
        if summary is not None:
            seconds = time.perf_counter() - began
            print(f"{self.name}: done in {seconds:.1f} s; {summary()}", file=stream, flush=True)
