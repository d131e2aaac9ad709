"""IPOPT on the CasADi graph of a step: exact gradients and Hessian, constraints explicit.

    min  C(z)   subject to   (Ψ_i − δ_i) / scale_i >= 0 at the samples,
                             hip height at the start >= ``MIN_HIP_HEIGHT``,
                             bounds on z (``biped.optimization.problem.bounds``)

C is the sthenic criterion (30), the energy criterion (31) or the energy per metre (31) / S,
without penalty. The energy
criterion's |Γ_i θ̇_i| is written exactly with slack variables s_ij (no smoothing):

    ∫ Σ_i |Γ_i θ̇_i| dt  =  min T Σ_j w_j Σ_i s_ij   s.t.  s_ij >= Γ_i θ̇_i,  s_ij >= −Γ_i θ̇_i

The electrical criterion (the motors' energy per metre without regeneration,
``biped.model.actuators``) likewise, a joint's negative power lost:

    (1/S) ∫ Σ_i max(P_i, 0) dt  =  min Σ_j w_j Σ_i s_ij / V   s.t.  s_ij >= P_ij,  s_ij >= 0

The solver works on scaled variables y = z / ``SCALES``. One ``Solver`` (graph, derivatives
and IPOPT instance) is built per robot, knee, criterion, safety and sample count and serves
every speed and every start (``solver_for``).

With ``radius_bounds`` the knee radii (r1, r2) [m] are variables too (scaled by
``RADIUS_SCALE``), the rolling knee's graph built with them as symbols
(``StepGraph(..., design=True)``): the gait and the knee optimised together
(``biped.optimization.design``). With bounds of four numbers the variables are a profiled
knee's (r1, r2 [m], k1, k2 [m/rad], ``biped.model.profile``), each scaled by
``RADIUS_SCALE``, and the surfaces' bounds (``biped.model.profile.surface_margins``: convex
and inside the disc of radius the upper bound of r_i over the knee's range) join the
constraints, divided by ``SURFACE_SCALES``.
"""

from __future__ import annotations

import functools
import time
from dataclasses import dataclass

import casadi as ca
import numpy as np

from biped.errors import BipedError
from biped.model.criteria import Safety
from biped.model.dynamics import Biped
from biped.model.profile import PARAMETERS, surface_margins
from biped.model.robot import Robot
from biped.optimization.derivatives import constraint_jacobian, lagrangian_hessian
from biped.optimization.problem import GaitProblem, bounds, scales, variable_names
from biped.optimization.symbolic import StepGraph
from biped.runtime.interrupts import kept_interrupts

# IPOPT's settings. ``tol``: its scaled optimality error; certified optima from different
# starts then agree to about 1e-8 relative.
IPOPT_OPTIONS = {
    "tol": 1e-9,
    "constr_viol_tol": 1e-9,
    "max_iter": 1000,
    "print_level": 0,
    "sb": "yes",
    "mu_strategy": "adaptive",
    # The criteria and constraints are of order one in the solver's scaled variables
    # (``biped.optimization.problem.SCALES``, ``CONSTRAINT_SCALES``); IPOPT's own gradient
    # scaling then takes about twice the iterations to the same optima
    # (``benchmarks/bench_optimize.py``).
    "nlp_scaling_method": "none",
}
# The barrier strategies a start can be solved with: IPOPT's adaptive one (the default) and
# its monotone one from mu = 0.01 (and a tighter tolerance). From the same start the two
# follow other paths through the energy criterion's basins and may end in other local minima
# (``biped.optimization.optimize``).
BARRIERS = {
    "adaptive": {},
    "monotone": {"mu_strategy": "monotone", "mu_init": 1e-2},
    # From mu = 1e-3: a start near an optimum keeps closer to it, along another path through
    # the energy criteria's close local minima (``biped.optimization.optimize.confirm``).
    "confirm": {"mu_strategy": "monotone", "mu_init": 1e-3},
    # From mu = 1e-4: a start near an optimum (the table's, at a neighbouring speed) keeps to
    # the local minimum nearest it, in 30-70 iterations where the barrier from 1e-2 takes
    # 80-170 (the energy criterion's table starts, ``biped.optimization.optimize``).
    "near": {"mu_strategy": "monotone", "mu_init": 1e-4},
    # From a converged point, ten times tighter: what ``IPOPT_OPTIONS``' tolerance leaves of
    # an optimum (the atlas's error bar). A hundred times is below the noise of the
    # derivatives: the dual infeasibility stalls at 1e-10 to 1e-9 and IPOPT ends at its
    # acceptable level in most sthenic cells (2 of 12 certified at 0.2-1 m/s, 0-3 cm; ten
    # times: 7 of 12, and 12 of 12 of the energy per metre's).
    "tight": {"tol": 1e-10, "constr_viol_tol": 1e-10},
}
# IPOPT's statuses that are a converged local optimum.
CONVERGED = ("Solve_Succeeded",)
# One unit of the knee radii in the solver's scaled space [m] (and of a profile's rates k1,
# k2 [m/rad]).
RADIUS_SCALE = 0.05
# The surfaces' bounds of a profile design are divided by these: the convexity margins by
# 0.1 m, the inside margins (limit² − |K − C|² [m²]) by the limit² (relative).
CONVEX_SCALE = 0.1


@dataclass(frozen=True)
class Solution:
    """IPOPT's answer from one start.

    Attributes:
        variables: z (21,) at the end.
        value: the criterion there (on the solver's samples, without penalty).
        status: IPOPT's return status (``Solve_Succeeded`` when converged).
        iterations: IPOPT iterations.
        constraint_violation: largest violation of a constraint or bound at the end, in the
            solver's scaled units.
        dual_infeasibility: IPOPT's unscaled dual infeasibility at the end.
        seconds: time of the solve.
        radii: (r1, r2) [m] at the end, when the radii are variables (else None); a
            profile design's (r1, r2, k1, k2) [m, m, m/rad, m/rad].
    """

    variables: np.ndarray
    value: float
    status: str
    iterations: int
    constraint_violation: float
    dual_infeasibility: float
    seconds: float
    radii: tuple | None = None

    @property
    def converged(self) -> bool:
        return self.status in CONVERGED


@functools.cache
def one_blas_thread() -> bool:
    """Run IPOPT's linear solver (MUMPS, on the OpenBLAS that CasADi ships) on one thread;
    returns whether that library was found.

    With several threads its sums come in an order that depends on the thread count, and an
    optimum's last digits with it (1e-11 of the criterion): a pool worker, a Dask worker
    (started with ``OPENBLAS_NUM_THREADS=1``) and this process would write different files.
    On one thread every process gives every bit the same; the problems are small, so more
    threads are not faster, and a sweep's workers share the cores anyway.
    """
    import ctypes
    from pathlib import Path

    # The file named as the library's SONAME: the one MUMPS loads (the wheel holds copies
    # under other names, which would load as other instances).
    path = Path(ca.__file__).parent / "libcasadi-tp-openblas.so.0"
    try:
        ctypes.CDLL(str(path)).openblas_set_num_threads(1)
    except (OSError, AttributeError):  # another platform's or build's CasADi
        return False
    return True


class Solver:
    """IPOPT on one problem family (every speed): ``solve(problem, start)``.

    Args:
        radius_bounds: ((r1 low, r2 low), (r1 high, r2 high)) [m]: the knee radii are
            variables within these bounds (``solve(problem, start, radii)``); None: they
            are ``model``'s. Four numbers a side: a profile's (r1, r2, k1, k2) (module
            docstring).
    """

    def __init__(
        self,
        model: Biped,
        criterion: str,
        safety: Safety,
        samples_per_half: int,
        radius_bounds=None,
        knots: int = 1,
    ):
        # CasADi calls back into Python for every operand's shape while it builds the graph;
        # an interrupt whose handler raises there is swallowed: raised again after the build.
        with kept_interrupts():
            self._build(model, criterion, safety, samples_per_half, radius_bounds, knots)

    def _build(self, model, criterion, safety, samples_per_half, radius_bounds, knots):
        one_blas_thread()
        design = radius_bounds is not None
        self.knee_size = len(radius_bounds[0]) if design else 0  # 2 radii, or 4 of a profile
        profile = self.knee_size == len(PARAMETERS)
        motors = criterion == "electrical"
        self.graph = graph = StepGraph(
            model, samples_per_half, safety, design, knots, motors, profile=profile
        )
        self.criterion = criterion
        self.design = design
        self.scales, self.size = scales(knots), len(variable_names(knots))
        y = ca.SX.sym("y", self.size)
        unknowns, scaled = [graph.z], [ca.DM(self.scales) * y]
        if design:
            rho = ca.SX.sym("rho", self.knee_size)
            y = ca.vertcat(y, rho)
            unknowns.append(graph.radii)
            scaled.append(RADIUS_SCALE * rho)
        surfaces = []
        if design and profile:
            limits = tuple(float(v) for v in radius_bounds[1][:2])
            margins = surface_margins([RADIUS_SCALE * rho[i] for i in range(4)], limits, ca)
            divisors = [CONVEX_SCALE] * 2 + [limits[0] ** 2] * 2 + [CONVEX_SCALE] * 2
            divisors += [limits[1] ** 2] * 2  # the order of ``MARGINS``
            surfaces = [m / d for m, d in zip(margins, divisors, strict=True)]
        x, objective, g = self._objective_and_constraints(graph, criterion, y, surfaces)
        head = ca.substitute(graph.head, ca.vertcat(*unknowns), ca.vertcat(*scaled))
        flat = ca.substitute([graph.flat(ca.vertcat(objective, g))], unknowns, scaled)[0]
        self.hessian = lagrangian_hessian(graph, x, graph.speed, head, objective, g)
        self.jacobian = constraint_jacobian(graph, x, graph.speed, head, g)
        # CasADi's reverse mode on the flat graph (cheaper a call than chained through the
        # samples), dense as IPOPT reads it.
        gradient = ca.densify(ca.gradient(flat[0], x))
        self.gradient = ca.Function(
            "nlp_grad_f", [x, graph.speed], [flat[0], gradient], ["x", "p"], ["f", "grad_f_x"]
        )
        nlp = {"x": x, "p": graph.speed, "f": flat[0], "g": flat[1:]}
        name = "design" if design else "gait"
        self.nlp = ca.nlpsol(name, "ipopt", nlp, self.ipopt_options("adaptive"))
        self._nlps = {"adaptive": self.nlp}  # and the other barriers', built when first used
        # The powers the slacks bound: the motors' P_i for the electrical criterion (s >= P,
        # s >= 0), the joints' Γ_i θ̇_i for the energy criteria (s >= |Γ θ̇|).
        slacked = graph.electrical_power if motors else graph.power
        self.evaluate = ca.Function(
            "evaluate", graph.inputs, [graph.sthenic, graph.energy, slacked]
        )
        self.lower, self.upper = bounds(knots)
        lower, upper = self.lower / self.scales, self.upper / self.scales
        if design:
            self.radius_bounds = tuple(tuple(map(float, side)) for side in radius_bounds)
            lower = np.concatenate([lower, np.array(self.radius_bounds[0]) / RADIUS_SCALE])
            upper = np.concatenate([upper, np.array(self.radius_bounds[1]) / RADIUS_SCALE])
        self.lbx = np.concatenate([lower, np.zeros(self.slacks)])
        self.ubx = np.concatenate([upper, np.full(self.slacks, np.inf)])
        self.n_constraints = g.shape[0]

    def _objective_and_constraints(self, graph: StepGraph, criterion: str, y, surfaces=()):
        """The NLP's variables x, objective and constraints, on the graph's symbols (the
        samples' quantities, the head; ``StepGraph.on_symbols``), the slacks and a profile's
        ``surfaces`` bounds (on y)."""
        period = graph.head_symbol[graph.period_index]
        hip_height = graph.head_symbol[graph.hip_height_index]
        constraints = ca.vertcat(graph.on_symbols["constraints"], hip_height, *surfaces)
        if criterion == "sthenic":
            self.slacks = 0
            return y, graph.on_symbols["sthenic"], constraints
        # The slacks bound the motors' P_i (s >= P, s >= 0 by the bounds: the electrical
        # criterion) or the joints' Γ_i θ̇_i (s >= ±Γ θ̇: the energy criteria).
        electrical = criterion == "electrical"
        rows = graph.on_symbols["electrical_power" if electrical else "power"]
        power = ca.vec(rows)  # sample-major
        slack = ca.SX.sym("s", power.shape[0])
        self.slacks = power.shape[0]
        weights = ca.vec(ca.repmat(graph.weights, rows.shape[0], 1))
        objective = period * ca.dot(weights, slack)  # C_E, per step
        if criterion != "energy":  # per metre: T Σ w s / (V T)
            objective = ca.dot(weights, slack) / graph.speed
        bounds = [slack - power] if electrical else [slack - power, slack + power]
        return ca.vertcat(y, slack), objective, ca.vertcat(constraints, *bounds)

    def solve(
        self, problem, start, radii=None, hold_radii: bool = False, barrier: str = "adaptive"
    ) -> Solution:
        """IPOPT from the variables ``start`` (21,), clipped into the bounds, at
        ``problem.speed``; with radii as variables, from the knee radii ``radii`` (r1, r2) [m]
        clipped into theirs, or held at them (``hold_radii``: the gait alone optimised, IPOPT
        treating the radii as parameters). ``barrier``: one of ``BARRIERS``."""
        if barrier not in BARRIERS:
            raise BipedError(f"barrier = {barrier!r}: allowed {', '.join(map(repr, BARRIERS))}")
        with kept_interrupts():  # CasADi stops at Ctrl-C but swallows it: raised again
            return self._solve(problem, start, radii, hold_radii, barrier)

    def prepare(self, barriers) -> None:
        """Build IPOPT's instances of ``barriers`` now (before starts are forked to other
        processes, which then share them)."""
        for barrier in barriers:
            self._nlp(barrier)

    def _nlp(self, barrier: str):
        if barrier not in self._nlps:  # the same problem (IPOPT's oracle), other settings
            self._nlps[barrier] = ca.nlpsol(
                f"{self.nlp.name()}_{barrier}",
                "ipopt",
                self.nlp.oracle(),
                self.ipopt_options(barrier),
            )
        return self._nlps[barrier]

    def ipopt_options(self, barrier: str) -> dict:
        """nlpsol's options: ``IPOPT_OPTIONS`` with those of ``barrier``, the derivatives built
        sample by sample (``biped.optimization.derivatives``)."""
        options = {f"ipopt.{key}": value for key, value in IPOPT_OPTIONS.items()}
        options.update({f"ipopt.{key}": value for key, value in BARRIERS[barrier].items()})
        derivatives = {"hess_lag": self.hessian, "jac_g": self.jacobian, "grad_f": self.gradient}
        # A profiled knee's trial points may leave its family (no real rolling relation, a
        # flexion beyond its range: NaN), which IPOPT's line search steps back from; said
        # once by the report, not by every evaluation.
        quiet = {"show_eval_warnings": False} if self.graph.profile else {}
        return {**options, "print_time": False, **quiet, **derivatives}

    def _solve(self, problem, start, radii, hold_radii, barrier) -> Solution:
        began = time.perf_counter()
        nlp = self._nlp(barrier)
        z0 = np.clip(np.asarray(start, dtype=float), self.lower, self.upper)
        x0 = z0 / self.scales
        inputs = [z0, problem.speed]
        if self.design:
            if radii is None:
                raise BipedError("radii = None: allowed the knee radii (r1, r2) to start from")
            low, high = self.radius_bounds
            r0 = np.asarray(radii, dtype=float)
            if not hold_radii:  # held radii may lie beyond the design's bounds
                r0 = np.clip(r0, low, high)
            x0 = np.concatenate([x0, r0 / RADIUS_SCALE])
            inputs.append(r0)
        if self.slacks:
            power = np.asarray(self.evaluate(*inputs)[2]).T.ravel()
            start = np.maximum(power, 0.0) if self.criterion == "electrical" else np.abs(power)
            x0 = np.concatenate([x0, start if np.all(np.isfinite(power)) else 0.0])
        lbx, ubx = self.lbx, self.ubx
        if self.design and hold_radii:
            held = slice(self.size, self.size + self.knee_size)
            lbx, ubx = lbx.copy(), ubx.copy()
            lbx[held] = ubx[held] = r0 / RADIUS_SCALE
        result = nlp(x0=x0, p=problem.speed, lbx=lbx, ubx=ubx, lbg=0.0, ubg=np.inf)
        stats = nlp.stats()
        x = np.asarray(result["x"]).ravel()
        g = np.asarray(result["g"]).ravel()
        violation = max(
            float(np.max(np.maximum(-g, 0.0), initial=0.0)),
            float(np.max(np.maximum(lbx - x, 0.0), initial=0.0)),
            float(np.max(np.maximum(x - ubx, 0.0), initial=0.0)),
        )
        iterations = stats.get("iterations") or {}
        dual = iterations.get("inf_du") or [float("nan")]
        end = self.size + self.knee_size
        return Solution(
            variables=x[: self.size] * self.scales,
            radii=tuple(map(float, x[self.size : end] * RADIUS_SCALE)) if self.design else None,
            value=float(result["f"]),
            status=str(stats["return_status"]),
            iterations=int(stats["iter_count"]),
            constraint_violation=violation,
            dual_infeasibility=float(dual[-1]),
            seconds=time.perf_counter() - began,
        )


@functools.lru_cache(maxsize=8)
def _solver(robot: Robot, knee: str, criterion: str, safety: Safety, samples: int, knots) -> Solver:
    return Solver(Biped(robot, knee), criterion, safety, samples, knots=knots)


def forget_solvers() -> None:
    """Build each solver anew at its next use (``solver_for``): after a setting its build reads
    from the environment changed (``biped.optimization.compiled.SWITCH``)."""
    _solver.cache_clear()


def solver_for(problem: GaitProblem) -> Solver:
    """The solver of ``problem``'s family, built once per process and reused."""
    if not isinstance(problem, GaitProblem):
        raise BipedError(f"problem = {problem!r}: allowed a biped.optimization.problem.GaitProblem")
    return _solver(
        problem.model.robot,
        problem.knee,
        problem.criterion,
        problem.safety,
        problem.samples_per_half,
        problem.knots,
    )
