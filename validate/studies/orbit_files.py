"""Orbit studies of gait files run and written as ``biped orbit`` writes them: per gait file
its study (``orbit_study``) as ``<out>/<name>.json`` and ``.png``, together; given gaits of
both knees under the validation's controller, the knees compared at each criterion and speed
both were given at (``KneePair``, and per criterion ``KneeMean``) and ``<out>/knees.png``.
"""

from __future__ import annotations

import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from biped.model.units import unit_field
from biped.pages.orbit_figures import SPREADS, knob_figure, multipliers_figure, rho_difference
from biped.pages.orbit_figures import speeds_figure as knees_figure
from biped.pages.style import save, save_with_json
from biped.records.gait_file import Gait
from biped.records.provenance import provenance
from biped.runtime.runner import ProgressBar
from validate.checks.orbit import Steps
from validate.studies.orbit_study import OrbitStudy, StudiedOrbit, study

KNEES_FIGURE = "knees.png"


@dataclass(frozen=True)
class KneePair:
    """Both knees' orbits under the validation's controller at one criterion and speed, and
    ρ's difference (``rho_difference``: (rolling − revolute) / revolute) with its spread;
    None where a knee's walk has no orbit."""

    criterion: str
    speed: float = unit_field("m/s")
    revolute: StudiedOrbit = unit_field(StudiedOrbit, default=None)
    rolling: StudiedOrbit = unit_field(StudiedOrbit, default=None)
    difference: float | None = unit_field("%", default=None)
    spread: float | None = unit_field("%", default=None)

    @property
    def distinct(self) -> bool:
        """Whether the difference lies beyond ``SPREADS`` spreads of 0."""
        return self.difference is not None and abs(self.difference) > SPREADS * self.spread


@dataclass(frozen=True)
class KneeMean:
    """The knees' differences of one criterion over its speeds: how many, their mean and
    its spread (the spreads combined), how many of them are distinct."""

    criterion: str
    speeds: int
    mean: float = unit_field("%")
    spread: float = unit_field("%")
    distinct: int = 0


@dataclass(frozen=True)
class OrbitRun:
    """The studies of a run (one per gait file, in the order given), its wall time and the
    knees' figure written (None: not gaits of both knees under the validation's
    controller)."""

    studies: tuple[OrbitStudy, ...]
    wall: float = unit_field("s")
    knees_figure: Path | None = None

    @property
    def unstable(self) -> list[str]:
        """The gait files whose orbit under the validation's controller is not shown
        stable (none with a knob: a study)."""
        return [
            s.gait
            for s in self.studies
            if s.knob is None and s.orbits[0].figures.verdict != "stable"
        ]

    @property
    def walks(self) -> int:
        return sum(orbit.figures.walks for found in self.studies for orbit in found.orbits)


def title(found: OrbitStudy) -> str:
    """The gait file and what it is, as its figure's title and the printed lines say it."""
    return f"{found.gait}: {found.knee} knee, {found.criterion}, {found.speed} m/s"


def write(out: Path, name: str, found: OrbitStudy) -> None:
    """``<out>/<name>.json`` (the study with its provenance) and ``.png`` (the multipliers,
    or ρ against the knob), both or neither."""
    body = found.to_dict()
    if found.knob is None:
        figure = multipliers_figure(body["orbits"][0], title(found))
    else:
        figure = knob_figure(body, title(found))
    content = {**body, "provenance": provenance()}
    save_with_json(out, name, "orbit", content, figure)


def run_orbits(
    paths: list[str],
    gaits: list[Gait],
    names: list[str],
    out: str | Path,
    knob: str | None = None,
    values=(None,),
    model: str | None = None,
    steps: Steps | None = None,
    jobs: int = 1,
    progress: ProgressBar | None = None,
) -> OrbitRun:
    """The orbit study of each gait file (``paths``, read as ``gaits``) over ``values`` of
    ``knob`` (``orbit_study.study``), each written as ``<out>/<name>.json`` and ``.png``
    (``names``, one per file); without a knob, given gaits of both knees, also
    ``<out>/knees.png`` (ρ of both knees against speed)."""
    out = Path(out)
    began = time.perf_counter()
    results = study(gaits, knob, values, model, steps, jobs, progress=progress)
    wall = time.perf_counter() - began
    studies = []
    for path, gait, name, orbits in zip(paths, gaits, names, results, strict=True):
        studies.append(OrbitStudy.of(path, gait, knob, values, orbits))
        write(out, name, studies[-1])
    knees = None
    if knob is None and len({found.knee for found in studies}) == 2:
        rows = [
            {**s.orbits[0].to_dict(), "knee": s.knee, "criterion": s.criterion, "speed": s.speed}
            for s in studies
        ]
        knees = save(knees_figure(rows, "the optimal gaits' walks in MuJoCo"), out / KNEES_FIGURE)
    return OrbitRun(tuple(studies), wall, knees)


def knee_pairs(studies: list[OrbitStudy]) -> list[KneePair]:
    """The knees side by side at each criterion and speed both were given at (``studies``:
    each under the validation's controller), sorted by criterion and speed."""
    rows = {(s.criterion, s.speed, s.knee): s.orbits[0] for s in studies}
    pairs = []
    for criterion, speed in sorted({(c, v) for c, v, _ in rows}):
        revolute, rolling = (rows.get((criterion, speed, knee)) for knee in ("revolute", "rolling"))
        if revolute is None or rolling is None:
            continue
        difference = spread = None
        if revolute.found and rolling.found:
            difference, spread = rho_difference(rolling.to_dict(), revolute.to_dict())
        pairs.append(KneePair(criterion, speed, revolute, rolling, difference, spread))
    return pairs


def knee_means(pairs: list[KneePair]) -> list[KneeMean]:
    """Per criterion (in the order of ``pairs``), the mean of the knees' differences over
    its speeds where both have an orbit."""
    by_criterion: dict = {}
    for pair in pairs:
        if pair.difference is not None:
            by_criterion.setdefault(pair.criterion, []).append(pair)
    means = []
    for criterion, found in by_criterion.items():
        values = np.array([p.difference for p in found])
        spreads = np.array([p.spread for p in found])
        spread = float(np.sqrt(np.sum(spreads**2))) / len(values)
        distinct = sum(p.distinct for p in found)
        means.append(KneeMean(criterion, len(values), float(values.mean()), spread, distinct))
    return means
