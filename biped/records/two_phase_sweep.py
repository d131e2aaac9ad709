"""The summary of a sweep with double support (``biped sweep --double-support``): per speed
and knee the two-phase optimum beside the single-support optimum of the same point, and per
speed the knees' difference with and without the double support phase.

Each field carries its unit (``unit_field``); the file (``summary.json`` in the sweep's
``double-support/`` folder) holds the record, its ``units`` map and reads back to the same
record (``to_dict``, ``from_dict``). A figure that could not be measured (a point whose
solver did not converge, or infeasible) is null: unknown, never zero.
"""

from __future__ import annotations

import dataclasses
import json
from dataclasses import dataclass
from pathlib import Path

from biped.errors import BipedError
from biped.model.units import PERCENT, PURE, declared_units, unit_field
from biped.runtime.files import atomic_write_text

FORMAT = "biped-two-phase-sweep/1"
STEPS_PER_MINUTE = "steps/min"  # a cadence, as the two-phase page prints it
# The columns of ``PointSummary.line``.
HEADER = (
    "speed [m/s]  knee      C_Γ single / two phases [N²·m·s]  share  "
    "S single / two [m]  cadence single / two [steps/min]  C_E / S single / two [J/m]"
)


def _shown(value, form: str) -> str:
    """``value`` in ``form``; "unknown" for None (not measured)."""
    return "unknown" if value is None else format(value, form)


@dataclass(frozen=True)
class Phases:
    """One optimum's step (single support alone, or single then double support).

    Attributes:
        sthenic: C_Γ = (∫ ΓᵀΓ dt over the step) / S [N²·m·s]; for a two-phase gait over both
            phases on the solver's samples, for a single support on the check grid.
        share: T_ds / (T + T_ds) [1]; 0 for a single support.
        step_length: S [m].
        cadence: 60 / (T + T_ds) [steps/min].
        energy_per_metre: C_E / S, the joints' work ∫ Σ |Γ_i θ̇_i| dt over the step (both
            phases for a two-phase gait) per metre walked [J/m]; None for a two-phase file
            written before its double support's work was recorded.
    """

    sthenic: float = unit_field("N²·m·s")
    share: float = unit_field(PURE)
    step_length: float = unit_field("m")
    cadence: float = unit_field(STEPS_PER_MINUTE)
    energy_per_metre: float | None = unit_field("J/m", default=None)


@dataclass(frozen=True)
class PointSummary:
    """A speed and knee: the single-support optimum and the two-phase one (None: not
    certified, ``why`` says why)."""

    knee: str = unit_field(None)
    speed: float = unit_field("m/s")
    single: Phases | None = unit_field(Phases)
    double: Phases | None = unit_field(Phases)
    why: str = unit_field(None, default="")

    def line(self) -> str:
        """Both optima's C_Γ [N²·m·s], share, step length [m] and cadence [steps/min], in
        the columns of ``HEADER``; why the two-phase one is missing."""
        one, two = self.single, self.double
        return (
            f"{self.speed:11.3f}  {self.knee:8}  "
            f"{_shown(one and one.sthenic, '10.4f')} / {_shown(two and two.sthenic, '10.4f')}"
            f"         {_shown(two and two.share, '.3f')}  "
            f"{_shown(one and one.step_length, '.4f')} / "
            f"{_shown(two and two.step_length, '.4f')}"
            f"     {_shown(one and one.cadence, '6.1f')} / {_shown(two and two.cadence, '6.1f')}"
            f"                 {_shown(one and one.energy_per_metre, '7.2f')} / "
            f"{_shown(two and two.energy_per_metre, '7.2f')}" + ("" if two else f"  ({self.why})")
        )


@dataclass(frozen=True)
class KneeDifference:
    """(rolling − revolute) / revolute at one speed [%], negative where the rolling knee
    needs less: of C_Γ (``single``, ``double``, what the optima minimise) and of the same
    sthenic optima's energy per metre C_E / S (``energy_single``, ``energy_double``); None
    where either knee's figure is unknown."""

    speed: float = unit_field("m/s")
    single: float | None = unit_field(PERCENT)
    double: float | None = unit_field(PERCENT)
    energy_single: float | None = unit_field(PERCENT, default=None)
    energy_double: float | None = unit_field(PERCENT, default=None)

    def line(self) -> str:
        """The knees' difference without and with the double support phase."""
        return (
            f"{self.speed:.3f} m/s: rolling vs revolute C_Γ, single support "
            f"{_shown(self.single, '+.2f')} %, with double support {_shown(self.double, '+.2f')} %"
            f"; their C_E / S, single support {_shown(self.energy_single, '+.2f')} %, with "
            f"double support {_shown(self.energy_double, '+.2f')} %"
        )


class SummaryFile:
    """What the double support's summaries share (a sweep's here, an atlas's in
    ``biped.records.atlas_two_phase``): their units, their file written atomically as the
    JSON of ``to_dict`` and read back through ``from_dict``, an unreadable one named as a
    ``KIND``."""

    KIND = "summary"

    @classmethod
    def units(cls) -> dict:
        return declared_units(cls)

    def write(self, path: str | Path) -> Path:
        return atomic_write_text(path, json.dumps(self.to_dict(), indent=1, allow_nan=False))

    @classmethod
    def check_format(cls, content, source: str, allowed: str) -> None:
        """A BipedError naming ``source`` unless ``content`` is an object of format
        ``allowed``."""
        if not isinstance(content, dict) or content.get("format") != allowed:
            found = content.get("format") if isinstance(content, dict) else None
            raise BipedError(f"{source}: format {found!r}: allowed {allowed!r}")

    @classmethod
    def read(cls, path: str | Path):
        path = Path(path)
        try:
            content = json.loads(path.read_text())
        except (OSError, ValueError) as error:
            raise BipedError(f"{path}: unreadable {cls.KIND} ({error})") from None
        return cls.from_dict(content, str(path))


@dataclass(frozen=True)
class TwoPhaseSweepSummary(SummaryFile):
    """A sweep with double support: its share range and landing, its points and the knees'
    differences (``None`` fields: unknown)."""

    KIND = "two-phase sweep summary"

    share_range: tuple = unit_field(PURE)
    landing: str = unit_field(None)
    points: tuple = unit_field([PointSummary])
    differences: tuple = unit_field([KneeDifference])

    def to_dict(self) -> dict:
        content = {"format": FORMAT, **dataclasses.asdict(self)}
        content["share_range"] = list(self.share_range)
        content["points"] = [point_to_dict(p) for p in self.points]
        content["differences"] = [dataclasses.asdict(d) for d in self.differences]
        return {**content, "units": self.units()}

    @classmethod
    def from_dict(cls, content: dict, source: str = "summary") -> TwoPhaseSweepSummary:
        """The record of ``content`` (``to_dict``'s); a BipedError naming what is wrong."""
        cls.check_format(content, source, FORMAT)
        try:
            points = tuple(point_from_dict(p) for p in content["points"])
            differences = tuple(KneeDifference(**d) for d in content["differences"])
            return cls(tuple(content["share_range"]), content["landing"], points, differences)
        except (KeyError, TypeError) as error:
            raise BipedError(f"{source}: not a two-phase sweep summary ({error})") from None

    def table(self) -> str:
        """The summary as a table: per speed and knee both optima (``PointSummary.line``),
        then per speed the knees' difference (``KneeDifference.line``)."""
        points = sorted(self.points, key=lambda p: (p.speed, p.knee))
        lines = [HEADER] + [p.line() for p in points] + [d.line() for d in self.differences]
        return "\n".join(lines)


def point_to_dict(point: PointSummary) -> dict:
    """A point's object: an unknown optimum's figures each null (unknown, with its unit)."""
    content = dataclasses.asdict(point)
    for phase in ("single", "double"):
        if content[phase] is None:
            content[phase] = {f.name: None for f in dataclasses.fields(Phases)}
    return content


def point_from_dict(content: dict) -> PointSummary:
    """The record of ``point_to_dict``'s object (a KeyError or TypeError where it is not)."""
    single, double = _phases(content["single"]), _phases(content["double"])
    return PointSummary(**{**content, "single": single, "double": double})


def _phases(content) -> Phases | None:
    """The figures of an optimum, None where the file says them all unknown (null)."""
    if all(value is None for value in content.values()):
        return None
    return Phases(**content)
