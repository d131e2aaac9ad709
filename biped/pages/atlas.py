"""What the atlas says (``biped.studies.atlas``): ``atlas.csv``, a figure per criterion and
``atlas.md``, whose sentences are computed from the numbers.

The figure of a criterion: on the left the map of the difference between the knees over speed
x clearance (one panel per knee bend), blue where the rolling knee needs less, hatched where
the difference is not larger than its uncertainty, a cross where a knee has no certified
optimum, a red frame inside a cell where a knee's gait does not walk in MuJoCo;
on the right the differences against speed, one curve per clearance, with their error bars.
Its title, the CSV's walks and ``atlas.md`` say which problem the atlas answers and what the
walks of its optima say (their records, ``biped.studies.atlas.read_walk``).
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from biped.model.bezier import Bezier
from biped.model.criteria import CRITERION_UNITS
from biped.model.gait import family_words
from biped.model.kinematics import KNEES
from biped.pages.atlas_line import COLUMNS, AtlasLine
from biped.pages.style import (
    ATLAS_CELL_FONT,
    ATLAS_CELL_WIDTH,
    ATLAS_CURVES_WIDTH,
    ATLAS_DPI,
    ATLAS_MAP_AREA,
    ATLAS_MAP_MARGINS,
    FONT_HEADING,
    FONT_NOTE,
    FONT_SMALL,
    FONT_TITLE,
    save,
)
from biped.records.atlas_optimum import AtlasOptimum
from biped.runtime.files import atomic_write_text
from biped.studies.atlas import (
    MEASURES,
    RICHER_KNOTS,
    Cell,
    Difference,
    Point,
    Settings,
    Walk,
    difference,
    load,
    read_walk,
)

CRITERION_NAMES = {
    "sthenic": "sthenic criterion C_Γ (squared torques per metre walked)",
    "energy": "energy criterion C_E (per step)",
    "energy-per-metre": "energy per metre walked C_E / S",
    "electrical": "electrical energy per metre walked E / S (the motors', no regeneration)",
}
# The same in a figure's title, the subscripts as subscripts (mathtext).
FIGURE_NAMES = {
    "sthenic": r"sthenic criterion $C_\Gamma$ (squared torques per metre walked)",
    "energy": r"energy criterion $C_E$ (per step)",
    "energy-per-metre": r"energy per metre walked $C_E\,/\,S$",
    "electrical": r"electrical energy per metre walked $E\,/\,S$ (the motors', no regeneration)",
}
# The maps' colours: blue where the rolling knee needs less.
CMAP = "RdBu_r"
# The curves' speed axis: a tick at each speed for at most this many speeds, else
# matplotlib's; one speed in a span of this much either side of it [m/s].
SPEED_TICKS = 12
ONE_SPEED_SPAN = 0.05
# The mark of a cell whose gait does not walk in MuJoCo (for either knee): a red frame inside
# the cell, around its label, ``NOT_WALKING_INSET`` of a cell from its edges.
NOT_WALKING = {"fill": False, "edgecolor": "#d6001c", "linewidth": 2.2}
NOT_WALKING_INSET = 0.06
NOT_WALKING_LABEL = "red frame: a knee's gait does not walk in MuJoCo"


@dataclass(frozen=True)
class Row:
    """One line of ``atlas.csv``: a cell and criterion, both knees' final optima
    (``AtlasOptimum``, None where missing) and their difference; ``walks``: each knee's walk
    in MuJoCo (``Walk``, None where not walked), None when the atlas was not walked."""

    criterion: str
    cell: Cell
    difference: Difference
    revolute: AtlasOptimum | None
    rolling: AtlasOptimum | None
    walks: dict | None = None

    def walking(self) -> bool:
        """Both knees' gaits walk in MuJoCo."""
        return self.walks is not None and all(
            (w := self.walks.get(k)) is not None and w.walks for k in KNEES
        )

    def not_walking(self) -> bool:
        """A knee's gait walked and does not walk (a walk not measured is neither)."""
        return self.walks is not None and any(
            w is not None and w.walks is False for w in self.walks.values()
        )


def rows(folder, settings: Settings, walked: bool = True) -> list[Row]:
    """The atlas's lines; with each knee's walk (``read_walk``) when it was ``walked``."""
    found = []
    for criterion in settings.criteria:
        for cell in settings.cells():
            diff, finals = difference(folder, settings, criterion, cell)
            walks = None
            if walked:
                walks = {k: read_walk(folder, Point("final", k, criterion, cell)) for k in KNEES}
            found.append(Row(criterion, cell, diff, finals["revolute"], finals["rolling"], walks))
    return found


# The criteria that are an energy per metre walked: their cost of transport is the value over
# the robot's weight m g (dimensionless).
PER_METRE_ENERGIES = ("energy-per-metre", "electrical")


def line(row: Row, weight: float, knots: int | Bezier = 1) -> AtlasLine:
    """The line of ``atlas.csv`` of ``row``; ``weight`` [N] is the robot's, m g, for the cost
    of transport of the per-metre energies; ``knots`` the atlas's gait family (a spline's
    interior knots, or a ``Bezier``). A knee's cost is there only with a difference."""
    d = row.difference
    revolute, rolling = (
        None if r is None or d.value is None else r.costs[row.criterion]
        for r in (row.revolute, row.rolling)
    )

    def transport(cost):
        return None if cost is None or row.criterion not in PER_METRE_ENERGIES else cost / weight

    return AtlasLine(
        speed=row.cell.speed,
        clearance=row.cell.clearance,
        knee_bend=row.cell.knee_bend,
        knots=knots,
        criterion=row.criterion,
        unit=CRITERION_UNITS[row.criterion],
        revolute=revolute,
        rolling=rolling,
        difference=d.value,
        uncertainty=d.uncertainty,
        distinguishable=None if d.value is None else d.distinguishable,
        discretization=d.discretization,
        tolerance=d.tolerance,
        starts_spread=d.starts,
        starts_at_best_revolute=_starts(row.revolute),
        starts_at_best_rolling=_starts(row.rolling),
        richer_difference=d.richer,
        cost_of_transport_revolute=transport(revolute),
        cost_of_transport_rolling=transport(rolling),
        why_empty=why_empty(d),
        walks_revolute=walk_words(row, "revolute"),
        walks_rolling=walk_words(row, "rolling"),
    )


def _starts(final: AtlasOptimum | None) -> int | None:
    """The starts that reached a knee's final optimum (its record's), None without one."""
    return None if final is None else int(final.starts_at_best)


def csv_text(table: list[Row], weight: float, knots: int | Bezier = 1) -> str:
    """``atlas.csv``: its header (``COLUMNS``) and one line per cell and criterion
    (``line``); ``weight`` [N] is the robot's, m g."""
    lines = [",".join(COLUMNS), *(line(row, weight, knots).to_csv() for row in table)]
    return "\n".join(lines) + "\n"


def walk_words(row: Row, knee: str) -> str:
    """What the CSV says of a knee's walk: "yes", "no: " and why, "not walked" (no
    certified optimum, or the atlas not walked), "not measured: " and why."""
    walk = None if row.walks is None else row.walks.get(knee)
    if walk is None:
        return "not walked"
    if walk.walks is None:
        return walk.causes()
    return "yes" if walk.walks else f"no: {walk.causes()}"


def why_empty(d: Difference) -> str:
    """Why a line's empty numbers are: no difference (a knee not certified), or each re-solve
    of the cell that measured nothing (an unknown term leaves the uncertainty empty)."""
    if d.why:
        return d.why
    return "; ".join(f"{what} not measured ({why})" for what, why in d.unmeasured)


def figure(settings: Settings, table: list[Row], criterion: str, walked: bool = False):
    """The figure of one criterion (matplotlib ``Figure``), as the module says; ``walked``:
    the atlas's optima were walked in MuJoCo (the rows' ``walks``)."""
    from matplotlib.figure import Figure

    bends = settings.knee_bends
    width, height = _map_area(settings)
    fig = Figure(
        figsize=(
            (width + ATLAS_MAP_MARGINS[0]) * len(bends) + ATLAS_CURVES_WIDTH,
            height + ATLAS_MAP_MARGINS[1],
        ),
        layout="constrained",
    )
    axes = fig.subplots(1, len(bends) + 1, squeeze=False)[0]
    mine = [r for r in table if r.criterion == criterion]
    values = [r.difference.value for r in mine if r.difference.value is not None]
    top = max([abs(v) for v in values], default=1.0) or 1.0
    for ax, bend in zip(axes[:-1], bends, strict=True):
        _map_panel(fig, ax, settings, [r for r in mine if r.cell.knee_bend == bend], top)
        ax.set_title(
            f"{_bend_words(bend)}\ncells: difference ± uncertainty [%]", fontsize=FONT_TITLE
        )
        if walked:
            _walks_legend(ax, any(r.not_walking() for r in mine if r.cell.knee_bend == bend))
    _curves_panel(axes[-1], settings, [r for r in mine if r.cell.knee_bend == bends[0]])
    walks = (
        "walked in MuJoCo: a red frame where a knee's gait does not walk"
        if walked
        else "not walked in MuJoCo (--no-walks)"
    )
    fig.suptitle(
        f"{FIGURE_NAMES[criterion]} [{CRITERION_UNITS[criterion]}]: "
        "(rolling − revolute) / revolute knee\n"
        f"under {settings.constraints_words()}\n"
        "blue: the rolling knee needs less; hatched: not distinguishable (±?: uncertainty not "
        f"measured); x: no certified optimum of both knees\n{walks}",
        fontsize=FONT_HEADING,
    )
    return fig


def _walks_legend(ax, marked: bool) -> None:
    """The legend of the cells whose gait does not walk, under the map."""
    from matplotlib.patches import Patch

    label = NOT_WALKING_LABEL + ("" if marked else ": none")
    handle = Patch(label=label, **NOT_WALKING)
    ax.legend(
        handles=[handle],
        fontsize=FONT_NOTE,
        loc="upper center",
        bbox_to_anchor=(0.5, -0.16),
        ncols=1,
    )


def _map_panel(fig, ax, settings: Settings, rows_: list[Row], top: float) -> None:
    """The map of one knee bend's differences over speed x clearance, colours from -top to
    top [%], each cell labelled (``_cell_label``)."""
    speeds, clearances = list(settings.speeds), list(settings.clearances)
    grid = np.full((len(clearances), len(speeds)), np.nan)
    for r in rows_:
        if r.difference.value is not None:
            grid[clearances.index(r.cell.clearance), speeds.index(r.cell.speed)] = (
                r.difference.value
            )
    image = ax.imshow(
        grid,
        origin="lower",
        cmap=CMAP,
        vmin=-top,
        vmax=top,
        aspect="auto",
        extent=(-0.5, len(speeds) - 0.5, -0.5, len(clearances) - 0.5),
    )
    font = cell_font(settings)
    for r in rows_:
        at = (speeds.index(r.cell.speed), clearances.index(r.cell.clearance))
        _cell_label(ax, at, r.difference, top, font)
        if r.not_walking():
            _not_walking_frame(ax, at)
    ax.set_xticks(range(len(speeds)), [f"{s:g}" for s in speeds])
    ax.set_yticks(range(len(clearances)), [f"{100 * c:g}" for c in clearances])
    ax.set_xlabel("speed [m/s]")
    ax.set_ylabel("swing-foot clearance [cm]")
    fig.colorbar(image, ax=ax, label="rolling vs revolute [%]")


def _not_walking_frame(ax, at: tuple[int, int]) -> None:
    """The red frame of the cell ``at`` (speed, clearance indices): a gait does not walk; a
    white rim around it keeps it seen on the darkest red cells."""
    from matplotlib import patheffects
    from matplotlib.patches import Rectangle

    corner = (at[0] - 0.5 + NOT_WALKING_INSET, at[1] - 0.5 + NOT_WALKING_INSET)
    side = 1.0 - 2 * NOT_WALKING_INSET
    rim = [patheffects.withStroke(linewidth=2 * NOT_WALKING["linewidth"], foreground="white")]
    frame = Rectangle(corner, side, side, gid="not walking", zorder=2.5, **NOT_WALKING)
    frame.set_path_effects(rim)
    ax.add_patch(frame)


def _map_area(settings: Settings) -> tuple[float, float]:
    """[in] (width, height) of a map panel's plot area: ``ATLAS_MAP_AREA``, wider for many speeds
    (``ATLAS_CELL_WIDTH`` each)."""
    return max(ATLAS_MAP_AREA[0], ATLAS_CELL_WIDTH * len(settings.speeds)), ATLAS_MAP_AREA[1]


def cell_font(settings: Settings) -> float:
    """[pt] The font of a map cell's two lines of label: as large as the cell holds (about
    4 characters wide, 2.5 lines high), within ``ATLAS_CELL_FONT``."""
    width, height = _map_area(settings)
    cell = (72 * width / len(settings.speeds), 72 * height / len(settings.clearances))
    return float(np.clip(min(cell[0] / 3.6, cell[1] / 3.0), *ATLAS_CELL_FONT))


def _cell_label(ax, at: tuple[int, int], d: Difference, top: float, font: float) -> None:
    """A cell's difference ± uncertainty (white on the darkest cells; ±? where it is not
    measured), hatched when not distinguishable, the label on the cell's own colour over
    the hatching; a cross where a knee has no certified optimum."""
    from matplotlib import colormaps
    from matplotlib.patches import Rectangle

    x, y = at
    if d.value is None:
        ax.plot(x, y, "kx", markersize=10)
        return
    dark = abs(d.value) > 0.6 * top
    spread = "?" if d.uncertainty is None else f"{d.uncertainty:.1f}"
    ax.text(
        x,
        y,
        f"{d.value:+.1f}\n±{spread}",
        ha="center",
        va="center",
        fontsize=font,
        color="white" if dark else "black",
        bbox=dict(boxstyle="square,pad=0.15", lw=0, fc=colormaps[CMAP](0.5 + d.value / top / 2)),
    )
    if not d.distinguishable:
        ax.add_patch(Rectangle((x - 0.5, y - 0.5), 1, 1, fill=False, hatch="//", lw=0, ec="0.55"))


def _curves_panel(ax, settings: Settings, rows_: list[Row]) -> None:
    """The differences over speed, one curve per clearance, with their error bars; an open
    marker without a bar where the uncertainty is not measured; the legend beside the plot."""
    unknown = False
    for k, clearance in enumerate(settings.clearances):
        picked = [
            r for r in rows_ if r.cell.clearance == clearance and r.difference.value is not None
        ]
        if not picked:
            continue
        ax.plot([r.cell.speed for r in picked], [r.difference.value for r in picked], color=f"C{k}")
        ax.plot([], [], "o-", color=f"C{k}", label=f"clearance {100 * clearance:g} cm")
        measured = [r for r in picked if r.difference.uncertainty is not None]
        ax.errorbar(
            [r.cell.speed for r in measured],
            [r.difference.value for r in measured],
            yerr=[r.difference.uncertainty for r in measured],
            fmt="o",
            capsize=3,
            color=f"C{k}",
        )
        blind = [r for r in picked if r.difference.uncertainty is None]
        unknown = unknown or bool(blind)
        ax.plot(
            [r.cell.speed for r in blind],
            [r.difference.value for r in blind],
            "o",
            color=f"C{k}",
            fillstyle="none",
        )
    if unknown:
        ax.plot([], [], "o", color="0.4", fillstyle="none", label="uncertainty not measured")
    ax.axhline(0.0, color="k", lw=0.8)
    _speed_axis(ax, settings.speeds)
    ax.set_xlabel("speed [m/s]")
    ax.set_ylabel("(rolling − revolute) / revolute [%]")
    ax.set_title(
        f"{_bend_words(settings.knee_bends[0])}\nbars: uncertainty [%]", fontsize=FONT_TITLE
    )
    ax.legend(fontsize=FONT_SMALL, loc="upper left", bbox_to_anchor=(1.01, 1.0))  # off the curves


def _speed_axis(ax, speeds) -> None:
    """A tick at each speed, unless there are more than ``SPEED_TICKS`` or two lie closer
    than a ``SPEED_TICKS``-th of the span (then matplotlib's); one speed in a span of
    ``ONE_SPEED_SPAN`` either side."""
    speeds = sorted(speeds)
    span = speeds[-1] - speeds[0]
    if len(speeds) == 1:
        ax.set_xlim(speeds[0] - ONE_SPEED_SPAN, speeds[0] + ONE_SPEED_SPAN)
    gaps = np.diff(speeds)
    if len(speeds) <= SPEED_TICKS and (len(speeds) == 1 or gaps.min() >= span / SPEED_TICKS):
        ax.set_xticks(speeds, [f"{s:g}" for s in speeds])


def _bend_words(bend: float) -> str:
    """A panel's knee bend, in words."""
    if bend == 0.0:
        return "stance knee not inverted (the paper's)"
    return f"stance knee bent {bend:g} rad at least"


def sentences(settings: Settings, table: list[Row], walked: bool = False) -> str:
    """``atlas.md``: what the numbers say, criterion by criterion, computed from them;
    ``walked``: the atlas's optima were walked in MuJoCo (the rows' ``walks``)."""
    lines = ["# Where the rolling knee pays off", ""]
    clearances = [100 * c for c in settings.clearances]
    bends = settings.knee_bends
    lines.append(
        f"Optimal gaits of both knees (Table 1 robot unless the record says otherwise), "
        f"{family_words(settings.knots)}, under {settings.constraints_words()}, over "
        f"{_count(len(settings.speeds), 'speed')} ({_span(settings.speeds, 'm/s')}), "
        f"{_count(len(clearances), 'swing-foot clearance')} ({_span(clearances, 'cm')}) and "
        + ("a least stance-knee bend" if len(bends) == 1 else "least stance-knee bends")
        + f" of {_span(bends, 'rad')}. Each difference is "
        "(rolling − revolute) / revolute on the check grid, with its uncertainty: the finer "
        "grid's change, the tighter tolerance's and the spread of the starts; a difference "
        "no larger than it is not distinguishable."
    )
    for criterion in settings.criteria:
        lines += ["", f"## {CRITERION_NAMES[criterion]} [{CRITERION_UNITS[criterion]}]", ""]
        mine = [r for r in table if r.criterion == criterion]
        lines += _criterion_sentences(mine)
        lines += _walking_sentences(mine) if walked else []
        lines += _richer_sentences(mine)
    lines += ["", "## Do the optima walk?", ""]
    if not walked:
        lines.append(
            "Not walked: the atlas was written without walking its optima in MuJoCo "
            "(`biped atlas --no-walks`); `biped validate GAIT.json` walks any of its gait files."
        )
    else:
        lines += _walks_sentences(settings, table)
    return "\n".join(lines) + "\n"


def _walking_sentences(mine: list[Row]) -> list[str]:
    """The pay-off among walking gaits: the best difference among the cells where both
    knees' gaits walk in MuJoCo, beside the one over all certified cells (the line before)."""
    done = [r for r in mine if r.difference.value is not None]
    if not done:  # the line before says so
        return []
    walking = [r for r in done if r.walking()]
    cells = f"the {_count(len(done), 'certified cell')}"
    among = f"{len(walking)} of {cells}"
    if not walking:
        return [f"- Among walking gaits: both knees' gaits walk in MuJoCo in none of {cells}."]
    less = [r for r in walking if r.difference.distinguishable and r.difference.value < 0]
    if not less:
        return [
            f"- Among walking gaits (both knees' gaits walk in MuJoCo in {among}), the rolling "
            "knee needs distinguishably less in none."
        ]
    best = min(less, key=lambda r: r.difference.value)
    return [
        f"- Among walking gaits (both knees' gaits walk in MuJoCo in {among}), the rolling "
        f"knee needs less in {len(less)}, by {-best.difference.value:.2f} ± "
        f"{best.difference.uncertainty:.2f} % at most ({_where(best)})."
    ]


def _walks_sentences(settings: Settings, table: list[Row]) -> list[str]:
    """How many certified optima walk in MuJoCo, of how many, which checks ran where, and
    each cell whose gait does not walk (or whose walk was not measured), with why."""
    walks = [w for r in table for w in (r.walks or {}).values() if w is not None]
    walking = sum(bool(w.walks) for w in walks)
    full = sum(w.every_check for w in walks)
    optima = "optimum" if len(walks) == 1 else "optima"
    steps = sorted({w.steps for w in walks if w.steps is not None})
    lines = [
        f"Of the {len(walks)} certified {optima} walked in MuJoCo, {walking} walk: every check "
        "run on them passes (an orbit only 'undecided' is not a walk). Each was walked "
        f"{' or '.join(map(str, steps)) or 'its'} steps with contact and replayed with its own "
        f"torques (the forward and feedforward checks); {full} of them, at the corners of "
        "speed x clearance and at each criterion's best pay-off, with every check of `biped "
        "validate` (gains and orbit included). `atlas.csv` gives each knee's verdict, `walks/` "
        "each walk's record.",
        "",
    ]
    for criterion in settings.criteria:
        mine = [r for r in table if r.criterion == criterion]
        bad = [r for r in mine if r.not_walking() or _unmeasured_walk(r)]
        count = sum(bool(w.walks) for r in mine for w in (r.walks or {}).values() if w)
        of = sum(w is not None for r in mine for w in (r.walks or {}).values())
        line = f"- {CRITERION_NAMES[criterion]}: {count} of {of} walk"
        lines.append(
            line + (f"; {_count(len(bad), 'cell')} where a gait does not:" if bad else ".")
        )
        lines += [f"  - {_where(r)}: {_walk_causes(r)}" for r in bad]
    return lines


def _unmeasured_walk(row: Row) -> bool:
    return any(w is not None and w.walks is None for w in (row.walks or {}).values())


def _walk_causes(row: Row) -> str:
    """Each knee's walk of a cell that does not walk: its causes, or that it walks."""
    words = []
    for knee in KNEES:
        walk: Walk | None = (row.walks or {}).get(knee)
        if walk is None:
            words.append(f"{knee} not walked")
        elif walk.walks:
            words.append(f"{knee} walks")
        elif walk.walks is None:
            words.append(f"{knee} {walk.causes()}")
        else:
            words.append(f"{knee} does not walk: {walk.causes()}")
    return "; ".join(words)


def _count(count: int, noun: str) -> str:
    """ "1 cell", "2 cells"."""
    return f"{count} {noun}{'' if count == 1 else 's'}"


def _span(values, unit: str) -> str:
    """Values with their unit: "0.2 m/s", "0 and 3 cm", "0.2-1 m/s" for more than three."""
    words = [f"{v:g}" for v in values]
    if len(words) > 3:
        return f"{words[0]}-{words[-1]} {unit}"
    if len(words) > 1:
        return f"{', '.join(words[:-1])} and {words[-1]} {unit}"
    return f"{words[0]} {unit}"


def _listed(items: list, describe, most: int = 6) -> str:
    """The first ``most`` items, ``describe(item)`` each, "; " between, "..." for the rest."""
    return "; ".join(map(describe, items[:most])) + (" ..." if len(items) > most else "")


def _where(row: Row) -> str:
    cell = row.cell
    bend = f", knee bent {cell.knee_bend:g} rad" if cell.knee_bend else ""
    return f"{cell.speed:g} m/s, clearance {100 * cell.clearance:g} cm{bend}"


def _criterion_sentences(mine: list[Row]) -> list[str]:
    """Where the rolling knee needs less, more, where the knees cannot be told apart, where
    that is not known, and the empty cells, each with why."""
    done = [r for r in mine if r.difference.value is not None]
    if not done:
        return ["No cell has certified optima of both knees."]
    lines = []
    less = [r for r in done if r.difference.distinguishable and r.difference.value < 0]
    more = [r for r in done if r.difference.distinguishable and r.difference.value > 0]
    unknown = [r for r in done if r.difference.uncertainty is None]
    blind = [r for r in done if not r.difference.distinguishable and r not in unknown]
    if less:
        best = min(less, key=lambda r: r.difference.value)
        lines.append(
            f"- The rolling knee needs less in {len(less)} of {_count(len(done), 'cell')}, by "
            f"{-best.difference.value:.2f} ± {best.difference.uncertainty:.2f} % at most "
            f"({_where(best)})."
        )
    else:
        lines.append(
            f"- The rolling knee needs distinguishably less in none of {_count(len(done), 'cell')}."
        )
    if more:
        worst = max(more, key=lambda r: r.difference.value)
        lines.append(
            f"- It needs more in {_count(len(more), 'cell')}, by {worst.difference.value:.2f} ± "
            f"{worst.difference.uncertainty:.2f} % at most ({_where(worst)})."
        )
    if blind:
        lines.append(
            f"- The knees cannot be told apart in {_count(len(blind), 'cell')} (the difference "
            f"no larger than its uncertainty): {_listed(blind, _where)}."
        )
    if unknown:
        lines.append(
            f"- {_count(len(unknown), 'cell')} not distinguishable until "
            + ("its" if len(unknown) == 1 else "their")
            + " uncertainty is measured: "
            + _listed(unknown, lambda r: f"{_where(r)} ({_uncertainty_unmeasured(r)})")
            + "."
        )
    empty = [r for r in mine if r.difference.value is None]
    if empty:
        lines.append(
            f"- {_count(len(empty), 'cell')} "
            + ("has" if len(empty) == 1 else "have")
            + " no certified optimum of both knees: "
            + _listed(empty, lambda r: f"{_where(r)} ({r.difference.why})")
            + "."
        )
    return lines


def _richer_sentences(mine: list[Row]) -> list[str]:
    """How far the difference moves with the richer gait at the corner cells (its value with
    ``RICHER_KNOTS`` knots less the paper's spline's), and where it is not measured, why."""
    lines, words = [], f"the richer gait ({RICHER_KNOTS} interior knots)"
    moved = [r for r in mine if r.difference.value is not None and r.difference.richer is not None]
    if moved:
        moves = [r.difference.richer - r.difference.value for r in moved]
        span = f"{moves[0]:+.2f}" if len(moves) == 1 else f"{min(moves):+.2f} to {max(moves):+.2f}"
        lines.append(
            f"- With {words} at {_count(len(moved), 'corner cell')} ({_listed(moved, _where)}) "
            f"the difference moves by {span} percentage points (its value with {RICHER_KNOTS} "
            "knots less the paper's spline's)."
        )
    richer = MEASURES["richer"]
    missing = [(r, why) for r in mine for what, why in r.difference.unmeasured if what == richer]
    if missing:
        lines.append(
            f"- With {words} the difference is not measured at "
            f"{_count(len(missing), 'corner cell')}: "
            + _listed(missing, lambda found: f"{_where(found[0])} ({found[1]})")
            + "."
        )
    return lines


def _uncertainty_unmeasured(row: Row) -> str:
    """Which terms of a row's uncertainty are not measured, and why."""
    richer = MEASURES["richer"]
    found = [(what, why) for what, why in row.difference.unmeasured if what != richer]
    return "; ".join(f"{what} not measured: {why}" for what, why in found)


def write(folder, out=None, walked: bool = True) -> list[Path]:
    """``atlas.csv``, ``atlas-<criterion>.png`` and ``atlas.md`` of the atlas in ``folder``, in
    ``out`` (default the folder); ``walked``: its optima were walked in MuJoCo (their records
    read), else the pages say they were not (``--no-walks``)."""
    settings = load(folder)
    out = Path(folder if out is None else out)
    out.mkdir(parents=True, exist_ok=True)
    table = rows(folder, settings, walked)
    text = csv_text(table, settings.robot.weight, settings.knots)
    written = [atomic_write_text(out / "atlas.csv", text)]
    for criterion in settings.criteria:
        path = out / f"atlas-{criterion}.png"
        written.append(save(figure(settings, table, criterion, walked), path, ATLAS_DPI))
    written.append(atomic_write_text(out / "atlas.md", sentences(settings, table, walked)))
    return written
