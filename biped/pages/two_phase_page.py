"""The page of a two-phase gait (``biped optimize --double-support``): its Markdown, beside
the single support page's layout (``biped.pages.page``), with the figures of both phases
(``biped.pages.two_phase_figures``).

It names both phases and gives: the step's durations, the double support's share of the
step (within the problem's range), the step length and cadence, the sthenic criterion over
both phases, each beside the single support optimum's when one of the same knee, robot and
speed is given (``Page.single``); the landing (an impact holding both feet or a zero-speed
landing) and its impulses on each foot; each foot's tightest margin in double support; the
parameters by name with their units; the figures; and the validation in MuJoCo with the
checks not built for two phases said as not run (unknown, neither passed nor failed by the
gait).
"""

from __future__ import annotations

from pathlib import Path

from biped.model.double_support import FOOT_CONSTRAINTS
from biped.model.robot import FOOT_FRICTION
from biped.model.units import unit_text
from biped.pages.page import NOT_TABLED, Page, figure_text, relative_link
from biped.pages.two_phase_figures import FIGURE_NAMES, step_duration
from biped.records.gait_file import Gait
from biped.records.two_phase_gait import FEET, FOOT_UNITS, unit_of

# The landing's impulse on each foot (``TwoPhaseStep.impulse``): its components and units.
IMPULSE = (("Ix", "N·s"), ("Iz", "N·s"), ("Iy", "N·m·s"))
LANDING_WORDS = {
    "impact": "an impact that stops both feet (eqs. 21-24 with both feet held; the rear foot "
    "must be pushed by the ground, Iz ≥ 0)",
    "zero-speed": "at zero foot speed: the front foot arrives at rest, nothing jumps, no impulse",
}
FOOT_WORDS = {
    "normal_force": "normal force Fz",
    "friction_forward": "μ Fz − Fx",
    "friction_backward": "μ Fz + Fx",
    "zmp_heel": "ZMP ahead of the heel",
    "zmp_toe": "ZMP behind the toe",
}
# Why the page's curves of the rear foot kink in double support.
FRONT_RULE = (
    "The front foot's wrench is the optimizer's at its samples of the double support, linear "
    "between them (the file's rule): the rear foot's wrench and the torques follow from it, "
    "with a kink at each sample."
)
# Why the single support's curves jump at mid-step (``biped.pages.page.KNOT_WHY``'s reason).
KNOT_RULE = (
    "The single support's torques and ground forces jump at its mid-step, t = T/2: the "
    "paper's spline is C¹ there (eqs. 25-26), so the accelerations jump. At the landing the "
    "torques and the rear foot's forces jump too: the front foot takes its share of the load."
)
NOT_RUN = "not run"


def cadence(duration: float) -> float:
    """[steps/min] of a step lasting ``duration`` [s]."""
    return 60.0 / duration


def single_of(gait: Gait, candidates) -> Gait | None:
    """Among ``candidates``, the single support gait of the two-phase ``gait``'s knee, robot
    and speed (the first), else None."""
    for other in candidates:
        if (
            not other.two_phase
            and other.knee == gait.knee
            and other.robot == gait.robot
            and abs(other.speed - gait.speed) <= 1e-9
        ):
            return other
    return None


def phase_rows(gait: Gait, single: Gait | None) -> list[str]:
    """The table of the phases, beside the single support optimum's where given."""
    double = gait.double_support
    low, high = double.share_range
    rows = [
        ("single support T", gait.period, None if single is None else single.period, "s"),
        ("double support T_ds", double.duration, 0.0 if single else None, "s"),
        ("double support's share T_ds / (T + T_ds)", double.share, 0.0 if single else None, "1"),
        ("step T + T_ds", step_duration(gait), None if single is None else single.period, "s"),
        ("step length S", gait.step_length, None if single is None else single.step_length, "m"),
        (
            "cadence",
            cadence(step_duration(gait)),
            None if single is None else cadence(single.period),
            "steps/min",
        ),
        (
            "sthenic criterion C_Γ over the step",
            double.sthenic,
            None if single is None else single.costs.sthenic,
            "N²·m·s",
        ),
    ]
    if double.energy_per_metre is not None:  # a file written before has none
        rows.append(
            (
                "joints' work per metre C_E / S over the step",
                double.energy_per_metre,
                None if single is None else single.costs.energy_per_metre,
                "J/m",
            )
        )
    given = "single support optimum" if single else "single support optimum (not given)"
    lines = [f"| | two phases | {given} | unit |", "|---|---|---|---|"]
    for label, value, other, unit in rows:
        shown = "—" if other is None else f"{other:.4g}"
        lines += [f"| {label} | {value:.4g} | {shown} | {unit} |"]
    lines += [
        "",
        f"The problem allowed a share of {low:g} to {high:g}; the optimum's is {double.share:.4g}.",
    ]
    if single is None:
        lines += [
            "No single support gait of the same knee, robot and speed was given: pass its file "
            "to the same `biped report` to see it beside."
        ]
    return lines


def landing_friction(impulse) -> float | None:
    """|Ix| / Iz of one foot's landing impulse (Ix, Iz, Iy): the friction coefficient the
    landing needs on it; None where the ground gives no push (Iz <= 0: no friction holds)."""
    ix, iz = impulse[0], impulse[1]
    return abs(ix) / iz if iz > 0.0 else None


def landing_lines(gait: Gait) -> list[str]:
    """The landing's kind, its impulse on each foot and the friction each foot needs for it
    against the model's."""
    double = gait.double_support
    lines = [
        "",
        "## Landing",
        "",
        f"The landing is {LANDING_WORDS[double.landing]}.",
    ]
    if double.landing != "impact":
        return lines
    lines += [
        "",
        "| foot | "
        + " | ".join(f"{name} [{unit}]" for name, unit in IMPULSE)
        + " | \\|Ix\\| / Iz: friction needed [1] |",
        "|---" * (len(IMPULSE) + 2) + "|",
    ]
    impulse = double.landing_impulse
    for f, foot in enumerate(FEET):
        values = impulse[3 * f : 3 * f + 3]
        needed = landing_friction(values)
        shown = "no push (Iz ≤ 0): none holds" if needed is None else f"{needed:.3g}"
        lines += [f"| {foot} | " + " | ".join(f"{v:.4g}" for v in values) + f" | {shown} |"]
    worst = [landing_friction(impulse[3 * f : 3 * f + 3]) for f in range(len(FEET))]
    over = [foot for foot, w in zip(FEET, worst, strict=True) if w is None or w > FOOT_FRICTION]
    lines += [
        "",
        f"The model's friction is μ = {FOOT_FRICTION:g}: "
        + (
            f"the landing needs more on the {' and '.join(over)} "
            f"{'feet' if len(over) > 1 else 'foot'}: in MuJoCo it would slide there."
            if over
            else "both feet hold through the landing."
        ),
    ]
    return lines


def feet_lines(gait: Gait) -> list[str]:
    """Each foot's tightest margin Ψ in double support (on the file's fine grid)."""
    double = gait.double_support
    lines = [
        "",
        "## Both feet in double support",
        "",
        "Each foot's constraints Ψ ≥ 0 at their smallest over the double support's "
        f"{len(double.samples.t)} samples, the front wrench linear between the optimizer's "
        f"{len(double.front_wrench)} (rear foot pushed at the landing too): "
        f"{'all hold' if double.feasible else 'NOT all hold: the gait is not feasible'}.",
        "",
        "| constraint | " + " | ".join(f"{foot} foot" for foot in FEET) + " | unit |",
        "|---|---|---|---|",
    ]
    for k, name in enumerate(FOOT_CONSTRAINTS):
        values = " | ".join(f"{double.foot_margins[foot][k]:.4g}" for foot in FEET)
        lines += [f"| {FOOT_WORDS[name]} | {values} | {FOOT_UNITS[k]} |"]
    return lines


def validation_summary(report) -> str:
    """The verdict of a validation report and why: the checks run that pass, those not run
    (unknown: the report fails without them)."""
    if report is None:
        return "none (no report beside the gait file nor its recording: `biped validate`)."
    not_run = [c.name for c in report.checks if NOT_RUN in c.causes]
    run = [c for c in report.checks if NOT_RUN not in c.causes]
    unknown = f"; not run, unknown: {', '.join(not_run)}" if not_run else ""
    verdict = "PASS" if report.passed else "FAIL"
    passed = sum(c.passed for c in run)
    return f"**{verdict}** ({passed} of the {len(run)} checks run pass{unknown})."


def validation_lines(report, source: Path | None, where: str | None) -> list[str]:
    """The validation's section: its verdict, each check's figures; a check not built for two
    phases said as not run (unknown), never as passed."""
    lines = ["## Validation in MuJoCo", ""]
    if source is not None:
        lines += [f"Report [`{source}`]({where})."]
    lines += [validation_summary(report), ""]
    for check in report.checks:
        if NOT_RUN in check.causes:
            lines += [f"### {check.name}: NOT RUN (unknown)", ""]
        else:
            said = f" ({', '.join(check.causes)})" if check.causes else ""
            lines += [f"### {check.name}: {'PASS' if check.passed else 'FAIL'}{said}", ""]
        tabled = {n: v for n, v in check.figures.items() if n not in NOT_TABLED}
        if tabled:
            lines += ["| figure | value | unit |", "|---|---|---|"]
            lines += [
                f"| {n} | {figure_text(v)} | {unit_text(check.units.get(n, ''))} |"
                for n, v in tabled.items()
            ]
            lines += [""]
        if check.notes:
            lines += [f"- {note}" for note in check.notes] + [""]
    return lines


def two_phase_markdown(page: Page, folder: Path) -> str:
    """The Markdown of ``page`` of a two-phase gait, its links relative to ``folder``."""
    gait = page.gait
    optimizer = gait.optimizer
    title = (
        f"{gait.knee} knee, two-phase sthenic-optimal gait at {gait.speed:.3f} m/s: "
        "single support then double support"
    )
    converged = optimizer.status == "converged"
    state = (
        "a converged and feasible optimum"
        if converged and gait.feasible
        else f"not an optimum to trust (solver: {optimizer.status}, feasible: "
        f"{'yes' if gait.feasible else 'no'})"
    )
    lines = [f"# {title}", ""]
    lines += [f"Gait file [`{page.source}`]({relative_link(page.source, folder)}): {state}"]
    if optimizer.starts_at_best == 1:
        lines[-1] += f", reached by a single start of {optimizer.starts}"
    lines[-1] += "."
    lines += [f"Validation in MuJoCo: {validation_summary(page.validation)}", ""]
    for link in page.links:
        note = f" ({link.note})" if link.note else ""
        lines += [f"- {link.label}: [`{link.path}`]({relative_link(link.path, folder)}){note}"]
    if page.links:
        lines += [""]
    lines += ["## Phases", ""]
    lines += phase_rows(gait, page.single)
    lines += landing_lines(gait)
    lines += feet_lines(gait)
    lines += ["", "## Parameters", "", "| parameter | value | unit |", "|---|---|---|"]
    lines += [f"| {n} | {v:.6g} | {unit_of(n)} |" for n, v in gait.parameters.items()]
    lines += ["", "## Figures", "", f"The double support is shaded. {KNOT_RULE}", ""]
    lines += [FRONT_RULE, ""]
    lines += [f"![{name[:-4]}]({page.name}/{name})" + "\n" for name in FIGURE_NAMES]
    if page.validation is not None:
        where = None
        if page.validation_source is not None:
            where = relative_link(page.validation_source, folder)
        lines += validation_lines(page.validation, page.validation_source, where)
    return "\n".join(lines) + "\n"
