"""Gait files: one optimal gait as JSON, written atomically, read back with checks.

Layout (SI units, the paper's coordinate order; ground at z = 0, stance ankle at x = 0):

    knee, criterion, speed [m/s], period [s], step_length [m],
    safety {clearance, zmp_margin} [m] (margins beyond the paper's constraints), feasible,
    costs {sthenic [N²·m·s], energy [J], energy_per_metre [J/m]} (on the check grid of 202
        samples per step: what the comparisons, tables and figures use),
    robot {field: value}, parameters {name: value} (the 21 of ``biped.model.gait.PARAMETERS``),
    constraints {name: worst Ψ_i on the samples, less the safety margins: >= 0 when met},
    impact {impulse [N·s, N·s, N·m·s], trailing_foot_lift [m/s] (heel, toe), consistent
            (Iz > 0 and the trailing foot lifts: the flat-foot impact model holds), qd_minus,
            qd_plus},
    optimizer {method, status ("converged" when the best start's solver converged), starts,
               starts_at_best, iterations, constraint_violation, dual_infeasibility,
               seconds, seed, value (the criterion on the solver's 52 samples per step, which
               ranks the starts; it differs from costs.<criterion> by a fraction of a percent),
               history (each start), variables (the solver's variables)},
    provenance {package, version, python, platform, numpy, scipy, casadi, mujoco, command}
        (``biped.records.provenance``: what produced the file),
    units {path: unit} of every number above and below ("costs.sthenic": "N²·m·s",
        ``biped.records.units``),
    samples {t, q, qd, qdd, torques, wrench, zmp}

The samples run from t = 0 to t = T inclusive on both spline pieces; t = T/2 appears twice,
left and right limits, because the accelerations (and torques) jump at the knot.

``read`` checks the format and names the bad field; ``read_consistent`` also recomputes what
the parameters determine (period, step length, samples, costs, constraints, ``feasible``,
impact) and refuses a file whose figures are not those of its parameters, naming the field:
every command that reads a gait file a user gives reads it with ``read_consistent``.
"""

from __future__ import annotations

import dataclasses
import json
import math
from pathlib import Path

import numpy as np

from biped.errors import BipedError
from biped.model.criteria import CONSTRAINTS, CRITERIA, Safety
from biped.model.dynamics import JOINTS, Biped
from biped.model.gait import PARAMETERS
from biped.model.impact import trailing_foot_lift
from biped.model.kinematics import COORDINATES, KNEES
from biped.model.robot import Robot
from biped.optimization.optimize import Optimum, check_speed
from biped.optimization.problem import VARIABLES
from biped.records.provenance import provenance as make_provenance
from biped.records.units import gait_units
from biped.runtime.files import atomic_write_text

FORMAT = "biped-gait/2"  # 2: safety margins recorded
# Shortest step a gait file may hold [m]: shorter is no walk (a speed near 0).
MIN_STEP_LENGTH = 1e-3
SAMPLE_FIELDS = {"t": 1, "q": 9, "qd": 9, "qdd": 9, "torques": 6, "wrench": 3, "zmp": 1}
# What a gait file is and who writes it, for a message refusing another file.
GAIT_FILE = f"a gait file (format {FORMAT!r}) that biped optimize, sweep, design or pipeline writes"
# The project's other JSON files with a "format", by its prefix (the version follows "/"):
# what each is, and the command that writes it.
OTHER_FORMATS = {
    "biped-sweep/": "a sweep's record (which biped sweep writes, as sweep.json)",
    "biped-design-map/": (
        "a design map's record (which biped design-map writes, as design-map.json)"
    ),
    "biped-paper-method/": (
        "the record of the paper's method's runs (which biped sweep --paper-seeds writes, as "
        "paper-method/settings.json)"
    ),
}


def to_dict(optimum: Optimum, robot: Robot, seed: int, provenance: dict | None = None) -> dict:
    """The JSON-ready content of a gait file.

    Args:
        provenance: what produced it (default: ``biped.records.provenance.provenance()`` now).
    """
    ev = optimum.evaluation
    step = optimum.step
    model = Biped(robot, optimum.knee)
    qd_plus, _ = model.impact(*step.end)
    return {
        "format": FORMAT,
        "knee": optimum.knee,
        "criterion": optimum.criterion,
        "speed": optimum.speed,
        "period": step.period,
        "step_length": step.step_length,
        "safety": dataclasses.asdict(optimum.safety),
        "feasible": optimum.feasible,
        "costs": {
            "sthenic": ev.sthenic,
            "energy": ev.energy,
            "energy_per_metre": ev.energy / step.step_length,
        },
        "robot": robot.to_dict(),
        "parameters": dict(zip(PARAMETERS, map(float, optimum.parameters), strict=True)),
        "constraints": dict(zip(CONSTRAINTS, map(float, ev.worst), strict=True)),
        "impact": {
            "impulse": step.impulse.tolist(),
            "trailing_foot_lift": trailing_foot_lift(model, step.end[0], qd_plus).tolist(),
            "consistent": bool(
                step.impulse[1] > 0 and np.all(trailing_foot_lift(model, step.end[0], qd_plus) >= 0)
            ),
            "qd_minus": step.end[1].tolist(),
            "qd_plus": step.start[1].tolist(),
        },
        "optimizer": {
            **optimum.report.to_dict(),
            "variables": dict(zip(VARIABLES, map(_finite_or_none, optimum.variables), strict=True)),
        },
        "provenance": dict(provenance) if provenance is not None else make_provenance(),
        "units": gait_units(optimum.criterion),
        "samples": {
            "t": ev.t.tolist(),
            "q": ev.q.tolist(),
            "qd": ev.qd.tolist(),
            "qdd": ev.qdd.tolist(),
            "torques": ev.torques.tolist(),
            "wrench": ev.wrench.tolist(),
            "zmp": ev.zmp.tolist(),
        },
    }


def write_json(path: str | Path, content: dict) -> Path:
    """Write JSON whole or not at all (``biped.runtime.files``), creating the folder; returns the
    path."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    return atomic_write_text(path, json.dumps(content, indent=1, allow_nan=False))


def _finite_number(value) -> bool:
    """A JSON number other than a boolean, finite as a float (integers beyond floats are not)."""
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        return False
    try:
        return math.isfinite(float(value))
    except OverflowError:
        return False


def _finite_or_none(value):
    return float(value) if math.isfinite(value) else None


def _positive_number(value) -> bool:
    return _finite_number(value) and value > 0


def parameters(gait: dict) -> np.ndarray:
    """The 21 parameters (in ``PARAMETERS`` order) of a gait read by ``read``."""
    return np.array([gait["parameters"][name] for name in PARAMETERS])


def other_kind(content) -> str | None:
    """What a JSON file of this project other than a gait file is, and which command writes
    it ("a robustness map (which biped robustness writes)"), or None if it is none of them
    (a gait file, of any version, or something else)."""
    if not isinstance(content, dict):
        return None
    found = content.get("format")
    for prefix, kind in OTHER_FORMATS.items():
        if isinstance(found, str) and found.startswith(prefix):
            return kind
    if {"nominal", "limits", "ranges"} <= content.keys():
        return "a robustness map (which biped robustness writes)"
    if _validation_report(content):
        return "a validation report (which biped validate --json and biped pipeline write)"
    if content and all(_validation_report(value) for value in content.values()):
        return "the validation reports of several gait files (which biped validate --json writes)"
    if isinstance(content.get("point"), dict) and "certified" in content:
        return "one optimization of a design map (which biped design-map writes)"
    return None


def _validation_report(content) -> bool:
    """Whether ``content`` is a validation report (``validate.report.as_json``)."""
    return (
        isinstance(content, dict)
        and "passed" in content
        and isinstance(content.get("inverse_dynamics"), dict)
    )


def read(path: str | Path, allowed: str = GAIT_FILE) -> dict:
    """Read a gait file; samples become numpy arrays. Raises BipedError if it is not one,
    saying what it is if it is another of this project's files and what is ``allowed``
    (default a gait file: what the command takes)."""
    path = Path(path)
    try:
        content = json.loads(path.read_text())
    except OSError as error:
        raise BipedError(f"gait file {str(path)!r} cannot be read: {error.strerror}") from None
    except (ValueError, RecursionError) as error:  # JSONDecodeError and UnicodeDecodeError too
        reason = "nested too deeply" if isinstance(error, RecursionError) else error
        raise BipedError(
            f"gait file {str(path)!r} is not valid JSON ({reason}): allowed a gait file "
            "written by biped optimize, sweep, design or pipeline"
        ) from None

    def bad(what):
        return BipedError(f"gait file {str(path)!r} is corrupt: {what}")

    kind = other_kind(content)
    if kind is not None:  # a valid file of another kind is not corrupt
        raise BipedError(f"{str(path)!r} is {kind}, not a gait file: allowed {allowed}")
    found = content.get("format") if isinstance(content, dict) else None
    if isinstance(found, str) and found.startswith("biped-gait/") and found != FORMAT:
        raise BipedError(
            f"gait file {str(path)!r} has format {found!r}, another version's: allowed {allowed}"
        )
    if not isinstance(content, dict) or content.get("format") != FORMAT:
        raise bad(f"format is not {FORMAT!r}")
    for key in ("knee", "criterion", "speed", "period", "step_length", "feasible", "costs"):
        if key not in content:
            raise bad(f"missing {key!r}")
    for key in ("speed", "period", "step_length"):
        if not _positive_number(content[key]):
            raise bad(f"{key} = {content[key]!r}, allowed a number > 0")
    try:
        content["safety"] = Safety(**content["safety"])
    except (KeyError, TypeError, BipedError) as error:
        raise bad(f"safety {content.get('safety')!r}: {error}") from None
    if content["knee"] not in KNEES:
        raise bad(f"knee = {content['knee']!r}, allowed {', '.join(KNEES)}")
    if content["criterion"] not in CRITERIA:
        raise bad(f"criterion = {content['criterion']!r}, allowed {', '.join(CRITERIA)}")
    if not isinstance(content["feasible"], bool):
        raise bad(f"feasible = {content['feasible']!r}, allowed true or false")
    costs = content["costs"]
    if not isinstance(costs, dict) or not all(_finite_number(costs.get(name)) for name in CRITERIA):
        raise bad(f"costs = {costs!r}, allowed finite numbers for {', '.join(CRITERIA)}")
    try:
        content["robot"] = Robot.from_mapping(content["robot"], source="robot")
        names = set(content["parameters"])
    except (KeyError, TypeError) as error:
        raise bad(f"robot or parameters missing ({error})") from None
    except BipedError as error:
        raise bad(str(error)) from None
    if (
        not isinstance(content["parameters"], dict)
        or names != set(PARAMETERS)
        or not all(map(_finite_number, content["parameters"].values()))
    ):
        raise bad(f"parameters are not the {len(PARAMETERS)} finite numbers of the gait")
    try:
        check_speed(Biped(content["robot"], content["knee"]), content["speed"])
    except BipedError as error:
        raise bad(str(error)) from None
    speed, period, length = content["speed"], content["period"], content["step_length"]
    if length < MIN_STEP_LENGTH:
        raise bad(f"step_length = {length!r} m, allowed {MIN_STEP_LENGTH} m or more")
    if not math.isclose(length, speed * period, rel_tol=1e-6):
        raise bad(
            f"step_length = {length!r} m, allowed speed × period = {speed * period!r} m "
            f"(speed {speed!r} m/s, period {period!r} s)"
        )
    samples = content.get("samples")
    if not isinstance(samples, dict):
        raise bad("missing samples")
    for key, width in SAMPLE_FIELDS.items():
        if key not in samples:
            raise bad(f"samples.{key} missing")
        try:
            array = np.asarray(samples[key], dtype=float)
        except (TypeError, ValueError, OverflowError):
            raise bad(f"samples.{key} is not an array of numbers") from None
        shape = "(N,)" if width == 1 else f"(N, {width})"
        if array.ndim != (1 if width == 1 else 2) or (width > 1 and array.shape[1] != width):
            raise bad(f"samples.{key} has shape {array.shape}, allowed {shape}")
        if not np.all(np.isfinite(array)):
            where = tuple(int(i) for i in np.argwhere(~np.isfinite(array))[0])
            raise bad(
                f"samples.{key}{list(where)} = {array[where]} is not finite: allowed finite numbers"
            )
        samples[key] = array
    rows = {key: len(samples[key]) for key in SAMPLE_FIELDS}
    counts = list(rows.values())
    common = max(counts, key=counts.count)  # the odd one out is to blame
    for key, count in rows.items():
        if count != common:
            raise bad(f"samples.{key} has {count} rows, the other samples {common}")
    t = samples["t"]
    if common < 2 or t[0] != 0.0 or np.any(np.diff(t) < 0.0):
        raise bad("samples.t does not rise from 0: allowed 2 or more times from 0 to period")
    if not math.isclose(t[-1], period, rel_tol=1e-6):
        raise bad(f"samples.t ends at {t[-1]!r} s, allowed the period {period!r} s")
    return content


# Consistency: the derived fields of a gait file against those recomputed from its parameters.
# A file keeps every bit of its numbers (JSON), so only the rounding of another CPU or numpy
# build (1e-13 of a field's size or so) may separate them; an edited figure differs by far
# more. Allowed difference: CONSISTENCY_RTOL × the field's largest magnitude (at least 1 in
# its unit, so fields near zero are not held to nothing).
CONSISTENCY_RTOL = 1e-9
# Names of the columns of the sample arrays, for the messages.
_COLUMNS = {
    "q": COORDINATES,
    "qd": COORDINATES,
    "qdd": COORDINATES,
    "torques": JOINTS,
    "wrench": ("Fx", "Fz", "Cy"),
}


def _unit(units: dict, field: str, column: int | None = None) -> str:
    unit = units.get(field, "")
    if isinstance(unit, list):
        unit = unit[column] if column is not None else ""
    return f" {unit}" if unit and unit != "1" else ""


def _mismatch(found, expected) -> tuple[int, float] | None:
    """The flat index and size of the largest difference beyond the tolerance, or None."""
    found, expected = np.asarray(found, dtype=float), np.asarray(expected, dtype=float)
    tolerance = CONSISTENCY_RTOL * max(float(np.max(np.abs(expected), initial=0.0)), 1.0)
    difference = np.abs(found - expected).ravel()
    worst = int(np.argmax(difference))
    return (worst, float(difference[worst])) if difference[worst] > tolerance else None


def check_consistency(gait: dict, source: str = "gait") -> None:
    """Raise a ``BipedError`` naming the first field of ``gait`` (as ``read`` returns it) that
    does not belong to its parameters, recomputed as ``to_dict`` computes them (no MuJoCo):
    period and step length, the samples on the check grid, the costs, the constraints,
    ``feasible`` and the impact. ``source`` names the file in the message."""
    from biped.model.criteria import evaluate_step
    from biped.model.gait import build_step
    from biped.optimization.optimize import CHECK_SAMPLES_PER_HALF

    def bad(what):
        return BipedError(f"{source} is inconsistent: {what}")

    model = Biped(gait["robot"], gait["knee"])
    try:
        step = build_step(model, gait["speed"], parameters(gait))
    except BipedError as error:
        raise bad(f"its parameters build no step ({error})") from None
    evaluation = evaluate_step(model, step, CHECK_SAMPLES_PER_HALF, safety=gait["safety"])
    units = gait_units(gait["criterion"])
    for key in ("period", "step_length"):
        expected = getattr(step, key)
        if _mismatch(gait[key], expected):
            raise bad(f"{key} = {gait[key]!r}{_unit(units, key)}, its parameters give {expected!r}")
    samples = gait["samples"]
    for key in SAMPLE_FIELDS:
        expected = getattr(evaluation, key)
        field = f"samples.{key}"
        if samples[key].shape != expected.shape:
            raise bad(
                f"{field} has shape {samples[key].shape}, the parameters' samples "
                f"{expected.shape}: {field} do not belong to the parameters"
            )
        found = _mismatch(samples[key], expected)
        if found:
            index, size = found
            row, column = divmod(index, expected.shape[1]) if expected.ndim == 2 else (index, None)
            where = f"t = {evaluation.t[row]:.4f} s" + (
                f", {_COLUMNS[key][column]}" if column is not None else ""
            )
            raise bad(
                f"{field} do not belong to the parameters (off by {size:.3g}"
                f"{_unit(units, field, column)} at {where})"
            )
    costs = {
        "sthenic": evaluation.sthenic,
        "energy": evaluation.energy,
        "energy_per_metre": evaluation.energy / step.step_length,
    }
    constraints = dict(zip(CONSTRAINTS, map(float, evaluation.worst), strict=True))
    for group, expected_values in (("costs", costs), ("constraints", constraints)):
        stored = gait.get(group)
        if not isinstance(stored, dict):
            raise bad(f"{group} missing")
        for name, expected in expected_values.items():
            field = f"{group}.{name}"
            value = stored.get(name)
            if not _finite_number(value) or _mismatch(value, expected):
                raise bad(
                    f"{field} = {value!r}{_unit(units, field)}, its parameters give "
                    f"{expected!r}{_unit(units, field)}"
                )
    if gait["feasible"] != evaluation.feasible:
        violated = ", ".join(f"{k} = {v:.3g}" for k, v in evaluation.violations().items())
        raise bad(
            f"feasible = {str(gait['feasible']).lower()}, its parameters give "
            f"{str(evaluation.feasible).lower()}" + (f" (Ψ < 0: {violated})" if violated else "")
        )
    impact = gait.get("impact")
    if impact is not None:
        qd_plus, impulse = model.impact(*step.end)
        expected_impact = {
            "impulse": step.impulse,
            "qd_minus": step.end[1],
            "qd_plus": step.start[1],
            "trailing_foot_lift": trailing_foot_lift(model, step.end[0], qd_plus),
        }
        for name, expected in expected_impact.items():
            field = f"impact.{name}"
            try:
                found = _mismatch(impact[name], expected)
            except (KeyError, TypeError, ValueError):
                raise bad(f"{field} is not the {np.shape(expected)} numbers it should be") from None
            if found:
                raise bad(f"{field} does not belong to the parameters (off by {found[1]:.3g})")
        lift = expected_impact["trailing_foot_lift"]
        consistent = bool(step.impulse[1] > 0 and np.all(lift >= 0))
        if impact.get("consistent") is not consistent:
            raise bad(
                f"impact.consistent = {impact.get('consistent')!r}, its parameters give "
                f"{str(consistent).lower()}"
            )


def read_consistent(path: str | Path, allowed: str = GAIT_FILE) -> dict:
    """``read``, then ``check_consistency``: a gait file whose derived fields (samples, costs,
    constraints, feasible, impact) are those of its parameters."""
    gait = read(path, allowed)
    check_consistency(gait, f"gait file {str(path)!r}")
    return gait
