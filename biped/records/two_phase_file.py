"""The gait file of a two-phase optimum (``biped optimize --double-support``): a ``Gait`` with
its ``double_support`` block (``biped.records.two_phase_gait``), made from the solver's answer.

``solve``: the two-phase optimum from a single-support one and its gait, what
``biped optimize --double-support`` and ``biped pipeline --double-support`` both run.

Kept apart from ``biped.records.gait_file`` because it reads the two-phase NLP's variables
(``biped.optimization.two_phase``, CasADi): reading the file needs neither.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from biped.optimization.report import Report
from biped.optimization.two_phase import (
    WRENCH,
    TwoPhaseProblem,
    TwoPhaseResult,
    TwoPhaseSolver,
    optimize_two_phase,
    to_parameters,
)
from biped.records.gait_file import Gait, Optimizer
from biped.records.two_phase_gait import unit_of

__all__ = ["TwoPhaseSolve", "gait_of", "solve", "unit_of"]


def optimizer_record(problem: TwoPhaseProblem, result: TwoPhaseResult, seed: int) -> Optimizer:
    """The solver's record of ``result``'s best start: IPOPT's status ("converged" when it
    converged), the starts, its iterations and violation, every variable by name (IPOPT's dual
    infeasibility is not kept by the two-phase solver: not measured, null)."""
    best = result.best
    report = Report(
        method="ipopt",
        status="converged" if best.converged else best.status,
        starts=result.starts,
        starts_at_best=result.at_best,
        iterations=best.iterations,
        constraint_violation=best.constraint_violation,
        dual_infeasibility=float("nan"),
        seconds=result.seconds,
        seed=seed,
        value=best.value,
    )
    names = problem.names
    return Optimizer.of(report, best.variables, names)


def gait_of(problem: TwoPhaseProblem, result: TwoPhaseResult, seed: int) -> Gait:
    """The two-phase gait of ``result``'s best start (which must exist)."""
    single, best = problem.single, result.best
    z = np.asarray(best.variables, dtype=float)
    front = z[-len(WRENCH) * (problem.samples + 1) :].reshape(-1, len(WRENCH))
    return Gait.from_two_phase(
        robot=single.model.robot,
        knee=single.knee,
        speed=single.speed,
        parameters=to_parameters(problem, z),
        landing=problem.landing,
        front_wrench=front,
        share_range=problem.share,
        optimizer=optimizer_record(problem, result, seed),
        safety=single.safety,
    )


@dataclass(frozen=True)
class TwoPhaseSolve:
    """The two-phase optimum of ``problem`` from a single-support optimum (``solve``).

    Attributes:
        problem: the two-phase problem solved.
        result: IPOPT's starts and their best (``TwoPhaseResult``; its ``best`` None when no
            start converged to an optimum feasible on the numeric model).
        setup_seconds: [s] the solver's building (its graphs and IPOPT).
        gait: the best start's two-phase gait, None when there is none.
    """

    problem: TwoPhaseProblem
    result: TwoPhaseResult
    setup_seconds: float
    gait: Gait | None

    def counts(self) -> str:
        """The starts' tally: converged, feasible, at the best value."""
        r = self.result
        return (
            f"{r.converged} of {r.starts} starts converged, {r.feasible} feasible, "
            f"{r.at_best} at the best value"
        )

    def failure(self) -> str:
        """Why there is no two-phase optimum: the tally and each start's end."""
        return f"no two-phase optimum ({self.counts()}: {'; '.join(self.result.outcomes)})"

    def line(self, single_value: float) -> str:
        """The optimum beside the single-support one's C_Γ ``single_value`` [N²·m·s] (the
        optimum must exist)."""
        low, high = self.problem.share
        best, checked = self.result.best, self.result.checked
        return (
            f"two phases (double support {low:g} to {high:g} of the step, "
            f"{self.problem.landing} landing): C = {checked.value:.6g} N²·m·s (single support "
            f"on the check grid) at a share of {best.share:.4f}, single support alone "
            f"{single_value:.6g} ({checked.value / single_value:.3g} times); IPOPT: "
            f"{self.counts()}"
        )


def solve(
    problem: TwoPhaseProblem, single_variables, single_value: float, starts: int, seed: int
) -> TwoPhaseSolve:
    """The two-phase optimum of ``problem`` from the single-support optimum's variables and
    C_Γ [N²·m·s] (``optimize_two_phase``: ``starts`` starts, perturbations seeded by
    ``seed``) and its gait when there is one."""
    solver = TwoPhaseSolver(problem)
    result = optimize_two_phase(solver, single_variables, single_value, starts, seed)
    gait = None if result.best is None else gait_of(problem, result, seed)
    return TwoPhaseSolve(problem, result, solver.setup_seconds, gait)
