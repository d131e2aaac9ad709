"""Figures and table of the revolute/rolling comparison, from a sweep's gait files.

Fig. 4: optimal sthenic criterion vs speed (left), energy of the same gaits (middle), the
rolling knee's difference to the revolute knee in % (right).
Figs. 5-7: torques, angles and |Fx| / Fz of the sthenic-optimal gaits at 0.3 m/s.
Fig. 8: optimal energy criterion vs speed (left), sthenic criterion of the same gaits
(middle), the difference in % (right).
comparison.md: our headline numbers beside the paper's.

Every difference between the knees is ``biped.optimization.comparison.relative_change``: (rolling −
revolute) / revolute in %, negative where the rolling knee needs less; every value is the
criterion on the check grid (the gait files' ``costs``). The sthenic criterion is per metre
walked, the energy criterion per step.

A sweep lacking a criterion (or a knee's certified optima of it) gives the figures and rows of
the other criterion only, and says what it leaves out (``compared_criteria``); one with
nothing to compare is refused.

Each figure is built by a function returning a matplotlib ``Figure`` (``sweep_figures``;
``time_figure`` with the panels ``TORQUE_PANELS``, ``ANGLE_PANELS``, ``GROUND_PANELS`` serves
single gaits too); ``make_figures`` writes them as a set, all or none.

No point hides the others: in Figs. 4 and 8 a gait whose optimum is not certified (the solver
did not converge, or the optimum is infeasible) is a grey cross, out of the curves; a value off
the bulk of its panel (beyond ``FENCE`` interquartile ranges outside the quartiles) is a
triangle at the panel's edge with its value written beside it, and the axis spans the bulk.
"""

from __future__ import annotations

import sys
import textwrap
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from matplotlib.figure import Figure

from biped.errors import BipedError
from biped.model.criteria import CRITERIA, CRITERION_UNITS
from biped.model.dynamics import JOINTS
from biped.model.gait import FREE_ANGLES
from biped.model.kinematics import ANGLES, BODY_DIRECTIONS, COORDINATES, KNEES
from biped.model.robot import FOOT_FRICTION
from biped.optimization.comparison import (
    CERTIFIED,
    CHECK_GRID,
    DIFFERENCE,
    SOLVER_GRID,
    relative_change,
)
from biped.pages.style import (
    FONT_CAPTION,
    FONT_NOTE,
    FONT_SMALL,
    FONT_TITLE,
    KNEE_LABELS,
    KNEE_STYLE,
    PAPER_CRITERION_SIZE,
    TIME_PANEL_SIZE,
    save,
)
from biped.records.gait_file import Gait
from biped.runtime.files import atomic_set
from biped.studies.paper_method import spread_lines
from biped.studies.sweep import MANIFEST

# The paper's headline numbers; differences [%] rolling vs revolute (``relative_change``): its
# 17 % less sthenic criterion and 11 % less energy for the rolling knee.
PAPER = {
    "sthenic_difference": -17.0,
    "best_speed": {"revolute": 0.27, "rolling": 0.30},
    "energy_difference": -11.0,
}
DETAIL_SPEED = 0.3  # [m/s] of Figs. 5-7
FLAGGED_COLOR = "0.35"
FLAGGED_MARK = dict(linestyle="none", marker="x", markersize=9, markeredgewidth=2)
# A value is off the bulk of its panel beyond FENCE interquartile ranges below the first
# quartile or above the third (Tukey's "far out"), judged only with MIN_BULK values or more;
# it is drawn at the panel's edge only when the axis spanning it would be more than SQUASH
# times the bulk's span (the bulk squashed), else the axis spans it too.
FENCE = 3.0
MIN_BULK = 5
SQUASH = 3.0
# Room around the bulk, a fraction of its span on each side.
PAD = 0.08
CRITERION_AXES = {
    "sthenic": rf"sthenic criterion $C_\Gamma$ per metre walked [{CRITERION_UNITS['sthenic']}]",
    "energy": rf"energy criterion $C_E$ per step [{CRITERION_UNITS['energy']}]",
}
DIFFERENCE_AXIS = "(rolling − revolute) / revolute [%]"
DIFFERENCE_COLOR = "k"
# Points of a difference panel labelled with their value, at most.
MAX_LABELLED = 15
# The figures of each criterion's optima, in order.
FIGURES = {"sthenic": ("fig4.png", "fig5.png", "fig6.png", "fig7.png"), "energy": ("fig8.png",)}
# Why the other criterion of a criterion's optima looks as it does (a figure's caption and
# comparison.md).
OTHER_NOTES = {
    "energy": (
        "The energy criterion counts only the joints' work |Γ θ̇| and is per step: a torque "
        "where a joint barely turns costs nothing, and short quick steps are cheap. Its optima "
        "take such steps with large hip torques, so their sthenic criterion (every torque "
        "squared, per metre) is many times the sthenic optimum's and jumps from speed to "
        "speed, where the optimum moves between minima of nearly equal energy but unlike "
        "torques: it is not what they minimise."
    ),
}
TIME_AXIS = "normalised time t/T"


def certified(gait: Gait) -> bool:
    """Whether a gait file holds a certified optimum (``biped.optimization.comparison.CERTIFIED``; a
    sweep's files are its final optima): its solver converged and it is feasible on the
    check grid."""
    return gait.feasible and gait.optimizer.status == "converged"


def read_sweep(folder: str | Path) -> tuple[dict, list]:
    """The certified optima as {(knee, criterion): [gait, ...] sorted by speed}, and the
    gaits that are not certified (a list)."""
    folder = Path(folder)
    if not folder.is_dir():
        what = "is a file" if folder.exists() else "does not exist"
        raise BipedError(f"sweep folder {str(folder)!r} {what}: allowed a folder of 'biped sweep'")
    files = sorted(p for p in folder.glob("*.json") if p.name != MANIFEST)
    if not files:
        raise BipedError(f"sweep folder {str(folder)!r} has no gait files: run 'biped sweep'")
    series: dict = {}
    flagged = []
    for path in files:
        gait = Gait.read(path, consistent=True)  # its figures its parameters'
        if certified(gait):
            series.setdefault((gait.knee, gait.criterion), []).append(gait)
        else:
            flagged.append(gait)
    for gaits in series.values():
        gaits.sort(key=lambda g: g.speed)
    return series, flagged


def _curve(series, knee, criterion, cost):
    gaits = series.get((knee, criterion), [])
    return np.array([g.speed for g in gaits]), np.array([g.costs.criterion(cost) for g in gaits])


def off_bulk(values) -> np.ndarray:
    """Which values (bool array) lie off the bulk: beyond ``FENCE`` interquartile ranges
    outside the quartiles; none when fewer than ``MIN_BULK`` values are finite."""
    values = np.asarray(values, dtype=float)
    finite = values[np.isfinite(values)]
    if finite.size < MIN_BULK:
        return np.zeros(values.shape, dtype=bool)
    q1, q3 = np.percentile(finite, [25.0, 75.0])
    spread = FENCE * (q3 - q1)
    return (values < q1 - spread) | (values > q3 + spread)


def bulk_limits(values) -> tuple[float, float]:
    """Axis limits (low, high) with ``PAD``: spanning every value, or only those on the bulk
    (``off_bulk``) where spanning every value would squash it (``SQUASH``)."""
    values = np.asarray(values, dtype=float)
    finite = values[np.isfinite(values)]
    bulk = finite[~off_bulk(finite)]
    if bulk.size == 0:
        return 0.0, 1.0
    low, high = float(bulk.min()), float(bulk.max())
    if np.ptp(finite) <= SQUASH * max(high - low, 1e-12):
        low, high = float(finite.min()), float(finite.max())
    pad = PAD * max(high - low, 0.05 * max(abs(low), abs(high)), 1e-12)
    return low - pad, high + pad


def note(ax, text: str, xy, offset, **style) -> None:
    """``text`` ``offset`` points away from ``xy`` (data units), in 8 pt unless ``style`` says."""
    ax.annotate(
        text, xy=xy, xytext=offset, textcoords="offset points", **{"fontsize": FONT_NOTE, **style}
    )


def _mark_off_scale(ax, x, value, limits, color, text) -> None:
    """A value outside the axis limits: a triangle at the edge, its value beside it."""
    low, high = limits
    above = value > high
    edge = high if above else low
    marker, va = ("^", "top") if above else ("v", "bottom")
    ax.plot([x], [edge], linestyle="none", marker=marker, markersize=9, color=color, clip_on=False)
    box = dict(boxstyle="round,pad=0.2", fc="white", ec=color, alpha=0.85)
    note(ax, text, (x, edge), (0, -16 if above else 16), ha="center", va=va, color=color, bbox=box)


def difference_curve(series, criterion, cost) -> tuple[np.ndarray, np.ndarray]:
    """Speeds [m/s] where both knees have a certified ``criterion`` optimum, and the
    difference of their ``cost`` there [%] (``relative_change``, rolling vs revolute)."""
    values = {
        knee: {
            round(g.speed, 6): g.costs.criterion(cost) for g in series.get((knee, criterion), ())
        }
        for knee in KNEES
    }
    speeds = sorted(set(values["revolute"]) & set(values["rolling"]))
    return np.array(speeds, dtype=float), np.array(
        [relative_change(values["rolling"][v], values["revolute"][v]) for v in speeds],
        dtype=float,
    )


def _difference_panel(ax, series, criterion) -> None:
    """The rolling knee's difference to the revolute knee [%] of the optimal criterion at
    each speed both knees have, with the zero line; values off the bulk at the edge."""
    speeds, percent = difference_curve(series, criterion, criterion)
    limits = bulk_limits(np.append(percent, 0.0))
    outside = (percent < limits[0]) | (percent > limits[1])
    ax.axhline(0.0, color="0.4", linewidth=1.0)
    ax.plot(speeds, np.where(outside, np.nan, percent), color=DIFFERENCE_COLOR, marker="D")
    for x, value, out in zip(speeds, percent, outside, strict=True):
        if out:
            _mark_off_scale(ax, x, value, limits, DIFFERENCE_COLOR, f"{x:.3f} m/s: {value:+.1f} %")
        elif len(speeds) <= MAX_LABELLED:
            note(ax, f"{value:+.1f} %", (x, value), (0, 7), ha="center", fontsize=FONT_SMALL)
    if len(speeds) == 0:
        empty = "no speed where both knees\nhave a certified optimum"
        ax.text(
            0.5, 0.5, empty, ha="center", va="center", transform=ax.transAxes, fontsize=FONT_TITLE
        )
    ax.set_ylim(*limits)
    sign = "below 0: the rolling knee needs less"
    ax.text(0.02, 0.02, sign, transform=ax.transAxes, fontsize=FONT_NOTE, color="0.3")


def criterion_figure(series, criterion, other, title, flagged=()) -> Figure:
    """Fig. 4 or 8: the optimal ``criterion`` against the speed (left), the ``other``
    criterion of the same gaits (middle), both knees, and the rolling knee's difference to
    the revolute knee in the optimal criterion (right); ``flagged``: gaits not certified.
    The caption states the difference's sign, and why the ``other`` panel looks as it does
    where that needs a word (``OTHER_NOTES``)."""
    fig = Figure(figsize=PAPER_CRITERION_SIZE, layout="constrained")
    axes = fig.subplots(1, 3)
    crosses = [g for g in flagged if g.criterion == criterion]
    for ax, cost in zip(axes, (criterion, other), strict=False):
        unit = CRITERION_UNITS[cost]
        gaits = [g for k in KNEES for g in series.get((k, criterion), [])]
        everything = [g.costs.criterion(cost) for g in gaits]
        limits = bulk_limits(everything or [g.costs.criterion(cost) for g in crosses])
        for knee in KNEES:
            v, c = _curve(series, knee, criterion, cost)
            outside = (c < limits[0]) | (c > limits[1])
            ax.plot(v, np.where(outside, np.nan, c), label=KNEE_LABELS[knee], **KNEE_STYLE[knee])
            for x, value in zip(v[outside], c[outside], strict=True):
                text = f"{knee} {x:.3f} m/s:\n{value:.4g} {unit}, off scale"
                _mark_off_scale(ax, x, value, limits, KNEE_STYLE[knee]["color"], text)
        for i, gait in enumerate(crosses):
            x, value = gait.speed, gait.costs.criterion(cost)
            status = gait.optimizer.status
            why = "infeasible" if not gait.feasible else f"solver: {status}"
            label = "not certified" if i == 0 else None
            if limits[0] <= value <= limits[1]:
                ax.plot([x], [value], color=FLAGGED_COLOR, label=label, **FLAGGED_MARK)
                text = f"{gait.knee}: not certified\n({why})"
                note(ax, text, (x, value), (6, 6), color=FLAGGED_COLOR)
            else:
                text = f"{gait.knee} {x:.3f} m/s: {value:.4g} {unit},\nnot certified ({why})"
                _mark_off_scale(ax, x, value, limits, FLAGGED_COLOR, text)
        ax.set_ylim(*limits)
        ax.set_ylabel(CRITERION_AXES[cost])
        ax.legend(fontsize=FONT_NOTE)
    _difference_panel(axes[2], series, criterion)
    axes[2].set_ylabel(DIFFERENCE_AXIS)
    for ax in axes:
        ax.set_xlabel("walking speed [m/s]")
        ax.grid(alpha=0.3)
    axes[0].set_title(f"optimal {criterion} criterion")
    axes[1].set_title(f"{other} criterion of the same gaits")
    axes[2].set_title(f"rolling vs revolute knee, optimal {criterion} criterion")
    fig.suptitle(title)
    caption = [
        f"Right: {DIFFERENCE}, at each speed where both knees have a certified optimum.",
        "Sthenic criterion per metre walked, energy criterion per step.",
    ]
    if criterion in OTHER_NOTES:
        caption.append(f"Middle: {OTHER_NOTES[criterion]}")
    fig.supxlabel("\n".join(_wrap(line) for line in caption), fontsize=FONT_CAPTION, ha="center")
    return fig


def _wrap(text: str, width: int = 170) -> str:
    return "\n".join(textwrap.wrap(text, width, break_on_hyphens=False))


def _bullet(text: str) -> list[str]:
    """A Markdown list item ``text`` ("- ...") in lines of 88 characters at most."""
    return textwrap.wrap(text, 88, subsequent_indent="  ", break_on_hyphens=False)


def _detail_gaits(series):
    gaits = {}
    for knee in KNEES:
        candidates = series.get((knee, "sthenic"), [])
        if not candidates:
            raise BipedError(
                f"no certified sthenic-optimal gait of the {knee} knee in the sweep: "
                "figures need both knees"
            )
        gaits[knee] = min(candidates, key=lambda g: abs(g.speed - DETAIL_SPEED))
    return gaits


@dataclass(frozen=True)
class Panel:
    """One plot of a time figure: its title, y label and the values of a gait on its
    samples (``values(gait)``, shape (N,)); ``decorate(ax, gaits)`` adds what the panel
    needs beyond the curves (limits, reference lines, marks)."""

    title: str
    ylabel: str
    values: Callable[[dict], np.ndarray]
    decorate: Callable | None = None


def joint_label(i: int, joint: str) -> str:
    """'Γ2 stance knee' for the second joint."""
    return f"Γ{i + 1} {joint.replace('_', ' ')}"


def angle_label(angle: str) -> str:
    """'stance shank q1' for q1: the body whose absolute angle it is, and its symbol."""
    return f"{BODY_DIRECTIONS[ANGLES.index(angle)].replace('_', ' ')} {angle}"


def _column(field: str, i: int):
    return lambda gait: getattr(gait.samples, field)[:, i]


def _degrees(k: int):
    return lambda gait: np.degrees(gait.samples.q[:, k])


def friction_needed(gait: Gait) -> np.ndarray:
    """|Fx| / Fz on the samples: the least friction coefficient the stance foot needs."""
    wrench = gait.samples.wrench
    return np.abs(wrench[:, 0]) / wrench[:, 1]


def _friction_marks(ax, gaits) -> None:
    label = f"μ = {FOOT_FRICTION:g}, the model's friction"
    ax.axhline(FOOT_FRICTION, color="k", linestyle="--", linewidth=1.2, label=label)
    top = FOOT_FRICTION
    for row, (knee, gait) in enumerate(gaits.items()):
        ratio = friction_needed(gait)
        i = int(np.argmax(ratio))
        t = gait.samples.t[i] / gait.period
        color = KNEE_STYLE[knee]["color"]
        ax.plot([t], [ratio[i]], marker="o", markersize=8, fillstyle="none", color=color)
        text = f"largest |Fx|/Fz {ratio[i]:.3f}"
        note(ax, text, (t, ratio[i]), (-8, 8 + 12 * row), ha="right", color=color)
        top = max(top, float(ratio[i]))
    ax.set_ylim(0.0, 1.15 * top)
    ax.legend(fontsize=FONT_NOTE, loc="center left")


def _sole_marks(ax, gaits) -> None:
    robot = next(iter(gaits.values())).robot
    for name, x in robot.sole_edges().items():
        ax.axhline(x, color="0.4", linestyle=":", linewidth=1.0)
        note(ax, name, (0.0, x), (2, 2), color="0.4")


TORQUE_PANELS = tuple(
    Panel(joint_label(i, joint), "torque [N·m]", _column("torques", i))
    for i, joint in enumerate(JOINTS)
)
ANGLE_PANELS = tuple(
    Panel(angle_label(angle), "angle from the vertical [°]", _degrees(COORDINATES.index(angle)))
    for angle in FREE_ANGLES
)
GROUND_PANELS = (
    Panel("|Fx| / Fz: friction needed", "ratio [1]", friction_needed, _friction_marks),
    Panel("Fz: normal force", "force [N]", _column("wrench", 1)),
    Panel("x_ZMP from the stance ankle", "position [m]", lambda g: g.samples.zmp, _sole_marks),
)


def time_figure(gaits: dict, title: str, panels, columns: int = 3) -> Figure:
    """One plot per panel over the step's normalised time, a curve per gait.

    Args:
        gaits: {knee: gait file content}, drawn in the knee's colour.
    """
    rows = int(np.ceil(len(panels) / columns))
    fig = Figure(
        figsize=(TIME_PANEL_SIZE[0] * columns, TIME_PANEL_SIZE[1] * rows), layout="constrained"
    )
    axes = np.atleast_1d(fig.subplots(rows, columns)).ravel()
    for ax, panel in zip(axes, panels, strict=False):
        for knee, gait in gaits.items():
            s = gait.samples
            ax.plot(
                s.t / gait.period,
                panel.values(gait),
                color=KNEE_STYLE[knee]["color"],
                label=KNEE_LABELS[knee],
            )
        if panel.decorate is not None:
            panel.decorate(ax, gaits)
        ax.set_title(panel.title)
        ax.set_xlabel(TIME_AXIS)
        ax.set_ylabel(panel.ylabel)
        ax.grid(alpha=0.3)
    if panels and panels[0].decorate is None:
        axes[0].legend(fontsize=FONT_NOTE)
    for ax in axes[len(panels) :]:
        ax.remove()
    speeds = ", ".join(f"{k} {g.speed:.3f} m/s" for k, g in gaits.items())
    fig.suptitle(f"{title} ({speeds})")
    return fig


def compared_criteria(series: dict, flagged=()) -> tuple[tuple[str, ...], list[str]]:
    """The criteria whose figures and rows a sweep can give (certified optima of both knees),
    and a sentence for each criterion left out, saying what the sweep lacks."""
    in_sweep = {g.criterion for gaits in series.values() for g in gaits}
    in_sweep |= {g.criterion for g in flagged}
    compared, missing = [], []
    for criterion in CRITERIA:
        lacking = [knee for knee in KNEES if not series.get((knee, criterion))]
        if criterion not in in_sweep:
            missing.append(
                f"the sweep has no {criterion} optima (`biped sweep --criteria sthenic energy` "
                "makes both)"
            )
        elif lacking:
            knees = " and ".join(f"the {knee} knee" for knee in lacking)
            missing.append(f"the sweep has no certified {criterion} optimum of {knees}")
        else:
            compared.append(criterion)
    return tuple(compared), missing


def left_out_figures(criteria) -> list[str]:
    """The figures of a set that a sweep comparing only ``criteria`` leaves out."""
    return [name for c in CRITERIA if c not in criteria for name in FIGURES[c]]


def left_out_text(criteria) -> str:
    """'fig8.png and the energy rows': what a sweep comparing only ``criteria``
    leaves out."""
    others = [c for c in CRITERIA if c not in criteria]
    return f"{', '.join(left_out_figures(criteria))} and the {' and '.join(others)} rows"


def sweep_figures(series: dict, flagged=(), criteria=CRITERIA) -> dict:
    """Figs. 4-8 of a sweep ({file name: Figure}), those of ``criteria`` only (``FIGURES``);
    ``flagged``: gaits not certified."""
    figures = {}
    if "sthenic" in criteria:
        gaits = _detail_gaits(series)
        title = "Fig. 4: sthenic optimisation"
        figures["fig4.png"] = criterion_figure(series, "sthenic", "energy", title, flagged)
        for number, what, panels in (
            (5, "joint torques", TORQUE_PANELS),
            (6, "absolute angles", ANGLE_PANELS),
            (7, "ground reaction", GROUND_PANELS),
        ):
            title = f"Fig. {number}: {what} of the sthenic-optimal gaits"
            figures[f"fig{number}.png"] = time_figure(gaits, title, panels)
    if "energy" in criteria:
        title = "Fig. 8: energy optimisation"
        figures["fig8.png"] = criterion_figure(series, "energy", "sthenic", title, flagged)
    return figures


def _minimum(series, knee, criterion):
    """(speed [m/s], value) of the knee's least certified ``criterion`` optimum."""
    v, c = _curve(series, knee, criterion, criterion)
    i = int(np.argmin(c))
    return float(v[i]), float(c[i])


def _percent(value: float) -> str:
    """'-0.8 %' (the sign always written)."""
    return f"{value:+.1f} %"


def _pair(revolute: float, rolling: float) -> str:
    """'0.7812 / 0.7781 (-0.4 %)': both knees' values to four digits and their difference,
    which values rounded alike would hide."""
    return f"{revolute:.4g} / {rolling:.4g} ({_percent(relative_change(rolling, revolute))})"


def _over(speeds) -> str:
    """Where a difference of the knees is taken: the mean over the speeds both knees have,
    or the one speed."""
    if len(speeds) == 1:
        return f"at {speeds[0]:.3f} m/s, the one speed both knees have"
    return f"mean over the {len(speeds)} speeds both knees have"


def _grid_place(speed: float, series) -> str:
    """What a least value's speed is on the sweep's grid: its one speed or an end of it
    (where the minimum may lie beyond), else nothing."""
    speeds = sorted({round(g.speed, 6) for gaits in series.values() for g in gaits})
    if len(speeds) == 1:
        return " (the sweep's one speed: no minimum located)"
    if round(speed, 6) in (speeds[0], speeds[-1]):
        return f" (the {'slowest' if round(speed, 6) == speeds[0] else 'fastest'} of the sweep)"
    return ""


def _criterion_rows(series, criterion) -> list[str]:
    """The table's rows of one criterion compared (both knees have certified optima)."""
    unit = CRITERION_UNITS[criterion]
    per = "per metre walked" if criterion == "sthenic" else "per step"
    speed = {knee: _minimum(series, knee, criterion)[0] for knee in KNEES}
    best = {knee: _minimum(series, knee, criterion)[1] for knee in KNEES}
    speeds, differences = difference_curve(series, criterion, criterion)
    mean = _mean_difference(differences)
    paper = _percent(PAPER[f"{criterion}_difference"])
    rows = [
        f"| {criterion} criterion, rolling vs revolute, at each knee's best speed "
        f"| {paper} | {_percent(relative_change(best['rolling'], best['revolute']))} |",
        f"| {criterion} criterion, rolling vs revolute, {_over(speeds)} | | {mean} |",
    ]
    if criterion == "sthenic":
        rows += [
            f"| speed of minimum sthenic criterion, {knee} [m/s] "
            f"| {PAPER['best_speed'][knee]} | {speed[knee]:.3f}{_grid_place(speed[knee], series)} |"
            for knee in KNEES
        ]
    rows.append(
        f"| minimum {criterion} criterion, revolute / rolling (rolling vs revolute) "
        f"[{unit} {per}] | | {_pair(best['revolute'], best['rolling'])} |"
    )
    return rows + _electrical_rows(series, criterion)


def _electrical_rows(series, criterion) -> list[str]:
    """The motors' energy per metre without regeneration (the gait files' actuators) of the
    ``criterion`` optima: at each knee's least one, and rolling vs revolute over the speeds
    both knees have; none when a gait file was written before the actuators."""
    if any(g.costs.electrical is None for k in KNEES for g in series[(k, criterion)]):
        return []
    least = {
        knee: min(series[(knee, criterion)], key=lambda g: g.costs.criterion(criterion))
        for knee in KNEES
    }
    speeds, differences = difference_curve(series, criterion, "electrical")
    unit = CRITERION_UNITS["electrical"]
    electrical = {knee: least[knee].costs.electrical for knee in KNEES}
    return [
        f"| electrical energy per metre, no regeneration, of the least {criterion} optimum, "
        f"revolute / rolling (rolling vs revolute) [{unit}] | | "
        f"{_pair(electrical['revolute'], electrical['rolling'])} |",
        f"| electrical energy per metre of the {criterion} optima, rolling vs revolute, "
        f"{_over(speeds)} | | {_mean_difference(differences)} |",
    ]


def _mean_difference(differences) -> str:
    """The mean of the differences [%] at the speeds both knees have, or why there is none."""
    if not len(differences):
        return "none: no speed where both knees are certified"
    return _percent(float(np.mean(differences)))


def _detail_rows(series) -> tuple[list[str], dict]:
    """Rows on the sthenic optima near ``DETAIL_SPEED`` and the stance knee's largest
    flexion of each [rad]."""
    detail = _detail_gaits(series)
    flexion = {
        knee: float(np.max(g.samples.q[:, 3] - g.samples.q[:, 2])) for knee, g in detail.items()
    }
    rows = [
        f"| largest stance-knee flexion q2 - q1, sthenic optimum near {DETAIL_SPEED} m/s, "
        f"revolute / rolling [rad] | | {flexion['revolute']:.3f} / {flexion['rolling']:.3f} |",
        *(
            f"| period / step length of that gait, {knee} [s / m] | | "
            f"{detail[knee].period:.3f} / {detail[knee].step_length:.3f} |"
            for knee in KNEES
        ),
    ]
    return rows, flexion


def comparison_table(series, flagged=()) -> str:
    """Markdown table of the headline numbers, ours beside the paper's, for the criteria
    the sweep can compare (``compared_criteria``), saying what it leaves out."""
    criteria, missing = compared_criteria(series, flagged)
    safeties = sorted({g.safety for gaits in series.values() for g in gaits}, key=str)
    everything = [g for c in criteria for k in KNEES for g in series[(k, c)]]
    total = len(everything)
    confirmed = sum(g.optimizer.starts_at_best >= 2 for g in everything)
    safety = "; ".join(
        f"swing-foot clearance {s.clearance:g} m, ZMP margin {s.zmp_margin:g} m" for s in safeties
    )
    lines = [
        "# Revolute vs rolling knee: headline numbers",
        "",
        "Generated by `biped figures` from the gait files of `biped sweep`; margins beyond",
        f"the paper's constraints: {safety or '-'} (0 is the paper's problem).",
        "Differences, rolling vs revolute, the paper's numbers too:",
        f"{DIFFERENCE}.",
        "",
    ]
    if missing:
        lines += [f"Left out: {left_out_text(criteria)}: {'; '.join(missing)}.", ""]
    lines += ["| quantity | paper | ours |", "|---|---|---|"]
    for criterion in criteria:
        lines += _criterion_rows(series, criterion)
    flexion = None
    if "sthenic" in criteria:
        rows, flexion = _detail_rows(series)
        lines += rows
    lines += [
        "",
        *(_explanations(flexion, series, criteria) if flexion is not None else []),
        "Conventions behind our numbers (see `biped/model/gait.py`, `biped/model/criteria.py`,",
        "`biped/optimization/comparison.py`):",
        "",
        "- d of eq. (30) is read as the swing foot's travel in one step, twice the step length,",
        "  so C_Γ is per metre walked; C_E of eq. (31) is per step, as printed.",
        *_bullet(
            f"- Every value is the criterion on {CHECK_GRID} (the gait files' `costs`); "
            f"the value on {SOLVER_GRID}, `optimizer.value`, only ranks the starts of an "
            "optimization."
        ),
        "- The speed grid is the sweep's; a minimum between grid points is reported at the",
        "  nearest grid speed.",
        *_bullet(f"- Every value is certified: {CERTIFIED}."),
        f"  {confirmed} of {total} optima were reached by at least two starts (the neighbouring",
        "  speeds' optima among them).",
        "",
    ]
    return "\n".join(lines)


def _explanations(flexion, series, criteria) -> list[str]:
    """Sentences that explain a difference with the paper, each only where the data
    shows it (the sthenic optima of both knees; the energy optima's sthenic criterion
    where ``criteria`` has energy too)."""
    lines = ["Where ours differ from the paper's, what the data shows:", ""]
    straight = max(flexion.values())
    if straight < 0.1:
        lines += [
            f"- The stance knee bends at most {straight:.3f} rad in the sthenic optima near",
            f"  {DETAIL_SPEED} m/s. The two knees differ only when the knee bends (the",
            "  knee-link angle equals the segment angles when it is straight), so the two",
            "  robots walk almost alike.",
        ]
    lines += _slowest_lines(series)
    if len({round(g.speed, 6) for gaits in series.values() for g in gaits}) > 1:
        per_step = {knee: _minimum_per_step(series, knee) for knee in KNEES}
        lines += [
            "- Under the other reading of d in eq. (30), C_Γ per step (∫ΓᵀΓ dt, no 2/d), the",
            f"  minimum is at {per_step['revolute']:.3f} m/s (revolute) and "
            f"{per_step['rolling']:.3f} m/s (rolling).",
        ]
    if "energy" in criteria:
        lines += _bullet(f"- Fig. 8, middle: {OTHER_NOTES['energy']}")
    return [*lines, ""]


def _slowest_lines(series) -> list[str]:
    """Where the sthenic optima are least at the sweep's slowest speed: that it falls all
    the way down to it only where each knee's falls at every step of the grid; nothing from
    one speed, where there is no trend."""
    curves = [_curve(series, knee, "sthenic", "sthenic") for knee in KNEES]
    speeds = sorted({float(v) for v, _ in curves for v in v})
    if len(speeds) < 2 or any(int(np.argmin(c)) != 0 for _, c in curves):
        return []
    if all(len(c) > 1 and np.all(np.diff(c) > 0) for _, c in curves):
        return [
            "- The sthenic criterion per metre falls at every step of the sweep as the speed",
            "  decreases: its minimum is at the slowest speed of the sweep, and may lie below.",
        ]
    return ["- The sthenic criterion per metre is least at the slowest speed of the sweep."]


def _minimum_per_step(series, knee) -> float:
    """[m/s] Speed of the knee's least sthenic criterion per step (certified optima)."""
    best = min(series[(knee, "sthenic")], key=lambda g: g.costs.sthenic * g.step_length)
    return float(best.speed)


def make_figures(sweep_folder: str | Path, out_folder: str | Path, stream=None) -> list[Path]:
    """Write fig4.png ... fig8.png and comparison.md, all or none; returns their paths.

    A sweep lacking a criterion, or a knee's certified optima of it, gives the figures and
    rows of the other criterion only; what is left out is said in comparison.md and in a
    line on ``stream`` (default ``sys.stderr``), and a left-out figure of an earlier set in
    ``out_folder`` is removed, so the folder never mixes two sweeps' figures. A sweep with
    nothing to compare (no criterion with certified optima of both knees) is refused before
    anything is written; the files are written into a staging folder and moved into
    ``out_folder`` only once all are written, so an earlier set there stays whole.
    """
    series, flagged = read_sweep(sweep_folder)
    criteria, missing = compared_criteria(series, flagged)
    if not criteria:
        raise BipedError(
            f"sweep folder {str(sweep_folder)!r} has nothing to compare: {'; '.join(missing)}; "
            "allowed a sweep with certified optima of both knees for at least one criterion"
        )
    figures = sweep_figures(series, flagged, criteria)
    certified_values = {
        key: {round(g.speed, 6): g.costs.criterion(key[1]) for g in gaits}
        for key, gaits in series.items()
    }
    table = "\n".join(
        [comparison_table(series, flagged), *spread_lines(sweep_folder, certified_values)]
    )
    out = Path(out_folder)
    with atomic_set(out, "figures") as staging:
        for name, figure in figures.items():
            save(figure, staging / name)
        (staging / "comparison.md").write_text(table, encoding="utf-8")
    for name in left_out_figures(criteria):  # an earlier set's, of another sweep
        (out / name).unlink(missing_ok=True)
    if missing:
        print(
            f"figures: left out {left_out_text(criteria)} of comparison.md: {'; '.join(missing)}",
            file=sys.stderr if stream is None else stream,
        )
    return [out / name for name in figures] + [out / "comparison.md"]
