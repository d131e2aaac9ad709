"""The figure of a designed knee profile (``biped design --profile``): the two surfaces to
scale beside the designed circles, where the contact runs on them over a step, and the
joints' torques of the profile's gait beside the circles'.

Panels:

1. The knee at the straight leg, to scale [mm], in the thigh's frame (C2 at the origin, the
   thigh up): the thigh's and the shank's surfaces over the knee's range of flexion
   (``biped.model.profile.PROFILE_RANGE``), the designed circles dashed, the contact of the
   straight knee marked.
2. The contact's arc length S on the surfaces [mm] (S1(ψ1) = S2(ψ2), the same on both)
   over the step, stance and swing knees: where the surfaces roll.
3. The knees' flexion over the step [rad] (what moves the contact).
4-6. The torques of the knees, the hips and the ankles [N·m] of the profile's gait and,
   dashed, the circles' (their own optimal gait).
"""

from __future__ import annotations

import numpy as np
from matplotlib.figure import Figure

from biped.model.dynamics import JOINTS
from biped.model.kinematics import Q1, Q2, Q3, Q4
from biped.model.profile import PROFILE_RANGE, KneeProfile, knee_vectors, rolling
from biped.pages.style import FONT_NOTE, FONT_SMALL, FONT_TINY, PROFILE_SIZE, PROFILE_SPEEDS_SIZE

PROFILE_FIGURE = "profile.png"
COLORS = {"profile": "tab:red", "circles": "0.45"}
# The knees' (thigh, shank) angles and the torque columns (``JOINTS``) of each pair drawn.
KNEES = {"stance": (Q2, Q1), "swing": (Q3, Q4)}
TORQUE_PAIRS = (("knee", (1, 4)), ("hip", (2, 3)), ("ankle", (0, 5)))
# [mm] Around the surfaces in the drawing to scale.
ZOOM_MARGIN = 40.0


def surfaces(profile: KneeProfile, count: int = 121) -> dict[str, np.ndarray]:
    """The two surfaces at the straight knee, (count, 2) [m] in the thigh's frame from C2:
    the thigh's contact points over the range, and the shank's carried to the straight
    pose (turned back by the flexion about C1)."""
    theta = np.linspace(*PROFILE_RANGE, count)
    vectors = knee_vectors(profile, np.zeros_like(theta), -theta)
    contact = np.stack(vectors["contact"].position, -1)
    link = np.stack(vectors["link"].position, -1)
    c1 = np.array([0.0, -(profile.r1 + profile.r2)])  # C1 at the straight knee
    shank = contact - link
    c, s = np.cos(theta), np.sin(theta)
    turned = np.stack([c * shank[:, 0] - s * shank[:, 1], s * shank[:, 0] + c * shank[:, 1]], -1)
    return {"thigh": contact, "shank": c1 + turned}


def _shape_panel(ax, profile: KneeProfile, circles: tuple | None) -> None:
    drawn = surfaces(profile)
    for points in drawn.values():
        ax.plot(1e3 * points[:, 0], 1e3 * points[:, 1], color=COLORS["profile"], lw=2)
    ax.plot([0.0], [-1e3 * profile.r2], "k.", ms=8, label="contact, straight knee")
    if circles is not None:
        r1, r2 = circles
        arc = np.linspace(-np.pi, np.pi, 200)
        ax.plot(1e3 * r2 * np.sin(arc), -1e3 * r2 * np.cos(arc), "--", color=COLORS["circles"])
        ax.plot(
            1e3 * r1 * np.sin(arc),
            1e3 * (-r2 - r1 + r1 * np.cos(arc)),
            "--",
            color=COLORS["circles"],
            label=f"designed circles r1 {1e3 * r1:.0f}, r2 {1e3 * r2:.0f} mm",
        )
    ax.plot([0, 0], [0, -1e3 * (profile.r1 + profile.r2)], "k+", ms=10, label="C2, C1")
    points = 1e3 * np.concatenate(list(drawn.values()))
    low, high = points.min(axis=0) - ZOOM_MARGIN, points.max(axis=0) + ZOOM_MARGIN
    ax.set_xlim(low[0], high[0])
    ax.set_ylim(low[1], high[1])
    ax.set_aspect("equal")
    ax.set_xlabel("x [mm] (forward)")
    ax.set_ylabel("z [mm] (thigh up)")
    ax.set_title(f"surfaces over θ {PROFILE_RANGE[0]:g} to {PROFILE_RANGE[1]:g} rad, to scale")
    ax.legend(fontsize=FONT_SMALL, loc="lower left")


def _flexions(gait) -> dict[str, np.ndarray]:
    q = gait.samples.q
    return {side: q[:, thigh] - q[:, shank] for side, (thigh, shank) in KNEES.items()}


def _contact_panels(ax_arc, ax_flex, gait, profile: KneeProfile) -> None:
    t = gait.samples.t / gait.period
    for (side, theta), style in zip(_flexions(gait).items(), ("-", ":"), strict=True):
        roll = rolling(profile, theta)
        arc = profile.r2 * roll.psi2 + 0.5 * profile.k2 * roll.psi2**2
        ax_arc.plot(t, 1e3 * arc, style, color=COLORS["profile"], label=f"{side} knee")
        ax_flex.plot(t, theta, style, color=COLORS["profile"], label=f"{side} knee")
    ax_arc.set_title("contact's arc length on the surfaces")
    ax_arc.set_ylabel("S [mm]")
    ax_flex.set_title("knee flexion θ = q_thigh − q_shank")
    ax_flex.set_ylabel("θ [rad]")
    for ax in (ax_arc, ax_flex):
        ax.set_xlabel("t / T")
        ax.grid(alpha=0.3)
        ax.legend(fontsize=FONT_SMALL)


def _torque_panel(ax, joint: str, columns, gait, circles_gait) -> None:
    for label, g, dash in (("profile", gait, "-"), ("circles", circles_gait, "--")):
        if g is None:
            continue
        t = g.samples.t / g.period
        for column, width in zip(columns, (1.8, 1.0), strict=True):
            ax.plot(
                t,
                g.samples.torques[:, column],
                dash,
                lw=width,
                color=COLORS[label],
                label=f"{label}: {JOINTS[column].replace('_', ' ')}",
            )
    ax.set_title(f"{joint} torques")
    ax.set_xlabel("t / T")
    ax.set_ylabel("Γ [N·m]")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=FONT_TINY)


def profile_figure(gait, circles_gait=None) -> Figure:
    """The figure of the module docstring for a profile's gait file (``gait``: a
    ``biped.records.gait_file.Gait`` with a profiled robot or a design that kept circles)
    and the designed circles' gait (None: not drawn)."""
    robot = gait.robot
    profile = KneeProfile.of(robot)
    circles = None if circles_gait is None else (circles_gait.robot.r1, circles_gait.robot.r2)
    fig = Figure(figsize=PROFILE_SIZE, layout="constrained")
    axes = fig.subplots(2, 3).ravel()
    _shape_panel(axes[0], profile, circles)
    _contact_panels(axes[1], axes[2], gait, profile)
    for ax, (joint, columns) in zip(axes[3:], TORQUE_PAIRS, strict=True):
        _torque_panel(ax, joint, columns, gait, circles_gait)
    fig.suptitle(
        f"knee profile r1 {1e3 * profile.r1:.1f} mm, r2 {1e3 * profile.r2:.1f} mm, "
        f"k1 {1e3 * profile.k1:+.1f} mm/rad, k2 {1e3 * profile.k2:+.1f} mm/rad; "
        f"{gait.criterion}, {gait.speed:.3f} m/s"
    )
    return fig


SPEEDS_FIGURE = "speeds.png"
# The knees of ``biped.studies.profile_speeds`` as the legend names them.
LEGENDS = {
    "circles": "circles designed at each speed",
    "machined": "circles designed with it, machined",
}


def speeds_figure(rows, criterion: str, designed_at: float) -> Figure:
    """The changes over the speeds (``biped.studies.profile_speeds``): the profile machined
    for ``designed_at`` against the circles designed at each speed, the circles designed with
    it (machined too) and the revolute knee, the circles against the revolute knee [%]; a
    speed not certified is left out (a gap)."""
    fig = Figure(figsize=PROFILE_SPEEDS_SIZE, layout="constrained")
    ax = fig.subplots()
    speeds = np.array([row.speed for row in rows])
    for (first, second), style in (
        (("profile", "circles"), dict(color=COLORS["profile"], marker="o")),
        (("profile", "machined"), dict(color="tab:purple", marker="D", ls="-.")),
        (("profile", "revolute"), dict(color=COLORS["profile"], marker="s", ls="--")),
        (("circles", "revolute"), dict(color=COLORS["circles"], marker="^", ls=":")),
    ):
        values = [row.change(first, second) for row in rows]
        shown = np.array([np.nan if v is None else v for v in values])
        label = f"{first} vs {LEGENDS.get(second, second)}"
        ax.plot(speeds, shown, label=label, **style)
    ax.axvline(designed_at, color="0.6", lw=0.8)
    ax.text(
        designed_at,
        0.02,
        f" profile designed at {designed_at:.3f} m/s",
        transform=ax.get_xaxis_transform(),
        fontsize=FONT_NOTE,
    )
    ax.axhline(0.0, color="k", lw=0.6)
    ax.set_xlabel("walking speed [m/s]")
    ax.set_ylabel(f"change of the {criterion} criterion [%]")
    ax.set_title("one machined knee profile over the speeds (negative: it needs less)")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=FONT_NOTE)
    return fig
