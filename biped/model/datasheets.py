"""Actuator datasheets: the figures of a catalog entry as its vendor prints them, read into the
fields of ``biped.model.actuators.Actuator`` (SI units).

A catalog (``catalog.json`` beside this module, format ``CATALOG_FORMAT``) lists entries::

    {"name": "AK80-64 KV80", "source": "CubeMars: https://...",
     "datasheet": {"reduction_ratio": 64, "phase_to_phase_resistance [mΩ]": 220, ...},
     "assumed": {"gear_efficiency": 0.81, "viscous_friction": 0.1},
     "checks": {"motor_constant [N·m/√W]": 0.29}, "note": "..."}

``datasheet`` keys are "figure [unit]" (``FIGURES``: each figure, the field it gives and the
units it may be printed in, with their factors to SI); ``assumed`` gives by their names the
fields no datasheet gives; every field once, from one or the other. ``checks`` holds printed
figures the actuator does not use but that check the others (tests/test_sizing.py), ``note``
what a reader should know of the entry. Anything else is refused, naming the key and the value
as the file has them.
"""

from __future__ import annotations

import json
import math
import re

from biped.errors import BipedError

CATALOG_FORMAT = "biped-actuator-catalog/2"
ENTRY_KEYS = ("name", "source", "datasheet", "assumed", "checks", "note")
# Units: their factor to SI as (numerator, denominator), each exact in floating point.
_ONE = (1.0, 1.0)
_MILLI = (1.0, 1e3)
_RPM = (2.0 * math.pi, 60.0)
# A datasheet's figure -> (the actuator's field, {unit: factor to SI}); "" is a pure number.
FIGURES = {
    "reduction_ratio": ("gear_ratio", {"": _ONE}),
    "torque_constant": ("torque_constant", {"N·m/A": _ONE}),
    "phase_to_phase_resistance": ("resistance", {"mΩ": _MILLI, "Ω": _ONE}),
    "rotor_inertia": ("rotor_inertia", {"g·cm²": (1.0, 1e7), "kg·m²": _ONE}),
    "rated_torque": ("continuous_torque", {"N·m": _ONE}),
    "peak_torque": ("peak_torque", {"N·m": _ONE}),
    "no_load_speed": ("max_speed", {"rpm": _RPM, "rad/s": _ONE}),
    "max_speed": ("max_speed", {"rpm": _RPM, "rad/s": _ONE}),
    "voltage": ("supply_voltage", {"V": _ONE}),
    "weight": ("mass", {"g": _MILLI, "kg": _ONE}),
    # The torque that turns the unpowered actuator from its output: its friction at the joint.
    "back_drive_torque": ("coulomb_friction", {"N·m": _ONE}),
}
_KEY = re.compile(r"^(?P<figure>[a-z_]+)(?: \[(?P<unit>[^\]]+)\])?$")


def loads(text: str, source: str):
    """A catalog's JSON content; a key written twice in one object is refused."""

    def once(pairs):
        keys = [key for key, _ in pairs]
        twice = next((key for key in keys if keys.count(key) > 1), None)
        if twice is not None:
            raise BipedError(f"catalog {source!r}: key {twice!r} written twice: allowed once")
        return dict(pairs)

    try:
        return json.loads(text, object_pairs_hook=once)
    except ValueError as error:
        raise BipedError(f"catalog {source!r} is not valid JSON ({error})") from None


def entries(content, source: str) -> list[dict]:
    """The entries of a catalog's content (format ``CATALOG_FORMAT``), each a table with a
    name of its own and a source; a BipedError naming what is not."""
    found = content.get("actuators") if isinstance(content, dict) else None
    if not isinstance(found, list) or not found:
        raise BipedError(f"catalog {source!r}: allowed a list 'actuators' of one entry or more")
    names = set()
    for index, entry in enumerate(found):
        where = f"catalog {source!r} actuators[{index}]"
        if not isinstance(entry, dict):
            raise BipedError(f"{where} = {entry!r}: allowed a table of {', '.join(ENTRY_KEYS)}")
        unknown = sorted(set(entry) - set(ENTRY_KEYS))
        if unknown:
            raise BipedError(f"{where} has {unknown[0]!r}: allowed {', '.join(ENTRY_KEYS)}")
        for key in ("name", "source"):
            if not isinstance(entry.get(key), str) or not entry[key].strip():
                raise BipedError(f"{where}.{key} = {entry.get(key)!r}: allowed a text")
        if entry["name"] in names:
            raise BipedError(f"{where}.name = {entry['name']!r}: allowed a name of its own")
        names.add(entry["name"])
    return found


def fields_of(entry: dict, fields, positive, source: str) -> tuple[dict, dict]:
    """The actuator's field values of an entry, in SI units, and where each came from
    ({field: "datasheet 'key' = value" or "assumed 'field' = value"}, as the file has it).
    ``fields``: the actuator's field names, every one to be given once; ``positive``: those
    that must be > 0 (the others >= 0)."""
    values, origins = {}, {}
    sheet, assumed = entry.get("datasheet"), entry.get("assumed", {})
    for part, table in (("datasheet", sheet), ("assumed", assumed)):
        if not isinstance(table, dict):
            raise BipedError(f"{source}: {part} = {table!r}: allowed a table")
    given = [(f"datasheet {key!r}", *_figure(key, value, source)) for key, value in sheet.items()]
    for name, value in assumed.items():
        if name not in fields:
            raise BipedError(f"{source}: assumed {name!r}: allowed one of {', '.join(fields)}")
        given.append((f"assumed {name!r}", name, value, (1.0, 1.0)))
    for origin, field, value, (numerator, denominator) in given:
        origin = f"{origin} = {value!r}"
        if field in values:
            raise BipedError(
                f"{source}: {origin} gives {field} again ({origins[field]}): allowed each once"
            )
        number = _number(value, origin, source)
        if number < 0.0 or (field in positive and number == 0.0):
            raise BipedError(
                f"{source}: {origin} is invalid: allowed {'> 0' if field in positive else '>= 0'}"
            )
        values[field], origins[field] = number * numerator / denominator, origin
    missing = [field for field in fields if field not in values]
    if missing:
        raise BipedError(
            f"{source}: no {', '.join(missing)}: allowed each field from the datasheet or assumed"
        )
    return values, origins


def _figure(key: str, value, source: str) -> tuple:
    """(field, value, factor to SI) of a datasheet's ``key`` ("figure [unit]")."""
    match = _KEY.match(key)
    figure = match["figure"] if match else None
    if figure not in FIGURES:
        raise BipedError(
            f"{source}: datasheet {key!r} = {value!r}: allowed a figure of "
            f"{', '.join(FIGURES)}, as 'figure [unit]'"
        )
    field, units = FIGURES[figure]
    unit = match["unit"] or ""
    if unit not in units:
        shown = " or ".join(f"'{figure} [{u}]'" if u else repr(figure) for u in units)
        raise BipedError(f"{source}: datasheet {key!r} = {value!r}: allowed {shown}")
    return field, value, units[unit]


def _number(value, origin: str, source: str) -> float:
    """A finite real number of the file, as a float."""
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise BipedError(f"{source}: {origin} is invalid: allowed a number")
    try:
        number = float(value)
    except OverflowError:
        number = math.inf
    if not math.isfinite(number):
        raise BipedError(f"{source}: {origin} is invalid: allowed a finite number")
    return number
