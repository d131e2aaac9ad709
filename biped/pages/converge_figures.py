"""The figure of ``biped converge`` (``biped.studies.converge``): each knee's optimum and the
difference between the knees against the number of parameters of the gait family, with
their error bars, the paper's family marked."""

from __future__ import annotations

import numpy as np
from matplotlib.figure import Figure
from matplotlib.ticker import NullLocator

from biped.model.criteria import CRITERION_UNITS
from biped.model.gait import family_label
from biped.pages.style import CONVERGE_SIZE, FONT_NOTE, KNEE_STYLE

PAPER_PARAMETERS = 21  # the paper's spline, one interior knot


def converge_figure(records, criterion: str, speed: float, converged_at) -> Figure:
    """Two panels over the parameters of each rung (``RungRecord``): each knee's optimum
    [the criterion's unit] and the difference (rolling − revolute) / revolute [%], each with
    its error bar (none where unknown), the paper's family and the rung of convergence
    marked."""
    fig = Figure(figsize=CONVERGE_SIZE, layout="constrained")
    top, bottom = fig.subplots(2, 1, sharex=True)
    size = np.array([record.parameters for record in records], dtype=float)
    for knee, style in KNEE_STYLE.items():
        values = np.array([record.knees[knee].value for record in records])
        errors = np.array([_known(record.knees[knee].error) for record in records])
        top.errorbar(size, values, yerr=errors, label=f"{knee} knee", capsize=3, **style)
    bars = np.array([_known(record.difference_error) for record in records])
    differences = np.array([record.difference for record in records])
    bottom.errorbar(size, differences, yerr=bars, color="k", marker="D", capsize=3)
    for n, difference, bar in zip(size, differences, bars, strict=True):
        shown = "± unknown" if np.isnan(bar) else f"± {bar:.2g} %"
        bottom.annotate(shown, (n, difference), textcoords="offset points", xytext=(6, 6),
                        fontsize=FONT_NOTE)  # fmt: skip
    bottom.axhline(0.0, color="0.5", lw=0.6)
    paper = any(record.knots == 1 for record in records)  # no rung of a Bézier ladder
    for ax in (top, bottom):
        if paper:
            ax.axvline(PAPER_PARAMETERS, color="0.6", ls=":", lw=1.0)
            ax.text(PAPER_PARAMETERS, 0.97, " paper's family (K = 1)", fontsize=FONT_NOTE, va="top",
                    transform=ax.get_xaxis_transform())  # fmt: skip
        if converged_at is not None:
            at = next(r.parameters for r in records if r.knots == converged_at)
            ax.axvline(at, color="tab:green", lw=1.0)
        ax.grid(alpha=0.3)
        ax.set_xscale("log")
        ax.xaxis.set_minor_locator(NullLocator())
    ax = bottom
    labels = [f"{int(n)}\n({family_label(r.knots)})" for n, r in zip(size, records, strict=True)]
    ax.set_xticks(size, labels)
    top.set_ylabel(f"{criterion} optimum [{CRITERION_UNITS[criterion]}]")
    top.legend(title="error bars: finer grid, tighter tolerance, starts", title_fontsize=FONT_NOTE)
    bottom.set_ylabel("rolling vs revolute [%]")
    kind = "interior knots K" if paper or isinstance(records[0].knots, int) else "Bézier degree n"
    bottom.set_xlabel(f"parameters of the gait family ({kind})")
    verdict = (
        "not converged" if converged_at is None else f"converged at {family_label(converged_at)}"
    )
    top.set_title(f"optima over nested gait families, {speed:g} m/s ({verdict})")
    return fig


def _known(error) -> float:
    return float("nan") if error is None else float(error)
