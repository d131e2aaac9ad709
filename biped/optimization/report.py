"""How an optimum was found, as gait files record it (``optimizer``): the solver's report of
a multistart (``Report``) and of each of its starts (``Start``), and their JSON form. Kept apart
from the solvers (``biped.optimization.optimize``), so that reading a gait file needs neither
CasADi nor MuJoCo.

May import: ``biped.model``, the standard library, numpy.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

import numpy as np

from biped.model.criteria import CRITERION_UNITS
from biped.model.units import PURE, unit_field


def _criterion_unit(criterion: str) -> str:
    """The unit of a value of ``criterion`` (what the value is: ``SOLVER_VALUE``)."""
    return CRITERION_UNITS[criterion]


@dataclass(frozen=True)
class Start:
    """One start of the solver and where it ended."""

    kind: str  # "first guess", "perturbed", "nelder-mead", "given"
    value: float = unit_field(_criterion_unit)  # criterion reached (SOLVER_VALUE)
    status: str  # solver status
    iterations: int = unit_field(PURE)


@dataclass(frozen=True)
class Report:
    """How an optimum was found, as recorded in gait files (``optimizer``): ``status`` is
    ``"converged"`` when the best start's solver converged, else the solver's own status
    (IPOPT's return status, or ``"budget exhausted"`` for Nelder-Mead); the numbers at the
    best start, ``starts_at_best`` the converged starts within ``AGREEMENT`` of its value (the
    sthenic optimum under both barriers counts once)."""

    method: str  # "ipopt" or "nelder-mead"
    status: str
    starts: int = unit_field(PURE)
    starts_at_best: int = unit_field(PURE)
    iterations: int = unit_field(PURE)  # the best start's
    # the largest violation of a constraint or bound at the best point, of the solver's
    # scaled constraints
    constraint_violation: float = unit_field(PURE)
    dual_infeasibility: float = unit_field(PURE)  # IPOPT's measure; NaN for Nelder-Mead
    seconds: float = unit_field("s")  # wall time of all starts
    seed: int = unit_field(PURE)  # of the perturbed starts and of Nelder-Mead's restarts
    # SOLVER_VALUE; costs.<criterion> of a gait file is CHECKED_VALUE
    value: float = unit_field(_criterion_unit, default=float("nan"))
    history: tuple = unit_field([Start], default_factory=tuple)  # every start

    @property
    def converged(self) -> bool:
        return self.status == "converged"

    @property
    def confirmed(self) -> bool:
        """Reached from at least two starts."""
        return self.starts_at_best >= 2

    def to_dict(self) -> dict:
        """The report as JSON: its fields in order, a value that is not finite as null."""
        return _to_json(self)

    @classmethod
    def from_dict(cls, content: dict) -> Report:
        """The report written by ``to_dict`` (a missing ``value``: NaN)."""
        return _from_json(cls, content)

    def summary(self) -> str:
        """One line for the command line."""
        agreement = (
            f"{self.starts_at_best} of {self.starts} starts at the best value"
            if self.method == "ipopt"
            else f"{self.starts} start"
        )
        measures = (
            f"constraint violation {self.constraint_violation:.1e}, dual infeasibility "
            f"{self.dual_infeasibility:.1e}"
            if self.method == "ipopt"
            else "constraints as penalties (no solver measure of them)"
        )
        return (
            f"{self.method}: {self.status}, {agreement}, {self.iterations} iterations, "
            f"{measures}, {self.seconds:.2f} s"
        )


def _finite_or_none(value):
    return float(value) if np.isfinite(value) else None


def _to_json(record) -> dict:
    """The fields of a ``Report`` or a ``Start`` in order: floats finite or None, the
    history a list."""

    def value(v):
        if isinstance(v, tuple):
            return [_to_json(start) for start in v]
        return _finite_or_none(v) if isinstance(v, float) else v

    return {f.name: value(getattr(record, f.name)) for f in dataclasses.fields(record)}


def _from_json(cls, content: dict):
    """The ``Report`` or ``Start`` of ``_to_json``: None as NaN; a field with a default
    value may be missing."""
    convert = {
        "str": str,
        "int": int,
        "float": lambda v: float("nan") if v is None else float(v),
        "tuple": lambda v: tuple(_from_json(Start, start) for start in v),
        "dict": dict,
    }
    fields = dataclasses.fields(cls)
    given = [f for f in fields if f.name in content or f.default is dataclasses.MISSING]
    return cls(**{f.name: convert[f.type](content[f.name]) for f in given})
