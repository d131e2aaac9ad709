"""Robustness maps of gait files run and written as ``biped robustness`` writes them: per gait
file its map (``robustness.robustness_map``) as ``<out>/<name>.json`` and ``.png``, together,
none where the nominal walk fails.
"""

from __future__ import annotations

import time
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path

from biped.errors import BipedError
from biped.model.units import unit_field
from biped.pages.robustness_figure import robustness_figure
from biped.pages.style import save_with_json
from biped.records.gait_file import Gait
from biped.records.provenance import provenance
from biped.runtime.runner import ProgressBar
from validate.scene.model import committed_model
from validate.studies.robustness import GaitMap, RobustnessSettings, robustness_map


@dataclass(frozen=True)
class MappedGait:
    """A gait file's map (``GaitMap``; written unless its nominal walk failed: ``written``)
    and the wall time it took."""

    mapped: GaitMap
    wall: float = unit_field("s")

    @property
    def written(self) -> bool:
        return self.mapped.map.passed


def model_source(gait: Gait, model: str | None) -> str:
    """What the map's walks were played on: ``model`` as given, the committed model, or the
    one generated from the gait's robot."""
    if model is not None:
        return model
    committed = committed_model(gait.biped)
    if committed is None:
        return "generated from the gait's robot (validate.scene.mjcf)"
    return f"mjcf/{committed.name}"  # the committed model, wherever this copy keeps it


def write(out: Path, name: str, mapped: GaitMap) -> None:
    """``<out>/<name>.json`` (the map with its provenance) and ``.png``, both or neither."""
    content = {**mapped.to_dict(), "provenance": provenance()}
    title = f"{mapped.gait}: {mapped.knee} knee, {mapped.speed} m/s"
    figure = robustness_figure(mapped.map, title)
    save_with_json(out, name, "robustness", content, figure)


def map_gaits(
    paths: list[str],
    gaits: list[Gait],
    names: list[str],
    out: str | Path,
    model: str | None = None,
    settings: RobustnessSettings | None = None,
    progress: ProgressBar | None = None,
) -> Iterator[MappedGait]:
    """Each gait file's map (``paths``, read as ``gaits``), in turn, written as
    ``<out>/<name>.json`` and ``.png`` (``names``, one per file) where its nominal walk
    walks; yielded as each is done (``settings`` None: ``RobustnessSettings()``). A
    BipedError names the gait file."""
    out, settings = Path(out), RobustnessSettings() if settings is None else settings
    for path, gait, name in zip(paths, gaits, names, strict=True):
        if progress is not None:
            progress.advance(0, note=str(path))
        began = time.perf_counter()
        try:
            result = robustness_map(gait, model, settings, progress=progress)
        except BipedError as error:
            raise BipedError(f"gait file {str(path)!r}: {error}") from None
        wall = time.perf_counter() - began
        source = model_source(gait, model)
        found = GaitMap(str(path), gait.knee, gait.criterion, gait.speed, source, result)
        if result.passed:
            write(out, name, found)
        yield MappedGait(found, wall)
