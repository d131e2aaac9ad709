"""The figures of a two-phase gait's page (``biped optimize --double-support``): its whole
step, single support then double support, over the step's normalised time t / (T + T_ds),
the double support shaded.

    phases_torques.png   the six joint torques over the whole step
    phases_angles.png    the absolute angles [°] over the whole step
    phases_feet.png      both feet's normal force Fz, tangential force Fx, the friction each
                         needs |Fx| / Fz and each foot's ZMP from its own ankle within its
                         sole: the rear (single support's stance) foot through the whole step,
                         the front foot in double support only
    phases_landing.png   the same four panels zoomed on the double support (a tenth to a
                         fifth of the step: too narrow to read beside the whole step)

The single support's curves are the gait file's samples on the check grid; the double
support's its ``double_support.samples`` (``biped.records.two_phase_gait.PhaseSamples``), in
the single support's labels: the stance leg is the rear leg, the swing leg the front one. The
shading spans [T, T + T_ds] of the step, the phase's share of it (``phase_span``); the
landing is the line at its start (an impact's jump or a zero-speed landing's none).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from matplotlib.figure import Figure

from biped.model import double_support as ds
from biped.model.dynamics import JOINTS
from biped.model.gait import FREE_ANGLES
from biped.model.kinematics import COORDINATES
from biped.model.robot import FOOT_FRICTION
from biped.pages.figures import angle_label, joint_label
from biped.pages.style import FONT_NOTE, FONT_SMALL, KNEE_LABELS, KNEE_STYLE, TIME_PANEL_SIZE
from biped.records.gait_file import Gait

TORQUES = "phases_torques.png"
ANGLES = "phases_angles.png"
FEET = "phases_feet.png"
LANDING = "phases_landing.png"
FIGURE_NAMES = (TORQUES, ANGLES, FEET, LANDING)
# [1] Room left of the landing in the zoom on the double support, a fraction of its width.
ZOOM_LEAD = 0.15
# [°] The least span of an angle's axis.
LEAST_ANGLE_SPAN = 1.0
TIME_AXIS = "normalised time t / (T + T_ds) of the whole step"
# The double support's shading: its label is how tests and readers find it.
SHADE_LABEL = "double support"
SHADE = dict(color="0.85", alpha=0.7, linewidth=0, zorder=0)
# Each foot's line style: the rear foot (the single support's stance foot) and the front one.
FOOT_LINES = {"rear": "-", "front": "--"}


def step_duration(gait: Gait) -> float:
    """T + T_ds [s]: the whole step of a two-phase gait."""
    return gait.period + gait.double_support.duration


def phase_span(gait: Gait) -> tuple[float, float]:
    """[1] The double support on the step's normalised time: from the landing, T / (T +
    T_ds), to lift-off, 1; its width is the phase's share of the step."""
    return gait.period / step_duration(gait), 1.0


def single_time(gait: Gait) -> np.ndarray:
    """[1] The single support's samples on the step's normalised time."""
    return gait.samples.t / step_duration(gait)


def double_time(gait: Gait) -> np.ndarray:
    """[1] The double support's samples on the step's normalised time."""
    return (gait.period + gait.double_support.samples.t) / step_duration(gait)


def whole_step(gait: Gait, single: np.ndarray, double: np.ndarray) -> tuple:
    """(t, values) over the whole step: the single support's ``single`` then the double
    support's ``double``, joined at the landing."""
    return np.concatenate([single_time(gait), double_time(gait)]), np.concatenate([single, double])


@dataclass(frozen=True)
class Curve:
    """One line of a panel: its label, (t, values) and line style."""

    label: str
    t: np.ndarray
    values: np.ndarray
    linestyle: str = "-"


@dataclass(frozen=True)
class PhasePanel:
    """One plot over the whole step: title, y label (with its unit), its ``curves(gait)``
    and ``decorate(ax, gait)`` for what it needs beyond them."""

    title: str
    ylabel: str
    curves: Callable[[Gait], list[Curve]]
    decorate: Callable | None = None


def _joint_curve(j: int):
    def curves(gait: Gait) -> list[Curve]:
        t, values = whole_step(
            gait, gait.samples.torques[:, j], gait.double_support.samples.torques[:, j]
        )
        return [Curve(KNEE_LABELS[gait.knee], t, values)]

    return curves


def _angle_curve(k: int):
    def curves(gait: Gait) -> list[Curve]:
        single, double = gait.samples.q[:, k], gait.double_support.samples.q[:, k]
        t, values = whole_step(gait, single, double)
        return [Curve(KNEE_LABELS[gait.knee], t, np.degrees(values))]

    return curves


def foot_values(gait: Gait, quantity: Callable) -> list[Curve]:
    """Each foot's ``quantity(wrench, zmp)`` over the step: the rear foot's through the whole
    step (the single support's stance foot, then the rear foot of double support), the front
    foot's in double support."""
    phase, h = gait.double_support.samples, gait.robot.ankle_height
    rear = quantity(phase.rear_wrench, ds.zmp(phase.rear_wrench, h))
    t, values = whole_step(gait, quantity(gait.samples.wrench, gait.samples.zmp), rear)
    front = quantity(phase.front_wrench, ds.zmp(phase.front_wrench, h))
    return [
        Curve("rear foot", t, values, FOOT_LINES["rear"]),
        Curve("front foot", double_time(gait), front, FOOT_LINES["front"]),
    ]


def _feet(quantity: Callable):
    return lambda gait: foot_values(gait, quantity)


def _friction_line(ax, gait: Gait) -> None:
    """The model's friction μ, the ratio no foot may exceed."""
    ax.axhline(FOOT_FRICTION, color="k", linestyle=":", linewidth=1.0)
    ax.annotate(
        f"μ = {FOOT_FRICTION:g}, the model's friction",
        (0.0, FOOT_FRICTION),
        xycoords=("axes fraction", "data"),
        xytext=(4, -10),
        textcoords="offset points",
        fontsize=FONT_NOTE,
    )
    ax.set_ylim(0.0, 1.15 * max(FOOT_FRICTION, *(np.nanmax(c.values) for c in _ratio(gait))))


def _ratio(gait: Gait) -> list[Curve]:
    return foot_values(gait, lambda w, _: np.abs(w[:, 0]) / w[:, 1])


def _sole_lines(ax, gait: Gait) -> None:
    """The sole's heel and toe from the ankle: where each foot's ZMP must stay."""
    for name, x in gait.robot.sole_edges().items():
        ax.axhline(x, color="0.4", linestyle=":", linewidth=1.0)
        ax.annotate(
            f"{name} of the sole",
            (0.0, x),
            xycoords=("axes fraction", "data"),
            xytext=(2, 2),
            textcoords="offset points",
            fontsize=FONT_NOTE,
            color="0.4",
        )


TORQUE_PANELS = tuple(
    PhasePanel(joint_label(j, joint), "torque [N·m]", _joint_curve(j))
    for j, joint in enumerate(JOINTS)
)


def _least_span(ax, gait: Gait) -> None:
    """At least ``LEAST_ANGLE_SPAN`` on the y axis: an angle held (the flat swing foot's,
    to 1e-9 °) drawn flat, not its rounding magnified."""
    low, high = ax.get_ylim()
    if high - low < LEAST_ANGLE_SPAN:
        middle = 0.5 * (low + high)
        ax.set_ylim(middle - 0.5 * LEAST_ANGLE_SPAN, middle + 0.5 * LEAST_ANGLE_SPAN)


ANGLE_PANELS = tuple(
    PhasePanel(
        angle_label(a),
        "angle from the vertical [°]",
        _angle_curve(COORDINATES.index(a)),
        _least_span,
    )
    for a in FREE_ANGLES
)
FEET_PANELS = (
    PhasePanel("Fz: each foot's normal force", "force [N]", _feet(lambda w, _: w[:, 1])),
    PhasePanel("Fx: each foot's tangential force", "force [N]", _feet(lambda w, _: w[:, 0])),
    PhasePanel("|Fx| / Fz: friction each foot needs", "ratio [1]", _ratio, _friction_line),
    PhasePanel(
        "x_ZMP from each foot's own ankle", "position [m]", _feet(lambda _, z: z), _sole_lines
    ),
)


def shade_double_support(ax, gait: Gait) -> None:
    """The double support shaded (``phase_span``), the landing marked at its start."""
    start, end = phase_span(gait)
    ax.axvspan(start, end, label=SHADE_LABEL, **SHADE)
    landing = gait.double_support.landing
    ax.axvline(start, color="0.3", linestyle="-.", linewidth=1.0, label=f"landing ({landing})")


def phase_figure(gait: Gait, title: str, panels, columns: int = 3, zoom: bool = False) -> Figure:
    """One plot per panel over the whole step (``zoom``: over the double support and a little
    before it), the double support shaded, in the knee's colour (``KNEE_STYLE``); the first
    panel's legend names the phases and the lines."""
    rows = int(np.ceil(len(panels) / columns))
    size = (TIME_PANEL_SIZE[0] * columns, TIME_PANEL_SIZE[1] * rows)
    fig = Figure(figsize=size, layout="constrained")
    axes = np.atleast_1d(fig.subplots(rows, columns)).ravel()
    color = KNEE_STYLE[gait.knee]["color"]
    for ax, panel in zip(axes, panels, strict=False):
        shade_double_support(ax, gait)
        for curve in panel.curves(gait):
            ax.plot(
                curve.t, curve.values, color=color, linestyle=curve.linestyle, label=curve.label
            )
        if panel.decorate is not None:
            panel.decorate(ax, gait)
        start, end = phase_span(gait)
        ax.set_xlim(start - ZOOM_LEAD * (end - start) if zoom else 0.0, end)
        if zoom and panel.decorate is None:  # a reference's panel keeps its reference in sight
            _fit_y(ax)
        ax.set_title(panel.title)
        ax.set_xlabel(TIME_AXIS)
        ax.set_ylabel(panel.ylabel)
        ax.grid(alpha=0.3)
    axes[0].legend(fontsize=FONT_SMALL, loc="best")
    for ax in axes[len(panels) :]:
        ax.remove()
    share = gait.double_support.share
    fig.suptitle(
        f"{title}\n{KNEE_LABELS[gait.knee]}, {gait.speed:.3f} m/s; double support shaded: "
        f"{share:.1%} of the step"
    )
    return fig


def _fit_y(ax) -> None:
    """The y limits of the lines' points within the x limits (a zoom's)."""
    low, high = ax.get_xlim()
    values = []
    for line in ax.lines:
        x, y = (np.asarray(v, dtype=float) for v in line.get_data())
        if x.size > 2:  # a curve, not a reference line
            values.append(y[(x >= low) & (x <= high)])
    values = np.concatenate(values) if values else np.zeros(0)
    values = values[np.isfinite(values)]
    if values.size:
        pad = 0.08 * max(np.ptp(values), 1e-9)
        ax.set_ylim(values.min() - pad, values.max() + pad)


def two_phase_figures(gait: Gait) -> dict[str, Figure]:
    """The figures of a two-phase gait's page, by file name (``FIGURE_NAMES``)."""
    return {
        TORQUES: phase_figure(gait, "joint torques over the whole step", TORQUE_PANELS),
        ANGLES: phase_figure(gait, "absolute angles over the whole step", ANGLE_PANELS),
        FEET: phase_figure(gait, "both feet's ground forces and ZMP", FEET_PANELS, 2),
        LANDING: phase_figure(
            gait, "both feet in double support (zoom)", FEET_PANELS, 2, zoom=True
        ),
    }
