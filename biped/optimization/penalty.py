"""The paper's method (§4): Nelder-Mead on the penalised criterion, and an SLSQP polish.

The constraints enter the criterion through the exponential penalty of eqs. (30)-(31), so
the problem is unconstrained and solved by ``scipy.optimize.minimize(method="Nelder-Mead")``
on the paper's 21 parameters, restarted from the best point with a fresh simplex as the
paper suggests. The simplex works on scaled parameters so that one unit is a comparable
change of every parameter (``SCALES``). Nelder-Mead in 21 dimensions stops far from the
minimum (its result changes by factors of several with the budget and the seed); it is kept
so that its results can be set beside certified optima (``biped.optimization.optimize``),
and as one kind of first guess for IPOPT.

``polish`` is the SLSQP refinement with finite-difference derivatives used before IPOPT, kept
for the benchmark that compares the two.
"""

from __future__ import annotations

import numpy as np

from biped.errors import UnreachableError
from biped.model.criteria import (
    BUILD_ERROR_COST,
    BUILD_ERROR_SLOPE,
    CONSTRAINT_SCALES,
    checked_mask,
    evaluate_step,
    margin_profile,
)
from biped.model.gait import N_PARAMETERS, StepBuildError, build_step
from biped.optimization.problem import GaitProblem

# Samples per spline piece of the penalised criterion.
OPTIMIZE_SAMPLES_PER_HALF = 40
# The paper's kind of budget: a first Nelder-Mead run, then restarts from the best point.
EVALUATIONS_PER_RUN = 1500
MAX_RESTARTS = 1
# Samples per spline piece of the polish (its constraints are Ψ - δ at every sample).
POLISH_SAMPLES_PER_HALF = 25
# SLSQP iterations of the polish at most.
POLISH_ITERATIONS = 200
# One unit of the scaled search space, per parameter: [m, m, rad, rad/s x5, rad/s² x12, s].
SCALES = np.array([0.02, 0.02, 0.03] + [0.3] * 5 + [2.0] * 12 + [0.05])


def cost(problem: GaitProblem, p, samples_per_half=OPTIMIZE_SAMPLES_PER_HALF) -> float:
    """The criterion (30) or (31) of parameters p, penalties (with margins) and Err included."""
    try:
        step = build_step(problem.model, problem.speed, p)
    except StepBuildError as error:
        return BUILD_ERROR_COST + BUILD_ERROR_SLOPE * error.excess
    except UnreachableError:
        return BUILD_ERROR_COST
    evaluation = evaluate_step(
        problem.model, step, samples_per_half, margins=True, safety=problem.safety
    )
    value = evaluation.cost(problem.criterion, step.step_length)
    return value if np.isfinite(value) else BUILD_ERROR_COST


class _Polish:
    """The criterion without penalty and the constraints Ψ - δ as separate functions, for
    SLSQP. SLSQP differentiates both by finite differences at the same points, so the step
    evaluations of the latest points are kept and serve both."""

    def __init__(self, problem: GaitProblem, origin, samples_per_half):
        self.problem, self.origin = problem, origin
        self.samples = samples_per_half
        self.cache: dict = {}
        self.count = 0
        self.reference = None
        self.mask = checked_mask(samples_per_half)
        self.margins = margin_profile(samples_per_half)[self.mask]
        self.scales = np.broadcast_to(CONSTRAINT_SCALES, self.mask.shape)[self.mask]

    def _evaluate(self, z):
        key = z.tobytes()
        if key in self.cache:
            return self.cache[key]
        self.count += 1
        problem = self.problem
        try:
            step = build_step(problem.model, problem.speed, self.origin + SCALES * z)
        except StepBuildError as error:
            value = (None, -(1.0 + error.excess) * np.ones(self.margins.shape))
        except UnreachableError:
            value = (None, -np.ones(self.margins.shape))
        else:
            ev = evaluate_step(problem.model, step, self.samples, safety=problem.safety)
            criterion = ev.value(problem.criterion, step.step_length)
            psi = (ev.constraints[self.mask] - self.margins) / self.scales
            if not np.all(np.isfinite(psi)) or not np.isfinite(criterion):
                value = (None, -np.ones(self.margins.shape))
            else:
                value = (criterion, psi)
        if len(self.cache) > 4 * N_PARAMETERS:
            self.cache.pop(next(iter(self.cache)))
        self.cache[key] = value
        return value

    def objective(self, z):
        value, _ = self._evaluate(z)
        if self.reference is None:
            self.reference = abs(value) if value else 1.0
        return BUILD_ERROR_COST if value is None else value / self.reference

    def constraints(self, z):
        return self._evaluate(z)[1]


def minimize(*args, **kwargs):
    """``scipy.optimize.minimize``, imported on first use: importing it costs every process
    0.2 s, and an optimization by IPOPT needs none of it."""
    from scipy.optimize import minimize as scipy_minimize

    return scipy_minimize(*args, **kwargs)


def polish(problem: GaitProblem, parameters, max_iterations=POLISH_ITERATIONS):
    """SLSQP (finite differences) from ``parameters`` on min C s.t. Ψ_i >= δ_i.

    Returns (parameters, evaluations, SLSQP's message).
    """
    work = _Polish(problem, np.asarray(parameters, float), POLISH_SAMPLES_PER_HALF)
    result = minimize(
        work.objective,
        np.zeros(N_PARAMETERS),
        method="SLSQP",
        constraints=[{"type": "ineq", "fun": work.constraints}],
        options={"maxiter": max_iterations, "ftol": 1e-10},
    )
    return work.origin + SCALES * result.x, work.count, str(result.message)


def nelder_mead(
    problem: GaitProblem,
    start,
    rng: np.random.Generator,
    max_restarts: int = MAX_RESTARTS,
    evaluations_per_run: int = EVALUATIONS_PER_RUN,
):
    """Nelder-Mead on the penalised criterion from the paper's parameters ``start``,
    restarted from the best point (§4).

    Returns (parameters, best value after each run, evaluations, converged): converged is
    False when the last run stopped on its evaluation budget.
    """
    counter = [0]
    start = np.asarray(start, dtype=float)

    def objective(z):
        counter[0] += 1
        return cost(problem, start + SCALES * z)

    best_z = np.zeros(N_PARAMETERS)
    best = objective(best_z)
    history = [best]
    converged = False
    for run in range(max_restarts + 1):
        signs = np.ones(N_PARAMETERS) if run == 0 else rng.choice([-1.0, 1.0], N_PARAMETERS)
        size = 1.0 if run == 0 else 0.5
        simplex = np.vstack([best_z, best_z + size * np.diag(signs)])
        result = minimize(
            objective,
            best_z,
            method="Nelder-Mead",
            options={
                "initial_simplex": simplex,
                "maxfev": evaluations_per_run,
                "xatol": 1e-4,
                "fatol": 1e-6 * max(abs(best), 1.0),
                "adaptive": True,
            },
        )
        converged = bool(result.success)
        improved = result.fun < best - 1e-6 * abs(best)
        if result.fun < best:
            best, best_z = float(result.fun), result.x
        history.append(best)
        if run > 0 and not improved:
            break
    return start + SCALES * best_z, history, counter[0], converged
