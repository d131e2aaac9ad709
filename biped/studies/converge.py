"""Both knees' optima over a ladder of nested gait families, until the comparison converges.

At each rung K of the ladder (``biped.optimization.ladder``: 1, 3, 7, 15 interior knots,
each family holding the one below), each knee's optimum of one problem, started from its
optimum at the rung below, and the knees compared (``biped.optimization.knees``): the
difference of the criterion both minimise with its error bar (finer grid, tighter tolerance,
starts), and each optimum's own uncertainty (the same moves of its value).

The convergence rule (``settled``): a sequence has settled at the first rung whose value
changed from the rung below's by no more than that rung's error bar. The comparison has
converged at the first rung where both knees' optima and the difference between them have
settled; each knee's optimum stops improving where its own sequence settles. An error bar
that could not be measured never lets a sequence settle there.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass

from biped.model.gait import family_json, family_label
from biped.optimization.comparison import relative_change
from biped.optimization.knees import KNEES, compare_knees, optimum_uncertainty, resolved
from biped.optimization.ladder import Rung


def settles_at(values, errors, i: int) -> bool:
    """Whether rung ``i``'s value changed from the one below's by no more than its own error
    bar (``errors``, the values' unit; None: unknown, never)."""
    if i < 1 or errors[i] is None:
        return False
    if not all(math.isfinite(v) for v in (values[i], values[i - 1])):
        return False
    return abs(values[i] - values[i - 1]) <= errors[i]


def settled(values, errors) -> int | None:
    """The index of the first rung that ``settles_at``; None when none does."""
    return next((i for i in range(1, len(values)) if settles_at(values, errors, i)), None)


@dataclass(frozen=True)
class KneeRung:
    """One knee's optimum at one rung."""

    value: float  # the criterion on the check grid [its unit, ``CRITERION_UNITS``]
    uncertainty: float | None  # [%] what moves it, relative (None: unknown)
    why_unknown: str | None  # why the uncertainty is unknown
    certified: bool  # converged, feasible on the check grid
    status: str  # IPOPT's
    monotone: bool  # no worse than the rung below's optimum embedded here (1e-9 relative)
    start_value: float | None  # the rung below's optimum on this rung's grid [its unit]
    setup_seconds: float  # [s] building the rung's solvers
    seconds: float  # [s] the rung's multistart
    resolve_seconds: float  # [s] both knees' re-solves (finer grid, tighter), shared

    @property
    def error(self) -> float | None:
        """The uncertainty in the value's unit (None: unknown)."""
        return None if self.uncertainty is None else abs(self.value) * self.uncertainty / 100


@dataclass(frozen=True)
class RungRecord:
    """Both knees at one rung of the ladder."""

    knots: int  # the family: interior knots K, or a ``Bezier``
    parameters: int  # of the family (21 for the paper's spline)
    knees: dict  # knee -> KneeRung
    difference: float  # (rolling − revolute) / revolute [%]
    difference_error: float | None  # [%] its error bar (None: unknown)

    @property
    def certified(self) -> bool:
        return all(rung.certified for rung in self.knees.values())

    def to_dict(self) -> dict:
        return {
            "knots": family_json(self.knots),
            "parameters": self.parameters,
            "difference": self.difference,
            "difference_error": self.difference_error,
            "knees": {knee: _rung_dict(rung) for knee, rung in self.knees.items()},
        }


def _rung_dict(rung: KneeRung) -> dict:
    """A knee's rung as JSON: ``why_unknown`` only where the uncertainty is unknown."""
    found = dict(vars(rung))
    if found["why_unknown"] is None:
        del found["why_unknown"]
    return found


def rung_record(rungs: dict) -> RungRecord:
    """The record of one rung from each knee's ``Rung`` ({knee: Rung}): the knees compared
    where both are certified (else the difference's error bar is unknown)."""
    optima = {knee: rungs[knee].optimum for knee in KNEES}
    both = all(optimum.certified for optimum in optima.values())
    began = time.perf_counter()
    resolves = resolved(optima) if both else None
    spent = time.perf_counter() - began
    if both:
        criterion = compare_knees(optima, resolves)[0]
        difference, error = criterion.value, criterion.uncertainty
    else:
        costs = [optima[knee].value for knee in KNEES]
        difference, error = relative_change(costs[1], costs[0]), None
    knees = {}
    for knee in KNEES:
        rung = rungs[knee]
        moved = (
            optimum_uncertainty(rung.optimum, resolves[0][knee], resolves[1][knee])
            if both
            else "not measured (a knee's optimum is not certified)"
        )
        knees[knee] = KneeRung(
            value=rung.value,
            uncertainty=None if isinstance(moved, str) else moved,
            why_unknown=moved if isinstance(moved, str) else None,
            certified=rung.certified,
            status=rung.optimum.report.status,
            monotone=rung.monotone,
            start_value=rung.start_value,
            setup_seconds=rung.setup_seconds,
            seconds=rung.seconds,
            resolve_seconds=spent / len(KNEES),
        )
    first = rungs[KNEES[0]]
    return RungRecord(first.knots, first.parameters, knees, difference, error)


@dataclass(frozen=True)
class Convergence:
    """The ladder's verdict (module docstring)."""

    converged_at: int | None  # the family (knots K) of the rung where the comparison converged
    stops_improving: dict  # knee -> the family where its optimum settles (None: not yet)

    def to_dict(self) -> dict:
        def written(family):
            return None if family is None else family_json(family)

        stops = {knee: written(family) for knee, family in self.stops_improving.items()}
        return {"converged_at": written(self.converged_at), "stops_improving": stops}


def convergence(records: list[RungRecord]) -> Convergence:
    """Where the comparison converged and where each knee's optimum stops improving."""
    knots = [record.knots for record in records]
    sequences = {
        knee: (
            [record.knees[knee].value for record in records],
            [record.knees[knee].error for record in records],
        )
        for knee in KNEES
    }
    sequences["difference"] = (
        [record.difference for record in records],
        [record.difference_error for record in records],
    )
    both = next(
        (
            i
            for i in range(1, len(records))
            if all(settles_at(*sequence, i) for sequence in sequences.values())
        ),
        None,
    )
    stops = {knee: settled(*sequences[knee]) for knee in KNEES}
    shown = {knee: None if i is None else knots[i] for knee, i in stops.items()}
    return Convergence(None if both is None else knots[both], shown)


__all__ = [
    "Convergence",
    "KneeRung",
    "Rung",
    "RungRecord",
    "convergence",
    "settled",
    "settles_at",
]


def content_of(problem, records: list, verdict: Convergence, robot, unit: str) -> dict:
    """The JSON of a ``biped converge`` run, with the unit of every number (``units``)."""
    from biped.model.units import PERCENT, PURE, robot_unit

    content = {
        "format": "biped-converge/1",
        "speed": problem.speed,
        "criterion": problem.criterion,
        "problem": problem.describe(),
        "robot": robot.to_dict(),
        "rungs": [record.to_dict() for record in records],
        **verdict.to_dict(),
    }
    units = {f"robot.{name}": robot_unit(name) for name in content["robot"] if name != "actuators"}
    family = "" if isinstance(records[0].knots, int) else ".bezier"  # {"bezier": n}
    units.update({"speed": "m/s", f"rungs[].knots{family}": PURE})
    units[_unit_key("converged_at", content["converged_at"])] = PURE
    units.update({"rungs[].parameters": PURE, "rungs[].difference": PERCENT})
    units["rungs[].difference_error"] = PERCENT
    for knee in KNEES:
        key = f"stops_improving.{knee}"
        units[_unit_key(key, content["stops_improving"][knee])] = PURE
        row = f"rungs[].knees.{knee}"
        units.update({f"{row}.value": unit, f"{row}.start_value": unit})
        units[f"{row}.uncertainty"] = PERCENT
        for name in ("setup_seconds", "seconds", "resolve_seconds"):
            units[f"{row}.{name}"] = "s"
    content["units"] = units
    return content


def _unit_key(key: str, written) -> str:
    """The unit's key of a family as written (``family_json``): ``key`` for K or none,
    ``key.bezier`` for {"bezier": n}."""
    return f"{key}.bezier" if isinstance(written, dict) else key


def sentence(records: list, verdict: Convergence, unit: str) -> list[str]:
    """What ``biped converge`` prints: a line a rung, then the verdict in a sentence."""
    lines = []
    for record in records:
        knees = "; ".join(
            f"{knee} {rung.value:.4f} {unit} ± {_shown(rung.uncertainty)}"
            f"{'' if rung.certified else ' NOT CERTIFIED (' + rung.status + ')'}, "
            f"{rung.setup_seconds + rung.seconds:.1f} s"
            for knee, rung in record.knees.items()
        )
        resolves = sum(rung.resolve_seconds for rung in record.knees.values())
        lines.append(
            f"{family_label(record.knots)} ({record.parameters} parameters): {knees}; difference "
            f"{record.difference:+.2f} % ± {_shown(record.difference_error)} (re-solves "
            f"{resolves:.1f} s)"
        )
    stops = ", ".join(
        f"the {knee} knee's at {'no rung yet' if k is None else family_label(k)}"
        for knee, k in verdict.stops_improving.items()
    )
    if verdict.converged_at is None:
        last = records[-1]
        lines.append(
            f"Not converged over {', '.join(family_label(r.knots) for r in records)}: the last "
            "rung's "
            f"difference is {last.difference:+.2f} % ± {_shown(last.difference_error)}; the "
            f"optimum stops improving: {stops}."
        )
    else:
        at = next(r for r in records if r.knots == verdict.converged_at)
        lines.append(
            f"Converged at {family_label(at.knots)} ({at.parameters} parameters): the rolling "
            "knee's "
            f"optimum differs from the revolute knee's by {at.difference:+.2f} % ± "
            f"{_shown(at.difference_error)}; the optimum stops improving: {stops}."
        )
    return lines


def _shown(value) -> str:
    """[%] An error bar as printed, or "unknown"."""
    return "unknown" if value is None else f"{value:.2g} %"
