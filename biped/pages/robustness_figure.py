"""The figure of a robustness map (``validate.studies.robustness``): one row per condition.

Drawn from the map (a ``validate.studies.robustness.RobustnessMap``, read by its fields:
``limits``, ``settings``, ``push_time``; one written earlier read back by
``RobustnessMap.from_dict``), without MuJoCo. Each row: the range the gait walks over (a bar
from one limit to the other), the bisection's uncertainty beyond each limit up to the first
value that failed (hatched), the bracket searched (grey line) and the nominal walk's value
(black line).
"""

from __future__ import annotations

from matplotlib.figure import Figure

from biped.pages.style import FONT_NOTE, FONT_TITLE, ROBUSTNESS_SIZE

WALKS = "#2a9d8f"
UNSURE_BAR = dict(color="#e9c46a", hatch="///", edgecolor="0.3")
BRACKET = "0.6"

# Rows: title, the limits at the low and the high end (None: the nominal value is that end),
# the factor of the drawn values, the axis scale.
ROWS = (
    ("push on the trunk [N·s]", "push_backward", "push_forward", 1.0, "linear"),
    ("friction coefficient μ", "friction", None, 1.0, "linear"),
    ("trunk mass error [%]", "trunk_mass_lighter", "trunk_mass_heavier", 100.0, "linear"),
    ("servo stiffness kp / kp₀", "kp_scale_low", "kp_scale_high", 1.0, "log"),
)


def _end(limit, factor: float) -> tuple:
    """A limit's end of its row: (the value found to walk, the first value found to fail or
    None, the bracket's far end), each times ``factor``."""
    fails = limit.fails_at
    return (
        factor * limit.limit,
        None if fails is None else factor * fails,
        factor * limit.bracket[1],
    )


def robustness_figure(result, title: str) -> Figure:
    """The figure of a map (``RobustnessMap``) whose nominal walk walked."""
    limits = result.limits
    figure = Figure(figsize=ROBUSTNESS_SIZE, layout="constrained")
    axes = figure.subplots(len(ROWS), 1)
    for ax, (label, low, high, factor, scale) in zip(axes, ROWS, strict=True):
        nominal = factor * limits[low].bracket[0]
        searched = [_end(limits[name], factor) for name in (low, high) if name is not None]
        (low_walks, _, low_far), (high_walks, _, high_far) = (
            (nominal, None, nominal) if name is None else _end(limits[name], factor)
            for name in (low, high)  # None: the nominal value is that end, not searched
        )
        ax.set_xscale(scale)
        ax.plot([low_far, high_far], [0, 0], color=BRACKET, linewidth=1, zorder=1)
        ax.barh(0, high_walks - low_walks, left=low_walks, height=0.5, color=WALKS, zorder=2)
        for walks, fails, _ in searched:
            if fails is not None:
                start, stop = sorted((walks, fails))
                ax.barh(0, stop - start, left=start, height=0.5, zorder=2, **UNSURE_BAR)
            text = f"{walks:.3g}" if fails is not None else f"≥ {walks:.3g} (bracket end walks)"
            ax.annotate(text, (walks, 0.3), ha="center", va="bottom", fontsize=FONT_NOTE)
        ax.axvline(nominal, color="k", linewidth=1.5, zorder=3)
        ax.annotate(
            f"nominal {nominal:g}", (nominal, -0.3), ha="center", va="top", fontsize=FONT_NOTE
        )
        ax.set_ylim(-0.8, 0.8)
        ax.set_yticks([])
        ax.set_title(label, fontsize=FONT_TITLE, loc="left")
    settings = result.settings
    figure.suptitle(
        f"{title}\nwalks of {settings.steps} steps, pushes at mid-step {settings.push_step} "
        f"({result.push_time:.3f} s), {settings.iterations} bisections per limit\n"
        "green: walks; hatched: up to the first failing value; grey: bracket searched",
        fontsize=FONT_TITLE,
    )
    return figure
