"""A ladder of nested gait families climbed: one problem's optimum in each family, each rung
started from the rung below's optimum embedded exactly in it.

The families K = 1, 3, 7, 15, ... interior knots (``biped.model.gait.ladder``) each halve the
pieces of the one below, so each holds it: the rung below's optimal gait is a gait of the
richer family (``GaitProblem.embedded``, the same motion), among the rung's starts
(``optimize(..., below=...)``), and the richer optimum is never worse than it, up to the
solver's samples, which differ between families (``biped.optimization.problem.solver_samples``:
the embedded gait may sit a little inside a margin between the rung's samples).
``Rung.start_value`` is that gait's criterion on the rung's check grid, ``Rung.monotone``
whether the rung's optimum is no worse (``MONOTONE_TOLERANCE``, relative).
"""

from __future__ import annotations

import dataclasses
import time
from dataclasses import dataclass

from biped.errors import BipedError
from biped.model.bezier import Bezier
from biped.model.gait import check_embedding, check_knots, parameter_names
from biped.optimization.optimize import DEFAULT_STARTS, Optimum, checked, optimize, prepare
from biped.optimization.problem import GaitProblem

# A rung's optimum is no worse than the rung below's within this, relative.
MONOTONE_TOLERANCE = 1e-9


@dataclass(frozen=True)
class Rung:
    """One family of a ladder and its optimum.

    Attributes:
        knots: interior knots K of the family.
        optimum: the problem's optimum in it (``Optimum``; its value on the check grid).
        setup_seconds: [s] building its solvers (0 when built already in this process).
        seconds: [s] its multistart, the rung below's start among its starts.
        start_value: the rung below's optimum embedded in this family, its criterion on this
            family's check grid (the criterion's unit; None on the first rung).
    """

    knots: int
    optimum: Optimum
    setup_seconds: float
    seconds: float
    start_value: float | None

    @property
    def parameters(self) -> int:
        """The family's parameters (21 for the paper's spline)."""
        return len(parameter_names(self.knots))

    @property
    def value(self) -> float:
        return self.optimum.value

    @property
    def certified(self) -> bool:
        return self.optimum.certified

    @property
    def monotone(self) -> bool:
        """Whether the optimum is no worse than the rung below's embedded in this family
        (``MONOTONE_TOLERANCE``); True on the first rung."""
        if self.start_value is None:
            return True
        return self.value <= self.start_value * (1.0 + MONOTONE_TOLERANCE)


def check_ladder(knots) -> tuple:
    """``knots`` if a ladder: at least one family, each holding the one before
    (``biped.model.gait.check_embedding``: splines of more knots, or Bézier curves of higher
    degrees), else a clear error."""
    rungs = tuple(check_knots(k) for k in knots)
    if not rungs:
        raise BipedError("ladder = (): allowed one family or more, such as 1,3,7,15")
    for below, above in zip(rungs, rungs[1:], strict=False):
        same = isinstance(above, Bezier) == isinstance(below, Bezier)
        if same and _size(above) <= _size(below):
            raise BipedError(
                f"ladder {rungs}: {above} after {below}, allowed increasing knots or degrees"
            )
        check_embedding(below, above)  # a spline and a Bézier: refused (but a single cubic)
    return rungs


def _size(family) -> int:
    """The order of a family on a ladder: its knots, or a Bézier's degree."""
    return family.degree if isinstance(family, Bezier) else family


def embedded_optimum(problem: GaitProblem, below: Optimum) -> Optimum:
    """The optimum ``below`` of a family ``problem``'s holds, as a gait of ``problem``'s
    family (the same motion), evaluated on its check grid; its report is ``below``'s."""
    variables = problem.embedded(below.variables, below.problem.knots)
    return checked(problem, variables, below.report)


def climb(
    problem: GaitProblem,
    knots=(1, 3, 7, 15),
    seed: int = 0,
    starts: int = DEFAULT_STARTS,
    jobs: int | None = None,
    progress=None,
) -> list[Rung]:
    """``problem``'s optimum in each family of the ladder ``knots`` (``check_ladder``), each
    rung's starts holding the rung below's optimum (``optimize(..., below=...)``); a rung
    whose optimum is not converged still starts the next (its report says so).
    ``progress(rung)`` is called as each rung ends."""
    rungs, below = [], None
    for k in check_ladder(knots):
        family = dataclasses.replace(problem, knots=k, samples_per_half=None)
        setup = prepare(family)
        began = time.perf_counter()
        optimum = optimize(family, seed, starts, jobs=jobs, below=below)
        seconds = time.perf_counter() - began
        start = None if below is None else embedded_optimum(family, below).value
        rung = Rung(k, optimum, setup, seconds, start)
        rungs.append(rung)
        if progress is not None:
            progress(rung)
        below = optimum
    return rungs


__all__ = ["Rung", "check_ladder", "climb", "embedded_optimum"]
