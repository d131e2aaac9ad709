"""Units of the numbers in the project's JSON files: a ``units`` map beside them.

Gait files (``biped.records.gait_file``, whose ``Gait`` declares the unit of each field) and
validation reports keep their key names; their ``units`` object maps the path of each numeric
field to its unit::

    "costs.sthenic": "N²·m·s",
    "samples.q": ["rad", "rad", "rad", "rad", "rad", "rad", "rad", "m", "m"],
    "optimizer.history[].value": "N²·m·s"

A path goes through objects by key, and ``[]`` stands for every element of a list of objects.
A unit is a string in the notation the project prints (``N·m``, ``rad/s²``), ``"1"`` for a pure
number (a count, a ratio) and ``"T"`` for a fraction of the gait's period (``is_unit``): a
unit, never prose, and one number has one unit; a list holds one unit per column of an array
whose columns differ. What a number is goes with its record's documentation, not its unit:
``optimizer.value`` is the criterion on the solver's samples, which ranks the starts, where
``costs`` hold it on the check grid, which the comparisons use (``biped.optimization.comparison``).
Only numbers (and null, a figure that could not be measured) have units; texts, booleans and
``provenance`` have none.

A record declares the unit of each of its fields beside it (``unit_field``), and its map
follows from the declarations (``declared_units``): the gait file's ``Gait`` and its inner
records, the optimizer's ``Report``, a walk's figures (``validate.checks.units``).
"""

from __future__ import annotations

import dataclasses
import re

from biped.model.criteria import CONSTRAINTS
from biped.model.kinematics import ANGLES, COORDINATES

PURE = "1"  # a count or a ratio
PERCENT = "%"  # a ratio in hundredths (a change, ``biped.optimization.comparison``)
PERIOD = "T"  # a fraction of the gait's period
# The units that are a fraction of one of the gait's or the robot's own figures: of the
# period T, of the step length S, of the robot's weight m g.
FRACTIONS = (PERIOD, "S", "weight")
# SI symbols a unit is made of (a product with "·", a quotient with "/", powers ² and ³).
SYMBOLS = ("m", "s", "kg", "N", "J", "W", "A", "V", "Ω", "rad", "Hz")
_FACTOR = f"(?:{'|'.join(SYMBOLS)})[²³]?"
_UNIT = re.compile(rf"{_FACTOR}(?:[·/]{_FACTOR})*")
# Fields without units: what produced the file, and the map itself.
SKIPPED = ("provenance", "units")


def is_unit(text) -> bool:
    """Whether ``text`` is one unit: ``PURE``, ``PERCENT``, one of ``FRACTIONS``, or SI
    symbols (``SYMBOLS``) multiplied and divided ("N²·m·s", "rad/s²"), nothing else."""
    return isinstance(text, str) and (
        text in (PURE, PERCENT, *FRACTIONS) or _UNIT.fullmatch(text) is not None
    )


def unit_text(unit) -> str:
    """A unit as a page prints it: a string as it is; one per column as runs of columns
    ("rad (1-6), rad/s (7-12)"), or the one unit all columns share."""
    if isinstance(unit, str):
        return unit
    runs: list[list] = []
    for column, each in enumerate(unit, start=1):
        if runs and runs[-1][0] == each:
            runs[-1][2] = column
        else:
            runs.append([each, column, column])
    if len(runs) == 1:
        return str(runs[0][0])
    return ", ".join(f"{u} ({a})" if a == b else f"{u} ({a}-{b})" for u, a, b in runs)


def numeric_paths(content: dict, skip=SKIPPED) -> list[str]:
    """Paths (see the module) of every number, array of numbers or null in ``content``,
    leaving out the top-level fields ``skip``."""
    paths: list[str] = []

    def walk(value, path):
        if isinstance(value, dict):
            for key, item in value.items():
                if not path and key in skip:
                    continue
                walk(item, f"{path}.{key}" if path else key)
        elif isinstance(value, list) and value and all(isinstance(v, dict) for v in value):
            for item in value:
                walk(item, f"{path}[]")
        elif _numeric(value):
            paths.append(path)

    walk(content, "")
    return sorted(set(paths))


def _numeric(value) -> bool:
    if value is None:
        return True
    if isinstance(value, bool):
        return False
    if isinstance(value, (int, float)):
        return True
    if isinstance(value, (list, tuple)):
        return bool(value) and all(_numeric(v) for v in value)
    return hasattr(value, "dtype") and value.dtype.kind in "iuf"  # a numpy array


def missing(content: dict, units: dict) -> list[str]:
    """The numeric paths of ``content`` that ``units`` does not give."""
    return [path for path in numeric_paths(content) if path not in units]


def robot_unit(field: str) -> str:
    """Unit of a ``biped.Robot`` field, from its name."""
    if field.endswith("_mass"):
        return "kg"
    if field.endswith("_inertia"):
        return "kg·m²"
    if field == "gravity":
        return "m/s²"
    if field in ("k1", "k2"):  # a knee profile's rates (``biped.model.profile``)
        return "m/rad"
    return "m"  # lengths, centres of mass, the heel, the knee radii


def parameter_unit(name: str) -> str:
    """Unit of a gait parameter (``biped.model.gait.PARAMETERS``) or solver variable
    (``biped.optimization.problem.VARIABLES``)."""
    if name in ("x_hip", "z_hip"):
        return "m"
    if name == "period":
        return "s"
    if name.startswith("end_rate_") or "_rate_" in name:  # the ends' and the knots' rates
        return "rad/s"
    if "_accel_" in name:
        return "rad/s²"
    return "rad"  # the trunk angle, the knee bends


# Units of Ψ1..Ψ7 (``biped.model.criteria.CONSTRAINTS``), as their margins δ.
CONSTRAINT_UNITS = dict(zip(CONSTRAINTS, ("N", "m", "m", "rad", "rad", "m", "m"), strict=True))


def per_coordinate(angle: str, length: str) -> list[str]:
    """One unit per coordinate (``COORDINATES``): ``angle`` for the angles, else ``length``."""
    return [angle if name in ANGLES else length for name in COORDINATES]


def unit_field(unit, columns: tuple | None = None, metadata: dict | None = None, **kwargs):
    """A record's field with its unit (a string, one per column, a map of sub-fields to
    units, a record type whose fields carry theirs, ``[type]`` for a list of such records, a
    function of the gait's criterion, or None: no number), for an array of samples the names
    of its columns (None: one number a sample), and any further ``metadata``."""
    metadata = {"unit": unit, "columns": columns, **(metadata or {})}
    return dataclasses.field(metadata=metadata, **kwargs)


def declared_units(record, prefix: str = "", criterion: str | None = None) -> dict:
    """The units of ``record``'s fields (a record type, fields made by ``unit_field``), their
    paths under ``prefix``; a field without a number (unit None) has none."""
    units = {}
    for f in dataclasses.fields(record):
        unit = f.metadata.get("unit")
        unit = unit(criterion) if callable(unit) and not isinstance(unit, type) else unit
        path = f"{prefix}{f.name}"
        if isinstance(unit, list) and len(unit) == 1 and isinstance(unit[0], type):
            units.update(declared_units(unit[0], f"{path}[].", criterion))
        elif isinstance(unit, type):
            units.update(declared_units(unit, f"{path}.", criterion))
        elif isinstance(unit, dict):
            units.update({f"{path}.{key}": value for key, value in unit.items()})
        elif unit is not None:
            units[path] = unit
    return units
