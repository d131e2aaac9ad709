"""The one style of every figure of the project: its resolution, the two knees' colours,
markers and names, and how a figure is written (a PNG, atomically).

Every module drawing a figure (``biped.pages``, ``validate.studies``) takes its knees' look
from ``KNEE_STYLE`` and ``KNEE_LABELS`` and writes it with ``save``: a figure is never half
written, whoever reads the folder meanwhile.
"""

from __future__ import annotations

import json
from pathlib import Path

from matplotlib.figure import Figure

from biped.runtime.files import atomic_path, atomic_set

DPI = 120  # [dots/inch] of every figure written
# [dots/inch] of the atlas's maps: wide figures of one panel per knee bend, kept at the
# resolution they were first published at (their pixels unchanged).
ATLAS_DPI = 110
KNEE_LABELS = {"revolute": "revolute knee", "rolling": "rolling knee"}
KNEE_STYLE = {
    "revolute": dict(color="tab:blue", marker="o"),
    "rolling": dict(color="tab:red", marker="s"),
}

# Two gait families side by side (``atlas_families``): the base (the paper's spline) and the
# rich one, apart from the knees' colours.
FAMILY_STYLE = {
    "base": dict(color="0.35", marker="o"),
    "rich": dict(color="tab:purple", marker="D"),
}


def save(figure: Figure, path: str | Path, dpi: float = DPI) -> Path:
    """Write ``figure`` as the PNG ``path`` at ``dpi``, atomically (``atomic_path``: the
    file whole or as it was); its folder must exist. Returns ``path``."""
    path = Path(path)
    with atomic_path(path) as staging:
        figure.savefig(staging, dpi=dpi, format="png")
    return path


def save_with_json(out: str | Path, name: str, kind: str, content: dict, figure: Figure) -> None:
    """``<out>/<name>.json`` (``content``) and ``<out>/<name>.png`` (``figure``), both or
    neither (``atomic_set`` under the label ``<kind>-<name>``)."""
    with atomic_set(out, f"{kind}-{name}") as staging:
        text = json.dumps(content, indent=1, allow_nan=False)
        (staging / f"{name}.json").write_text(text, encoding="utf-8")
        save(figure, staging / f"{name}.png")
