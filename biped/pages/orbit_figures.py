"""Figures of a walk's orbit in MuJoCo, drawn from the JSON of the orbit check
(``validate.checks.orbit``: a validation report's ``orbit`` object, or a study's ``orbits``).

    multipliers_figure   the Floquet multipliers in the complex plane with the unit circle,
                         the spectral radius and its uncertainty as circles
    knob_figure          ρ against a scale of one controller gain, its uncertainty, the
                         values without an orbit apart, where the verdict changes and
                         where ρ crosses 1
    speeds_figure        ρ of both knees against the walking speed, and their difference
"""

from __future__ import annotations

import numpy as np
from matplotlib.figure import Figure

from biped.optimization.comparison import relative_change
from biped.pages.figures import DIFFERENCE_AXIS
from biped.pages.style import (
    FONT_NOTE,
    FONT_SMALL,
    FONT_TITLE,
    KNEE_STYLE,
    MULTIPLIERS_SIZE,
    ORBIT_KNEES_PANEL_SIZE,
    ORBIT_VARIED_SIZE,
)

# How many spreads of ρ the uncertainty bands span (the orbit check's margin).
SPREADS = 2.0
FALLS = dict(linestyle="none", marker="x", markersize=9, markeredgewidth=2)
# Where the speeds figure marks each knee's walks that fall (ρ axis).
FALL_ROWS = {"revolute": 1.52, "rolling": 1.42}
VERDICT_COLOURS = {
    "stable": "#2a9d8f",
    "undecided": "#e9c46a",
    "unstable": "#e76f51",
    "another orbit": "#8d99ae",
}


def _circle(ax, radius: float, **style) -> None:
    angle = np.linspace(0.0, 2.0 * np.pi, 361)
    ax.plot(radius * np.cos(angle), radius * np.sin(angle), **style)


def multipliers_figure(orbit: dict, title: str) -> Figure:
    """The multipliers of an orbit check's figures (``orbit``) in the complex plane."""
    figure = Figure(figsize=MULTIPLIERS_SIZE, layout="constrained")
    ax = figure.subplots()
    _circle(ax, 1.0, color="k", linewidth=1.2, label="unit circle |μ| = 1")
    ax.axhline(0.0, color="0.8", linewidth=0.8, zorder=0)
    ax.axvline(0.0, color="0.8", linewidth=0.8, zorder=0)
    if "spectral_radius" not in orbit:
        ax.text(0.0, 0.0, f"no orbit: {orbit.get('verdict', '')}", ha="center", va="center")
    else:
        rho, spread = orbit["spectral_radius"], orbit["spectral_radius_spread"]
        angle = np.linspace(0.0, 2.0 * np.pi, 361)
        inner, outer = max(rho - SPREADS * spread, 0.0), rho + SPREADS * spread
        ax.fill(
            np.concatenate([outer * np.cos(angle), inner * np.cos(angle[::-1])]),
            np.concatenate([outer * np.sin(angle), inner * np.sin(angle[::-1])]),
            color=VERDICT_COLOURS.get(orbit["verdict"], "0.7"),
            alpha=0.25,
            linewidth=0,
            label=f"ρ ± {SPREADS:g} spreads: {inner:.2f} to {outer:.2f}",
        )
        _circle(ax, rho, color="0.3", linestyle="--", linewidth=1.0, label=f"ρ = {rho:.3f}")
        real, imag = np.array(orbit["multipliers_real"]), np.array(orbit["multipliers_imag"])
        ax.plot(real, imag, "o", color="#264653", markersize=7, label="multipliers μ")
        ax.plot(
            [0.0],
            [0.0],
            "o",
            fillstyle="none",
            color="#e76f51",
            markersize=11,
            label=f"section (the flow): |J f| / |f| = {orbit['flow_multiplier']:.3f}",
        )
    ax.set_xlim(-1.25, 1.25)
    ax.set_ylim(-1.25, 1.25)
    ax.set_aspect("equal")
    ax.set_xlabel("Re μ [1]")
    ax.set_ylabel("Im μ [1]")
    ax.legend(loc="upper left", fontsize=FONT_SMALL, framealpha=0.9)
    verdict = orbit.get("verdict", "")
    ax.set_title(
        f"{title}\nFloquet multipliers of the walk's return map: {verdict}", fontsize=FONT_TITLE
    )
    return figure


def knob_figure(content: dict, title: str) -> Figure:
    """ρ against the knob's values of a study's content
    (``validate.studies.orbit_study.OrbitStudy.to_dict``): each orbit's ρ with its bar; the
    values without an orbit in a strip above, off ρ's scale (nothing measured there); a band
    between two values where the verdict changes, dotted where ρ crosses 1 in it; the legend
    below, off the data, naming only what is drawn."""
    figure = Figure(figsize=ORBIT_VARIED_SIZE, layout="constrained")
    strip, ax = figure.subplots(2, 1, sharex=True, height_ratios=(1.0, 6.0))
    values, orbits = np.array(content["values"], float), content["orbits"]
    found = [(v, o) for v, o in zip(values, orbits, strict=True) if "spectral_radius" in o]
    for value, orbit in found:
        rho, bar = orbit["spectral_radius"], SPREADS * orbit["spectral_radius_spread"]
        colour = VERDICT_COLOURS.get(orbit["verdict"], "0.5")
        ax.errorbar([value], [rho], yerr=[[bar], [bar]], fmt="o", color=colour, capsize=3)
    fell = [v for v, o in zip(values, orbits, strict=True) if "spectral_radius" not in o]
    strip.plot(fell, [0.5] * len(fell), color=VERDICT_COLOURS["unstable"], **FALLS)
    for verdict in sorted({o["verdict"] for _, o in found}, key=list(VERDICT_COLOURS).index):
        ax.plot([], [], "o", color=VERDICT_COLOURS[verdict], label=f"ρ: {verdict}")
    if fell:
        ax.plot([], [], color=VERDICT_COLOURS["unstable"], label="no orbit: unstable", **FALLS)
    _boundaries(ax, strip, content["boundaries"])
    ax.axhline(1.0, color="k", linewidth=1.2, label="ρ = 1")
    tops = [o["spectral_radius"] + SPREADS * o["spectral_radius_spread"] for _, o in found]
    ax.set_ylim(0.0, 1.08 * max([1.2, *tops]))
    strip.set_ylim(0.0, 1.0)
    strip.set_yticks([])
    strip.set_ylabel("no\norbit", rotation=0, ha="right", va="center", fontsize=FONT_NOTE)
    strip.tick_params(labelbottom=False)
    ax.set_xlabel(f"scale of {content['scales']} [1]")
    ax.set_ylabel("spectral radius ρ [1]")
    figure.legend(loc="outside lower center", ncols=3, fontsize=FONT_SMALL)
    figure.suptitle(
        f"{title}\nρ of the walk's return map, bars: ± {SPREADS:g} spreads (the landing's "
        "noise); above: the scales without an orbit (no ρ)",
        fontsize=FONT_TITLE,
    )
    return figure


def _boundaries(ax, strip, boundaries: list[dict]) -> None:
    """Each boundary of a knob's study: a grey band between its two values (on both
    panels), and a dotted line where ρ crosses 1 (where both have an orbit)."""
    for k, boundary in enumerate(boundaries):
        a, b = boundary["between"]
        label = "verdict changes between these scales" if k == 0 else None
        for panel in (ax, strip):
            panel.axvspan(a, b, color="0.9", zorder=0, label=label if panel is ax else None)
    crossings = [b["radius_crosses_1_at"] for b in boundaries]
    for k, at in enumerate(x for x in crossings if x is not None):
        label = "ρ crosses 1 (linear between the two)" if k == 0 else None
        ax.axvline(at, color="0.3", linestyle=":", label=label)


def speeds_figure(rows: list[dict], title: str) -> Figure:
    """ρ of each knee against speed, one panel per criterion, and rolling - revolute below;
    ``rows``: one per gait, its ``knee``, ``criterion``, ``speed`` and orbit figures."""
    criteria = sorted({row["criterion"] for row in rows}, key=lambda c: c != "sthenic")
    figure = Figure(
        figsize=(ORBIT_KNEES_PANEL_SIZE[0] * len(criteria), ORBIT_KNEES_PANEL_SIZE[1]),
        layout="constrained",
    )
    axes = figure.subplots(2, len(criteria), squeeze=False, height_ratios=(2.0, 1.0), sharex="col")
    for column, criterion in enumerate(criteria):
        top, bottom = axes[0, column], axes[1, column]
        by_knee = {}
        for knee, style in KNEE_STYLE.items():
            chosen = sorted(
                (r for r in rows if r["criterion"] == criterion and r["knee"] == knee),
                key=lambda r: r["speed"],
            )
            by_knee[knee] = {r["speed"]: r for r in chosen}
            found = [r for r in chosen if "spectral_radius" in r]
            top.errorbar(
                [r["speed"] for r in found],
                [r["spectral_radius"] for r in found],
                yerr=[SPREADS * r["spectral_radius_spread"] for r in found],
                capsize=3,
                label=f"{knee} knee",
                **style,
            )
            fell = [r["speed"] for r in chosen if "spectral_radius" not in r]
            if fell:  # at the top, one row per knee
                row = FALL_ROWS[knee]
                top.plot(fell, [row] * len(fell), color=style["color"], clip_on=False, **FALLS)
        top.axhline(1.0, color="k", linewidth=1.2)
        top.plot([], [], color="0.4", label="falls: no orbit", **FALLS)
        top.set_ylim(0.0, 1.6)
        top.set_ylabel("spectral radius ρ [1]")
        top.set_title(f"{criterion}-optimal gaits", fontsize=FONT_TITLE)
        top.legend(fontsize=FONT_SMALL, loc="lower right")
        _difference(bottom, by_knee)
    figure.suptitle(
        f"{title}\nbars ± {SPREADS:g} spreads of ρ over MuJoCo's physics-step grid",
        fontsize=FONT_TITLE,
    )
    return figure


def rho_difference(rolling: dict, revolute: dict) -> tuple[float, float]:
    """[%] (ρ rolling - ρ revolute) / ρ revolute and its spread (the two spreads combined,
    to first order), from two orbits' figures."""
    a, b = rolling["spectral_radius"], revolute["spectral_radius"]
    sa, sb = rolling["spectral_radius_spread"], revolute["spectral_radius_spread"]
    return relative_change(a, b), 100.0 * (a / b) * float(np.hypot(sa / a, sb / b))


def _difference(ax, by_knee: dict) -> None:
    """ρ's difference between the knees (``rho_difference``) at each speed both have an
    orbit, ± 2 spreads."""
    speeds = sorted(set(by_knee.get("rolling", {})) & set(by_knee.get("revolute", {})))
    found = [
        (v, rho_difference(by_knee["rolling"][v], by_knee["revolute"][v]))
        for v in speeds
        if "spectral_radius" in by_knee["rolling"][v]
        and "spectral_radius" in by_knee["revolute"][v]
    ]
    ax.axhline(0.0, color="k", linewidth=1.0)
    if found:
        ax.errorbar(
            [v for v, _ in found],
            [d for _, (d, _) in found],
            yerr=[SPREADS * s for _, (_, s) in found],
            fmt="o",
            color="0.3",
            capsize=3,
        )
    ax.set_xlabel("walking speed [m/s]")
    ax.set_ylabel(f"ρ: {DIFFERENCE_AXIS}", fontsize=FONT_NOTE)
