"""The figure of ``biped criteria`` (``biped.studies.criteria_matrix``): each knee's matrix
side by side, a row per criterion minimised and a column per criterion measured, each cell
coloured by how far its value is above the column's own optimum and labelled with the value
and its unit; beside them the knees' difference in each cell. Unknown cells are grey and
say so."""

from __future__ import annotations

import numpy as np
from matplotlib.colors import LogNorm, TwoSlopeNorm
from matplotlib.figure import Figure

from biped.model.criteria import CRITERION_UNITS
from biped.pages.criteria_page import problem_words
from biped.pages.style import CRITERIA_SIZE, FONT_TITLE, KNEE_LABELS, KNEE_STYLE
from biped.studies.criteria_matrix import STUDIED, CriteriaStudy, KneeMatrix

UNKNOWN_COLOUR = "0.85"
# A criterion's name on an axis, broken over lines.
SHORT = {"sthenic": "sthenic", "energy-per-metre": "energy per\nmetre", "electrical": "electrical"}
# [%] The least half-range of the knees' difference's colours, which end at the largest
# difference on the diagonal (each knee at its own optimum, measured in its criterion): the
# cells off it, other minima's figures, may lie far beyond and are drawn saturated.
LEAST_SCALE = 1.0
# Cells darker than this share of their colour scale are labelled in white.
DARK = 0.6
# The ratio to the column's own optimum the colour scale ends at (darkest above).
MOST_RATIO = 30.0


def criteria_figure(study: CriteriaStudy) -> Figure:
    """Three panels: the revolute and the rolling knee's matrices (the colour: the value over
    the column's own optimum, log scale; the text: the value [unit] and what it costs [%]),
    and the knees' difference (rolling − revolute) / revolute [%] in each cell."""
    fig = Figure(figsize=CRITERIA_SIZE, layout="constrained")
    axes = fig.subplots(1, 3)
    ratios = LogNorm(vmin=1.0, vmax=MOST_RATIO)
    image = None
    for ax, matrix in zip(axes, study.knees, strict=False):
        image = _knee_panel(ax, matrix, ratios)
    fig.colorbar(image, ax=list(axes[:2]), shrink=0.8,
                 label="value / the column's own optimum (log scale)")  # fmt: skip
    _difference_panel(fig, axes[2], study)
    fig.suptitle(f"Each criterion on each criterion's optimum, {problem_words(study)}")
    return fig


def _knee_panel(ax, matrix: KneeMatrix, norm):
    """One knee's matrix (``criteria_figure``); returns its image for the colour bar."""
    ratios = np.full((len(STUDIED), len(STUDIED)), np.nan)
    for i, optimized in enumerate(STUDIED):
        for j, measured in enumerate(STUDIED):
            cost = matrix.cost(optimized, measured) if i != j else 0.0
            known = matrix.known(optimized, measured)
            if cost is not None and known is not None:
                ratios[i, j] = 1.0 + cost / 100.0
            value = "unknown" if known is None else f"{known:.4g}"
            text = f"{value}\n{CRITERION_UNITS[measured]}"
            if i != j:
                text += "\nunknown" if cost is None else f"\n{cost:+.1f} %"
            _label(ax, (i, j), text, norm(ratios[i, j]))
    image = ax.imshow(_masked(ratios), cmap=_cmap("Oranges"), norm=norm)
    _axes(ax, "optimum of (criterion minimised)" if matrix.knee == "revolute" else None)
    ax.set_title(KNEE_LABELS[matrix.knee], color=KNEE_STYLE[matrix.knee]["color"])
    return image


def _difference_panel(fig, ax, study: CriteriaStudy) -> None:
    """(rolling − revolute) / revolute [%] in each cell, a diverging scale about 0 up to the
    diagonal's largest (``LEAST_SCALE``)."""
    known = [[study.difference(a, b) for b in STUDIED] for a in STUDIED]
    found = np.array([[np.nan if d is None else d for d in row] for row in known])
    diagonal = np.abs(np.diag(found))
    largest = max(np.nanmax(diagonal) if np.isfinite(diagonal).any() else 0.0, LEAST_SCALE)
    norm = TwoSlopeNorm(vcenter=0.0, vmin=-largest, vmax=largest)
    for (i, j), difference in np.ndenumerate(found):
        shown = "unknown" if np.isnan(difference) else f"{difference:+.2f} %"
        _label(ax, (i, j), shown, 2.0 * abs(norm(difference) - 0.5))
    image = ax.imshow(_masked(found), cmap=_cmap("RdBu_r"), norm=norm)
    label = "(rolling − revolute) / revolute [%],\nto the diagonal's largest"
    fig.colorbar(image, ax=ax, shrink=0.8, extend="both", label=label)
    _axes(ax, None)
    ax.set_title("rolling vs revolute knee")


def _label(ax, at: tuple, text: str, shade) -> None:
    """``text`` in the cell ``at`` (row, column), bold on the diagonal, white on a dark
    ``shade`` (its share of the colour scale, NaN: unknown)."""
    row, column = at
    shade = np.clip(shade, 0.0, 1.0)  # beyond the scale (saturated, or infinite): its end
    dark = bool(np.isfinite(shade) and shade > DARK)
    ax.text(column, row, text, ha="center", va="center", fontsize=FONT_TITLE,
            fontweight="bold" if row == column else "normal",
            color="white" if dark else "black")  # fmt: skip


def _masked(values: np.ndarray) -> np.ma.MaskedArray:
    return np.ma.masked_invalid(values)


def _cmap(name: str):
    from matplotlib import colormaps

    return colormaps[name].with_extremes(bad=UNKNOWN_COLOUR)


def _axes(ax, rows: str | None) -> None:
    """The criteria on both axes: measured across, minimised down (``rows``: its label)."""
    ticks = range(len(STUDIED))
    ax.set_xticks(ticks, [f"{SHORT[c]}\n[{CRITERION_UNITS[c]}]" for c in STUDIED])
    ax.set_yticks(ticks, [SHORT[c] for c in STUDIED])
    ax.set_xlabel("criterion measured")
    if rows is not None:
        ax.set_ylabel(rows)
    ax.tick_params(length=0)


__all__ = ["criteria_figure"]
