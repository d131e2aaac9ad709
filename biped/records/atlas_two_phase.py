"""The summary of an atlas with double support (``biped atlas --double-support``): per cell
(speed, clearance, knee bend) and knee the two-phase optimum beside the atlas's single-support
optimum (``biped.records.two_phase_sweep.PointSummary``), per cell the rolling knee's
sthenic difference without and with the double support phase and whether the phase changes
its sign or its size, and each cell where the two-phase problem is not built, with why.

Each field carries its unit (``unit_field``); the file (``summary.json`` in the atlas's
``double-support/`` folder) holds the record and its ``units`` map and reads back to the same
record. A figure not measured (an optimum not certified) is null: unknown, never zero.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

from biped.errors import BipedError
from biped.model.units import PURE, unit_field
from biped.records.two_phase_sweep import (
    HEADER,
    KneeDifference,
    PointSummary,
    SummaryFile,
    point_from_dict,
    point_to_dict,
)

FORMAT = "biped-atlas-two-phase/1"
CELL_HEADER = "clearance [m]  bend [rad]  " + HEADER


def _cell(clearance: float, knee_bend: float) -> str:
    """A cell's clearance and knee bend in words (the speed is the line's)."""
    return f"clearance {clearance:.3f} m, bend {knee_bend:.3f} rad"


@dataclass(frozen=True)
class CellPoint:
    """A knee at a cell: both optima (``point``: its speed, knee, single and two-phase
    figures, why the two-phase one is missing) at the cell's clearance and knee bend."""

    clearance: float = unit_field("m")
    knee_bend: float = unit_field("rad")
    point: PointSummary = unit_field(PointSummary)

    def line(self) -> str:
        """In the columns of ``CELL_HEADER``."""
        return f"{self.clearance:13.3f}  {self.knee_bend:10.3f}  {self.point.line()}"


@dataclass(frozen=True)
class CellDifference:
    """At a cell, (rolling − revolute) / revolute of C_Γ without and with double support
    (``difference``, None where either knee is unknown)."""

    clearance: float = unit_field("m")
    knee_bend: float = unit_field("rad")
    difference: KneeDifference = unit_field(KneeDifference)

    def change(self) -> str:
        """What double support does to the rolling knee's pay-off: changes its sign, or
        moves it by so many points (larger or smaller in size); unknown when either is."""
        one, two = self.difference.single, self.difference.double
        if one is None or two is None:
            return "unknown (an optimum not certified)"
        if (one < 0.0) != (two < 0.0):
            was, now = ("pays off", "costs more") if one < 0.0 else ("costs more", "pays off")
            return (
                f"double support CHANGES THE SIGN: the rolling knee {was} in single support, "
                f"{now} with it"
            )
        size = "larger" if abs(two) > abs(one) else "smaller"
        side = "pay-off" if one < 0.0 else "extra cost"
        times = f", {abs(two) / abs(one):.2f} times" if one else ""
        return (
            f"same sign; the rolling knee's {side} {size} with double support "
            f"({two - one:+.2f} points{times})"
        )

    def line(self) -> str:
        return f"{_cell(self.clearance, self.knee_bend)}, {self.difference.line()}: {self.change()}"


@dataclass(frozen=True)
class NotBuilt:
    """A cell and criterion of the atlas whose two-phase problem is not built, and why (the
    problem's own refusal)."""

    criterion: str = unit_field(None)
    speed: float = unit_field("m/s")
    clearance: float = unit_field("m")
    knee_bend: float = unit_field("rad")
    why: str = unit_field(None)

    def line(self) -> str:
        return (
            f"{self.criterion} at {self.speed:.3f} m/s, {_cell(self.clearance, self.knee_bend)}: "
            f"not built ({self.why})"
        )


@dataclass(frozen=True)
class AtlasTwoPhaseSummary(SummaryFile):
    """An atlas with double support: its share range and landing, the knees at its cells, the
    cells' differences and the cells not built (``None`` figures: unknown)."""

    KIND = "atlas two-phase summary"

    share_range: tuple = unit_field(PURE)
    landing: str = unit_field(None)
    points: tuple = unit_field([CellPoint])
    differences: tuple = unit_field([CellDifference])
    not_built: tuple = unit_field([NotBuilt])

    def to_dict(self) -> dict:
        return {
            "format": FORMAT,
            "share_range": list(self.share_range),
            "landing": self.landing,
            "points": [{**_place(p), "point": point_to_dict(p.point)} for p in self.points],
            "differences": [
                {**_place(d), "difference": dataclasses.asdict(d.difference)}
                for d in self.differences
            ],
            "not_built": [dataclasses.asdict(n) for n in self.not_built],
            "units": self.units(),
        }

    @classmethod
    def from_dict(cls, content: dict, source: str = "summary") -> AtlasTwoPhaseSummary:
        """The record of ``content`` (``to_dict``'s); a BipedError naming what is wrong."""
        cls.check_format(content, source, FORMAT)
        try:
            points = tuple(
                CellPoint(p["clearance"], p["knee_bend"], point_from_dict(p["point"]))
                for p in content["points"]
            )
            differences = tuple(
                CellDifference(d["clearance"], d["knee_bend"], KneeDifference(**d["difference"]))
                for d in content["differences"]
            )
            not_built = tuple(NotBuilt(**n) for n in content["not_built"])
            share = tuple(content["share_range"])
            return cls(share, content["landing"], points, differences, not_built)
        except (KeyError, TypeError) as error:
            raise BipedError(f"{source}: not an atlas two-phase summary ({error})") from None

    def missing(self) -> list[CellPoint]:
        """The knees at built cells without a two-phase optimum (a failure each)."""
        return [p for p in self.points if p.point.double is None]

    def table(self) -> str:
        """Per cell and knee both optima (``CellPoint.line``), per cell the knees' difference
        and what double support does to it, then the cells not built."""
        points = sorted(
            self.points, key=lambda p: (p.knee_bend, p.clearance, p.point.speed, p.point.knee)
        )
        lines = [CELL_HEADER] + [p.line() for p in points]
        lines += [d.line() for d in self.differences] + [n.line() for n in self.not_built]
        return "\n".join(lines)


def _place(record) -> dict:
    return {"clearance": record.clearance, "knee_bend": record.knee_bend}
