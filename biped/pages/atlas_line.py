"""One line of ``atlas.csv`` as a record (``AtlasLine``), each field with its unit and its
column, and its one codec: ``AtlasLine.to_csv`` writes the line, ``AtlasLine.from_csv`` reads
it back; ``COLUMNS``, the header, is the fields' columns in order. ``biped.pages.atlas``
makes the lines from the atlas's rows (``line``).

A number not known (no certified optimum, a re-solve that did not converge) is None and an
empty cell, never 0.
"""

from __future__ import annotations

import csv
import dataclasses
from dataclasses import dataclass

from biped.model.bezier import Bezier
from biped.model.criteria import CRITERION_UNITS
from biped.model.units import PURE, unit_field
from biped.studies.atlas import RICHER_KNOTS


def _column(header: str, form: str, unit=None, **kwargs):
    """A field written in the column ``header`` as ``form``: "f3" (3 decimals), "g6" (6
    significant digits), "int", "text", "yes/no" (a verdict, empty when not known),
    "quoted" (a sentence, in double quotes, empty when there is none), "family" (a gait
    family: K, or "bezier N")."""
    return unit_field(unit, metadata={"header": header, "form": form}, **kwargs)


def _cost_unit(criterion: str):
    return CRITERION_UNITS.get(criterion)


@dataclass(frozen=True)
class AtlasLine:
    """One cell and criterion of the atlas: both knees' costs and their difference with its
    uncertainty, the starts that reached each optimum, the richer family's difference, the
    costs of transport and each knee's walk in MuJoCo, in words."""

    speed: float = _column("speed [m/s]", "f3", "m/s")
    clearance: float = _column("clearance [m]", "f3", "m")  # the swing foot's, least
    knee_bend: float = _column("knee bend [rad]", "f3", "rad")  # the stance knee's, least
    # the gaits' family: a spline's interior knots K, or "bezier N" (a Bézier of degree N)
    knots: int | Bezier = _column("knots", "family", PURE)
    criterion: str = _column("criterion", "text")
    unit: str = _column("unit", "text")  # of the knees' costs (``CRITERION_UNITS``)
    # the knees' certified costs on the check grid, None without a difference
    revolute: float | None = _column("revolute", "g10", _cost_unit)
    rolling: float | None = _column("rolling", "g10", _cost_unit)
    difference: float | None = _column("difference [%]", "g6", "%")  # (rolling − rev.) / rev.
    uncertainty: float | None = _column("uncertainty [%]", "g3", "%")  # the three terms' sum
    distinguishable: bool | None = _column("distinguishable", "yes/no")  # None: no difference
    discretization: float | None = _column("discretization [%]", "g3", "%")  # finer grid's
    tolerance: float | None = _column("tolerance [%]", "g3", "%")  # tighter tolerance's
    starts_spread: float | None = _column("starts spread [%]", "g3", "%")
    starts_at_best_revolute: int | None = _column("starts at best revolute", "int", PURE)
    starts_at_best_rolling: int | None = _column("starts at best rolling", "int", PURE)
    richer_difference: float | None = _column(
        f"difference with {RICHER_KNOTS} knots [%]", "g6", "%"
    )  # the corner cells' only
    # a per-metre energy's cost over the robot's weight m g; None for the other criteria
    cost_of_transport_revolute: float | None = _column("cost of transport revolute", "g6", PURE)
    cost_of_transport_rolling: float | None = _column("cost of transport rolling", "g6", PURE)
    why_empty: str = _column("why empty", "quoted")  # no difference, or a term not measured
    # "yes", "no: " and why, "not walked", "not measured: " and why
    walks_revolute: str = _column("walks revolute", "quoted")
    walks_rolling: str = _column("walks rolling", "quoted")

    def to_csv(self) -> str:
        """The line of ``atlas.csv``, its cells in ``COLUMNS``' order."""
        return ",".join(_cell(getattr(self, f.name), f.metadata["form"]) for f in _FIELDS)

    @classmethod
    def from_csv(cls, line: str) -> AtlasLine:
        """The record of a line of ``atlas.csv`` (``to_csv``'s); ValueError if it is not one."""
        cells = next(csv.reader([line]))
        if len(cells) != len(_FIELDS):
            raise ValueError(f"{len(cells)} cells in a line of atlas.csv: allowed {len(_FIELDS)}")
        values = zip(_FIELDS, cells, strict=True)
        return cls(**{f.name: _value(cell, f.metadata["form"]) for f, cell in values})


_FIELDS = dataclasses.fields(AtlasLine)
COLUMNS = tuple(f.metadata["header"] for f in _FIELDS)


def _cell(value, form: str) -> str:
    if form == "quoted":
        return "" if not value else '"' + value.replace('"', '""') + '"'
    if form == "yes/no":
        return "" if value is None else ("yes" if value else "no")
    if form == "family":
        return f"bezier {value.degree}" if isinstance(value, Bezier) else str(value)
    if value is None:
        return ""
    if form in ("int", "text"):
        return str(value)
    return f"{value:.{form[1:]}{form[0]}}"


def _value(cell: str, form: str):
    if form in ("quoted", "text"):
        return cell
    if form == "yes/no":
        if cell not in ("", "yes", "no"):
            raise ValueError(f"{cell!r} in a verdict's column of atlas.csv: allowed yes, no, ''")
        return None if cell == "" else cell == "yes"
    if form == "family":
        kind, _, degree = cell.partition(" ")
        return Bezier(int(degree)) if kind == "bezier" else int(cell)
    if cell == "":
        return None
    return int(cell) if form == "int" else float(cell)
