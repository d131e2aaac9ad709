"""One machined knee over the speeds: the profile designed at one speed (its gait file's
robot), its optimal gait at each speed of a sweep beside the circles designed at that speed
and the revolute knee.

At each speed V, for the file's criterion and margins:

- revolute: the revolute knee's optimal gait (``biped.optimization.optimize.optimize``);
- circles: the rolling knee's radii designed with the gait at V
  (``biped.optimization.design.optimize_design``, from the profile robot's radii), a knee
  made for that speed;
- machined: the optimal gait at V of the circles designed at the profile's own speed, as
  machined (their radii held): the single knee of circles the profile replaces;
- profile: the optimal gait at V of the profile as machined (its r1, r2, k1, k2 held), also
  started from the other knees' optimal gaits.

The change of the profile against the circles, (profile − circles) / circles, tells what a
single knee machined for one speed buys (negative) or costs (positive) against a knee of
circles redesigned at every speed; against the machined circles, what the profile buys over
the circles it replaces; against the revolute knee, what it buys at all. A speed
where any of the three is not certified (converged and feasible) is said so, its changes
left unknown (None), never zero.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

import numpy as np

from biped.errors import BipedError
from biped.model.criteria import CRITERION_UNITS, Safety
from biped.model.dynamics import Biped
from biped.model.robot import Robot
from biped.optimization.comparison import relative_change
from biped.optimization.design import MIN_RADIUS, DesignProblem, optimize_design, radius_limits
from biped.optimization.optimize import DEFAULT_STARTS, optimize
from biped.optimization.problem import GaitProblem

# The knees of a row, in order.
KNEES = ("revolute", "circles", "machined", "profile")
# The changes of a row (first, second), by name.
CHANGES = {
    "profile_vs_circles": ("profile", "circles"),
    "profile_vs_machined": ("profile", "machined"),
    "profile_vs_revolute": ("profile", "revolute"),
    "circles_vs_revolute": ("circles", "revolute"),
}


@dataclass(frozen=True)
class SpeedRow:
    """The three knees at one speed (module docstring)."""

    speed: float  # [m/s]
    values: dict  # knee -> criterion on the check grid (its unit, the criterion's)
    certified: dict  # knee -> bool
    radii: tuple  # [m] the circles designed at this speed (r1, r2)

    @property
    def all_certified(self) -> bool:
        return all(self.certified.values())

    def change(self, first: str, second: str) -> float | None:
        """[%] (first − second) / second; None unless both are certified optima."""
        if not (self.certified[first] and self.certified[second]):
            return None
        return relative_change(self.values[first], self.values[second])

    def to_dict(self) -> dict:
        return {
            "speed": self.speed,
            "values": dict(self.values),
            "certified": dict(self.certified),
            "circles_radii": {"r1": self.radii[0], "r2": self.radii[1]},
            **{name: self.change(*pair) for name, pair in CHANGES.items()},
        }


def row_at(
    robot: Robot,
    machined: tuple,
    speed: float,
    criterion: str,
    safety: Safety,
    seed: int = 0,
    starts: int = DEFAULT_STARTS,
) -> SpeedRow:
    """The four knees at ``speed`` for the profiled ``robot`` and the circles ``machined``
    (r1, r2) [m] designed at its own speed (module docstring)."""
    revolute = optimize(
        GaitProblem(Biped(robot, "revolute"), speed, criterion, safety), seed, starts
    )
    circles_robot = dataclasses.replace(robot, k1=0.0, k2=0.0)
    limits = radius_limits(circles_robot)
    own = tuple(
        float(np.clip(r, MIN_RADIUS, high))
        for r, high in zip((robot.r1, robot.r2), limits, strict=True)
    )
    circles_robot = dataclasses.replace(circles_robot, r1=own[0], r2=own[1])
    design = optimize_design(
        DesignProblem(circles_robot, speed, criterion, safety),
        seed=seed,
        starts=starts,
        given=[(revolute.variables, own)],
    )
    given = [o.variables for o in (design.optimum, revolute) if np.all(np.isfinite(o.variables))]
    held = dataclasses.replace(circles_robot, r1=machined[0], r2=machined[1])
    fixed = optimize(
        GaitProblem(Biped(held, "rolling"), speed, criterion, safety), seed, starts, given=given
    )
    given += [fixed.variables] if np.all(np.isfinite(fixed.variables)) else []
    profile = optimize(
        GaitProblem(Biped(robot, "rolling"), speed, criterion, safety), seed, starts, given=given
    )
    optima = {"revolute": revolute, "circles": design.optimum, "machined": fixed}
    optima["profile"] = profile
    return SpeedRow(
        speed=float(speed),
        values={knee: float(o.value) for knee, o in optima.items()},
        certified={knee: bool(o.certified) for knee, o in optima.items()},
        radii=tuple(float(r) for r in design.radii),
    )


def table(rows: list[SpeedRow], unit: str) -> str:
    """The rows as text: each knee's criterion and the profile's changes ("vs": (profile −
    other) / other), "n/a" where not certified."""
    lines = [
        f"{'speed [m/s]':>11}{f'revolute [{unit}]':>20}{'circles':>11}{'r1 [m]':>8}{'r2 [m]':>8}"
        f"{'machined':>11}{'profile':>11}{'vs circles':>12}{'vs machined':>13}{'vs revolute':>13}"
    ]
    for row in rows:

        def shown(value, digits=".3f"):
            return "n/a" if value is None else f"{value:+{digits}} %"

        flag = (
            ""
            if row.all_certified
            else "  NOT CERTIFIED: " + ", ".join(k for k, ok in row.certified.items() if not ok)
        )
        lines.append(
            f"{row.speed:11.3f}{row.values['revolute']:20.4f}{row.values['circles']:11.4f}"
            f"{row.radii[0]:8.4f}{row.radii[1]:8.4f}{row.values['machined']:11.4f}"
            f"{row.values['profile']:11.4f}{shown(row.change('profile', 'circles')):>12}"
            f"{shown(row.change('profile', 'machined')):>13}"
            f"{shown(row.change('profile', 'revolute'), '.2f'):>13}{flag}"
        )
    return "\n".join(lines)


def content_of(path: str, gait, machined: tuple, rows: list[SpeedRow]) -> dict:
    """The JSON of ``biped profile-speeds``: the profile's gait file (``path``, read as
    ``gait``), its robot, criterion and speed of design, the machined circles (r1, r2) [m],
    each speed's row and the units of every number."""
    content = {
        "gait": path,
        "robot": gait.robot.to_dict(),
        "criterion": gait.criterion,
        "designed_at": gait.speed,
        "machined_circles": dict(zip(("r1", "r2"), machined, strict=True)),
        "rows": [row.to_dict() for row in rows],
    }
    content["units"] = units(content, CRITERION_UNITS[gait.criterion])
    return content


def units(content: dict, criterion_unit: str) -> dict:
    """The ``units`` map of a profile-speeds file (``biped.model.units``): every number's."""
    from biped.model.units import PERCENT, robot_unit

    found = {f"robot.{name}": robot_unit(name) for name in content["robot"] if name != "actuators"}
    found.update({"designed_at": "m/s", "rows[].speed": "m/s"})
    found.update({f"machined_circles.{name}": "m" for name in ("r1", "r2")})
    found.update({f"rows[].values.{knee}": criterion_unit for knee in KNEES})
    found.update({f"rows[].circles_radii.{name}": "m" for name in ("r1", "r2")})
    for name in CHANGES:
        found[f"rows[].{name}"] = PERCENT
    return found


def machined_circles(gait, path) -> tuple:
    """(r1, r2) [m] of the circles designed at the profile's speed: its design block's row
    of the designed circles."""
    rows = (gait.design or {}).get("compared") if isinstance(gait.design, dict) else None
    for row in rows or []:
        if row.get("knee") == "rolling, optimal radii" and row.get("radii"):
            return float(row["radii"]["r1"]), float(row["radii"]["r2"])
    raise BipedError(
        f"gait file {path!r} has no designed circles in its design block: allowed the gait "
        "file of biped design --profile"
    )
