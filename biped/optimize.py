"""Optimal gait at a given speed: Nelder-Mead with restarts (§4), then an SLSQP polish.

1. The paper's method. The constraints enter the criterion through the exponential penalty
   of eqs. (30)-(31), so the problem is unconstrained and solved by
   ``scipy.optimize.minimize(method="Nelder-Mead")``, restarted from the best point with a
   fresh simplex as the paper suggests. The simplex works on scaled parameters so that one
   unit is a comparable change of every parameter (``SCALES``).
2. A polish. Nelder-Mead in 21 dimensions stalls far from the minimum (its result changes by
   factors of several with the budget and the first guess), so its result is refined by
   ``scipy.optimize.minimize(method="SLSQP")`` on the same criterion with the constraints
   written explicitly, Ψ_i >= δ_i at every sample of the polish grid.

A gait is reported feasible only if every constraint holds with zero penalty on a fine grid
(``CHECK_SAMPLES_PER_HALF`` per spline piece); of the candidates (after Nelder-Mead, after
the polish) the best feasible one is returned.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np
from scipy.optimize import minimize

from biped.criteria import (
    BUILD_ERROR_COST,
    BUILD_ERROR_SLOPE,
    CRITERIA,
    PAPER_SAFETY,
    Safety,
    StepEvaluation,
    checked_mask,
    evaluate_step,
    margin_profile,
)
from biped.dynamics import Biped
from biped.errors import BipedError, UnreachableError
from biped.gait import N_PARAMETERS, Step, StepBuildError, build_step

# Samples per spline piece while optimising and when checking the optimum.
OPTIMIZE_SAMPLES_PER_HALF = 40
CHECK_SAMPLES_PER_HALF = 100  # 202 samples per step
# Default search budget: a first Nelder-Mead run, then restarts from the best point.
EVALUATIONS_PER_RUN = 1500
MAX_RESTARTS = 1
# Duration of a step in the first guess [s].
FIRST_GUESS_PERIOD = 0.6
# Samples per spline piece of the polish (its constraints are Ψ - δ at every sample).
POLISH_SAMPLES_PER_HALF = 25
# SLSQP iterations of the polish at most.
POLISH_ITERATIONS = 200
# Constraints are divided by these in the polish so that all are of order one [N, m, ...].
CONSTRAINT_SCALES = np.array([1000.0, 0.1, 0.1, 1.0, 1.0, 0.1, 0.1])
# One unit of the scaled search space, per parameter: [m, m, rad, rad/s x5, rad/s² x12, s].
SCALES = np.array([0.02, 0.02, 0.03] + [0.3] * 5 + [2.0] * 12 + [0.05])


def max_walking_speed(model: Biped) -> float:
    """[m/s] √(g L), L the leg length: above it (Froude number > 1) gravity cannot keep the
    stance foot on the ground as the hip vaults over it, whatever the gait."""
    leg = model.robot.shank_length + model.robot.thigh_length
    return float(np.sqrt(model.gravity * leg))


def check_speed(model: Biped, speed: float) -> float:
    """Return ``speed`` if walkable at all, raise a clear error otherwise."""
    high = max_walking_speed(model)
    if not (np.isfinite(speed) and 0.0 < speed <= high):
        raise BipedError(
            f"speed = {speed!r} m/s: allowed 0 < speed <= {high:.3g} m/s "
            f"(√(g·leg length): faster, the stance foot leaves the ground)"
        )
    return float(speed)


def check_criterion(criterion: str) -> str:
    if criterion not in CRITERIA:
        raise BipedError(f"criterion = {criterion!r}: allowed 'sthenic', 'energy'")
    return criterion


def initial_parameters(model: Biped, speed: float, period: float = FIRST_GUESS_PERIOD):
    """A walkable first guess: hip midway between the feet, legs turning as stiff pendulums.

    Args:
        period: duration of the step T [s]; the step length is speed x T.
    """
    leg = model.robot.shank_length + model.robot.thigh_length
    length = min(speed * period, leg)  # a step the legs can reach at any speed
    period = length / speed
    height = np.sqrt((0.97 * leg) ** 2 - (length / 2) ** 2) + model.robot.ankle_height
    rate = -speed / leg
    p = np.zeros(N_PARAMETERS)
    p[0:3] = [-length / 2, height, 0.0]
    p[3:7] = rate  # q1..q4 turn backwards as the hip passes over the feet
    p[20] = period
    return p


def cost(model: Biped, speed, criterion, p, samples_per_half, safety: Safety = PAPER_SAFETY):
    """The criterion (30) or (31) of parameters p, penalties (with margins) and Err included."""
    try:
        step = build_step(model, speed, p)
    except StepBuildError as error:
        return BUILD_ERROR_COST + BUILD_ERROR_SLOPE * error.excess
    except UnreachableError:
        return BUILD_ERROR_COST
    evaluation = evaluate_step(model, step, samples_per_half, margins=True, safety=safety)
    value = evaluation.cost(criterion, step.step_length)
    return value if np.isfinite(value) else BUILD_ERROR_COST


@dataclass
class Optimum:
    """Result of one optimisation."""

    knee: str
    criterion: str
    speed: float  # [m/s]
    parameters: np.ndarray  # (21,)
    step: Step
    evaluation: StepEvaluation  # on the fine check grid
    value: float  # criterion on the fine grid
    evaluations: int  # number of criterion evaluations
    seconds: float
    history: list = field(default_factory=list)  # best value after each restart
    safety: Safety = PAPER_SAFETY  # margins required beyond the paper's constraints

    @property
    def feasible(self) -> bool:
        return self.evaluation.feasible

    def rank(self) -> tuple:
        """Sort key: feasible before infeasible, then lower criterion."""
        return (not self.feasible, self.value)

    def costs(self) -> dict:
        """Both criteria of the gait (no penalty)."""
        return {"sthenic": self.evaluation.sthenic, "energy": self.evaluation.energy}


class _Polish:
    """The criterion without penalty and the constraints Ψ - δ as separate functions, for
    SLSQP. SLSQP differentiates both by finite differences at the same points, so the step
    evaluations of the latest points are kept and serve both."""

    def __init__(self, model, speed, criterion, origin, samples_per_half, safety=PAPER_SAFETY):
        self.model, self.speed, self.criterion, self.origin = model, speed, criterion, origin
        self.safety = safety
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
        try:
            step = build_step(self.model, self.speed, self.origin + SCALES * z)
        except StepBuildError as error:
            value = (None, -(1.0 + error.excess) * np.ones(self.margins.shape))
        except UnreachableError:
            value = (None, -np.ones(self.margins.shape))
        else:
            ev = evaluate_step(self.model, step, self.samples, safety=self.safety)
            criterion = ev.sthenic if self.criterion == "sthenic" else ev.energy
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


def polish(
    model, speed, criterion, parameters, max_iterations=POLISH_ITERATIONS, safety=PAPER_SAFETY
):
    """SLSQP from ``parameters`` on min C s.t. Ψ_i >= δ_i on the optimisation grid.

    Returns (parameters, evaluations). The criterion here is smooth in the parameters
    except where |Γ_i θ̇_i| changes sign (energy criterion), which SLSQP tolerates.
    """
    problem = _Polish(
        model, speed, criterion, np.asarray(parameters, float), POLISH_SAMPLES_PER_HALF, safety
    )
    result = minimize(
        problem.objective,
        np.zeros(N_PARAMETERS),
        method="SLSQP",
        constraints=[{"type": "ineq", "fun": problem.constraints}],
        options={"maxiter": max_iterations, "ftol": 1e-10},
    )
    return problem.origin + SCALES * result.x, problem.count


def nelder_mead(
    model, speed, criterion, start, rng, max_restarts, evaluations_per_run, safety=PAPER_SAFETY
):
    """Nelder-Mead on the penalised criterion, restarted from the best point (§4).

    Returns (parameters, best value after each run, evaluations).
    """
    counter = [0]

    def objective(z):
        counter[0] += 1
        p = start + SCALES * z
        return cost(model, speed, criterion, p, OPTIMIZE_SAMPLES_PER_HALF, safety)

    best_z = np.zeros(N_PARAMETERS)
    best = objective(best_z)
    history = [best]
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
        improved = result.fun < best - 1e-6 * abs(best)
        if result.fun < best:
            best, best_z = float(result.fun), result.x
        history.append(best)
        if run > 0 and not improved:
            break
    return start + SCALES * best_z, history, counter[0]


def optimize(
    model: Biped,
    speed: float,
    criterion: str = "sthenic",
    seed: int = 0,
    max_restarts: int = MAX_RESTARTS,
    evaluations_per_run: int = EVALUATIONS_PER_RUN,
    starts=None,
    polish_iterations: int = POLISH_ITERATIONS,
    polish_starts=(),
    safety: Safety = PAPER_SAFETY,
) -> Optimum:
    """Minimise the criterion at walking speed ``speed`` [m/s].

    From each first guess: Nelder-Mead with restarts on the penalised criterion (the paper's
    method), then an SLSQP polish with the constraints explicit. The best feasible result
    (on the fine check grid) over all first guesses wins; if none is feasible, the best.

    Args:
        seed: orients the restart simplices; the same seed gives the same result.
        max_restarts: restarts from the best point after the first run.
        evaluations_per_run: criterion evaluations per Nelder-Mead run.
        starts: first guesses, each 21 parameters (default: ``initial_parameters``).
        polish_iterations: SLSQP iterations at most (0: no polish).
        polish_starts: guesses close to an optimum (e.g. the optimum at a neighbouring
            speed), polished directly without Nelder-Mead.
        safety: margins of ours beyond the paper's constraints (``Safety``): swing-foot
            clearance, ZMP distance from the sole's edges. The paper's problem by default.
    """
    speed = check_speed(model, speed)
    criterion = check_criterion(criterion)
    rng = np.random.default_rng(seed)
    if starts is None:
        starts = [initial_parameters(model, speed)]
    starts = np.reshape(starts, (-1, N_PARAMETERS))
    began = time.perf_counter()
    candidates = []
    evaluations = 0
    history = []
    for start in starts:
        parameters, runs, count = nelder_mead(
            model,
            speed,
            criterion,
            np.asarray(start, float),
            rng,
            max_restarts,
            evaluations_per_run,
            safety,
        )
        evaluations += count
        history.append(runs)
        candidates.append(parameters)
        if polish_iterations > 0:
            polished, count = polish(model, speed, criterion, parameters, polish_iterations, safety)
            evaluations += count
            candidates.append(polished)
    for start in polish_starts:
        candidates.append(np.asarray(start, float))
        if polish_iterations > 0:
            polished, count = polish(model, speed, criterion, start, polish_iterations, safety)
            evaluations += count
            candidates.append(polished)
    best = None
    for parameters in candidates:
        try:
            step = build_step(model, speed, parameters)
        except (StepBuildError, UnreachableError):
            continue
        evaluation = evaluate_step(model, step, CHECK_SAMPLES_PER_HALF, safety=safety)
        value = evaluation.cost(criterion, step.step_length)
        rank = (not evaluation.feasible, value)
        if best is None or rank < best[0]:
            best = (rank, parameters, step, evaluation, value)
    if best is None:
        raise BipedError(f"no first guess at {speed} m/s gives a posture within reach")
    _, parameters, step, evaluation, value = best
    return Optimum(
        knee=model.knee,
        criterion=criterion,
        speed=speed,
        parameters=parameters,
        step=step,
        evaluation=evaluation,
        value=value,
        evaluations=evaluations,
        seconds=time.perf_counter() - began,
        history=history,
        safety=safety,
    )
