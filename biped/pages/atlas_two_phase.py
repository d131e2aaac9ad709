"""The figure of an atlas with double support (``biped.records.atlas_two_phase``): per cell
(speed, clearance, knee bend) the knees' difference in C_Γ, (rolling − revolute) / revolute,
in single support (hatched) and with double support (solid). A difference not measured (an
optimum not certified) has no bar and says "unknown", never drawn as zero.
"""

from __future__ import annotations

from pathlib import Path

from matplotlib.figure import Figure

from biped.pages.style import (
    ATLAS_TWO_PHASE_CELL,
    ATLAS_TWO_PHASE_WIDTHS,
    FONT_NOTE,
    FONT_SMALL,
    FONT_TITLE,
    save,
)
from biped.records.atlas_two_phase import AtlasTwoPhaseSummary

WIDTH = 0.38  # of a bar, a cell 1 apart from the next
BARS = {
    "single": ("single support", "//", -WIDTH / 2),
    "double": ("with double support", "", WIDTH / 2),
}


def _label(cell) -> str:
    words = f"{cell.difference.speed:.2f} m/s\n{1000 * cell.clearance:.0f} mm"
    return words + (f"\n{cell.knee_bend:.2f} rad" if cell.knee_bend else "")


def atlas_two_phase_figure(summary: AtlasTwoPhaseSummary, path: str | Path) -> Path:
    """Write the figure of ``summary`` as the PNG ``path``; returns it."""
    cells = sorted(
        summary.differences, key=lambda d: (d.knee_bend, d.clearance, d.difference.speed)
    )
    width, height = ATLAS_TWO_PHASE_CELL
    least, labels = ATLAS_TWO_PHASE_WIDTHS
    fig = Figure(figsize=(max(least, width * len(cells) + labels), height), layout="constrained")
    axis = fig.subplots()
    for phase, (label, hatch, shift) in BARS.items():
        labelled = False
        for x, cell in enumerate(cells):
            value = getattr(cell.difference, phase)
            if value is None:
                axis.text(x + shift, 0.0, "unknown", rotation=90, ha="center", fontsize=FONT_SMALL)
                continue
            axis.bar(x + shift, value, WIDTH, color="0.75" if hatch else "0.3", hatch=hatch,
                     edgecolor="0.2", label=None if labelled else label)  # fmt: skip
            labelled = True
            axis.annotate(f"{value:+.1f}", (x + shift, value), ha="center", fontsize=FONT_SMALL,
                          va="bottom" if value >= 0 else "top")  # fmt: skip
    axis.axhline(0.0, color="0.6", linewidth=0.8)
    axis.set_xticks(range(len(cells)), [_label(c) for c in cells])
    axis.set_ylabel("C_Γ, (rolling − revolute) / revolute [%]")
    low, high = summary.share_range
    axis.set_title(
        f"the knees' difference per cell (< 0: the rolling knee needs less);\ndouble support "
        f"{low:g} to {high:g} of the step, {summary.landing} landing",
        fontsize=FONT_TITLE,
    )
    axis.legend(fontsize=FONT_NOTE)
    axis.grid(alpha=0.3, axis="y")
    return save(fig, path)
