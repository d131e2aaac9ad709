"""Certified optima: one model written twice, exact derivatives, converged and confirmed
optima, loud failure, the same answer whatever the CPU's kernels."""

import dataclasses
import functools
import json
import os
import subprocess
import sys

import casadi as ca
import numpy as np
import pytest

import biped
from biped.model.criteria import PAPER_SAFETY, Safety, clearance_profile, evaluate_step
from biped.model.gait import build_step
from biped.optimization.optimize import (
    AGREEMENT,
    CONFIRM,
    GUESS_PERIODS,
    MONOTONE,
    MONOTONE_START,
    NEAR,
    STHENIC_START,
    Candidate,
    Report,
    Start,
    confirm,
    optimize,
    starts_at_value,
    table_starts,
)
from biped.optimization.problem import SCALES, GaitProblem, bounds, max_walking_speed
from biped.optimization.solver import solver_for
from biped.optimization.symbolic import StepGraph
from biped.optimization.table import OTHER_KNEE_START, TABLE_START
from tests.conftest import optimal_gait

ROBOT = biped.Robot.paper()
UNEQUAL = dataclasses.replace(ROBOT, r1=0.03, r2=0.08)
SAMPLES = 25
NAN = float("nan")


def random_variables(problem, rng):
    """Variables around the first guess, knees bent between 0.05 and 0.3 rad."""
    z = problem.first_guess() + 0.3 * SCALES * rng.standard_normal(21)
    z[:2] = rng.uniform(0.05, 0.3, 2)
    return z


def numeric(problem, z, samples=SAMPLES):
    step = build_step(problem.model, problem.speed, problem.to_parameters(z))
    return step, evaluate_step(problem.model, step, samples, safety=problem.safety)


@pytest.mark.parametrize("knee, robot", [("revolute", ROBOT), ("rolling", UNEQUAL)])
@pytest.mark.parametrize("safety", [PAPER_SAFETY, Safety(clearance=0.02, zmp_margin=0.01)])
def test_symbolic_model_equals_numeric_model(knee, robot, safety):
    """The CasADi graph and the numpy model give the same torques, wrench, constraints and
    criteria to 1e-12 (relative) at random parameters."""
    problem = GaitProblem(biped.Biped(robot, knee), 0.3, safety=safety)
    function = StepGraph(problem.model, SAMPLES, safety).function()
    rng = np.random.default_rng(7)
    for _ in range(3):
        z = random_variables(problem, rng)
        out = function(z=z, speed=problem.speed)
        _, ev = numeric(problem, z)

        def same(symbolic, value, what):
            value = np.asarray(value)
            scale = np.max(np.abs(value))
            np.testing.assert_allclose(
                np.asarray(symbolic), value, rtol=1e-12, atol=1e-12 * scale, err_msg=what
            )

        same(out["parameters"].full().ravel(), problem.to_parameters(z), "parameters")
        same(out["torques"].full().T, ev.torques, "torques")
        same(out["wrench"].full().T, ev.wrench, "wrench")
        checked = ~np.isnan(ev.constraints)
        same(out["psi"].full().T[checked], ev.constraints[checked], "constraints")
        same(float(out["sthenic"]), ev.sthenic, "sthenic")
        same(float(out["energy"]), ev.energy, "energy")


def test_symbolic_model_tells_another_robot():
    """The equality above is not trivial: the graph of other knee radii gives torques that
    differ from the numeric model's by far more than 1e-12."""
    problem = GaitProblem(biped.Biped(UNEQUAL, "rolling"), 0.3)
    other = StepGraph(biped.Biped(ROBOT, "rolling"), SAMPLES, PAPER_SAFETY).function()
    z = random_variables(problem, np.random.default_rng(1))
    _, ev = numeric(problem, z)
    assert np.max(np.abs(other(z=z, speed=0.3)["torques"].full().T - ev.torques)) > 1e-3


@pytest.mark.parametrize("criterion", ["sthenic", "energy"])
def test_graph_gradient_matches_finite_differences(criterion):
    """The graph's exact gradient of the criterion agrees with central finite differences
    of the numeric model."""
    problem = GaitProblem(biped.Biped(UNEQUAL, "rolling"), 0.3, criterion)
    graph = StepGraph(problem.model, SAMPLES, PAPER_SAFETY)
    expression = graph.sthenic if criterion == "sthenic" else graph.energy
    gradient = ca.Function("g", [graph.z, graph.speed], [ca.gradient(expression, graph.z)])
    z = random_variables(problem, np.random.default_rng(3))
    exact = gradient(z, 0.3).full().ravel()
    for i in range(21):
        h = 1e-6 * SCALES[i]
        up, down = z.copy(), z.copy()
        up[i] += h
        down[i] -= h
        difference = (
            getattr(numeric(problem, up)[1], criterion)
            - getattr(numeric(problem, down)[1], criterion)
        ) / (2 * h)
        assert difference == pytest.approx(exact[i], rel=1e-5, abs=1e-6 * np.abs(exact).max())


@pytest.mark.parametrize("knee", biped.KNEES)
def test_variables_round_trip_through_the_papers_parameters(knee):
    """Knee bends -> hip position -> inverse geometric model -> the same knee bends."""
    problem = GaitProblem(biped.Biped(UNEQUAL, knee), 0.25)
    rng = np.random.default_rng(2)
    for _ in range(5):
        z = random_variables(problem, rng)
        np.testing.assert_allclose(
            problem.from_parameters(problem.to_parameters(z)), z, rtol=0, atol=1e-10
        )


@pytest.mark.parametrize("knee", biped.KNEES)
def test_default_optimum_is_certified(knee):
    """IPOPT converged, every start reached the same value, constraints hold on the fine
    grid and also on a grid ten times denser than the check's (no violation between
    samples)."""
    optimum = optimal_gait(knee)
    report = optimum.report
    assert report.converged and report.method == "ipopt"
    assert report.starts_at_best == report.starts >= 3
    assert report.constraint_violation < 1e-8 and report.dual_infeasibility < 1e-6
    assert optimum.feasible and optimum.certified
    dense = evaluate_step(optimum.problem.model, optimum.step, 1000)
    assert np.nanmin(dense.constraints) >= 0.0
    starts = [s.value for s in report.history]
    assert np.ptp(starts) <= AGREEMENT * min(starts)


@pytest.mark.parametrize("knee", biped.KNEES)
def test_optimum_is_a_constrained_minimum(knee):
    """No nearby point that meets the solver's constraints (Ψ_i >= δ_i at its samples) has
    a lower criterion: small random moves from the optimum, kept when feasible, all cost
    more (optimality seen from outside the solver)."""
    optimum = optimal_gait(knee)
    problem = optimum.problem
    function = StepGraph(problem.model, SAMPLES, PAPER_SAFETY).function()
    rng = np.random.default_rng(4)
    lower, upper = bounds()
    tried = 0
    for _ in range(200):
        z = np.clip(optimum.variables + 1e-4 * SCALES * rng.standard_normal(21), lower, upper)
        out = function(z=z, speed=problem.speed)
        if np.min(out["constraints"].full()) >= 0.0:
            tried += 1
            assert float(out["sthenic"]) >= optimum.report.value * (1 - 1e-12)
    assert tried >= 5


@functools.cache
def energy_optimum(knee: str):
    """The energy optimum at 0.3 m/s from one start of each kind (``starts=1``), computed
    once for the tests that read it."""
    return optimize(GaitProblem(biped.Biped(ROBOT, knee), 0.3, "energy"), starts=1)


def test_energy_criterion_is_exact_at_the_optimum():
    """The slack formulation of |Γ θ̇| reaches the true energy criterion: the solver's
    value equals the numeric energy at its samples."""
    optimum = energy_optimum("revolute")
    problem = optimum.problem
    assert optimum.report.converged
    _, ev = numeric(problem, optimum.variables)
    assert optimum.report.value == pytest.approx(ev.energy, rel=1e-7)


def test_energy_optimum_spends_no_more_than_the_gait_of_least_torque():
    """The sthenic optimum is a feasible gait of the energy problem: the energy optimum
    must spend at most its energy (on the solver's samples). From the first guesses alone
    IPOPT settles in a basin of short fast steps that spends 3.4 times more (rolling knee,
    0.3 m/s); the sthenic optimum as a start is what finds the lower basin."""
    model = biped.Biped(ROBOT, "rolling")
    energy = GaitProblem(model, 0.3, "energy")
    sthenic = optimal_gait("rolling")
    _, ev = numeric(energy, sthenic.variables)
    optimum = energy_optimum("rolling")
    assert optimum.report.converged
    kinds = [s.kind for s in optimum.report.history]
    assert kinds == [  # the table covers 0.3 m/s: its starts replace the first guesses
        TABLE_START,
        TABLE_START + NEAR,
        OTHER_KNEE_START,
        OTHER_KNEE_START + MONOTONE,
        OTHER_KNEE_START + NEAR,
        STHENIC_START,
        MONOTONE_START,
    ]
    assert optimum.report.value <= ev.energy
    for period in GUESS_PERIODS:  # the sthenic criterion's first guesses, adaptive barrier
        first_guess_only = optimize(energy, starts=0, given=[energy.first_guess(period)])
        assert first_guess_only.report.value > 2 * optimum.report.value


def test_the_energy_criterion_starts_from_the_sthenic_optimum_under_both_barriers():
    """The energy criterion has close local minima: from the sthenic optimum (revolute knee,
    0.3 m/s) IPOPT's adaptive barrier ends 0.1 % above where its monotone barrier ends, and
    the optimum is the lower of the two (without the monotone start it would be the
    higher)."""
    optimum = energy_optimum("revolute")
    problem = optimum.problem
    values = {s.kind: s.value for s in optimum.report.history}
    assert values[MONOTONE_START] < (1 - 5e-4) * values["sthenic optimum"]
    assert optimum.report.value == min(values.values())
    with pytest.raises(biped.BipedError, match="barrier = 'other': allowed 'adaptive'"):
        solver_for(problem).solve(problem, problem.first_guess(), barrier="other")


def test_a_given_sthenic_optimum_must_be_of_the_same_problem():
    """The sthenic start handed to the energy criterion (a sweep's) is refused, naming it,
    when it is the optimum of another speed or not an optimum."""
    sthenic = optimal_gait("rolling")  # 0.3 m/s
    other = GaitProblem(sthenic.problem.model, 0.325, "energy")
    with pytest.raises(biped.BipedError, match="sthenic at 0.3 m/s .rolling knee.: allowed"):
        optimize(other, starts=1, sthenic=sthenic)
    with pytest.raises(
        biped.BipedError, match="sthenic = 1.0: allowed a biped.optimization.optimize"
    ):
        optimize(other, starts=1, sthenic=1.0)


def test_one_point_solved_under_both_barriers_is_one_start_at_the_best():
    """Two solves from the sthenic optimum that end at the same value do not confirm each
    other; a second start that ends there does."""
    value = 1.0

    def start(kind, v=value):
        return Start(kind, v, "Solve_Succeeded", 50)

    pair = [start(STHENIC_START), start(MONOTONE_START, value * (1 + 1e-8))]
    assert starts_at_value(pair, value) == 1
    assert starts_at_value([*pair, start("first guess")], value) == 2
    table = [start(TABLE_START), start(TABLE_START + MONOTONE)]
    assert starts_at_value(table, value) == 1 and starts_at_value(table + pair, value) == 2
    assert starts_at_value([start("first guess S = 0.1 m" + MONOTONE)] + pair, value) == 2
    assert starts_at_value([start("first guess"), start("given")], value) == 2
    assert starts_at_value([start(MONOTONE_START), start("given", 2.0)], value) == 1


def test_a_point_solved_under_three_barriers_is_one_start_at_the_best():
    """The confirmation's barrier (``CONFIRM``) names the same start: a point re-solved from
    mu = 1e-3 does not confirm itself; another start's re-solve does; given starts, which
    share a kind, count as many as the most of one barrier."""
    value = 1.0

    def start(kind, v=value):
        return Start(kind, v, "Solve_Succeeded", 50)

    other = [start(OTHER_KNEE_START), start(OTHER_KNEE_START + MONOTONE)]
    assert starts_at_value(other + [start(OTHER_KNEE_START + CONFIRM)], value) == 1
    assert starts_at_value([start(OTHER_KNEE_START + CONFIRM), start("first guess")], value) == 2
    given = [start("given"), start("given"), start("given" + CONFIRM)]
    assert starts_at_value(given, value) == 2
    assert starts_at_value(given + [start("given" + CONFIRM)] * 2, value) == 3
    kinds = [Candidate("given", None).kind, Candidate("given", None, "confirm").kind]
    assert kinds == ["given", "given" + CONFIRM]
    assert Candidate(TABLE_START, None).under("monotone").kind == TABLE_START + MONOTONE
    with pytest.raises(biped.BipedError, match="barrier = .gentle."):
        Candidate("given", None, "gentle")


def test_a_best_reached_by_one_start_is_confirmed_by_the_near_starts():
    """At 0.25 m/s the revolute knee's least energy per step is reached by one start of
    ``optimize`` (the other knee's under the monotone barrier); ``confirm`` reaches it again
    from the table's starts from mu = 1e-3, names them in the history and finds nothing
    worse. A confirmed optimum is returned as it is."""
    problem = GaitProblem(biped.Biped(ROBOT, "revolute"), 0.25, "energy")
    single = optimize(problem)
    assert single.certified and single.report.starts_at_best == 1
    confirmed = confirm(problem, single)
    assert confirmed.certified and confirmed.report.confirmed
    assert confirmed.report.value <= single.report.value * (1 + AGREEMENT)
    added = confirmed.report.history[len(single.report.history) :]
    at_best = [
        s.kind
        for s in added
        if abs(s.value - confirmed.report.value) <= AGREEMENT * confirmed.report.value
    ]
    assert at_best and all(kind.endswith(CONFIRM) for kind in at_best)
    assert confirm(problem, confirmed) is confirmed
    unconverged = dataclasses.replace(
        single, report=dataclasses.replace(single.report, status="Maximum_Iterations_Exceeded")
    )
    assert confirm(problem, unconverged) is unconverged
    with pytest.raises(biped.BipedError, match="problem = 0.25: allowed a biped"):
        confirm(0.25, single)
    with pytest.raises(biped.BipedError, match="optimum = None: allowed a biped"):
        confirm(problem, None)


def test_confirm_solves_no_start_the_optimum_holds_already(monkeypatch):
    """``confirm`` leaves out the starts an optimum's history holds already (the energy
    criterion's other-knee start under the monotone barrier is one of its own starts): the
    same start solved again would reach its own value and count it twice."""
    from biped.optimization import optimize as optimize_module

    problem = GaitProblem(biped.Biped(ROBOT, "revolute"), 0.25, "energy")
    own = OTHER_KNEE_START + MONOTONE
    report = Report(
        method="ipopt",
        status="converged",
        starts=1,
        starts_at_best=1,
        iterations=10,
        constraint_violation=0.0,
        dual_infeasibility=0.0,
        seconds=0.1,
        seed=0,
        value=0.78,
        history=(Start(own, 0.78, "Solve_Succeeded", 10),),
    )
    single = optimize_module.checked(problem, problem.first_guess(), report)
    asked = []

    class Asked(Exception):
        """Raised instead of solving."""

    def record(candidates, *args, **kwargs):
        asked.extend(start.kind for start in candidates)
        raise Asked

    monkeypatch.setattr(optimize_module, "multistart", record)
    with pytest.raises(Asked):
        confirm(problem, single, given=[problem.first_guess()])
    assert asked == [TABLE_START + CONFIRM, OTHER_KNEE_START + CONFIRM, "given" + CONFIRM]


def test_a_given_start_that_is_a_table_start_is_left_out():
    """A given start within ``SAME_START`` of the variables' scales of one of the table's
    starts (a campaign's other-knee optimum, the table's other-knee start) is that start:
    ``apart_from_table`` leaves it out, an optimization with its own starts solves it once,
    and a start farther away is kept."""
    from biped.optimization.optimize import SAME_START, apart_from_table
    from biped.optimization.problem import scales

    problem = GaitProblem(biped.Biped(ROBOT, "revolute"), 0.3, "sthenic")
    (other,) = [s.variables for s in table_starts(problem, 1) if s.source == OTHER_KNEE_START]
    near = other + 0.1 * SAME_START * scales()
    far = other + 10 * SAME_START * scales()
    kept = apart_from_table(problem, [near, far, problem.first_guess()])
    assert len(kept) == 2 and np.array_equal(kept[0], far)
    optimum = optimize(problem, starts=1, given=[near])
    assert [s.kind for s in optimum.report.history].count("given") == 0
    with_far = optimize(problem, starts=1, given=[far])
    assert [s.kind for s in with_far.report.history].count("given") == 1


def test_a_single_start_says_which_start_and_how_far_the_next_optimum_lies():
    """A best value one start reached is named with that start and the next optimum's
    distance and starts (the two barriers of one point counted once)."""
    from biped.optimization.optimize import single_start_note

    def start(kind, v):
        return Start(kind, v, "Solve_Succeeded", 50)

    history = (
        start(TABLE_START, 1.0),
        start(STHENIC_START, 1.001),
        start(MONOTONE_START, 1.001),
        start("given", 1.001),
        Start("given", 0.5, "Infeasible_Problem_Detected", 9),
    )
    report = Report("ipopt", "converged", 5, 1, 50, 1e-9, 1e-9, 1.0, 0, 1.0, history)
    note = single_start_note(report)
    assert note == f"by the {TABLE_START} alone; the next optimum +0.1 %, by 2 starts"


def test_a_single_start_under_several_barriers_is_named_once():
    """One start that reached the best under two barriers is named once with both; a given
    start says what it is."""
    from biped.optimization.optimize import CONFIRM, NEAR, single_start_note

    def start(kind, v):
        return Start(kind, v, "Solve_Succeeded", 50)

    history = (start(TABLE_START, 1.0), start(TABLE_START + NEAR, 1.0), start("given", 1.2))
    report = Report("ipopt", "converged", 3, 2, 50, 1e-9, 1e-9, 1.0, 0, 1.0, history)
    assert single_start_note(report).startswith(
        f"by the {TABLE_START} under the adaptive barrier and the monotone barrier from 1e-4 "
        "alone; the next optimum +20 %"
    )
    history = (start("given" + CONFIRM, 1.0), start(TABLE_START, 1.1))
    report = Report("ipopt", "converged", 2, 1, 50, 1e-9, 1e-9, 1.0, 0, 1.0, history)
    assert single_start_note(report).startswith(
        "by a given start (another problem's optimum, or an earlier stage's) under the "
        "monotone barrier from 1e-3 alone"
    )


def test_a_nelder_mead_summary_says_its_constraints_are_penalties_not_nan():
    """Nelder-Mead has no constraint or dual measure: its line says so instead of "nan";
    IPOPT's gives both."""
    nan = float("nan")
    nelder_mead = Report("nelder-mead", "budget exhausted", 1, 1, 201, nan, nan, 0.5, 0, 1.0)
    assert "nan" not in nelder_mead.summary() and "penalties" in nelder_mead.summary()
    ipopt = Report("ipopt", "converged", 5, 5, 42, 1e-9, 8.9e-11, 0.5, 0, 1.0)
    assert "constraint violation 1.0e-09, dual infeasibility 8.9e-11" in ipopt.summary()


def test_report_read_back_from_its_json_is_the_report():
    """A report written as JSON and read back is the same report: a value that is not
    finite written as null and read as NaN, a file without the best value read as NaN."""
    history = (Start("first guess", 1.5, "Solve_Succeeded", 40), Start("given", NAN, "x", 3))
    report = Report("ipopt", "converged", 2, 1, 40, 1e-9, NAN, 2.5, 7, 1.5, history)
    content = json.loads(json.dumps(report.to_dict()))
    assert list(content) == [f.name for f in dataclasses.fields(Report)]
    assert content["dual_infeasibility"] is None and content["history"][1]["value"] is None
    back = Report.from_dict(content)
    assert repr(back) == repr(report)
    del content["value"]
    assert np.isnan(Report.from_dict(content).value)


def test_papers_method_stops_far_above_the_certified_optimum():
    """Nelder-Mead on the penalised criterion (the paper's method, small budget) ends
    feasible but several times above the certified optimum, and says it ran out of budget."""
    problem = optimal_gait("rolling").problem
    paper = optimize(problem, method="nelder-mead", max_restarts=0, evaluations_per_run=300)
    assert paper.report.status == "budget exhausted" and not paper.certified
    assert paper.value > 2 * optimal_gait("rolling").value


def test_optimizer_is_deterministic():
    """The same problem and seed give the same variables, bit for bit."""
    problem = optimal_gait("rolling").problem
    again = optimize(problem)
    np.testing.assert_array_equal(again.variables, optimal_gait("rolling").variables)


_PROBE = """
import json, biped
from biped.optimization.optimize import optimize
from biped.optimization.problem import GaitProblem
o = optimize(GaitProblem(biped.Biped(biped.Robot.paper(), "rolling"), 0.3))
print(json.dumps([o.report.status, o.value]))
"""


@pytest.mark.parametrize(
    "environment",
    [{"OPENBLAS_NUM_THREADS": "1"}, {"NPY_DISABLE_CPU_FEATURES": "AVX512_ICL X86_V4"}],
    ids=["one BLAS thread", "no AVX-512"],
)
def test_same_optimum_on_other_kernels(environment):
    """The default optimum is the same to 1e-6 with one BLAS thread and without numpy's
    AVX-512 kernels (run in a fresh interpreter)."""
    env = {**os.environ, **environment}
    out = subprocess.run(
        [sys.executable, "-c", _PROBE], env=env, capture_output=True, text=True, check=True
    )
    status, value = json.loads(out.stdout.strip().splitlines()[-1])
    assert status == "converged"
    assert value == pytest.approx(optimal_gait("rolling").value, rel=1e-6)


_SOLVE_PROBE = """
import hashlib, json, numpy as np, biped
from biped.model.gait import spline_basis
from biped.optimization.problem import GaitProblem
from biped.optimization.solver import solver_for
def digest(array):
    return hashlib.sha256(np.ascontiguousarray(array, dtype=float).tobytes()).hexdigest()
problem = GaitProblem(biped.Biped(biped.Robot.paper(), "rolling"), 0.35, "energy")
end = solver_for(problem).solve(problem, problem.first_guess(0.1 / 0.35), barrier="monotone")
u = np.linspace(0.0, 1.0, 1001)
reach = np.linspace(0.4, 0.83, 400)[:, None] * np.array([[np.sin(0.3), -np.cos(0.3)]])
angles = [biped.Biped(biped.Robot.paper(), k).leg_angles(-reach) for k in biped.KNEES]
print(json.dumps({
    "bases": digest(np.concatenate([b.ravel() for b in spline_basis(25)[1]])),
    "leg angles": digest(np.concatenate([a.ravel() for a in angles])),
    "solution": digest(end.variables), "status": end.status,
    "numpy power": digest(u ** 3), "numpy arctan2": digest(np.arctan2(u - 0.5, u + 0.1)),
}))
"""


@functools.cache
def _probe(kernels: str) -> dict:
    """What ``_SOLVE_PROBE`` prints, run with all of numpy's kernels or without AVX-512's."""
    env = dict(os.environ)
    if kernels == "no AVX-512":
        env["NPY_DISABLE_CPU_FEATURES"] = "AVX512_ICL X86_V4"
    out = subprocess.run(
        [sys.executable, "-c", _SOLVE_PROBE], env=env, capture_output=True, text=True, check=True
    )
    return json.loads(out.stdout.strip().splitlines()[-1])


def test_a_solve_is_the_same_bits_without_avx512_kernels():
    """The solver's constant matrices (the spline bases), the legs' inverse geometry that
    starts it and builds every step, and an energy solve from one start are the same bits
    with numpy's AVX-512 kernels off: IPOPT and CasADi do not use numpy, and its kernels
    enter nothing they compute, so a basin of the energy criterion cannot change with the
    machine."""
    here, there = _probe("all"), _probe("no AVX-512")
    assert here["status"] == "Solve_Succeeded"
    fields = ("bases", "leg angles", "solution")
    assert [here[f] for f in fields] == [there[f] for f in fields]


@pytest.mark.parametrize("function", ["numpy power", "numpy arctan2"])
def test_numpy_kernels_differ_without_avx512_on_this_machine(function):
    """The check above can fail: numpy's power and arc tangent, which the bases and the
    inverse geometry avoid (``u * u * u``, the C library's ``atan2``), give other bits
    without AVX-512 kernels, where the machine has them."""
    here, there = _probe("all"), _probe("no AVX-512")
    if here[function] == there[function]:
        pytest.skip(f"numpy dispatches the same {function} kernel with and without AVX-512")
    assert here[function] != there[function]


@pytest.mark.parametrize(
    "speed, criterion, needle",
    [
        (0.0, "sthenic", "speed = 0.0"),
        (-0.1, "sthenic", "allowed"),
        (float("nan"), "sthenic", "speed = nan"),
        (5.0, "sthenic", "stance foot leaves the ground"),
        (0.3, "power", "criterion = 'power'"),
    ],
)
def test_bad_problem_is_rejected(speed, criterion, needle):
    """Bad speeds and criteria raise a clear error naming the value."""
    model = biped.Biped(ROBOT, "revolute")
    with pytest.raises(biped.BipedError, match=needle):
        GaitProblem(model, speed, criterion)
    assert 2.5 < max_walking_speed(model) < 3.0


def test_bad_solver_settings_are_rejected():
    """Bad method, starts or seed: a clear error naming the value."""
    problem = GaitProblem(biped.Biped(ROBOT, "revolute"), 0.3)
    with pytest.raises(biped.BipedError, match="method = 'slsqp'"):
        optimize(problem, method="slsqp")
    with pytest.raises(biped.BipedError, match="seed = -1"):
        optimize(problem, seed=-1)
    with pytest.raises(biped.BipedError, match="no start"):
        optimize(problem, starts=0)


def test_clearance_is_kept_by_the_optimum():
    """With a required clearance the optimal swing foot stays that high away from the ends,
    and the gait costs more than without it (the constraint is active)."""
    model = biped.Biped(ROBOT, "rolling")
    problem = GaitProblem(model, 0.3, safety=Safety(clearance=0.02))
    optimum = optimize(problem, starts=1)
    assert optimum.certified and optimum.safety.clearance == 0.02
    feet = model.points(optimum.evaluation.q, ["swing_heel", "swing_toe"])[..., 1]
    required = clearance_profile(100, 0.02)
    assert np.all(feet[1:-1] >= required[1:-1, None] - 1e-12)
    assert optimum.value > optimal_gait("rolling").value


def test_bad_safety_margins_are_rejected():
    """A negative or huge clearance or ZMP margin is a clear error."""
    for bad in (-0.01, 1.0, float("nan")):
        with pytest.raises(biped.BipedError, match="clearance"):
            Safety(clearance=bad)
    with pytest.raises(biped.BipedError, match="zmp_margin"):
        Safety(zmp_margin=0.2)


def test_solver_that_does_not_converge_fails_loudly(tmp_path, monkeypatch, capsys):
    """With IPOPT cut to 3 iterations no start converges: the report says so with IPOPT's
    status, and 'biped optimize' exits 1 naming it (not a silent fallback)."""
    from biped.optimization import solver
    from biped_cli import main

    monkeypatch.setitem(solver.IPOPT_OPTIONS, "max_iter", 3)
    solver._solver.cache_clear()
    try:
        problem = GaitProblem(biped.Biped(ROBOT, "revolute"), 0.3)
        optimum = optimize(problem, starts=1)
        assert optimum.report.status == "Maximum_Iterations_Exceeded"
        assert not optimum.certified
        out = tmp_path / "gait.json"
        argv = ["optimize", "--knee", "revolute", "--speed", "0.3", "--starts", "1"]
        assert main([*argv, "--out", str(out)]) == 1
        assert "Maximum_Iterations_Exceeded" in capsys.readouterr().err
    finally:
        solver._solver.cache_clear()


# Every walkable constraint asked, with a clearance (``biped.model.walkable``).
WALKING = Safety(
    clearance=0.02, landing_speed=0.3, friction=0.6, joint_margin=0.05, hip_progress=0.2
)


@pytest.mark.parametrize(
    "knee, criterion, radii, knots, safety",
    [
        ("revolute", "sthenic", None, 1, Safety(clearance=0.02)),
        ("rolling", "energy", None, 1, Safety(clearance=0.02)),
        ("rolling", "sthenic", "design", 1, Safety(clearance=0.02)),
        ("rolling", "energy", None, 3, Safety(clearance=0.02)),
        ("revolute", "energy", None, 1, WALKING),
        ("rolling", "sthenic", "design", 3, WALKING),
    ],
)
def test_derivatives_built_sample_by_sample_are_casadis(knee, criterion, radii, knots, safety):
    """The derivatives IPOPT uses (built per sample and chained through the head,
    ``biped.optimization.derivatives``): the Hessian of the Lagrangian and the constraints'
    Jacobian equal CasADi's own of the whole NLP to 1e-12 at random variables and
    multipliers, with a clearance margin (kept between the samples too), a design's radii,
    the energy criterion's slacks and the walkable constraints (the landing's and the
    impact's on the head), the Jacobian's sparsity holding every nonzero of CasADi's (the
    objective's gradient, CasADi's own, dense as IPOPT reads it); another robot's differ."""
    from biped.optimization.derivatives import dense, full_hessian
    from biped.optimization.solver import Solver

    model = biped.Biped(UNEQUAL, knee)
    bounds_ = ((0.001, 0.001), (0.15, 0.2)) if radii else None
    solver = Solver(model, criterion, safety, 6, bounds_, knots)
    oracle = solver.nlp.oracle()
    x, p = oracle.sx_in(0), oracle.sx_in(1)
    f, g = oracle.call([x, p])[:2]
    reference = full_hessian(x, p, f, g)
    first = ca.Function("first", [x, p], [g, ca.jacobian(g, x)])
    rng = np.random.default_rng(4)
    problem = GaitProblem(model, 0.3, criterion, knots=knots)
    for _ in range(2):
        z = problem.embedded(random_variables(GaitProblem(model, 0.3), rng)) / solver.scales
        xs = np.concatenate([z, rng.uniform(0.5, 2.0, 2 * bool(radii)), rng.random(solver.slacks)])
        lam_g = rng.standard_normal(g.shape[0])
        expected = dense(reference(xs, 0.3, 1.7, lam_g))
        found = dense(solver.hessian(xs, 0.3, 1.7, lam_g))
        np.testing.assert_allclose(found, expected, rtol=0, atol=1e-12 * np.abs(expected).max())
        constraints, jacobian = map(dense, first(xs, 0.3))
        chained = map(dense, solver.jacobian(xs, 0.3))
        for found_, expected_ in zip(chained, (constraints, jacobian), strict=True):
            scale = np.abs(expected_).max()
            np.testing.assert_allclose(found_, expected_, rtol=0, atol=1e-12 * scale)
    pattern = np.asarray(ca.DM(solver.jacobian.sparsity_out(1), 1))
    assert np.all(pattern[jacobian != 0] == 1)
    assert solver.gradient.sparsity_out(1).is_dense()  # IPOPT reads it as a dense vector
    heavier = dataclasses.replace(UNEQUAL, trunk_mass=1.1 * UNEQUAL.trunk_mass)
    other = Solver(biped.Biped(heavier, knee), criterion, safety, 6, bounds_, knots)
    wrong = dense(other.hessian(xs, 0.3, 1.7, lam_g))  # another robot's: told apart
    assert np.abs(wrong - expected).max() > 1e-6 * np.abs(expected).max()
    wrong = dense(other.jacobian(xs, 0.3)[1])
    assert np.abs(wrong - jacobian).max() > 1e-6 * np.abs(jacobian).max()


def test_hessian_needs_an_nlp_linear_in_the_samples_quantities():
    """The sample-by-sample Hessian holds only for an objective linear in the samples'
    quantities; another is refused, not differentiated wrongly."""
    from biped.optimization.derivatives import lagrangian_hessian

    graph = StepGraph(biped.Biped(ROBOT, "revolute"), 4, PAPER_SAFETY)
    x = ca.SX.sym("x", 21)
    head = ca.substitute(graph.head, graph.z, x)
    squares = ca.sumsqr(graph.rows("torques"))
    with pytest.raises(ValueError, match="not linear"):
        lagrangian_hessian(graph, x, graph.speed, head, squares, graph.on_symbols["constraints"])


def test_starts_solved_on_several_processes_end_as_on_one():
    """The starts of one optimization forked to two processes end where they end one after
    the other, every start to the bit (only the seconds differ)."""
    problem = GaitProblem(biped.Biped(ROBOT, "revolute"), 0.3)
    serial, forked = (optimize(problem, jobs=jobs) for jobs in (1, 2))
    assert forked.report.history == serial.report.history
    np.testing.assert_array_equal(forked.variables, serial.variables)


def test_a_sthenic_search_on_the_coarse_grid_ends_where_the_fine_grid_alone_ends():
    """The sthenic starts searched on the coarse grid and polished on the problem's end at
    the optimum the problem's grid alone reaches from them (to 1e-9, relative), the end
    evaluated on the problem's grid: at a speed of each end of the default sweep."""
    from biped.optimization import optimize as module

    for knee, speed in (("rolling", 0.15), ("revolute", 0.45)):
        problem = GaitProblem(biped.Biped(ROBOT, knee), speed)
        assert module.coarse_problem(problem).samples_per_half < problem.samples_per_half
        searched = optimize(problem)
        with pytest.MonkeyPatch.context() as patch:
            patch.setattr(module, "COARSE_CRITERIA", ())
            alone = optimize(problem)
        assert searched.certified and alone.certified
        assert searched.report.value == pytest.approx(alone.report.value, rel=1e-9)
        assert searched.report.confirmed
        fine = solver_for(problem).evaluate(searched.variables, speed)[0]
        assert float(fine) == pytest.approx(searched.report.value, rel=1e-12)


def test_only_the_sthenic_paper_spline_on_its_own_grid_is_searched_coarsely():
    """The energy criteria (close local minima a polish does not keep), richer families and
    grids asked for (an error bar's twice as many samples) are solved on their own grid."""
    from biped.optimization.optimize import coarse_problem

    model = biped.Biped(ROBOT, "rolling")
    assert coarse_problem(GaitProblem(model, 0.3)) is not None
    assert coarse_problem(GaitProblem(model, 0.3, "energy-per-metre")) is None
    assert coarse_problem(GaitProblem(model, 0.3, knots=3)) is None
    assert coarse_problem(GaitProblem(model, 0.3, samples_per_half=50)) is None


def test_starts_at_one_coarse_optimum_are_polished_once_and_others_apart():
    """Searches ending at one value (within AGREEMENT) share one polish; a search at another
    value is polished from its own end; one that did not converge is solved from its start
    on the problem's grid. Each end counts the iterations of both grids."""
    from biped.optimization.optimize import coarse_to_fine
    from biped.optimization.solver import Solution

    def solution(value, status="Solve_Succeeded", iterations=10):
        return Solution(np.array([value]), value, status, iterations, 0.0, 0.0, 0.5)

    searches = {
        1.0: solution(10.0),
        2.0: solution(10.0 * (1 + AGREEMENT / 10)),
        3.0: solution(12.0),
        4.0: solution(11.0, "Maximum_Iterations_Exceeded"),
    }
    polished = []

    def polish(start, barrier):
        polished.append((float(start[0]), barrier))
        return solution(float(start[0]) - 1, iterations=5)

    candidates = [Candidate(f"start {z:g}", np.array([z])) for z in searches]
    ends = coarse_to_fine(candidates, lambda z, _: searches[float(z[0])], polish, jobs=1)
    assert polished == [(10.0, "adaptive"), (12.0, "adaptive"), (4.0, "adaptive")]
    assert [end.value for end in ends] == [9.0, 9.0, 11.0, 3.0]
    assert [end.iterations for end in ends] == [15, 15, 15, 15]
