"""The pages of two atlases compared across gait families (``biped.studies.atlas_families``):
``families.json`` and ``families.png`` (per criterion, each common cell's difference between
the knees in both families with its error bar, and the verdict) and ``families.md`` (a
sentence per criterion, then every cell)."""

from __future__ import annotations

import textwrap
from pathlib import Path

import numpy as np
from matplotlib.figure import Figure

from biped.model.gait import family_label, family_words
from biped.pages.atlas import CRITERION_NAMES, FIGURE_NAMES
from biped.pages.style import (
    FAMILIES_CELL_SIZE,
    FAMILIES_LEAST_WIDTH,
    FAMILIES_MARGINS,
    FAMILY_STYLE,
    FONT_HEADING,
    FONT_NOTE,
    FONT_SMALL,
    FONT_TITLE,
    save_with_json,
)
from biped.runtime.files import atomic_write_text
from biped.studies.atlas_families import CellShift, FamilyComparison, Side

NAME = "families"
# Each verdict over its cell in the figure: its mark and colour.
VERDICT_MARKS = {
    "hides": ("hides", "tab:blue"),
    "invents": ("invents", "tab:red"),
    "same": ("=", "0.45"),
    "unknown": ("?", "0.45"),
}
# The two families' points beside each cell's tick [cells].
OFFSET = 0.16
TITLE_CHARS_PER_INCH = 15  # characters of the 9 pt title per inch of the figure's width


def figure(comparison: FamilyComparison) -> Figure:
    """A panel per criterion: each common cell's difference (rolling − revolute) / revolute
    [%] in the base and the rich family, each with its error bar (a hollow marker and "±?"
    where it is unknown), the cell's verdict above it."""
    criteria = comparison.criteria
    cells = max(comparison.counts(c)["cells"] for c in criteria)
    cell, margin = FAMILIES_CELL_SIZE, FAMILIES_MARGINS
    width = max(FAMILIES_LEAST_WIDTH, cell[0] * cells + margin[0])
    fig = Figure(figsize=(width, cell[1] * len(criteria) + margin[1]), layout="constrained")
    axes = np.atleast_1d(fig.subplots(len(criteria), 1))
    labels = {
        "base": f"{family_label(comparison.base_family)}: {family_words(comparison.base_family)}",
        "rich": f"{family_label(comparison.rich_family)}: {family_words(comparison.rich_family)}",
    }
    for ax, criterion in zip(axes, criteria, strict=True):
        mine = [s for s in comparison.shifts if s.criterion == criterion]
        _panel(ax, mine, labels)
        ax.set_title(FIGURE_NAMES.get(criterion, criterion), fontsize=FONT_HEADING)
    legend = "gait family (error bars: finer grid, tighter tolerance, starts)"
    axes[0].legend(fontsize=FONT_NOTE, loc="best", title=legend, title_fontsize=FONT_NOTE)
    title = [
        "The knees' difference (rolling − revolute) / revolute [%] in two gait families, "
        f"under {comparison.constraints}",
        "Above each cell: hides / invents (the base family hides or invents a pay-off of the "
        "rolling knee: a shift beyond both error bars; 'sign flips': the families disagree "
        "on which knee needs less), = (within both error bars), ? (an error bar not "
        "measured: hollow marker, ±?; 'none': no certified optimum of both knees)",
    ]
    chars = int(TITLE_CHARS_PER_INCH * width)
    fig.suptitle("\n".join(textwrap.fill(t, chars) for t in title), fontsize=FONT_TITLE)
    return fig


def _panel(ax, shifts: list[CellShift], labels: dict) -> None:
    x = np.arange(len(shifts), dtype=float)
    for side, dx in (("base", -OFFSET), ("rich", OFFSET)):
        style = FAMILY_STYLE[side]
        for i, shift in enumerate(shifts):
            found: Side = getattr(shift, side)
            if found.value is None:  # no certified optimum of both knees: said on the axis
                ax.annotate("none", (x[i] + dx, 0.0), xytext=(0, 3), textcoords="offset points",
                            rotation=90, ha="center", va="bottom", fontsize=FONT_SMALL,
                            color=style["color"])  # fmt: skip
                continue
            known = found.uncertainty is not None
            ax.errorbar(
                x[i] + dx,
                found.value,
                yerr=found.uncertainty if known else None,
                capsize=3,
                color=style["color"],
                marker=style["marker"],
                markerfacecolor=style["color"] if known else "white",
                label=labels[side] if i == 0 else None,
            )
            if not known:
                ax.annotate("±?", (x[i] + dx, found.value), xytext=(4, 2),
                            textcoords="offset points", fontsize=FONT_SMALL)  # fmt: skip
    for i, shift in enumerate(shifts):
        text, colour = VERDICT_MARKS[shift.verdict]
        text += "\nsign flips" if shift.sign_change else ""
        ax.annotate(text, (x[i], 1.0), xycoords=("data", "axes fraction"), xytext=(0, -10),
                    textcoords="offset points", ha="center", va="top", fontsize=FONT_NOTE,
                    color=colour)  # fmt: skip
    ax.axhline(0.0, color="0.5", lw=0.6)
    ax.set_xticks(x, [_cell_label(s) for s in shifts], fontsize=FONT_NOTE)
    ax.set_xlim(-0.6, len(shifts) - 0.4)
    ax.margins(y=0.25)
    ax.set_ylabel(
        "rolling vs revolute [%]\n(below 0: the rolling knee needs less)", fontsize=FONT_NOTE
    )
    ax.grid(alpha=0.3, axis="y")


def _cell_label(shift: CellShift) -> str:
    cell = shift.cell
    bend = f"\n{cell.knee_bend:g} rad" if cell.knee_bend else ""
    return f"{cell.speed:g} m/s\n{100 * cell.clearance:g} cm{bend}"


def _percent(side: Side) -> str:
    if side.value is None:
        return "none"
    bar = "unknown" if side.uncertainty is None else f"{side.uncertainty:.2g} %"
    return f"{side.value:+.2f} % ± {bar}"


def _walks(side: Side) -> str:
    return {True: "yes", False: "no", None: "not walked"}[side.walks]


def _where(shift: CellShift) -> str:
    return f"{shift.cell.speed:g} m/s, {100 * shift.cell.clearance:g} cm"


def _name(family) -> str:
    """A family as a sentence's subject: "the paper's spline (K = 1)", "the family n = 7"."""
    return "the paper's spline (K = 1)" if family == 1 else f"the family {family_label(family)}"


def sentence(comparison: FamilyComparison, criterion: str) -> str:
    """What the criterion's cells say, computed from them."""
    counts = comparison.counts(criterion)
    mine = [s for s in comparison.shifts if s.criterion == criterion]
    base = _name(comparison.base_family)
    parts = []
    for kind, words in (("hides", "hides a pay-off of the rolling knee"),
                        ("invents", "invents one")):  # fmt: skip
        found = [s for s in mine if s.verdict == kind]
        if not found:
            parts.append(f"{words} in no cell")
            continue
        largest = max(found, key=lambda s: abs(s.shift))
        parts.append(
            f"{words} in {counts[kind]} (by up to {abs(largest.shift):.2f} percentage points, "
            f"{_where(largest)}: {_percent(largest.base)} against {_percent(largest.rich)})"
        )
    text = (
        f"**{CRITERION_NAMES.get(criterion, criterion)}**: of {counts['cells']} cells, "
        f"{base} {parts[0]}, {parts[1]}; in {counts['same']} the difference moves "
        f"by no more than both error bars; {counts['unknown']} are unknown (an error bar not "
        "measured or no certified optimum)"
    )
    flips = [s for s in mine if s.sign_change]
    if flips:
        text += (
            f"; the families disagree on which knee needs less in {len(flips)} ("
            + ", ".join(_where(s) for s in flips)
            + ")"
        )
    return text + "."


def markdown(comparison: FamilyComparison) -> str:
    """``families.md``: what the comparison says, then every cell."""
    base, rich = comparison.base_family, comparison.rich_family
    lines = [
        "# The atlas in two gait families",
        "",
        f"The knees' difference (rolling − revolute) / revolute per cell, under "
        f"{comparison.constraints}, in {family_words(base)}, {family_label(base)} "
        f"(`{comparison.base}`), and in {family_words(rich)}, {family_label(rich)} "
        f"(`{comparison.rich}`), each with its error bar (finer grid, tighter tolerance, "
        "spread of the starts). A shift beyond the sum of both error bars is told apart: "
        "lower in the rich family, the base family hides a pay-off of the rolling knee; "
        "higher, it invents one. An error bar not measured leaves the cell unknown.",
        "",
    ]
    for criterion in comparison.criteria:
        lines += [f"- {sentence(comparison, criterion)}"]
    lines += [
        "",
        f"| criterion | speed [m/s] | clearance [cm] | {family_label(base)} [%] | "
        f"{family_label(rich)} [%] | shift [points] | verdict | both knees walk "
        f"({family_label(base)} / {family_label(rich)}) |",
        "|---|---|---|---|---|---|---|---|",
    ]
    for s in comparison.shifts:
        shift = "" if s.shift is None else f"{s.shift:+.2f}"
        flip = ", sign changes" if s.sign_change else ""
        labels = (family_label(base), family_label(rich))
        why = "; ".join(
            f"{label}: {w}" for label, w in zip(labels, (s.base.why, s.rich.why), strict=True) if w
        )
        lines.append(
            f"| {s.criterion} | {s.cell.speed:g} | {100 * s.cell.clearance:g} | "
            f"{_percent(s.base)} | {_percent(s.rich)} | {shift} | {s.verdict}{flip}"
            f"{' (' + why + ')' if why and s.verdict == 'unknown' else ''} | "
            f"{_walks(s.base)} / {_walks(s.rich)} |"
        )
    return "\n".join(lines) + "\n"


def write(comparison: FamilyComparison, out) -> list[Path]:
    """``families.json`` and ``families.png`` (both or neither), then ``families.md``, in
    ``out``."""
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    save_with_json(out, NAME, "atlas-families", comparison.to_dict(), figure(comparison))
    page = atomic_write_text(out / f"{NAME}.md", markdown(comparison))
    return [out / f"{NAME}.json", out / f"{NAME}.png", page]
