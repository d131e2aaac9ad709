"""The page of one gait: Markdown with its figures, for a designer to read before the JSON.

    <out>/<name>.md                  the page
    <out>/<name>/torques.png         joint torques over the step, one panel per joint
    <out>/<name>/angles.png          absolute angles [°], one panel per body
    <out>/<name>/ground.png          |Fx| / Fz against the model's friction, Fz, the ZMP
    <out>/<name>/constraints.png     Ψ1..Ψ7 over the step, the tightest sample of each marked
    <out>/<name>/orbit.png           the validation's Floquet multipliers (with a report)
    <out>/<name>/walk_torques.png    MuJoCo's joint torques over one step beside the model's
                                     (with a report: ``biped.pages.walk_figures``)

A two-phase gait's page (``biped optimize --double-support``) is ``biped.pages.two_phase_page``'s
with the figures of ``biped.pages.two_phase_figures`` instead.

The page gives the gait's parameters by name with their units, its criteria, the tightest
margin of each constraint (which sample of the step, and how far above the solver's margin δ),
where a constraint dips below δ between the solver's samples (an inset on its panel), the
jumps of the torques and ground reaction at the mid-step knot (marked on their panels), the
ligament load each knee needs (the rolling knee's surfaces carry no tension), the verdict,
causes and figures of its validation in MuJoCo when a report is given with MuJoCo's walk beside
the model's (torques per joint, ground force, energy per step), and links to the recording and the
video. ``write_pages`` writes pages as a set, all or none (``biped.runtime.files.atomic_set``).
The constraints are computed again from the gait's parameters on the grid the optimiser checks
feasibility on (``CHECK_SAMPLES``).
"""

from __future__ import annotations

import dataclasses
import functools
import os
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from matplotlib.figure import Figure
from matplotlib.ticker import FuncFormatter

from biped.model.actuators import Actuators
from biped.model.criteria import CONSTRAINTS, evaluate_step, margin_profile
from biped.model.dynamics import JOINTS
from biped.model.gait import breakpoints, build_step, parameter_names, piece_grid, pieces
from biped.model.units import CONSTRAINT_UNITS, parameter_unit, unit_text
from biped.optimization.comparison import GAINS, RADII
from biped.optimization.problem import CHECK_SAMPLES, SOLVER_SAMPLES
from biped.pages.figures import (
    ANGLE_PANELS,
    GROUND_PANELS,
    TORQUE_PANELS,
    Panel,
    certified,
    joint_label,
    note,
    time_figure,
)
from biped.pages.orbit_figures import multipliers_figure
from biped.pages.profile_figures import PROFILE_FIGURE, profile_figure
from biped.pages.style import FONT_NOTE, FONT_SMALL, FONT_TINY, KNEE_STYLE, save
from biped.pages.two_phase_figures import two_phase_figures
from biped.pages.walk_figures import TORQUES_FIGURE, has_profiles, torques_figure
from biped.pages.walk_figures import walk_lines as mujoco_walk_lines
from biped.records.gait_file import Gait
from biped.records.validation_report import ValidationReport
from biped.runtime.files import atomic_set

# What each constraint of eq. (28) keeps.
CONSTRAINT_MEANING = {
    "normal_force": "Ψ1 normal force Fz",
    "zmp_heel": "Ψ2 ZMP ahead of the heel",
    "zmp_toe": "Ψ3 ZMP behind the toe",
    "stance_knee": "Ψ4 stance knee flexion q2 − q1",
    "swing_knee": "Ψ5 swing knee flexion q3 − q4",
    "swing_heel": "Ψ6 swing heel height",
    "swing_toe": "Ψ7 swing toe height",
}
FIGURE_NAMES = ("torques.png", "angles.png", "ground.png", "constraints.png")
# The validation's orbit check drawn: its multipliers in the complex plane.
ORBIT_FIGURE = "orbit.png"
# What a check's table of figures leaves out: its verdict, notes and causes (said above and
# below it), the torques over one step (drawn: ``TORQUES_FIGURE``).
NOT_TABLED = (
    "passed",
    "notes",
    "causes",
    "profile_phase",
    "gait_torque_profile",
    "mujoco_torque_profile",
    "rotor_torque_profile",
    "servo_torque_profile",
)
# A constraint dips below δ_i where Ψ_i < δ_i (1 − DIP_TOLERANCE): IPOPT holds its
# constraints to about 1e-9 (the gait file's optimizer.constraint_violation), a millionth of δ.
DIP_TOLERANCE = 1e-6
# Mid-step, where the two spline pieces of eqs. (25)-(26) meet [t/T]: a knot of every family
# (1, 3, 5 interior knots), where the jumps are measured.
KNOT = 0.5
KNOTS_WHY = (
    "the spline is C¹ at each knot, so the accelerations jump there, and the torques and the "
    "ground reaction with them"
)
KNOT_WHY = (
    "the spline is C¹ at mid-step (eqs. 25-26, the paper's choice), so the accelerations "
    "jump there, and the torques and the ground reaction with them"
)


@dataclass(frozen=True)
class Tightest:
    """The tightest sample of one constraint relative to its margin: Ψ_i [unit] there, at
    t/T, and δ_i there, the margin the solver keeps from it
    (``biped.model.criteria.margin_profile``: constant, but ramping from 0 at the ends of the
    step for the swing foot)."""

    name: str
    value: float
    unit: str
    at: float
    margin: float

    @property
    def ratio(self) -> float:
        """Ψ_i / δ_i: about 1 where the constraint binds the optimum."""  # δ_i > 0: Ψ_i checked
        return self.value / self.margin


@functools.lru_cache(maxsize=8)  # a page's table, captions and figures all read it
def constraint_profile(gait: Gait, samples_per_half: int | None = None) -> tuple:
    """On the optimiser's check grid (or ``samples_per_half`` samples per piece): the
    step's normalised times t/T (N,), Ψ1..Ψ7 (N, 7) less the gait's safety margins (NaN
    where a constraint is not checked: the swing foot at the ends) and the solver's margins
    δ (N, 7); read-only, computed once per gait record and grid."""
    samples = CHECK_SAMPLES[gait.knots] if samples_per_half is None else samples_per_half
    step = build_step(gait.biped, gait.speed, gait.parameter_vector, gait.knots)
    evaluation = evaluate_step(gait.biped, step, samples, safety=gait.safety)
    arrays = (
        np.concatenate(piece_grid(samples, gait.knots)),
        evaluation.constraints,
        margin_profile(samples, gait.knots),
    )
    for array in arrays:
        array.setflags(write=False)
    return arrays


@dataclass(frozen=True)
class Dip(Tightest):
    """A constraint below the solver's margin on the check grid, at its smallest Ψ_i − δ_i
    there (Ψ_i, t/T and δ_i of that sample); and ``kept``: whether the solver's own samples
    (``SOLVER_SAMPLES_PER_HALF`` per piece) all hold Ψ_i >= δ_i, so that the dip lies between
    them."""

    kept: bool


def _below(psi: np.ndarray, delta: np.ndarray) -> np.ndarray:
    """Where Ψ < δ beyond ``DIP_TOLERANCE`` (False where Ψ is not checked)."""
    with np.errstate(invalid="ignore"):
        return (delta > 0) & (psi < delta * (1.0 - DIP_TOLERANCE))


def margin_dips(gait: Gait) -> list[Dip]:
    """The constraints that dip below the solver's margin δ on the check grid, each at its
    deepest sample (smallest Ψ_i − δ_i), in ``CONSTRAINTS`` order."""
    t_n, psi, delta = constraint_profile(gait)
    _, psi_solver, delta_solver = constraint_profile(gait, SOLVER_SAMPLES[gait.knots])
    dips = []
    for i, name in enumerate(CONSTRAINTS):
        below = _below(psi[:, i], delta[:, i])
        if not below.any():
            continue
        k = int(np.argmin(np.where(below, psi[:, i] - delta[:, i], np.inf)))
        kept = not _below(psi_solver[:, i], delta_solver[:, i]).any()
        unit = CONSTRAINT_UNITS[name]
        dips.append(Dip(name, float(psi[k, i]), unit, float(t_n[k]), float(delta[k, i]), kept))
    return dips


def _milli(value: float, unit: str) -> str:
    """'0.883 mrad' for 8.83e-4 rad: the constraints' small lengths and angles in milli-units."""
    if unit in ("m", "rad"):
        return f"{value * 1e3:.3g} m{unit}"
    return f"{value:.3g} {unit}"


def dip_sentence(gait: Gait, dips: list[Dip]) -> str:
    """Why Ψ_i reads below δ_i on the page, from the gait's dips ('' if none)."""
    if not dips:
        return ""
    each = ", ".join(
        f"{CONSTRAINT_MEANING[d.name].split()[0]} to {_milli(d.value, d.unit)} at t/T = "
        f"{d.at:.3f} (δ = {_milli(d.margin, d.unit)})"
        for d in dips
    )
    if gait.optimizer.method != "ipopt":
        why = (
            "the paper's method keeps the margins through its penalty only, not as bounds "
            "at samples"
        )
    elif all(d.kept for d in dips):
        why = (
            f"each between the solver's samples: the solver holds Ψ ≥ δ at its "
            f"{SOLVER_SAMPLES[gait.knots] + 1} samples per piece only (dots in the insets)"
        )
    else:
        kept = [CONSTRAINT_MEANING[d.name].split()[0] for d in dips if not d.kept]
        why = f"{', '.join(kept)} at the solver's own samples too: the solver did not hold δ"
    verdict = (
        "Ψ ≥ 0 holds on every sample of the check grid: the gait is feasible"
        if gait.feasible
        else "the gait is not feasible on the check grid"
    )
    return (
        f"Below the solver's margin δ on the check grid ({CHECK_SAMPLES[gait.knots] + 1} samples "
        f"per piece): {each}; {why}. {verdict}."
    )


def knot_times(gait: Gait) -> list[float]:
    """The interior knots of the gait's family [t/T] (``biped.model.gait.breakpoints``)."""
    return [float(t) for t in breakpoints(gait.knots)[1:-1]]


def _knots_text(gait: Gait) -> str:
    """'the knot t/T = 0.5' or 'the knots t/T = 0.25, 0.5, 0.75'."""
    times = knot_times(gait)
    shown = ", ".join(f"{t:.3g}" for t in times)
    return f"the knot{'s' if len(times) > 1 else ''} t/T = {shown}"


def _jumps_text(gait: Gait, why: str = "") -> str:
    """Where a figure's curves jump: ", jumping at the knot t/T = 0.5{why}", or for a family
    without a knot (a Bézier curve: its accelerations continuous) that they do not."""
    if not knot_times(gait):
        return f" ({gait.knots}: no knot, no jump)"
    return f", jumping at {_knots_text(gait)}{why}"


def _jump_place(gait: Gait) -> str:
    """Where the caption says the jumps are, up to the largest's value."""
    if gait.knots == 1:
        return f"t/T = {KNOT:g} (dash-dotted line; the largest jump "
    return f"{_knots_text(gait)} (dash-dotted lines; the largest jump at t/T = {KNOT:g}: "


def knot_index(gait: Gait) -> int | None:
    """The sample of the left limit at the mid-step knot (the next one is the right limit:
    the samples hold t = T/2 twice); None if they do not."""
    t = gait.samples.t
    twice = np.flatnonzero((np.diff(t) == 0.0) & np.isclose(t[1:], KNOT * gait.period))
    return int(twice[0]) if twice.size else None


def knot_jumps(gait: Gait, field: str) -> np.ndarray | None:
    """The jump (right limit − left limit) of ``samples[field]`` at the mid-step knot; None
    if the samples do not hold both limits."""
    k = knot_index(gait)
    values = getattr(gait.samples, field)
    return None if k is None else values[k + 1] - values[k]


def figure_captions(gait: Gait) -> dict[str, str]:
    """The sentence above each figure that needs one, by file name: why the torques and the
    ground reaction jump at the knot (their largest jumps), why Ψ dips below δ."""
    captions = {}
    torques, wrench = knot_jumps(gait, "torques"), knot_jumps(gait, "wrench")
    if torques is not None:
        i = int(np.argmax(np.abs(torques)))
        captions["torques.png"] = (
            f"The torques jump at {_jump_place(gait)}{torques[i]:+.3g} N·m, "
            f"{joint_label(i, JOINTS[i])}): {KNOT_WHY if gait.knots == 1 else KNOTS_WHY}."
        )
        zmp = knot_jumps(gait, "zmp")
        captions["ground.png"] = (
            f"The ground reaction jumps at t/T = {KNOT:g} too (Fx {wrench[0]:+.3g} N, "
            f"Fz {wrench[1]:+.3g} N, x_ZMP {zmp:+.3g} m), for the same reason."
        )
    dips = margin_dips(gait)
    if dips:
        names = ", ".join(CONSTRAINT_MEANING[d.name].split()[0] for d in dips)
        captions["constraints.png"] = (
            f"The insets zoom on {names} below the solver's margin δ: see the constraints above."
        )
    return captions


def tightest_margins(gait: Gait) -> list[Tightest]:
    """The tightest sample of each constraint, the tightest relative to the solver's margin
    first: its smallest Ψ_i / δ_i where the solver keeps a margin (δ_i > 0; the swing foot's
    margin ramps from 0 at the ends of the step, where its smallest Ψ_i binds nothing), its
    smallest Ψ_i where it keeps none."""
    t_n, psi, delta = constraint_profile(gait)
    rows = []
    for i, name in enumerate(CONSTRAINTS):
        held = delta[:, i] > 0.0
        tightness = np.where(held, psi[:, i] / np.where(held, delta[:, i], 1.0), np.inf)
        k = int(np.nanargmin(tightness if held.any() else psi[:, i]))
        unit = CONSTRAINT_UNITS[name]
        rows.append(Tightest(name, float(psi[k, i]), unit, float(t_n[k]), float(delta[k, i])))
    return sorted(rows, key=lambda row: row.ratio)


def _free_side(ax, x: float, width: float) -> tuple[str, str]:
    """Where a label beside x (``width`` wide in data units) covers the least of the axes'
    first curve: ('left' or 'right' of x, 'top' or 'bottom')."""
    t, y = np.asarray(ax.lines[0].get_xdata()), np.asarray(ax.lines[0].get_ydata())
    low, high = ax.get_ylim()
    best = None
    for side, (a, b) in (("right", (x, x + width)), ("left", (x - width, x))):
        near = y[(t >= a) & (t <= b)]
        for edge, room in (("top", high - np.max(near)), ("bottom", np.min(near) - low)):
            if best is None or room > best[0]:
                best = (room, side, edge)
    return best[1], best[2]


def _with_knot(panel: Panel, jump: float | None, knots: list[float], legend: bool = False) -> Panel:
    """``panel`` with the ``knots`` [t/T] marked (dash-dotted lines) and, if given, the jump
    of its values at the mid-step knot written beside it in the panel's unit."""
    unit = panel.ylabel.rsplit("[", 1)[-1].rstrip("]") if "[" in panel.ylabel else "1"
    unit = "" if unit == "1" else f" {unit}"

    def decorate(ax, gaits):
        for i, knot in enumerate(knots):
            label = "knot: spline C¹" if i == 0 else None
            ax.axvline(knot, color="0.45", linestyle="-.", linewidth=1.0, label=label)
        if panel.decorate is not None:
            panel.decorate(ax, gaits)
        elif legend:
            ax.legend(fontsize=FONT_NOTE, loc="best")
        if jump is not None:
            side, edge = _free_side(ax, KNOT, 0.2)
            ax.annotate(
                f"jump {jump:+.3g}{unit}",
                xy=(KNOT, 1.0 if edge == "top" else 0.0),
                xycoords=("data", "axes fraction"),
                xytext=(4 if side == "right" else -4, -4 if edge == "top" else 4),
                textcoords="offset points",
                ha="left" if side == "right" else "right",
                va=edge,
                fontsize=FONT_NOTE,
                color="0.3",
            )

    return dataclasses.replace(panel, decorate=decorate)


def _knot_panels(gait: Gait, panels: tuple) -> tuple:
    """Each panel with the knot marked and its jump there (the first with the legend)."""
    k = knot_index(gait)
    return tuple(
        _with_knot(
            panel,
            None if k is None else float(np.diff(panel.values(gait)[k : k + 2])[0]),
            knot_times(gait),
            legend=i == 0,
        )
        for i, panel in enumerate(panels)
    )


# Candidate places of a dip's inset, (x0, y0) of its lower-left corner in axes fraction,
# leaving room in the axes for its tick labels and title.
INSET_SIZE = (0.38, 0.36)
INSET_PLACES = tuple((x, y) for y in (0.5, 0.12) for x in (0.14, 0.36, 0.58))


def _inset_place(ax, avoid: list) -> tuple[float, float]:
    """The inset place covering the fewest of the first curve's points and of ``avoid``
    ((x, y) in data units, what must stay in sight: marks and their labels)."""
    to_axes = ax.transData + ax.transAxes.inverted()
    curve = to_axes.transform(ax.lines[0].get_xydata())
    marks = to_axes.transform(np.asarray(avoid, dtype=float).reshape(-1, 2))
    width, height = INSET_SIZE

    def covered(place, points, room):
        x0, y0 = place  # room beyond the box: its tick labels left and below, its title above
        inside = (
            (points[:, 0] > x0 - room[0])
            & (points[:, 0] < x0 + width + room[1])
            & (points[:, 1] > y0 - room[0])
            & (points[:, 1] < y0 + height + room[1])
        )
        return int(np.count_nonzero(inside))

    return min(
        INSET_PLACES,
        key=lambda p: covered(p, curve, (0.1, 0.06)) + 100 * covered(p, marks, (0.15, 0.15)),
    )


def solver_spacing(knots) -> float:
    """[t/T] Between two of the solver's samples in a family (``knots`` interior knots, or a
    ``Bezier``): ``SOLVER_SAMPLES[knots]`` intervals per piece, knots + 1 pieces (a Bézier
    curve: one)."""
    return 1.0 / (pieces(knots) * SOLVER_SAMPLES[knots])


def _dip_inset(
    ax, dip: Dip, profile, solver_profile, color: str, samples: tuple[float, bool], avoid: list
) -> None:
    """A zoom on the dip of Ψ_i below δ_i, placed clear of the curve and of ``avoid`` (see
    ``_inset_place``): the curve on the check grid, δ dotted; ``samples``: the spacing of
    the solver's samples [t/T] (the zoom spans three) and whether to draw them (dots on
    either side of it: an IPOPT optimum's)."""
    (t_n, psi, delta), (t_s, psi_s) = profile, solver_profile
    spacing, solver_samples = samples
    x0, x1 = dip.at - 1.5 * spacing, dip.at + 1.5 * spacing
    depth = dip.margin - dip.value
    y0, y1 = dip.value - 0.4 * depth, dip.margin + 1.2 * depth
    place = _inset_place(ax, [(dip.at, dip.value), *avoid])
    inset = ax.inset_axes([*place, *INSET_SIZE], xlim=(x0, x1), ylim=(y0, y1))
    inset.plot(t_n, psi, color=color, linewidth=1.2)
    inset.plot(t_n, delta, color="0.4", linestyle=":", linewidth=1.2)
    if solver_samples:
        inset.plot(t_s, psi_s, linestyle="none", marker="o", markersize=3.5, color="k")
    inset.plot([dip.at], [dip.value], marker="v", markersize=5, color=color)
    scale, unit = (1e3, f"m{dip.unit}") if dip.unit in ("m", "rad") else (1.0, dip.unit)
    inset.yaxis.set_major_formatter(FuncFormatter(lambda v, _: f"{v * scale:.4g}"))
    inset.tick_params(labelsize=FONT_TINY, length=2, pad=1)
    inset.set_ylabel(unit, fontsize=FONT_TINY, labelpad=1)
    inset.set_title(f"{_milli(dip.value, dip.unit)} < δ", fontsize=FONT_SMALL, pad=2)
    ax.indicate_inset_zoom(inset, edgecolor="0.3")


def _constraint_panels(gait: Gait) -> tuple:
    t_n, psi, delta = constraint_profile(gait)
    t_s, psi_solver, _ = constraint_profile(gait, SOLVER_SAMPLES[gait.knots])
    dips = {dip.name: dip for dip in margin_dips(gait)}
    samples = (solver_spacing(gait.knots), gait.optimizer.method == "ipopt")

    def panel(i, name):
        def mark(ax, gaits):
            k = int(np.nanargmin(psi[:, i]))
            color = KNEE_STYLE[gait.knee]["color"]
            ax.plot(t_n, delta[:, i], color="0.4", linestyle=":", linewidth=1.2, label="δ")
            ax.plot([t_n[k]], [psi[k, i]], marker="o", markersize=8, fillstyle="none", color=color)
            side = "right" if t_n[k] > 0.7 else "left" if t_n[k] < 0.3 else "center"
            low, high = ax.get_ylim()
            below = psi[k, i] > (low + high) / 2  # the text inside the axes
            text = f"smallest {psi[k, i]:.3g} {CONSTRAINT_UNITS[name]}\nat t/T = {t_n[k]:.2f}"
            xy, va = (t_n[k], psi[k, i]), "top" if below else "bottom"
            box = dict(boxstyle="round,pad=0.2", fc="white", ec="none", alpha=0.8)
            note(ax, text, xy, (0, -12 if below else 12), ha=side, va=va, color=color, bbox=box)
            if name in dips:
                _dip_inset(
                    ax,
                    dips[name],
                    (t_n, psi[:, i], delta[:, i]),
                    (t_s, psi_solver[:, i]),
                    color,
                    samples,
                    [(t_n[k], psi[k, i])],
                )

        return Panel(
            CONSTRAINT_MEANING[name],
            f"Ψ{i + 1} [{CONSTRAINT_UNITS[name]}]",
            lambda g: psi[:, i],
            mark,
        )

    return tuple(panel(i, name) for i, name in enumerate(CONSTRAINTS))


def _constraints_title(gait: Gait, dips: list[Dip]) -> str:
    """The constraints figure's title, saying what its insets show (if it has any)."""
    title = "constraints Ψ (the solver's margin δ dotted"
    if not dips:
        return f"{title})"
    between = gait.optimizer.method == "ipopt" and all(dip.kept for dip in dips)
    where = " between the solver's samples, dots" if between else ""
    return f"{title}; insets: Ψ below δ{where})"


def gait_figures(gait: Gait) -> dict[str, Figure]:
    """The page's figures of one gait, by file name."""
    gaits = {gait.knee: gait}
    return {
        "torques.png": time_figure(
            gaits,
            f"joint torques{_jumps_text(gait, ' where the spline is C¹')}",
            _knot_panels(gait, TORQUE_PANELS),
        ),
        "angles.png": time_figure(gaits, "absolute angles", ANGLE_PANELS),
        "ground.png": time_figure(
            gaits,
            f"ground reaction on the stance foot{_jumps_text(gait)}",
            _knot_panels(gait, GROUND_PANELS),
        ),
        "constraints.png": time_figure(
            gaits, _constraints_title(gait, margin_dips(gait)), _constraint_panels(gait), 4
        ),
    }


@dataclass(frozen=True)
class Link:
    """A file the page links to: ``label``, its path, a note after it."""

    label: str
    path: Path
    note: str = ""


@dataclass
class Page:
    """One gait's page: its name (files ``<name>.md`` and ``<name>/``), the gait file's path
    and record (``Gait.read``), its validation report (``ValidationReport``, or None) and the
    report's path, and links (recording, video)."""

    name: str
    source: Path
    gait: Gait
    validation: ValidationReport | None = None
    validation_source: Path | None = None
    links: list[Link] = field(default_factory=list)
    # A two-phase gait's single support optimum of the same knee, robot and speed, shown
    # beside it (``biped.pages.two_phase_page``); None: not given.
    single: Gait | None = None


def figure_text(value) -> str:
    """A figure of a page's table: 'n/a' for None, yes/no, a range 'low to high', 4 digits."""
    if value is None:
        return "n/a"
    if isinstance(value, bool):
        return "yes" if value else "no"
    if isinstance(value, (list, tuple)):  # a range "low to high", or a list of figures
        return (" to " if len(value) == 2 else ", ").join(figure_text(v) for v in value)
    if isinstance(value, float):
        return f"{value:.4g}"
    return str(value)


def relative_link(path: Path, folder: Path) -> str:
    """The link to ``path`` from a page written in ``folder``."""
    return Path(os.path.relpath(Path(path).resolve(), Path(folder).resolve())).as_posix()


def markdown(page: Page, folder: Path) -> str:
    """The page's Markdown, its links relative to ``folder`` (where the page is written);
    a two-phase gait's ``biped.pages.two_phase_page``'s."""
    gait = page.gait
    if gait.two_phase:
        from biped.pages.two_phase_page import two_phase_markdown  # it builds on this module

        return two_phase_markdown(page, folder)
    report = gait.optimizer
    title = f"{gait.knee} knee, {gait.criterion}-optimal gait at {gait.speed:.3f} m/s"
    optimum = (
        "certified optimum"
        if certified(gait)
        else f"not a certified optimum (solver: {report.status}, "
        f"feasible: {figure_text(gait.feasible)})"
    )
    lines = [f"# {title}", ""]
    lines += [f"Gait file [`{page.source}`]({relative_link(page.source, folder)}): {optimum}."]
    if page.validation is not None:
        verdict = "PASS" if page.validation.passed else "FAIL"
        lines += [f"Validation in MuJoCo: **{verdict}** (below)."]
    else:
        lines += [
            "Not validated in MuJoCo: no validation report beside the gait file nor beside "
            "its recording (`biped validate` writes one there)."
        ]
    lines += [""]
    for link in page.links:
        note = f" ({link.note})" if link.note else ""
        lines += [f"- {link.label}: [`{link.path}`]({relative_link(link.path, folder)}){note}"]
    if page.links:
        lines += [""]
    safety = gait.safety
    lines += ["## Gait", "", "| | value | unit |", "|---|---|---|"]
    lines += [
        f"| walking speed | {gait.speed:.4g} | m/s |",
        f"| period T | {gait.period:.4f} | s |",
        f"| step length | {gait.step_length:.4f} | m |",
        f"| swing-foot clearance asked (beyond the paper's) | {safety.clearance:g} | m |",
        f"| ZMP margin asked (beyond the paper's) | {safety.zmp_margin:g} | m |",
        f"| optimiser | {report.method}: {report.status}, "
        f"{report.starts_at_best} of {report.starts} starts at the best | |",
        *(
            [f"| knee radii r1 / r2 | {gait.robot.r1:.4g} / {gait.robot.r2:.4g} | m |"]
            if gait.knee == "rolling"
            else []
        ),
        *design_lines(gait),
        *profile_lines(gait, page.name),
        "",
        "## Criteria",
        "",
        "| criterion | value | unit |",
        "|---|---|---|",
    ]
    for name, label, value, unit in gait.costs.labelled():
        optimised = " (optimised)" if name == gait.criterion else ""
        lines += [f"| {label}{optimised} | {value:.5g} | {unit} |"]
    lines += drive_lines(gait)
    lines += knee_lines(gait)
    lines += walk_lines(gait)
    lines += _constraint_lines(gait)
    lines += ["", "## Parameters", "", "| parameter | value | unit |", "|---|---|---|"]
    lines += [
        f"| {name} | {gait.parameters[name]:.6g} | {parameter_unit(name)} |"
        for name in parameter_names(gait.knots)
    ]
    lines += ["", "## Figures", ""]
    captions = figure_captions(gait)
    for name in FIGURE_NAMES:
        if captions.get(name):
            lines += [captions[name], ""]
        lines += [f"![{name[:-4]}]({page.name}/{name})", ""]
    if page.validation is not None:
        lines += _validation_lines(page, folder)
    return "\n".join(lines) + "\n"


# The knees of a design's changes (``biped.optimization.design.GAINS``), as its table names them.
GAIN_WORDS = {"design": "optimal radii", "table1": "Table 1 radii", "revolute": "revolute"}


def design_lines(gait: Gait) -> list[str]:
    """The section of a designed knee (``biped design``: the file's ``design``): its radii
    within their bounds, the knees it was compared with and the changes; none for a gait of
    given radii."""
    design = gait.design
    if not isinstance(design, dict):
        return []
    at = design.get("at_bounds") or []
    lines = [
        "",
        "## Knee design",
        "",
        "The rolling knee's radii optimised with the gait (`biped design`)"
        + (f": {', '.join(at)}." if at else ", inside their bounds."),
        "",
        "| radius | value | lower bound | upper bound | unit |",
        "|---|---|---|---|---|",
    ]
    for name in RADII:
        values = [(design.get(key) or {}).get(name) for key in ("radii", "lower", "upper")]
        lines += [f"| {name} | {' | '.join(map(figure_text, values))} | m |"]
    lines += [
        "",
        "| knee compared | r1 [m] | r2 [m] | sthenic [N²·m·s] | energy [J] | certified |",
        "|---|---|---|---|---|---|",
    ]
    for knee in design.get("compared") or []:
        radii = knee.get("radii") or {}
        values = [radii.get(name, "-") for name in RADII] + [
            knee.get("sthenic"),
            knee.get("energy"),
        ]
        shown = " | ".join(v if isinstance(v, str) else figure_text(v) for v in values)
        lines += [f"| {knee.get('knee')} | {shown} | {figure_text(knee.get('certified'))} |"]
    gains = design.get("gains_percent") or {}
    lines += [
        "",
        f"Changes of the {gait.criterion} criterion, (first − second) / second; negative: the "
        "first needs less:",
        "",
    ]
    for name in GAINS:
        first, second = (GAIN_WORDS[part] for part in name.split("_vs_"))
        value = gains.get(name)
        shown = f"{value:+.2f} %" if isinstance(value, (int, float)) else "n/a"
        lines += [f"- {first} vs {second}: {shown}"]
    return lines


def profile_lines(gait: Gait, name: str) -> list[str]:
    """The section of a designed knee profile (``biped design --profile``: the design's
    ``profile``): its rates, the surfaces' margins, its gains and its figure."""
    profile = (gait.design or {}).get("profile") if isinstance(gait.design, dict) else None
    if not isinstance(profile, dict):
        return []
    rates = profile.get("rates") or {}
    gains = gait.design.get("gains_percent") or {}
    kept = "no profile ended below the circles: the circles are kept. " * bool(
        profile.get("kept_circles")
    )
    lines = [
        "",
        "## Knee profile",
        "",
        f"The surfaces' radii of curvature r_i + k_i ψ ({profile.get('family')} family, "
        f"`biped design --profile`), started from the designed circles; {kept}"
        f"k1 = {figure_text(rates.get('k1'))} m/rad, k2 = {figure_text(rates.get('k2'))} m/rad "
        f"(|k| <= {figure_text(profile.get('rate_bound'))} m/rad), over the knee's flexion "
        f"{figure_text(profile.get('range'))} rad.",
        "",
        "| surfaces' bound | margin | unit |",
        "|---|---|---|",
    ]
    for bound, margin in (profile.get("surface_margins") or {}).items():
        lines += [f"| {bound} | {figure_text(margin)} | {'m' if 'convex' in bound else 'm²'} |"]
    lines += [""]
    for key, words in (
        ("profile_vs_circles", "profile vs designed circles"),
        ("profile_vs_revolute", "profile vs revolute"),
    ):
        value = gains.get(key)
        lines += [f"- {words}: {value:+.3f} %" if isinstance(value, (int, float)) else ""]
    lines += ["", f"![knee profile]({name}/{PROFILE_FIGURE})"]
    return lines


def _circles_of(page: Page) -> Gait | None:
    """The designed circles' gait file a profile's design names (``circles_gait``), beside
    the page's gait file; None without one."""
    design = page.gait.design if isinstance(page.gait.design, dict) else {}
    name = design.get("circles_gait")
    path = Path(page.source).parent / name if isinstance(name, str) else None
    return Gait.read(path) if path is not None and path.is_file() else None


def _constraint_lines(gait: Gait) -> list[str]:
    """The section of the tightest margins, then the sentence on the dips below δ if any."""
    lines = [
        "",
        "## Constraints: tightest margins",
        "",
        "Each constraint Ψ_i ≥ 0 of eq. (28) at its smallest on the step (where, in t/T), and "
        "where it is tightest relative to the margin δ_i the solver keeps from it (the swing "
        "foot's margin ramps from 0 at the ends of the step, where its smallest Ψ binds "
        "nothing); the tightest first (Ψ / δ near 1: the constraint binds the optimum).",
        "",
        "| constraint | smallest Ψ | unit | at t/T | tightest Ψ / δ | at t/T | δ there |",
        "|---|---|---|---|---|---|---|",
    ]
    t_n, psi, _ = constraint_profile(gait)
    for row in tightest_margins(gait):
        column = psi[:, CONSTRAINTS.index(row.name)]
        k = int(np.nanargmin(column))
        lines += [
            f"| {CONSTRAINT_MEANING[row.name]} | {column[k]:.4g} | {row.unit} | {t_n[k]:.3f} | "
            f"{row.ratio:.3g} | {row.at:.3f} | {row.margin:g} |"
        ]
    dips = dip_sentence(gait, margin_dips(gait))
    return lines + (["", dips] if dips else [])


def drive_lines(gait: Gait) -> list[str]:
    """The motors' figures (``Electrical``; none for a file written before the actuators):
    a row per joint, then the energies drawn per step and per metre and the cost of
    transport, without and with regeneration (the negative power recovered: equal where no
    joint's power is negative)."""
    electrical = gait.electrical
    if electrical is None:
        return []
    which = {None: "the default set's", Actuators.legacy(): "the earlier default set's"}.get(
        gait.robot.actuators, "the robot file's"
    )
    per_joint = [f for f in dataclasses.fields(electrical) if f.metadata.get("columns")]
    totals = [f for f in dataclasses.fields(electrical) if not f.metadata.get("columns")]
    lines = [
        "",
        f"## Drive ({which} actuators, `biped.model.actuators`)",
        "",
        "| joint | "
        + " | ".join(f"{f.metadata['label']} [{f.metadata['unit']}]" for f in per_joint)
        + " |",
        "|---" * (len(per_joint) + 1) + "|",
    ]
    for j, joint in enumerate(JOINTS):
        values = " | ".join(f"{getattr(electrical, f.name)[j]:.4g}" for f in per_joint)
        lines += [f"| {joint} | {values} |"]
    lines += ["", "| figure | value | unit |", "|---|---|---|"]
    for f in totals:
        unit = f.metadata["unit"]
        lines += [f"| {f.metadata['label']} | {getattr(electrical, f.name):.5g} | {unit} |"]
    return lines


def walk_lines(gait: Gait) -> list[str]:
    """What walking the gait asks of the robot (``Impact``'s touchdown, ``Walkability``;
    none for a file written before them): the sole's landing, the friction the stance foot
    and the landing need, the joints' distance to their stops, the hip's least speed, and
    the tightest margin of each walkable constraint the gait was optimised under."""
    impact, walk = gait.impact, gait.walkability
    if walk is None or impact is None or impact.touchdown_speed is None:
        return []
    vx, vz = impact.touchdown_velocity
    landing = "unknown" if impact.friction_needed is None else f"{impact.friction_needed:.3g}"
    stops = f"{walk.joint_stop_distance:.3g}"
    bar = "\\|"  # a literal | in a Markdown table
    rows = [
        ("the sole's speed at touchdown", f"{impact.touchdown_speed:.3g}", "m/s"),
        ("its velocity (forward, up)", f"{vx:.3g}, {vz:.3g}", "m/s"),
        (f"the landing's impulse, {bar}Ix{bar} / Iz", landing, "1"),
        (f"the stance foot's largest {bar}Fx{bar} / Fz", f"{walk.friction_needed:.3g}", "1"),
        ("a hip's or ankle's least distance to its stop", stops, "rad"),
        ("the hip's least forward speed", f"{walk.least_hip_speed:.3g}", "m/s"),
    ]
    lines = ["", "## Landing and walkability", "", "| figure | value | unit |", "|---|---|---|"]
    lines += [f"| {what} | {value} | {unit} |" for what, value, unit in rows]
    asked = [f for f in dataclasses.fields(walk) if f.metadata.get("optional")]
    asked = [(f, getattr(walk, f.name)) for f in asked if getattr(walk, f.name) is not None]
    if asked:
        lines += ["", "Tightest margins of the walkable constraints it was optimised under:", ""]
        lines += ["| constraint | tightest margin | unit |", "|---|---|---|"]
        lines += [f"| {f.metadata['label']} | {v:.3g} | {f.metadata['unit']} |" for f, v in asked]
    return lines


def knee_lines(gait: Gait) -> list[str]:
    """The knee loads (``KneeLoads``; none for a file written before them): for the designer,
    the ligament load each knee needs, in stance and in swing, with its largest compression
    and the friction its rolling needs where compressed."""
    loads = gait.knee_loads
    if loads is None:
        return []
    rolling = sum(gait.biped.radii) > 0.0
    lines = ["", "## Knee loads: the ligaments each knee needs", "", _knee_sentence(gait), ""]
    lines += [
        "| knee | ligament load needed [N] | largest tension [N] | largest compression [N] | "
        "largest \\|T\\| / N where compressed |",
        "|---|---|---|---|---|",
    ]
    for k, side in enumerate(("stance", "swing")):
        tension, ratio = loads.max_tension[k], loads.max_slip_ratio[k]
        lines += [
            f"| {side} knee, in {side} | {f'{tension:.4g}' if rolling else 'none (a pin)'} | "
            f"{tension:.4g} | {loads.max_compression[k]:.4g} | "
            f"{'never compressed' if ratio is None else f'{ratio:.3g}'} |"
        ]
    return lines


def _knee_sentence(gait: Gait) -> str:
    """What the knee loads are and the verdict: whether the gait needs ligaments, how much."""
    loads = gait.knee_loads
    if sum(gait.biped.radii) == 0.0:
        return (
            "The force of the thigh on the lower leg through each knee's pin "
            "(`biped.model.knee_loads`), along the shank (N, > 0 compression, < 0 tension) "
            "and across it (T): the pin carries tension, so no ligament is needed."
        )
    what = (
        "The force of the thigh on the lower leg through each knee (`biped.model.knee_loads`), "
        "along the line of the rolling circles' centres (N: > 0 presses the surfaces "
        "together, < 0 pulls them apart) and across it (T, what keeps them rolling without "
        "slip). Two surfaces in contact carry no tension: where N < 0, ligaments (straps or "
        "crossed cables) must hold the knee together."
    )
    if not loads.needs_ligaments:
        return f"{what} This gait never pulls a knee apart: it needs no ligament."
    stance, swing = loads.max_tension
    return (
        f"{what} This gait needs ligaments: {stance:.4g} N in the stance knee (in stance), "
        f"{swing:.4g} N in the swing knee (in swing); each knee goes through both every stride."
    )


def _validation_lines(page: Page, folder: Path) -> list[str]:
    report = page.validation
    verdict = "PASS" if report.passed else "FAIL"
    lines = ["## Validation in MuJoCo", ""]
    if page.validation_source is not None:
        where = relative_link(page.validation_source, folder)
        lines += [f"Report [`{page.validation_source}`]({where}): **{verdict}**.", ""]
    figure = f"{page.name}/{TORQUES_FIGURE}" if has_profiles(report) else None
    lines += mujoco_walk_lines(report, figure)
    for check in report.checks:
        said = f" ({', '.join(check.causes)})" if check.causes else ""
        lines += [f"### {check.name}: {'PASS' if check.passed else 'FAIL'}{said}", ""]
        lines += ["| figure | value | unit |", "|---|---|---|"]
        for name, value in check.figures.items():
            if name not in NOT_TABLED:
                unit = unit_text(check.units.get(name, ""))
                lines += [f"| {name} | {figure_text(value)} | {unit} |"]
        lines += [""]
        if check.notes:  # sentences, one a line (a list of two figures is a range: "low to high")
            lines += [f"- {note}" for note in check.notes] + [""]
        if check.name == "orbit":
            lines += [f"![Floquet multipliers]({page.name}/{ORBIT_FIGURE})", ""]
    return lines


def page_figures(page: Page) -> dict[str, Figure]:
    """The page's figures: the gait's (``gait_figures``) and, with a validation report that
    has an orbit check, its multipliers (``ORBIT_FIGURE``), and with one whose forward check
    has the torques over one step, MuJoCo's beside the model's (``TORQUES_FIGURE``); a
    two-phase gait's are its phases' (``biped.pages.two_phase_figures``)."""
    if page.gait.two_phase:
        return two_phase_figures(page.gait)
    figures = gait_figures(page.gait)
    title = f"{page.gait.knee} knee, {page.gait.criterion}, {page.gait.speed:.3f} m/s"
    orbit = None if page.validation is None else page.validation.check("orbit")
    if orbit is not None:
        figures[ORBIT_FIGURE] = multipliers_figure(orbit.figures, title)
    if has_profiles(page.validation):
        figures[TORQUES_FIGURE] = torques_figure(page.validation.check("forward").figures, title)
    if profile_lines(page.gait, page.name):
        figures[PROFILE_FIGURE] = profile_figure(page.gait, _circles_of(page))
    return figures


def write_pages(pages: list[Page], out: str | Path) -> list[Path]:
    """Write each page and its figures into ``out``, all or none; returns every file written
    (each page, then its figures)."""
    out = Path(out)
    rendered = [(page, page_figures(page), markdown(page, out)) for page in pages]
    with atomic_set(out, "report") as staging:
        for page, figures, text in rendered:
            (staging / page.name).mkdir()
            for name, figure in figures.items():
                save(figure, staging / page.name / name)
            (staging / f"{page.name}.md").write_text(text, encoding="utf-8")
    return [
        path
        for page, figures, _ in rendered
        for path in [out / f"{page.name}.md", *(out / page.name / name for name in figures)]
    ]
