"""What the atlas keeps of one optimization (``biped.studies.atlas``: a stage of a knee and
criterion in a cell, ``<stage>/<knee>-<criterion>-<cell>.json``): the ``AtlasOptimum`` record,
each field with its unit, and its one codec (``to_dict``, ``to_json``, ``from_dict``, ``read``).

The file holds the record's fields in order and nothing else (no units map: the units are
declared here, ``units``); a value that is not finite is null.
"""

from __future__ import annotations

import dataclasses
import json
import math
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path

from biped.errors import BipedError
from biped.model.criteria import ALL_CRITERIA, CRITERION_UNITS
from biped.model.units import PURE, declared_units, parameter_unit, unit_field
from biped.optimization.optimize import Optimum, single_start_note
from biped.optimization.problem import variable_names
from biped.optimization.report import Report


def _criterion_unit(criterion: str) -> str:
    return CRITERION_UNITS[criterion]


@dataclass(frozen=True)
class AtlasOptimum:
    """One optimization of the atlas as its file holds it.

    Attributes:
        status: the solver's ("converged", else its own status).
        feasible: the optimum meets every constraint on the check grid.
        certified: converged and feasible (``Optimum.certified``).
        value: the criterion optimised, on the check grid [its unit]; None if not finite.
        costs: every criterion on the check grid, by name [each its unit].
        starts: the starts of the multistart [1].
        starts_at_best: the converged starts at the best value [1].
        single_start: what the next optimum the starts reached is, for a converged optimum
            one start alone reached (``single_start_note``), else None.
        next_optimum: the relative distance from the best to the next optimum the starts
            reached [1] (a ratio less 1), for such an optimum; else 0.
        violations: the violated constraints in one line ("" when feasible).
        period: the step's period T [s].
        step_length: the step's length S [m].
        seconds: the stage's wall time for this optimization [s].
        report: the solver's report of the multistart (``Report``, its fields' units).
        variables: the solver's variables in its family's order
            (``biped.optimization.problem.variable_names``), each its unit
            (``parameter_unit``); None where not finite.
    """

    status: str = unit_field(None)
    feasible: bool = unit_field(None)
    certified: bool = unit_field(None)
    value: float | None = unit_field(_criterion_unit)
    costs: Mapping[str, float] = unit_field({c: CRITERION_UNITS[c] for c in ALL_CRITERIA})
    starts: int = unit_field(PURE)
    starts_at_best: int = unit_field(PURE)
    single_start: str | None = unit_field(None)
    next_optimum: float = unit_field(PURE)
    violations: str = unit_field(None)
    period: float = unit_field("s")
    step_length: float = unit_field("m")
    seconds: float = unit_field("s")
    report: Report = unit_field(Report)
    variables: tuple[float | None, ...] = unit_field(None)  # units: ``units``

    @classmethod
    def from_optimum(cls, optimum: Optimum, seconds: float) -> AtlasOptimum:
        """What a stage keeps of ``optimum``, found in ``seconds`` [s]."""
        report, ev = optimum.report, optimum.evaluation
        single = report.converged and report.starts_at_best < 2
        return cls(
            status=report.status,
            feasible=optimum.feasible,
            certified=optimum.certified,
            value=_finite(optimum.value),
            costs={c: ev.value(c, optimum.step.step_length) for c in ALL_CRITERIA},
            starts=report.starts,
            starts_at_best=report.starts_at_best,
            single_start=single_start_note(report) if single else None,
            next_optimum=_next_optimum(report) if single else 0.0,
            violations=ev.violations_line(),
            period=optimum.step.period,
            step_length=optimum.step.step_length,
            seconds=seconds,
            report=report,
            variables=tuple(_finite(v) for v in optimum.variables),
        )

    @property
    def solved(self) -> bool:
        """The solver ended with all its variables (a start for another solve)."""
        return None not in self.variables

    def to_dict(self) -> dict:
        """The file's object: the fields in order, the report and variables as JSON."""
        content = {f.name: getattr(self, f.name) for f in dataclasses.fields(self)}
        return {
            **content,
            "costs": dict(self.costs),
            "report": self.report.to_dict(),
            "variables": list(self.variables),
        }

    def to_json(self) -> str:
        return json.dumps(self.to_dict(), indent=1, allow_nan=False)

    @classmethod
    def from_dict(cls, content: dict) -> AtlasOptimum:
        """The record of ``to_dict``; a BipedError naming the field if one is missing or of
        another type."""
        if not isinstance(content, dict):
            raise BipedError(f"atlas optimum = {content!r}: allowed an object")
        missing = [f.name for f in dataclasses.fields(cls) if f.name not in content]
        if missing:
            raise BipedError(f"atlas optimum lacks {', '.join(missing)}: allowed every field")
        try:
            fields = {f.name: content[f.name] for f in dataclasses.fields(cls)}
            fields["costs"] = {str(c): float(v) for c, v in content["costs"].items()}
            fields["report"] = Report.from_dict(content["report"])
            fields["variables"] = tuple(
                None if v is None else float(v) for v in fields["variables"]
            )
        except (AttributeError, KeyError, TypeError, ValueError) as error:
            raise BipedError(
                f"atlas optimum: {error!r}: allowed the fields to_dict writes"
            ) from None
        return cls(**fields)

    @classmethod
    def read(cls, path) -> AtlasOptimum | None:
        """The record in the file at ``path``, None if it is missing or unreadable (then the
        stage runs again)."""
        try:
            return cls.from_dict(json.loads(Path(path).read_text()))
        except (OSError, ValueError, UnicodeDecodeError, BipedError):
            return None

    @classmethod
    def units(cls, criterion: str, knots: int) -> dict:
        """The unit of every number of the file of an optimum of ``criterion`` in the family
        of ``knots`` interior knots, by path (``biped.model.units``)."""
        names = variable_names(knots)
        return {
            **declared_units(cls, criterion=criterion),
            "variables": [parameter_unit(name) for name in names],
        }


def _finite(value) -> float | None:
    return float(value) if math.isfinite(value) else None


def _next_optimum(report: Report) -> float:
    """The relative distance to the next optimum the starts reached above the best (0 when
    none did)."""
    best = report.value
    above = [
        s.value
        for s in report.history
        if s.status == "Solve_Succeeded" and math.isfinite(s.value) and s.value > best * (1 + 1e-6)
    ]
    return min(above) / best - 1.0 if above else 0.0
