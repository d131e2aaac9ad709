"""Each criterion's optimum of one problem, every criterion measured on every optimum: where
the criteria agree, and by how much they do not.

For each knee the problem (speed, margins, gait family) is optimized for each criterion of
``STUDIED`` (``optimize_criteria``: the certified multistart, ``biped.optimization.optimize``;
the criteria of work also started from the sthenic optimum, as every optimization of theirs),
then every criterion is measured on each optimum, on its check grid, without penalty: a
matrix M per knee (``KneeMatrix``) whose row is the criterion minimised and whose column the
criterion measured.

- The cost of optimizing a for b (``KneeMatrix.cost``): (M[a][b] − M[b][b]) / M[b][b] [%],
  how much worse in b the optimum of a is than b's own optimum.
- The knees' difference (``CriteriaStudy.difference``) at each cell of the matrix:
  (rolling − revolute) / revolute [%], each knee at its own optimum of the row's criterion.

What holds if the optima are optima and the matrix measures what it says: each optimum of c
is no worse in c than the other criteria's optima, the diagonal the least of its column
within ``AGREEMENT`` (relative: two starts reach the same optimum when their values agree to
it). Where another criterion's optimum is lower in c, the optimization of c is started again
from it (``cross_started``, which ``OptimumRow.restarted_from`` records); a column whose
diagonal is still not its least is said (``KneeMatrix.exceptions``) and the command exits 1.

Why they part, in each row: the optimum's electrical energy without the drives' friction and
without the rotors' inertia (``electrical_without``: what the sthenic criterion, the robot's
torques alone, does not see), and the joints' braking work (``braking_work``: what the energy
criteria pay as work and the electrical one barely).

A figure of an optimum that is not certified (converged and feasible on the check grid) is
not an answer: its costs and differences are unknown (None), never zero, and the command
exits 1.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass
from typing import ClassVar

import numpy as np

from biped.errors import BipedError
from biped.model.actuators import drive
from biped.model.bezier import Bezier
from biped.model.criteria import CRITERION_UNITS, Safety, safety_dict
from biped.model.gait import check_knots, family_json, parameter_names
from biped.model.robot import Robot
from biped.model.units import PERCENT, PURE, declared_units, robot_unit, unit_field
from biped.optimization.comparison import relative_change
from biped.optimization.knees import KNEES
from biped.optimization.optimize import (
    AGREEMENT,
    DEFAULT_STARTS,
    Optimum,
    best_of,
    confirm,
    optimize,
    refine,
)
from biped.optimization.problem import GaitProblem

# The criteria set side by side, in the order of the matrix's rows and columns: the paper's
# sthenic criterion, the joints' energy per metre walked, the motors' electrical energy per
# metre (``biped.model.criteria``).
STUDIED = ("sthenic", "energy-per-metre", "electrical")
# Each criterion's field in ``Values``.
FIELDS = {criterion: criterion.replace("-", "_") for criterion in STUDIED}


@dataclass(frozen=True)
class Values:
    """Every studied criterion of one gait on its check grid, without penalty (None: not
    measured, the gait not built)."""

    sthenic: float | None = unit_field(CRITERION_UNITS["sthenic"])
    energy_per_metre: float | None = unit_field(CRITERION_UNITS["energy-per-metre"])
    electrical: float | None = unit_field(CRITERION_UNITS["electrical"])

    def of(self, criterion: str) -> float | None:
        return getattr(self, FIELDS[criterion])

    @classmethod
    def of_optimum(cls, optimum: Optimum) -> Values:
        """The criteria measured on ``optimum``'s gait (``StepEvaluation.value``)."""
        length = optimum.step.step_length
        found = {FIELDS[c]: _measured(optimum.evaluation.value(c, length)) for c in STUDIED}
        return cls(**found)


def _measured(value) -> float | None:
    """A figure as recorded: a finite float, else None (unknown, never zero)."""
    value = float(value)
    return value if math.isfinite(value) else None


# What the sthenic criterion does not see of the drives (``biped.model.actuators.Actuator``):
# their friction, viscous and Coulomb, in the gear and the motor; the rotors' inertia, which
# the gear multiplies by its ratio squared.
FRICTION = ("viscous_friction", "coulomb_friction")
ROTORS = ("rotor_inertia",)


def electrical_without(optimum: Optimum, removed: tuple) -> float | None:
    """[J/m] ``optimum``'s electrical energy per metre without regeneration, as the criterion
    measures it, with the drives' constants ``removed`` set to 0 (the same torques, rates
    and accelerations, ``biped.model.actuators.drive``)."""
    ev = optimum.evaluation
    constants = ev.actuators.constants()
    held = {name: np.zeros_like(v) if name in removed else v for name, v in constants.items()}
    power = drive(held, ev.torques, ev.joint_rates, ev.joint_accels).power
    return _measured(ev.weights @ np.maximum(power, 0.0).sum(-1) / optimum.step.step_length)


def braking_work(optimum: Optimum) -> float | None:
    """[J/m] The joints' braking work per metre, −∫ Σ min(Γ_i θ̇_i, 0) dt / S, which the
    energy criteria count as they count positive work and the electrical one barely (the
    friction brakes through the gear, and the power sent back is lost, not paid)."""
    ev = optimum.evaluation
    work = ev.weights @ np.minimum(ev.torques * ev.joint_rates, 0.0).sum(-1)
    return _measured(-work / optimum.step.step_length)


@dataclass(frozen=True)
class OptimumRow:
    """One knee's optimum of one criterion and every criterion measured on it."""

    optimized: str = unit_field(None)  # the criterion minimised, one of STUDIED
    values: Values = unit_field(Values)  # every criterion on the optimum's check grid
    certified: bool = unit_field(None)  # converged, feasible on the check grid
    status: str = unit_field(None)  # the solver's
    period: float = unit_field("s")  # of the optimal step
    step_length: float = unit_field("m")  # of the optimal step
    starts: int = unit_field(PURE)  # of its multistart, the cross starts included
    starts_at_best: int = unit_field(PURE)  # converged starts at its value (AGREEMENT)
    seconds: float = unit_field("s")  # wall time of its starts
    # what the criteria weigh differently: the electrical energy per metre with the drives'
    # friction removed, with the rotors' inertia removed (``electrical_without``), and the
    # joints' braking (negative) work per metre (``braking_work``)
    frictionless: float | None = unit_field("J/m")
    rotorless: float | None = unit_field("J/m")
    braking: float | None = unit_field("J/m")
    # the criterion whose optimum started it again (``cross_started``); None: none, and
    # the JSON leaves it out
    restarted_from: str | None = unit_field(None, default=None)

    @classmethod
    def of_optimum(cls, optimum: Optimum, restarted_from: str | None = None) -> OptimumRow:
        report = optimum.report
        return cls(
            optimized=optimum.criterion,
            values=Values.of_optimum(optimum),
            certified=bool(optimum.certified),
            status=report.status,
            period=float(optimum.step.period),
            step_length=float(optimum.step.step_length),
            starts=int(report.starts),
            starts_at_best=int(report.starts_at_best),
            seconds=float(report.seconds),
            frictionless=electrical_without(optimum, FRICTION),
            rotorless=electrical_without(optimum, ROTORS),
            braking=braking_work(optimum),
            restarted_from=restarted_from,
        )


@dataclass(frozen=True)
class KneeMatrix:
    """One knee's optima of every studied criterion (rows, in the order of ``STUDIED``)."""

    knee: str = unit_field(None)
    rows: tuple = unit_field([OptimumRow])

    def __post_init__(self):
        if tuple(row.optimized for row in self.rows) != STUDIED:
            found = ", ".join(row.optimized for row in self.rows)
            raise BipedError(f"rows of the {self.knee} knee: {found}; allowed {STUDIED}")

    def row(self, optimized: str) -> OptimumRow:
        return self.rows[STUDIED.index(optimized)]

    @property
    def certified(self) -> bool:
        return all(row.certified for row in self.rows)

    def value(self, optimized: str, measured: str) -> float | None:
        """M[optimized][measured]: ``measured`` on the optimum of ``optimized`` [its unit]."""
        return self.row(optimized).values.of(measured)

    def known(self, optimized: str, measured: str) -> float | None:
        """M[optimized][measured] where the row is a certified optimum, else None."""
        return self.value(optimized, measured) if self.row(optimized).certified else None

    def cost(self, optimized: str, measured: str) -> float | None:
        """[%] How much worse in ``measured`` the optimum of ``optimized`` is than
        ``measured``'s own optimum; None unless both are certified and measured."""
        return _change(self.known(optimized, measured), self.known(measured, measured))

    def exceptions(self, tolerance: float = AGREEMENT) -> list[tuple[str, str]]:
        """(optimized, measured) where the optimum of ``optimized`` is lower in ``measured``
        than ``measured``'s own optimum by more than ``tolerance`` (relative): the
        diagonal is not the least of that column. Rows not certified are left out."""
        found = []
        for measured in STUDIED:
            own = self.known(measured, measured)
            for optimized in STUDIED:
                other = self.known(optimized, measured)
                if own is not None and other is not None and other < own - tolerance * abs(own):
                    found.append((optimized, measured))
        return found

    def diagonal_least(self, tolerance: float = AGREEMENT) -> bool | None:
        """Whether each optimum is the least in its own criterion of every optimum (within
        ``tolerance``, relative); None where a row is not certified (unknown)."""
        if not self.certified:
            return None
        return not self.exceptions(tolerance)

    def part(self, optimized: str, without: str) -> float | None:
        """[J/m] The part of the drives' friction (``without`` "frictionless") or of the
        rotors' inertia ("rotorless") in the electrical energy of the optimum of
        ``optimized``: the electrical energy less its value without them."""
        row = self.row(optimized)
        electrical, less = row.values.of("electrical"), getattr(row, without)
        return None if electrical is None or less is None else electrical - less

    def costs(self) -> dict:
        """{optimized: {measured: cost [%]}} for each pair of different criteria."""
        return {a: {b: self.cost(a, b) for b in STUDIED if b != a} for a in STUDIED}

    def to_dict(self) -> dict:
        content = {
            "knee": self.knee,
            "rows": [_row_dict(row) for row in self.rows],
            "costs": self.costs(),
            "diagonal_least": self.diagonal_least(),
        }
        if content["diagonal_least"] is None:  # unknown: a row not certified
            del content["diagonal_least"]
        return content

    @classmethod
    def from_dict(cls, content: dict) -> KneeMatrix:
        rows = []
        for row in content["rows"]:
            values = Values(**row["values"])
            rows.append(OptimumRow(**{**_fields_of(OptimumRow, row), "values": values}))
        return cls(knee=content["knee"], rows=tuple(rows))


def _change(value: float | None, reference: float | None) -> float | None:
    """[%] (value − reference) / reference, None where either is unknown."""
    if value is None or reference is None:
        return None
    return _measured(relative_change(value, reference))


def _row_dict(row: OptimumRow) -> dict:
    """A row as JSON, its values an object; ``restarted_from`` only where it was."""
    content = dataclasses.asdict(row)
    if content["restarted_from"] is None:
        del content["restarted_from"]
    return content


def _fields_of(kind, content: dict) -> dict:
    """The fields of the record type ``kind`` read from ``content`` (one with a default may
    be left out); a missing one refused."""
    fields = dataclasses.fields(kind)
    names = [f.name for f in fields if f.name in content or f.default is dataclasses.MISSING]
    lacking = [name for name in names if name not in content]
    if lacking:
        every = ", ".join(f.name for f in fields)
        raise BipedError(f"{kind.__name__} lacks {', '.join(lacking)}: allowed a record of {every}")
    return {name: content[name] for name in names}


@dataclass(frozen=True)
class CriteriaStudy:
    """Both knees' matrices of one problem (module docstring); ``to_dict`` and ``from_dict``
    its one codec, ``units`` the unit of each number it writes."""

    FORMAT: ClassVar[str] = "biped-criteria/1"
    speed: float = unit_field("m/s")
    family: int | Bezier = unit_field(None)  # interior knots K, or a Bézier family
    safety: Safety = unit_field(Safety)  # the margins of every optimization
    robot: Robot = unit_field(None)
    seed: int = unit_field(PURE)  # of the perturbed starts
    starts: int = unit_field(PURE)  # IPOPT's own starts of each optimization
    knees: tuple = unit_field([KneeMatrix])  # in the order of ``KNEES``

    def __post_init__(self):
        check_knots(self.family)
        if tuple(matrix.knee for matrix in self.knees) != KNEES:
            raise BipedError(f"knees {[m.knee for m in self.knees]}: allowed {list(KNEES)}")

    @property
    def parameters(self) -> int:
        """The family's parameters (21 for the paper's spline)."""
        return len(parameter_names(self.family))

    @property
    def certified(self) -> bool:
        return all(matrix.certified for matrix in self.knees)

    def knee(self, knee: str) -> KneeMatrix:
        return self.knees[KNEES.index(knee)]

    def difference(self, optimized: str, measured: str) -> float | None:
        """[%] (rolling − revolute) / revolute of ``measured`` at each knee's optimum of
        ``optimized``; None unless both are certified and measured."""
        values = [self.knee(knee).known(optimized, measured) for knee in KNEES]
        return _change(values[1], values[0])

    def differences(self) -> dict:
        """{optimized: {measured: difference [%]}} for every cell."""
        return {a: {b: self.difference(a, b) for b in STUDIED} for a in STUDIED}

    def to_dict(self) -> dict:
        """The JSON of ``biped criteria``: the fields, what follows from them (each knee's
        costs, the knees' differences, the parameters) and ``units``."""
        content = {
            "format": self.FORMAT,
            "speed": self.speed,
            "family": family_json(self.family),
            "parameters": self.parameters,
            "safety": safety_dict(self.safety),
            "robot": self.robot.to_dict(),
            "seed": self.seed,
            "starts": self.starts,
            "criteria": list(STUDIED),
            "knees": [matrix.to_dict() for matrix in self.knees],
            "differences": self.differences(),
        }
        content["units"] = self.units(content)
        return content

    @classmethod
    def from_dict(cls, content: dict) -> CriteriaStudy:
        """The study ``to_dict`` wrote (what follows from the fields is recomputed)."""
        if content.get("format") != cls.FORMAT:
            raise BipedError(f"format = {content.get('format')!r}: allowed {cls.FORMAT!r}")
        family = content["family"]
        return cls(
            speed=float(content["speed"]),
            family=Bezier(family["bezier"]) if isinstance(family, dict) else int(family),
            safety=Safety(**content["safety"]),
            robot=Robot.from_mapping(content["robot"], source="robot"),
            seed=int(content["seed"]),
            starts=int(content["starts"]),
            knees=tuple(KneeMatrix.from_dict(matrix) for matrix in content["knees"]),
        )

    def units(self, content: dict) -> dict:
        """The ``units`` map of ``content`` (``biped.model.units``): every number's."""
        units = {"speed": "m/s", "parameters": PURE, "seed": PURE, "starts": PURE}
        units["family.bezier" if isinstance(self.family, Bezier) else "family"] = PURE
        units.update(declared_units(Safety, "safety."))
        units = {k: v for k, v in units.items() if not k.startswith("safety.") or
                 k.removeprefix("safety.") in content["safety"]}  # fmt: skip
        units.update({f"robot.{name}": robot_unit(name) for name in content["robot"]})
        units.pop("robot.actuators", None)
        units.update(declared_units(OptimumRow, "knees[].rows[]."))
        for a in STUDIED:
            units.update({f"knees[].costs.{a}.{b}": PERCENT for b in STUDIED if b != a})
            units.update({f"differences.{a}.{b}": PERCENT for b in STUDIED})
        return units


@dataclass(frozen=True)
class KneeOptima:
    """One knee's optimum of each studied criterion (``optimize_criteria``)."""

    optima: dict  # criterion -> Optimum
    restarted: dict  # criterion -> the criterion whose optimum started it again


def optimize_criteria(
    problem: GaitProblem,
    seed: int = 0,
    starts: int = DEFAULT_STARTS,
    jobs: int | None = None,
    progress=None,
) -> KneeOptima:
    """``problem``'s optimum (its criterion replaced) of each of ``STUDIED``: each the
    certified multistart with its confirmation (``optimize``, ``confirm``, as ``biped
    optimize``), the criteria of work started from the sthenic optimum too; then
    ``cross_started``. ``progress(optimum)`` is called as each ends."""
    optima = {}
    for criterion in STUDIED:
        posed = dataclasses.replace(problem, criterion=criterion)
        sthenic = optima.get("sthenic") if criterion != "sthenic" else None
        found = optimize(posed, seed, starts, sthenic=sthenic, jobs=jobs)
        optima[criterion] = confirm(posed, found, jobs=jobs)
        if progress is not None:
            progress(optima[criterion])
    return cross_started(optima)


def cross_started(optima: dict, tolerance: float = AGREEMENT) -> KneeOptima:
    """``optima`` ({criterion: Optimum}), where another criterion's certified optimum is
    lower in c than c's own optimum (by more than ``tolerance``, relative), c solved again
    from the lowest such optimum (``refine``) and replaced by the better of the two
    (``best_of``: certified first, then the lower)."""
    found, restarted = dict(optima), {}
    for measured, own in optima.items():
        others = {
            name: other.evaluation.value(measured, other.step.step_length)
            for name, other in optima.items()
            if name != measured and other.certified
        }
        lowest = min(others, key=others.get, default=None)
        if lowest is None or not others[lowest] < own.value - tolerance * abs(own.value):
            continue
        again = refine(own.problem, optima[lowest].variables, seed=own.report.seed)
        found[measured] = best_of(own.problem, [own, again])
        restarted[measured] = lowest
    return KneeOptima(found, restarted)


def study_of(
    problem: GaitProblem, solved: dict, robot: Robot, seed: int, starts: int
) -> CriteriaStudy:
    """The record of ``problem``'s study from each knee's optima ({knee: KneeOptima})."""
    matrices = []
    for knee in KNEES:
        found = solved[knee]
        rows = tuple(
            OptimumRow.of_optimum(found.optima[c], found.restarted.get(c)) for c in STUDIED
        )
        matrices.append(KneeMatrix(knee, rows))
    return CriteriaStudy(
        speed=float(problem.speed),
        family=problem.knots,
        safety=problem.safety,
        robot=robot,
        seed=int(seed),
        starts=int(starts),
        knees=tuple(matrices),
    )


__all__ = [
    "FIELDS",
    "STUDIED",
    "CriteriaStudy",
    "KneeMatrix",
    "KneeOptima",
    "OptimumRow",
    "Values",
    "cross_started",
    "braking_work",
    "electrical_without",
    "optimize_criteria",
    "study_of",
]
