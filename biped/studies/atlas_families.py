"""Two atlases of one problem in two gait families, cell by cell: what the paper's spline
hides or invents of the rolling knee's pay-off beside a rich family (``biped compare-atlas``).

Each atlas (``biped.studies.atlas``) gives, per cell and criterion, the difference between the
knees, (rolling − revolute) / revolute [%], with its uncertainty (``atlas.Difference``). Two
atlases compare when they answer the same problem (robot, margins, knee bends) in two
families; their common cells are compared, for their common criteria. Per cell
(``verdict``), the shift is the rich family's difference less the base family's [percentage
points], and it is told apart from nothing when it is larger than the sum of both error bars
(a difference beyond both):

- ``hides``: the rich family's difference is lower: the base family hides (part of) a
  pay-off of the rolling knee (or shows a cost the rolling knee does not have);
- ``invents``: the rich family's difference is higher: the base family shows a pay-off (or
  part of one) that the richer gaits do not have;
- ``same``: the shift is within both error bars;
- ``unknown``: an error bar was not measured (a re-solve that did not converge) or a knee
  has no certified optimum: never counted as ``same``.

``sign_change``: the two differences have opposite signs and each is larger than its own
error bar (the families disagree on which knee needs less).
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from pathlib import Path

from biped.errors import BipedError
from biped.model.gait import family_json, family_label, family_words
from biped.model.kinematics import KNEES
from biped.model.units import PURE
from biped.studies import atlas
from biped.studies.atlas import Cell, Difference

FORMAT = "biped-atlas-families/1"
VERDICTS = ("hides", "invents", "same", "unknown")
# What must be the same in both atlases' records for their cells to compare: the problem.
SAME_PROBLEM = ("robot", "knee_bends", "actuator_limits", "safety")
# The corners' re-solve in 3 knots: not a term of a difference's error bar.
RICHER = atlas.MEASURES["richer"]


@dataclass(frozen=True)
class Side:
    """One family's difference in a cell.

    Attributes:
        value: (rolling − revolute) / revolute on the check grid [%], None without both
            knees' certified optima.
        uncertainty: its error bar [%] (``atlas.Difference.uncertainty``), None if a term
            was not measured.
        why: why there is no value, or which term is not measured ("" when both are known).
        walks: both knees' optima walk in MuJoCo (every check run passes; ``atlas.Walk``),
            None where a knee's was not walked or its walk not measured.
    """

    value: float | None
    uncertainty: float | None
    why: str = ""
    walks: bool | None = None

    @classmethod
    def of(cls, difference: Difference, walks: tuple = ()) -> Side:
        """A cell's ``atlas.Difference``, the richer-family term aside, and its knees'
        ``atlas.Walk`` records (None: not walked)."""
        measured = [f"{what}: {why}" for what, why in difference.unmeasured if what != RICHER]
        why = difference.why or "; ".join(f"not measured, {text}" for text in measured)
        verdicts = [None if w is None else w.walks for w in walks]
        both = None if not verdicts or None in verdicts else all(verdicts)
        return cls(difference.value, difference.uncertainty, why, both)

    @property
    def distinguishable(self) -> bool:
        """Larger than its error bar, which is measured."""
        return (
            self.value is not None
            and self.uncertainty is not None
            and abs(self.value) > self.uncertainty
        )

    def to_dict(self) -> dict:
        return dataclasses.asdict(self)


@dataclass(frozen=True)
class CellShift:
    """One cell and criterion in both families.

    Attributes:
        criterion: the criterion compared.
        cell: speed [m/s], clearance [m], knee bend [rad].
        base: the base family's difference (the paper's spline).
        rich: the rich family's difference.
        shift: rich less base [percentage points], None without both values.
        verdict: ``VERDICTS`` (see the module).
        sign_change: both distinguishable, of opposite signs.
    """

    criterion: str
    cell: Cell
    base: Side
    rich: Side
    shift: float | None
    verdict: str
    sign_change: bool

    def to_dict(self) -> dict:
        return {
            "criterion": self.criterion,
            **dataclasses.asdict(self.cell),
            "base": self.base.to_dict(),
            "rich": self.rich.to_dict(),
            "shift": self.shift,
            "verdict": self.verdict,
            "sign_change": self.sign_change,
        }


def verdict(base: Side, rich: Side) -> tuple[str, float | None, bool]:
    """(verdict, shift [percentage points], sign_change) of one cell (the module's rules): a
    shift is told apart only when both error bars are measured and it exceeds their sum."""
    if base.value is None or rich.value is None:
        return "unknown", None, False
    shift = rich.value - base.value
    sign_change = (
        base.distinguishable and rich.distinguishable and (base.value < 0) != (rich.value < 0)
    )
    if base.uncertainty is None or rich.uncertainty is None:
        return "unknown", shift, sign_change
    if abs(shift) <= base.uncertainty + rich.uncertainty:
        return "same", shift, sign_change
    return ("hides" if shift < 0 else "invents"), shift, sign_change


def cell_shift(criterion: str, cell: Cell, base: Side, rich: Side) -> CellShift:
    """The ``CellShift`` of one cell from both families' differences."""
    found, shift, sign_change = verdict(base, rich)
    return CellShift(criterion, cell, base, rich, shift, found, sign_change)


@dataclass(frozen=True)
class FamilyComparison:
    """Two atlases' common cells compared (``compare_atlases``).

    Attributes:
        base, rich: the atlases' folders.
        base_family, rich_family: their gait families (K, or a ``Bezier``).
        constraints: the problem both answer, in words.
        shifts: each common cell and criterion (``CellShift``), criterion by criterion.
    """

    base: str
    rich: str
    base_family: object
    rich_family: object
    constraints: str
    shifts: tuple

    def counts(self, criterion: str) -> dict:
        """How many of the criterion's cells have each verdict, and sign changes."""
        mine = [s for s in self.shifts if s.criterion == criterion]
        found = {v: sum(s.verdict == v for s in mine) for v in VERDICTS}
        return {**found, "sign_changes": sum(s.sign_change for s in mine), "cells": len(mine)}

    @property
    def criteria(self) -> tuple:
        return tuple(dict.fromkeys(s.criterion for s in self.shifts))

    def to_dict(self) -> dict:
        return {
            "format": FORMAT,
            "base": {"folder": self.base, "family": family_json(self.base_family)},
            "rich": {"folder": self.rich, "family": family_json(self.rich_family)},
            "families": {
                "base": family_words(self.base_family),
                "rich": family_words(self.rich_family),
            },
            "constraints": self.constraints,
            "counts": {c: self.counts(c) for c in self.criteria},
            "cells": [s.to_dict() for s in self.shifts],
            "units": UNITS,
        }


UNITS = {
    "cells[].speed": "m/s",
    "cells[].clearance": "m",
    "cells[].knee_bend": "rad",
    "cells[].base.value": "%",
    "cells[].base.uncertainty": "%",
    "cells[].rich.value": "%",
    "cells[].rich.uncertainty": "%",
    "cells[].shift": "percentage points",
    "cells[].base.walks": PURE,
    "cells[].rich.walks": PURE,
    "counts": PURE,
}


def check_pair(base: atlas.Settings, rich: atlas.Settings, names: tuple[str, str]) -> None:
    """A clear error unless both atlases answer the same problem in two families and share
    a cell."""
    found = base.to_dict(), rich.to_dict()
    for key in SAME_PROBLEM:
        if found[0].get(key) != found[1].get(key):
            raise BipedError(
                f"{names[1]}: its atlas was made with {key} = {found[1].get(key)!r}, "
                f"{names[0]}'s with {found[0].get(key)!r}: allowed two atlases of the same "
                "problem in two gait families"
            )
    if base.knots == rich.knots:
        raise BipedError(
            f"{names[1]}: its atlas is of the family {family_label(rich.knots)}, as "
            f"{names[0]}'s: allowed two atlases in two gait families"
        )
    if not common_criteria(base, rich):
        raise BipedError(
            f"{names[1]}: its atlas has the criteria {', '.join(rich.criteria)}, "
            f"{names[0]}'s {', '.join(base.criteria)}: allowed two atlases sharing a criterion"
        )
    if not common_cells(base, rich):
        raise BipedError(
            f"{names[1]}: no cell (speed, clearance, knee bend) in common with {names[0]}: "
            "allowed two atlases sharing a cell"
        )


def common_criteria(base: atlas.Settings, rich: atlas.Settings) -> list[str]:
    """The criteria of both atlases, in the base atlas's order."""
    return [criterion for criterion in base.criteria if criterion in rich.criteria]


def common_cells(base: atlas.Settings, rich: atlas.Settings) -> list[Cell]:
    """The cells of both atlases, in the base atlas's order."""
    theirs = set(rich.cells())
    return [cell for cell in base.cells() if cell in theirs]


def _load(folder, name: str) -> atlas.Settings:
    """The settings of the atlas in ``folder`` (the argument ``name``), else a clear error."""
    try:
        return atlas.load(folder)
    except BipedError as error:
        raise BipedError(f"{name} {str(folder)!r}: {error}") from None
    except (KeyError, TypeError, ValueError, AttributeError) as error:
        raise BipedError(
            f"{name} {str(folder)!r}: {Path(folder) / atlas.MANIFEST} is not an atlas record "
            f"({type(error).__name__}: {error}): allowed a folder biped atlas wrote"
        ) from None


def compare_atlases(base_folder, rich_folder) -> FamilyComparison:
    """The common cells of the atlases in ``base_folder`` and ``rich_folder`` compared, for
    each criterion of both; a BipedError if they are not two families of one problem."""
    base, rich = _load(base_folder, "BASE"), _load(rich_folder, "RICH")
    check_pair(base, rich, (str(base_folder), str(rich_folder)))
    shifts = []
    for criterion in common_criteria(base, rich):
        for cell in common_cells(base, rich):
            sides = [
                Side.of(
                    atlas.difference(folder, settings, criterion, cell)[0],
                    tuple(
                        atlas.read_walk(folder, atlas.Point("final", knee, criterion, cell))
                        for knee in KNEES
                    ),
                )
                for folder, settings in ((base_folder, base), (rich_folder, rich))
            ]
            shifts.append(cell_shift(criterion, cell, *sides))
    return FamilyComparison(
        str(Path(base_folder)),
        str(Path(rich_folder)),
        base.knots,
        rich.knots,
        base.constraints_words(),
        tuple(shifts),
    )
