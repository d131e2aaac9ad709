"""The page of ``biped criteria`` (``biped.studies.criteria_matrix``): per knee the table of
every criterion measured on each criterion's optimum and what optimizing one criterion costs
in another, the knees' difference at each optimum, and the sentence the command prints.
Unknown figures are written "unknown", never 0."""

from __future__ import annotations

from biped.model.criteria import CRITERION_UNITS, PAPER_SAFETY, WALKABLE
from biped.model.gait import family_label
from biped.studies.criteria_matrix import STUDIED, CriteriaStudy, KneeMatrix

UNKNOWN = "unknown"
COSTS_WORDS = (
    "What optimizing each criterion (rows) costs in each other (columns), relative to that "
    "other's own optimum:"
)
WHY_WORDS = (
    "Where the electrical energy goes (the same gaits; each part is the electrical energy "
    "less its value without the drives' friction, or without the rotors' inertia):"
)
# The margins' presets named.
MARGINS = {PAPER_SAFETY: "the paper's constraints", WALKABLE: "the walkable constraints"}


def family_words(study: CriteriaStudy) -> str:
    """ "the paper's spline (21 parameters)", "splines of K = 15 (189 parameters)",
    "Bézier curves of n = 11 (57 parameters)"."""
    family = study.family
    if family == 1:
        name = "the paper's spline"
    elif isinstance(family, int):
        name = f"splines of {family_label(family)} interior knots"
    else:
        name = f"Bézier curves of degree {family.degree}"
    return f"{name} ({study.parameters} parameters)"


def problem_words(study: CriteriaStudy) -> str:
    """The problem in words: speed, family, margins."""
    margins = MARGINS.get(study.safety, "margins of ours (criteria.json's safety)")
    return f"{study.speed:g} m/s, {family_words(study)}, {margins}"


def _value(value: float | None, digits: int = 4) -> str:
    return UNKNOWN if value is None else f"{value:.{digits}f}"


def _percent(value: float | None, digits: int = 1) -> str:
    return UNKNOWN if value is None else f"{value:+.{digits}f} %"


def _column(criterion: str) -> str:
    return f"{criterion} [{CRITERION_UNITS[criterion]}]"


def values_table(matrix: KneeMatrix) -> list[str]:
    """One knee's matrix: a row per criterion minimised, every criterion measured on its
    optimum (the diagonal in bold), the step, whether it is certified, and how many starts
    reached its value (one alone: another optimum may lie near, other in the other
    criteria)."""
    head = " | ".join(map(_column, STUDIED)) + " | period [s] | step [m] | starts at its value |"
    lines = ["| optimum of | " + head, "|---" * (len(STUDIED) + 4) + "|"]
    for row in matrix.rows:
        cells = []
        for measured in STUDIED:
            shown = _value(row.values.of(measured))
            cells.append(f"**{shown}**" if measured == row.optimized else shown)
        flag = "" if row.certified else f" (NOT CERTIFIED: {row.status})"
        step = f"{row.period:.4f} | {row.step_length:.4f}"
        starts = f"{row.starts_at_best} of {row.starts}"
        lines.append(f"| {row.optimized}{flag} | " + " | ".join(cells) + f" | {step} | {starts} |")
    return lines


def costs_table(matrix: KneeMatrix) -> list[str]:
    """What optimizing each criterion (row) costs in each other (column), relative to that
    other's own optimum [%]."""
    lines = ["| optimum of | " + " | ".join(STUDIED) + " |", "|---" * (len(STUDIED) + 1) + "|"]
    for optimized in STUDIED:
        cells = [
            "0 (its own)" if measured == optimized else _percent(matrix.cost(optimized, measured))
            for measured in STUDIED
        ]
        lines.append(f"| {optimized} | " + " | ".join(cells) + " |")
    return lines


def why_table(matrix: KneeMatrix) -> list[str]:
    """Where each optimum's electrical energy goes: the parts of the drives' friction and
    of the rotors' inertia in it (what the sthenic criterion does not see), and the joints'
    braking work, which the energy criteria pay as work and the electrical one barely
    (``biped.studies.criteria_matrix``: ``electrical_without``, ``braking_work``)."""
    lines = [
        "| optimum of | electrical [J/m] | of it, the drives' friction [J/m] | the rotors' "
        "inertia [J/m] | braking work [J/m] |",
        "|---|---|---|---|---|",
    ]
    for row in matrix.rows:
        optimized = row.optimized
        cells = (
            row.values.of("electrical"),
            matrix.part(optimized, "frictionless"),
            matrix.part(optimized, "rotorless"),
            row.braking,
        )
        lines.append(f"| {optimized} | " + " | ".join(_value(c, 2) for c in cells) + " |")
    return lines


def differences_table(study: CriteriaStudy) -> list[str]:
    """(rolling − revolute) / revolute [%] of each criterion (column) at each knee's optimum
    of each criterion (row)."""
    lines = ["| optimum of | " + " | ".join(STUDIED) + " |", "|---" * (len(STUDIED) + 1) + "|"]
    for optimized in STUDIED:
        cells = [_percent(study.difference(optimized, measured), 2) for measured in STUDIED]
        lines.append(f"| {optimized} | " + " | ".join(cells) + " |")
    return lines


def sentence(study: CriteriaStudy) -> list[str]:
    """What ``biped criteria`` prints last: per knee whether each optimum is the least in
    its own criterion and the largest cost of optimizing one criterion for another; the
    knees' difference at each criterion's own optimum."""
    lines = []
    for matrix in study.knees:
        verdict = matrix.diagonal_least()
        if verdict is None:
            bad = ", ".join(row.optimized for row in matrix.rows if not row.certified)
            lines.append(f"{matrix.knee} knee: NOT CERTIFIED ({bad}): its costs are unknown.")
            continue
        if not verdict:
            pairs = "; ".join(
                f"the {a} optimum is lower in {b} than its own" for a, b in matrix.exceptions()
            )
            lines.append(f"{matrix.knee} knee: an optimum is not the least of its criterion: "
                         f"{pairs}.")  # fmt: skip
            continue
        pairs = [(a, b) for a in STUDIED for b in STUDIED if a != b]
        worst = max(pairs, key=lambda pair: matrix.cost(*pair))
        least = min(pairs, key=lambda pair: matrix.cost(*pair))
        lines.append(
            f"{matrix.knee} knee: each optimum is the least of its own criterion; optimizing "
            f"{worst[0]} costs {_percent(matrix.cost(*worst))} in {worst[1]}, the most, "
            f"optimizing {least[0]} {_percent(matrix.cost(*least))} in {least[1]}, the least."
            + _why(matrix)
        )
    own = ", ".join(f"{c} {_percent(study.difference(c, c), 2)}" for c in STUDIED)
    lines.append(f"Rolling vs revolute, each at its own optimum of the criterion: {own}.")
    return lines


def tables(study: CriteriaStudy) -> list[str]:
    """Each knee's tables (values, costs) and the knees' differences, as Markdown lines."""
    lines = []
    for matrix in study.knees:
        lines += [f"## {matrix.knee} knee", "", *values_table(matrix), ""]
        lines += [COSTS_WORDS, "", *costs_table(matrix), ""]
        lines += [WHY_WORDS, "", *why_table(matrix), ""]
    lines += ["## Rolling vs revolute", "", "(rolling − revolute) / revolute of each criterion "
              "(columns) at each knee's optimum of a criterion (rows):", ""]  # fmt: skip
    return [*lines, *differences_table(study)]


def _why(matrix: KneeMatrix) -> str:
    """Why the electrical optimum parts from the others, in a sentence ("" where unknown)."""
    electrical = matrix.known("sthenic", "electrical")
    friction = matrix.part("sthenic", "frictionless")
    rotors = matrix.part("sthenic", "rotorless")
    braking = [matrix.row(optimized).braking for optimized in ("sthenic", "electrical")]
    if not electrical or None in (friction, rotors, *braking):
        return ""
    return (
        f" Of the sthenic optimum's electrical energy, {electrical:.1f} J/m, the drives' "
        f"friction makes {friction:.1f} and the rotors' inertia {rotors:.1f} J/m, which the "
        f"sthenic criterion does not see; the electrical optimum brakes the joints by "
        f"{braking[1]:.2f} J/m (the sthenic optimum {braking[0]:.2f})."
    )


def markdown(study: CriteriaStudy, figure: str | None = None, seconds: float | None = None) -> str:
    """The page: the problem, ``tables``, the sentence and the ``figure`` (its file name
    beside the page)."""
    starts = f"{study.starts} start{'s' if study.starts > 1 else ''}"
    lines = [
        f"# Criteria side by side at {problem_words(study)}",
        "",
        "Each knee's gait optimized for each criterion (rows), every criterion measured on "
        "each optimum on its check grid (columns; each optimum's own criterion in bold). "
        f"Seed {study.seed}, {starts} of IPOPT's own per optimization"
        + ("." if seconds is None else f", {seconds:.0f} s in all."),
        "",
        *tables(study),
        "",
        *sentence(study),
    ]
    if figure is not None:
        lines += ["", f"![Each criterion on each criterion's optimum, both knees]({figure})"]
    return "\n".join(lines) + "\n"


__all__ = [
    "costs_table",
    "differences_table",
    "markdown",
    "sentence",
    "tables",
    "values_table",
    "why_table",
]
