"""The profiled knee's CasADi graph (``biped.optimization.profile_graph``) is the numeric
model (``biped.model.profile_biped``): its numbers, its parameters as a design's symbols,
their derivatives and the solver's derivatives built sample by sample."""

import dataclasses

import casadi as ca
import numpy as np
import pytest

import biped
from biped.model.criteria import PAPER_SAFETY, Safety
from biped.model.profile import KneeProfile, surface_margins
from biped.optimization.problem import GaitProblem
from biped.optimization.symbolic import StepGraph
from tests.test_optimize import numeric, random_variables
from tests.test_profile import PROFILED, ROBOT


@pytest.fixture(scope="module")
def model():
    return biped.Biped(PROFILED, "rolling")


@pytest.mark.parametrize("safety", [PAPER_SAFETY, Safety(clearance=0.02, zmp_margin=0.01)])
def test_graph_is_the_numeric_model(model, safety):
    """The CasADi graph of the profile (its numbers, and its parameters as symbols) gives the
    numeric model's torques, wrench, constraints and criteria to 1e-12."""
    problem = GaitProblem(model, 0.3, safety=safety)
    fixed = StepGraph(model, 25, safety).function()
    design = StepGraph(biped.Biped(ROBOT, "rolling"), 25, safety, design=True, profile=True)
    rng = np.random.default_rng(7)
    for _ in range(2):
        z = random_variables(problem, rng)
        _, ev = numeric(problem, z)
        for out in (
            fixed(z=z, speed=0.3),
            design.function()(z=z, speed=0.3, radii=KneeProfile.of(PROFILED).vector),
        ):
            for name, value in (("torques", ev.torques), ("wrench", ev.wrench)):
                np.testing.assert_allclose(
                    out[name].full().T, value, rtol=1e-12, atol=1e-12 * np.abs(value).max()
                )
            checked = ~np.isnan(ev.constraints)
            scale = np.abs(ev.constraints[checked]).max()
            np.testing.assert_allclose(
                out["psi"].full().T[checked], ev.constraints[checked], atol=1e-12 * scale
            )
            assert float(out["sthenic"]) == pytest.approx(ev.sthenic, rel=1e-12)
            assert float(out["energy"]) == pytest.approx(ev.energy, rel=1e-12)


def test_design_graph_derivatives_in_the_profile_are_finite_differences():
    graph = StepGraph(biped.Biped(ROBOT, "rolling"), 25, PAPER_SAFETY, design=True, profile=True)
    gradient = ca.Function(
        "g", [graph.z, graph.speed, graph.radii], [ca.gradient(graph.sthenic, graph.radii)]
    )
    problem = GaitProblem(biped.Biped(PROFILED, "rolling"), 0.3)
    z = random_variables(problem, np.random.default_rng(4))
    point = KneeProfile.of(PROFILED).vector
    exact = gradient(z, 0.3, point).full().ravel()
    h = 1e-6
    for i, name in enumerate(("r1", "r2", "k1", "k2")):
        values = []
        for sign in (1, -1):
            robot = dataclasses.replace(PROFILED, **{name: point[i] + sign * h})
            values.append(numeric(GaitProblem(biped.Biped(robot, "rolling"), 0.3), z)[1].sthenic)
        difference = (values[0] - values[1]) / (2 * h)
        assert difference == pytest.approx(exact[i], rel=1e-5, abs=1e-6 * np.abs(exact).max())


@pytest.mark.parametrize("design", [False, True])
def test_solver_derivatives_built_sample_by_sample_are_casadis(design):
    """IPOPT's Hessian of the Lagrangian and constraints' Jacobian, chained sample by sample
    through the head (``biped.optimization.derivatives``), equal CasADi's own of the whole
    NLP to 1e-12 for a profile (held: the energy criterion; designed: its four parameters
    and the surfaces' bounds, with a clearance)."""
    from biped.optimization.derivatives import dense, full_hessian
    from biped.optimization.solver import Solver

    model = biped.Biped(PROFILED if not design else ROBOT, "rolling")
    bounds = ((1e-3, 1e-3, -0.5, -0.5), (0.18, 0.23, 0.5, 0.5)) if design else None
    criterion, safety = ("sthenic", Safety(clearance=0.02)) if design else ("energy", PAPER_SAFETY)
    solver = Solver(model, criterion, safety, 6, bounds)
    oracle = solver.nlp.oracle()
    x, p = oracle.sx_in(0), oracle.sx_in(1)
    f, g = oracle.call([x, p])[:2]
    reference = full_hessian(x, p, f, g)
    first = ca.Function("first", [x, p], [g, ca.jacobian(g, x)])
    rng = np.random.default_rng(4)
    problem = GaitProblem(biped.Biped(PROFILED, "rolling"), 0.3)
    z = random_variables(problem, rng) / solver.scales
    knee = np.array(KneeProfile.of(PROFILED).vector) / 0.05 if design else []
    xs = np.concatenate([z, knee, rng.random(solver.slacks)])
    lam_g = rng.standard_normal(g.shape[0])
    expected = dense(reference(xs, 0.3, 1.7, lam_g))
    found = dense(solver.hessian(xs, 0.3, 1.7, lam_g))
    np.testing.assert_allclose(found, expected, rtol=0, atol=1e-12 * np.abs(expected).max())
    constraints, jacobian = map(dense, first(xs, 0.3))
    for found_, expected_ in zip(
        map(dense, solver.jacobian(xs, 0.3)), (constraints, jacobian), strict=True
    ):
        np.testing.assert_allclose(found_, expected_, rtol=0, atol=1e-12 * np.abs(expected_).max())
    if design:  # the surfaces' eight bounds close the constraints, at their scales
        margins = surface_margins(KneeProfile.of(PROFILED), (0.18, 0.23))
        scales = [0.1, 0.1, 0.18**2, 0.18**2, 0.1, 0.1, 0.23**2, 0.23**2]
        np.testing.assert_allclose(constraints.ravel()[-8:], np.divide(margins, scales), rtol=1e-12)
