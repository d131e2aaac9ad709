"""The figure of a sweep with double support (``biped.records.two_phase_sweep``): against
speed, the knees' difference in C_Γ (what the optima minimise) and in the same optima's
energy per metre C_E / S, with and without the double support phase, then each knee's step
length and cadence, single support alone (dashed) and with double support (solid). A figure
not known (a point not certified, a file without its double support's work) is left out,
never drawn as zero.
"""

from __future__ import annotations

from pathlib import Path

from matplotlib.figure import Figure

from biped.pages.style import (
    FONT_NOTE,
    FONT_TITLE,
    KNEE_LABELS,
    KNEE_STYLE,
    TWO_PHASE_SWEEP_SIZE,
    save,
)
from biped.records.two_phase_sweep import TwoPhaseSweepSummary

PHASE_LINES = {"single": "--", "double": "-"}
PHASE_LABELS = {"single": "single support", "double": "with double support"}


def _known(pairs):
    """(speeds, values) of the pairs whose value is known."""
    kept = [(s, v) for s, v in pairs if v is not None]
    return [s for s, _ in kept], [v for _, v in kept]


def two_phase_sweep_figure(summary: TwoPhaseSweepSummary, path: str | Path) -> Path:
    """Write the figure of ``summary`` as the PNG ``path``; returns it."""
    fig = Figure(figsize=TWO_PHASE_SWEEP_SIZE, layout="constrained")
    difference, energy, length, cadence = fig.subplots(1, 4)
    for axis, prefix, figure in (
        (difference, "", "C_Γ"),
        (energy, "energy_", "C_E / S of the same optima"),
    ):
        for phase, line in PHASE_LINES.items():
            x, y = _known((d.speed, getattr(d, prefix + phase)) for d in summary.differences)
            axis.plot(x, y, line, color="0.2", marker="o", label=PHASE_LABELS[phase])
        axis.axhline(0.0, color="0.6", linewidth=0.8)
        axis.set(xlabel="speed [m/s]", ylabel=f"{figure}, (rolling − revolute) / revolute [%]")
    difference.set_title(
        "the knees' difference (< 0: the rolling knee needs less)", fontsize=FONT_TITLE
    )
    energy.set_title("the joints' work per metre, knees' difference", fontsize=FONT_TITLE)
    for knee in sorted({p.knee for p in summary.points}):
        rows = [p for p in summary.points if p.knee == knee]
        for phase, line in PHASE_LINES.items():
            label = f"{KNEE_LABELS[knee]}, {PHASE_LABELS[phase]}"
            for axis, field in ((length, "step_length"), (cadence, "cadence")):
                pairs = ((r.speed, _field(getattr(r, phase), field)) for r in rows)
                x, y = _known(pairs)
                axis.plot(x, y, line, label=label, **KNEE_STYLE[knee])
    length.set(xlabel="speed [m/s]", ylabel="step length S [m]")
    length.set_title("step length", fontsize=FONT_TITLE)
    cadence.set(xlabel="speed [m/s]", ylabel="cadence 60 / (T + T_ds) [steps/min]")
    cadence.set_title("cadence", fontsize=FONT_TITLE)
    low, high = summary.share_range
    fig.suptitle(
        f"double support {low:g} to {high:g} of the step, {summary.landing} landing, "
        "sthenic optima",
        fontsize=FONT_TITLE,
    )
    for axis in (difference, energy, length, cadence):
        axis.legend(fontsize=FONT_NOTE)
        axis.grid(alpha=0.3)
    return save(fig, path)


def _field(phases, field: str):
    return None if phases is None else getattr(phases, field)
