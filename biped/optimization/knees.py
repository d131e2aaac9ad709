"""The two knees' optima of one problem compared: each cost's difference, what moves it, and
a verdict.

The difference of a cost is (rolling − revolute) / revolute on the check grid
(``biped.optimization.comparison.relative_change``) of each knee's optimum of one criterion:
of the criterion both minimise, or of another cost of those same gaits, which neither
minimises (the energy of the sthenic optima is not the energy optima's). What moves it, as
the atlas measures it (``biped.studies.atlas``):

- the finer grid: each optimum re-solved with ``FINER`` times the solver's samples, the
  re-solved optima's difference less the difference;
- the tighter tolerance: each re-solved a hundred times more tightly (``TIGHT``), the same;
- the starts: for a knee whose best value one start alone reached, the relative distance to
  the next optimum its starts reached (``next_optimum``), the knees' in quadrature; 0 where
  at least two starts reached each knee's.

The uncertainty is their sum. A move that could not be measured is unknown, never zero: a
re-solve that did not converge (the tighter one may stop at IPOPT's acceptable level, where
its point still moves the difference by what is measured), or the starts' spread of a cost
the optima do not minimise where one start alone reached a knee's (its next optimum's other
costs are not known). The verdict: the rolling knee needs less, or more, where the
difference exceeds its uncertainty; the knees are not distinguishable where it does not;
unknown where the uncertainty is.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass

from biped.optimization.comparison import DIFFERENCE, relative_change
from biped.optimization.optimize import Optimum, next_optimum, refine

# The knees compared, the reference first.
KNEES = ("revolute", "rolling")
# The costs of a gait compared, with what each is and its unit (``Optimum.costs``).
COSTS = {
    "sthenic": "sthenic criterion [N²·m·s per metre]",
    "energy": "energy criterion [J per step]",
    "electrical": "electrical energy [J/m, no regeneration]",
}
# Times the solver's samples of the finer grid's re-solve (the atlas's).
FINER = 2
# A tighter re-solve that stops at IPOPT's acceptable level still measures the move.
TIGHT_ENDS = ("converged", "Solved_To_Acceptable_Level")
MOVES = ("finer grid", "tighter tolerance", "starts")


@dataclass(frozen=True)
class KneeDifference:
    """One cost of the two knees' optima compared.

    Attributes:
        cost: a key of ``COSTS``.
        minimised: whether it is the criterion the optima minimise.
        value: (rolling − revolute) / revolute [%].
        moves: [%] what moves it, by ``MOVES``: a float, or a string saying why it is unknown.
    """

    cost: str
    minimised: bool
    value: float
    moves: dict

    @property
    def uncertainty(self) -> float | None:
        """[%] The sum of the moves' sizes; None when one is unknown."""
        if any(isinstance(move, str) for move in self.moves.values()):
            return None
        return sum(abs(move) for move in self.moves.values())

    def verdict(self) -> str:
        unknown = [f"{name} {why}" for name, why in self.moves.items() if isinstance(why, str)]
        if unknown:
            return f"unknown: {'; '.join(unknown)}"
        if abs(self.value) <= self.uncertainty:
            return "the knees are not distinguishable (the difference is within its uncertainty)"
        knee = "the rolling knee" if self.minimised else "the rolling knee's gait"
        return f"{knee} needs {'less' if self.value < 0 else 'more'}"

    def line(self) -> str:
        """The difference, its uncertainty and each move, and the verdict, in one line."""
        what = COSTS[self.cost]
        what += ", which both minimise" if self.minimised else ", which neither minimises"
        if self.uncertainty is None:
            shown = f"{self.value:+.2f} % ± unknown"
        else:
            moves = ", ".join(f"{name} {abs(move):.2f}" for name, move in self.moves.items())
            shown = f"{self.value:+.2f} % ± {self.uncertainty:.2f} % ({moves})"
        return f"{what}: {shown}: {self.verdict()}"


def resolved(optima: dict) -> tuple[dict, dict]:
    """Each knee's optimum of ``optima`` re-solved on the finer grid and to the tighter
    tolerance ({knee: Optimum, or why it is not one}, each): what moves a difference."""
    fine = {knee: _finer(optimum) for knee, optimum in optima.items()}
    tight = {knee: _tighter(optimum) for knee, optimum in optima.items()}
    return fine, tight


def optimum_uncertainty(optimum: Optimum, fine, tight) -> float | str:
    """[%] What moves one optimum's value, relative: its re-solves on the finer grid and to
    the tighter tolerance (``resolved``), and the spread of its starts (``next_optimum``),
    summed; or why it is unknown (a re-solve failed, no other start converged)."""
    failed = [f"{name}: {why}" for name, why in (("finer grid", fine), ("tighter", tight))
              if isinstance(why, str)]  # fmt: skip
    spread = next_optimum(optimum.report)
    if spread is None:
        failed.append("starts: no other start converged")
    if failed:
        return f"not measured ({'; '.join(failed)})"
    moves = [relative_change(other.value, optimum.value) for other in (fine, tight)]
    return sum(abs(move) for move in moves) + 100 * spread


def compare_knees(optima: dict, resolves: tuple | None = None) -> list[KneeDifference]:
    """Each cost of ``COSTS`` of the knees' certified ``optima`` ({knee: Optimum}, one
    problem but the knee) compared, the criterion they minimise first; ``resolves``: their
    re-solves (``resolved``) when made already."""
    criterion = optima["rolling"].problem.criterion
    fine, tight = resolved(optima) if resolves is None else resolves
    found = []
    for cost in sorted(COSTS, key=lambda c: c != criterion):
        value = _change(optima, cost)
        moves = {
            "finer grid": _moved(fine, cost, value),
            "tighter tolerance": _moved(tight, cost, value),
            "starts": _starts(optima, cost == criterion),
        }
        found.append(KneeDifference(cost, cost == criterion, value, moves))
    return found


def _starts(optima: dict, minimised: bool):
    """[%] The spread of the starts of a cost (``next_optimum`` of each knee, in
    quadrature), or why it is not known."""
    single = [k for k in KNEES if optima[k].report.starts_at_best < 2]
    if not single:
        return 0.0
    if not minimised:  # the next optimum's other costs are not known
        return f"not known ({' and '.join(single)}: reached by a single start)"
    spreads = {k: next_optimum(optima[k].report) for k in KNEES}
    alone = [k for k, spread in spreads.items() if spread is None]
    if alone:
        return f"not known ({' and '.join(alone)}: no other start converged)"
    return 100 * math.hypot(*spreads.values())


def knee_lines(differences: list[KneeDifference], speed: float, criterion: str) -> list[str]:
    """What a command prints of ``compare_knees``: what is compared, then a line a cost."""
    return [
        f"rolling vs revolute knee, each knee's {criterion}-optimal gait at {speed} m/s "
        f"({DIFFERENCE}):",
        *(f"  {difference.line()}" for difference in differences),
    ]


def _change(optima: dict, cost: str) -> float:
    costs = {knee: optima[knee].costs()[cost] for knee in KNEES}
    return relative_change(costs["rolling"], costs["revolute"])


def _moved(resolved: dict, cost: str, value: float):
    """The re-solved optima's difference less ``value`` [%], or why it is unknown."""
    failed = [f"{knee}: {why}" for knee, why in resolved.items() if isinstance(why, str)]
    if failed:
        return f"not measured ({'; '.join(failed)})"
    return _change(resolved, cost) - value


def _finer(optimum: Optimum):
    """The optimum re-solved on the finer grid, or why it is not one."""
    problem = dataclasses.replace(
        optimum.problem, samples_per_half=FINER * optimum.problem.samples_per_half
    )
    found = refine(problem, optimum.variables)
    return found if found.certified else _failure(found)


def _tighter(optimum: Optimum):
    """The optimum re-solved to the tighter tolerance, or why it is not one."""
    found = refine(optimum.problem, optimum.variables, "tight")
    return found if found.feasible and found.report.status in TIGHT_ENDS else _failure(found)


def _failure(optimum: Optimum) -> str:
    report = optimum.report
    return report.status if not report.converged else "infeasible on the check grid"
