"""The one style of every figure of the project: its resolution, the two knees' colours,
markers and names, and how a figure is written (a PNG, atomically).

Every module drawing a figure (``biped.pages``, ``validate.studies``) takes its size
(``*_SIZE``) and its fonts (``FONT_*``) from here, its knees' look from ``KNEE_STYLE`` and
``KNEE_LABELS``, and writes it with ``save``: a figure is never half written, whoever reads
the folder meanwhile.
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
# [in] An atlas map's cell: its width at least, and its label's font [pt] from the first size
# (the least readable) up to the second, as the cell allows.
ATLAS_CELL_WIDTH = 0.45
ATLAS_CELL_FONT = (8.0, 14.0)
# [in] An atlas map panel's plot area at least (width, height) and what its labels, colour
# bar and titles take beside it; the width of its curves' panel with its legend beside it.
ATLAS_MAP_AREA = (3.6, 3.2)
ATLAS_MAP_MARGINS = (1.6, 1.4)
ATLAS_CURVES_WIDTH = 7.4
# [pt] The figures' font sizes, one scale for all (matplotlib's default, 10 pt, labels the
# axes and their ticks).
FONT_TINY = 6  # an inset's ticks and labels, the legend of a crowded panel
FONT_SMALL = 7  # a legend beside curves, a value over a bar
FONT_NOTE = 8  # notes and annotations, most legends
FONT_CAPTION = 8.5  # the caption under a figure
FONT_TITLE = 9  # a panel's title, a figure's title of two lines
FONT_HEADING = 10  # a figure's title over several panels
# [in] (width, height) of each figure, or of one panel of a figure that grows with them.
PAPER_CRITERION_SIZE = (16, 5.0)  # a criterion against speed, both knees (figures)
TIME_PANEL_SIZE = (4.4, 3.2)  # a panel of a quantity over the step (figures, pages)
CONVERGE_SIZE = (8, 6.4)  # the ladder of gait families (converge_figures)
CRITERIA_SIZE = (16, 5.6)  # each criterion measured on each optimum, both knees (criteria_figures)
DESIGN_MAP_SIZE = (6.4, 5.6)  # the criterion over the radii at one speed (design_map_figures)
DESIGN_SPEEDS_SIZE = (10, 4)  # the designed radii and gains over speed (design_map_figures)
MULTIPLIERS_SIZE = (5.6, 5.6)  # Floquet multipliers in the complex plane (orbit_figures)
ORBIT_VARIED_SIZE = (7.0, 5.2)  # the spectral radius as a gain varies (orbit_figures)
ORBIT_KNEES_PANEL_SIZE = (5.2, 6.4)  # a criterion's panel of the knees' orbits (orbit_figures)
PROFILE_SIZE = (15, 8.4)  # a knee profile's surfaces and their contact (profile_figures)
# the knees with and without double support (two_phase_sweep_figures)
TWO_PHASE_SWEEP_SIZE = (18, 4.4)
# [in] an atlas with double support: the width of a cell's pair of bars, and the height
ATLAS_TWO_PHASE_CELL = (1.3, 4.2)  # (atlas_two_phase)
ATLAS_TWO_PHASE_WIDTHS = (5.0, 1.5)  # [in] the least figure, the axis's labels (atlas_two_phase)
PROFILE_SPEEDS_SIZE = (8, 4.6)  # a profile's criterion over speed (profile_figures)
ROBUSTNESS_SIZE = (8.0, 6.0)  # a gait's robustness map (robustness_figure)
WALK_TORQUES_SIZE = (13.2, 6.8)  # MuJoCo's torques beside the model's (walk_figures)
MARGINS_SIZE = (11, 5.0)  # the walkable margins' study (validate.studies.margins_study)
# Two atlases in two gait families (atlas_families): per cell (width) and per criterion
# (height), the labels' and title's room beside them, and the least width [in].
FAMILIES_CELL_SIZE = (0.62, 3.1)
FAMILIES_MARGINS = (2.0, 1.6)
FAMILIES_LEAST_WIDTH = 7.0
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
