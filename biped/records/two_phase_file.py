"""The gait file of a two-phase optimum (``biped optimize --double-support``): a ``Gait`` with
its ``double_support`` block (``biped.records.two_phase_gait``), made from the solver's answer.

Kept apart from ``biped.records.gait_file`` because it reads the two-phase NLP's variables
(``biped.optimization.two_phase``, CasADi): reading the file needs neither.
"""

from __future__ import annotations

import numpy as np

from biped.optimization.report import Report
from biped.optimization.two_phase import (
    WRENCH,
    TwoPhaseProblem,
    TwoPhaseResult,
    to_parameters,
)
from biped.records.gait_file import Gait, Optimizer
from biped.records.two_phase_gait import unit_of

__all__ = ["gait_of", "unit_of"]


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
