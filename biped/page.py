"""The page of one gait: Markdown with its figures, for a designer to read before the JSON.

    <out>/<name>.md                  the page
    <out>/<name>/torques.png         joint torques over the step, one panel per joint
    <out>/<name>/angles.png          absolute angles [°], one panel per body
    <out>/<name>/ground.png          |Fx| / Fz against the model's friction, Fz, the ZMP
    <out>/<name>/constraints.png     Ψ1..Ψ7 over the step, the tightest sample of each marked

The page gives the gait's parameters by name with their units, its criteria, the tightest
margin of each constraint (which sample of the step, and how far above the solver's margin δ),
the verdict and figures of its validation in MuJoCo when a report is given, and links to the
recording and the video. ``write_pages`` writes pages as a set, all or none
(``biped.files.atomic_set``). The constraints are computed again from the gait's parameters
on the grid the optimiser checks feasibility on (``CHECK_SAMPLES_PER_HALF``).
"""

from __future__ import annotations

import os
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from matplotlib.figure import Figure

from biped import gait_file
from biped.criteria import CONSTRAINTS, evaluate_step, margin_profile
from biped.dynamics import Biped
from biped.figures import (
    ANGLE_PANELS,
    DPI,
    GROUND_PANELS,
    STYLE,
    TORQUE_PANELS,
    Panel,
    certified,
    time_figure,
)
from biped.files import atomic_set
from biped.gait import PARAMETERS, build_step, half_grid
from biped.optimize import CHECK_SAMPLES_PER_HALF
from biped.units import CONSTRAINT_UNITS, CRITERION_UNITS, parameter_unit

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
COST_NAMES = {
    "sthenic": ("sthenic criterion C_Γ (per metre walked)", CRITERION_UNITS["sthenic"]),
    "energy": ("energy criterion C_E (per step)", CRITERION_UNITS["energy"]),
    "energy_per_metre": ("energy per metre walked", "J/m"),
}
FIGURE_NAMES = ("torques.png", "angles.png", "ground.png", "constraints.png")


@dataclass(frozen=True)
class Tightest:
    """The tightest sample of one constraint: the smallest Ψ_i [unit], at t/T, and δ_i
    there, the margin the solver keeps from it (``biped.criteria.margin_profile``: constant,
    but ramping from 0 at the ends of the step for the swing foot)."""

    name: str
    value: float
    unit: str
    at: float
    margin: float

    @property
    def ratio(self) -> float:
        """Ψ_i / δ_i: about 1 where the constraint binds the optimum."""  # δ_i > 0: Ψ_i checked
        return self.value / self.margin


def constraint_profile(gait: dict) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """On the optimiser's check grid: the step's normalised times t/T (N,), Ψ1..Ψ7 (N, 7)
    less the gait's safety margins (NaN where a constraint is not checked: the swing foot at
    the ends) and the solver's margins δ (N, 7)."""
    model = Biped(gait["robot"], gait["knee"])
    step = build_step(model, gait["speed"], gait_file.parameters(gait))
    evaluation = evaluate_step(model, step, CHECK_SAMPLES_PER_HALF, safety=gait["safety"])
    t_n = np.concatenate(half_grid(CHECK_SAMPLES_PER_HALF))
    return t_n, evaluation.constraints, margin_profile(CHECK_SAMPLES_PER_HALF)


def tightest_margins(gait: dict) -> list[Tightest]:
    """The tightest sample of each constraint (its smallest Ψ_i), the tightest relative to
    the solver's margin there first."""
    t_n, psi, delta = constraint_profile(gait)
    rows = []
    for i, name in enumerate(CONSTRAINTS):
        k = int(np.nanargmin(psi[:, i]))
        unit = CONSTRAINT_UNITS[name]
        rows.append(Tightest(name, float(psi[k, i]), unit, float(t_n[k]), float(delta[k, i])))
    return sorted(rows, key=lambda row: row.ratio)


def _constraint_panels(gait: dict) -> tuple:
    t_n, psi, delta = constraint_profile(gait)

    def panel(i, name):
        def mark(ax, gaits):
            k = int(np.nanargmin(psi[:, i]))
            color = STYLE[gait["knee"]]["color"]
            ax.plot(t_n, delta[:, i], color="0.4", linestyle=":", linewidth=1.2, label="δ")
            ax.plot([t_n[k]], [psi[k, i]], marker="o", markersize=8, fillstyle="none", color=color)
            side = "right" if t_n[k] > 0.7 else "left" if t_n[k] < 0.3 else "center"
            low, high = ax.get_ylim()
            below = psi[k, i] > (low + high) / 2  # the text inside the axes
            ax.annotate(
                f"smallest {psi[k, i]:.3g} {CONSTRAINT_UNITS[name]}\nat t/T = {t_n[k]:.2f}",
                xy=(t_n[k], psi[k, i]),
                xytext=(0, -12 if below else 12),
                textcoords="offset points",
                ha=side,
                va="top" if below else "bottom",
                fontsize=8,
                color=color,
                bbox=dict(boxstyle="round,pad=0.2", fc="white", ec="none", alpha=0.8),
            )

        return Panel(
            CONSTRAINT_MEANING[name],
            f"Ψ{i + 1} [{CONSTRAINT_UNITS[name]}]",
            lambda g: psi[:, i],
            mark,
        )

    return tuple(panel(i, name) for i, name in enumerate(CONSTRAINTS))


def gait_figures(gait: dict) -> dict[str, Figure]:
    """The page's figures of one gait, by file name."""
    gaits = {gait["knee"]: gait}
    return {
        "torques.png": time_figure(gaits, "joint torques", TORQUE_PANELS),
        "angles.png": time_figure(gaits, "absolute angles", ANGLE_PANELS),
        "ground.png": time_figure(gaits, "ground reaction on the stance foot", GROUND_PANELS),
        "constraints.png": time_figure(
            gaits, "constraints Ψ (the solver's margin δ dotted)", _constraint_panels(gait), 4
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
    and content (``gait_file.read``), its validation report (JSON content, or None) and the
    report's path, and links (recording, video)."""

    name: str
    source: Path
    gait: dict
    validation: dict | None = None
    validation_source: Path | None = None
    links: list[Link] = field(default_factory=list)


def _number(value) -> str:
    if value is None:
        return "n/a"
    if isinstance(value, bool):
        return "yes" if value else "no"
    if isinstance(value, (list, tuple)):
        return " to ".join(_number(v) for v in value)
    if isinstance(value, float):
        return f"{value:.4g}"
    return str(value)


def _relative(path: Path, folder: Path) -> str:
    return Path(os.path.relpath(Path(path).resolve(), Path(folder).resolve())).as_posix()


def markdown(page: Page, folder: Path) -> str:
    """The page's Markdown, its links relative to ``folder`` (where the page is written)."""
    gait = page.gait
    report = gait["optimizer"]
    title = f"{gait['knee']} knee, {gait['criterion']}-optimal gait at {gait['speed']:.3f} m/s"
    optimum = (
        "certified optimum"
        if certified(gait)
        else f"not a certified optimum (solver: {report.get('status')}, "
        f"feasible: {_number(gait['feasible'])})"
    )
    lines = [f"# {title}", ""]
    lines += [f"Gait file [`{page.source}`]({_relative(page.source, folder)}): {optimum}."]
    if page.validation is not None:
        verdict = "PASS" if page.validation.get("passed") else "FAIL"
        lines += [f"Validation in MuJoCo: **{verdict}** (below)."]
    else:
        lines += ["Not validated in MuJoCo: no validation report beside the gait file."]
    lines += [""]
    for link in page.links:
        note = f" ({link.note})" if link.note else ""
        lines += [f"- {link.label}: [`{link.path}`]({_relative(link.path, folder)}){note}"]
    if page.links:
        lines += [""]
    safety = gait["safety"]
    lines += ["## Gait", "", "| | value | unit |", "|---|---|---|"]
    lines += [
        f"| walking speed | {gait['speed']:.4g} | m/s |",
        f"| period T | {gait['period']:.4f} | s |",
        f"| step length | {gait['step_length']:.4f} | m |",
        f"| swing-foot clearance asked (beyond the paper's) | {safety.clearance:g} | m |",
        f"| ZMP margin asked (beyond the paper's) | {safety.zmp_margin:g} | m |",
        f"| optimiser | {report.get('method')}: {report.get('status')}, "
        f"{report.get('starts_at_best')} of {report.get('starts')} starts at the best | |",
        "",
        "## Criteria",
        "",
        "| criterion | value | unit |",
        "|---|---|---|",
    ]
    for name, (label, unit) in COST_NAMES.items():
        if name in gait["costs"]:
            optimised = " (optimised)" if name == gait["criterion"] else ""
            lines += [f"| {label}{optimised} | {gait['costs'][name]:.5g} | {unit} |"]
    lines += [
        "",
        "## Constraints: tightest margins",
        "",
        "Each constraint Ψ_i ≥ 0 of eq. (28) at its smallest on the step (where, in t/T), "
        "beside the margin δ_i the solver keeps from it there; the tightest relative to δ "
        "first (Ψ / δ near 1: the constraint binds the optimum).",
        "",
        "| constraint | smallest Ψ | unit | at t/T | δ there | Ψ / δ |",
        "|---|---|---|---|---|---|",
    ]
    for row in tightest_margins(gait):
        lines += [
            f"| {CONSTRAINT_MEANING[row.name]} | {row.value:.4g} | {row.unit} | {row.at:.3f} | "
            f"{row.margin:g} | {row.ratio:.3g} |"
        ]
    lines += ["", "## Parameters", "", "| parameter | value | unit |", "|---|---|---|"]
    lines += [
        f"| {name} | {gait['parameters'][name]:.6g} | {parameter_unit(name)} |"
        for name in PARAMETERS
    ]
    lines += ["", "## Figures", ""]
    for name in FIGURE_NAMES:
        lines += [f"![{name[:-4]}]({page.name}/{name})", ""]
    if page.validation is not None:
        lines += _validation_lines(page, folder)
    return "\n".join(lines) + "\n"


def _validation_lines(page: Page, folder: Path) -> list[str]:
    report = page.validation
    units = report.get("units") or {}
    verdict = "PASS" if report.get("passed") else "FAIL"
    lines = ["## Validation in MuJoCo", ""]
    if page.validation_source is not None:
        where = _relative(page.validation_source, folder)
        lines += [f"Report [`{page.validation_source}`]({where}): **{verdict}**.", ""]
    for check, figures in report.items():
        if not isinstance(figures, dict) or "passed" not in figures:
            continue
        lines += [f"### {check}: {'PASS' if figures['passed'] else 'FAIL'}", ""]
        lines += ["| figure | value | unit |", "|---|---|---|"]
        for name, value in figures.items():
            if name not in ("passed", "notes"):
                lines += [f"| {name} | {_number(value)} | {units.get(f'{check}.{name}', '')} |"]
        lines += [""]
        notes = figures.get("notes") or []
        if notes:  # sentences, one a line (a list of figures is a range: "low to high")
            lines += [f"- {note}" for note in notes] + [""]
    return lines


def write_pages(pages: list[Page], out: str | Path) -> list[Path]:
    """Write each page and its figures into ``out``, all or none; returns the pages' paths."""
    out = Path(out)
    rendered = [(page, gait_figures(page.gait), markdown(page, out)) for page in pages]
    with atomic_set(out, "report") as staging:
        for page, figures, text in rendered:
            (staging / page.name).mkdir()
            for name, figure in figures.items():
                figure.savefig(staging / page.name / name, dpi=DPI)
            (staging / f"{page.name}.md").write_text(text, encoding="utf-8")
    return [out / f"{page.name}.md" for page in pages]
