"""The derivatives of a step's NLP IPOPT uses, built sample by sample: the Hessian of the
Lagrangian (``hess_lag``) and the constraints' Jacobian (``jac_g``). (The objective's
gradient is CasADi's reverse mode on the flat graph, ``biped.optimization.solver``: cheaper
a call than chained through the samples.)

The solver's NLP (``biped.optimization.solver``) has variables x (the scaled gait
variables, the knee radii of a design, the energy criterion's slacks) and the parameter p
(the speed). Its objective f and constraints g are written on the step's head h(x)
(``StepGraph.head``: spline coefficients, T, radii, hip height), on the samples' quantities
Q (``StepGraph.quantities``), on x and on p; sample j's quantities are
Q_j = sample(B_j h(x)), B_j a constant matrix (``StepGraph.basis``). The chain rule through
the samples and the head gives the first derivatives of any e(Q, h, x, p),

    de/dx = ∂e/∂Q · diag_j(∂sample/∂v (v_j)) · B · J + ∂e/∂h · J + ∂e/∂x,    J = ∂h/∂x,

and, with f and g linear in Q, so that L = λ_f f + λ_gᵀ g weighs the quantities by
M = ∂L/∂Q depending on λ and p alone, the second:

    ∇²L = Jᵀ (Σ_j B_jᵀ ∇²_v (M_j · sample)(v_j) B_j) J + ∇²_x (G · h(x)) + Aᵀ (∇²_w L) A

with G = Σ_j B_jᵀ ∇_v (M_j · sample)(v_j) + ∂L/∂h held fixed in the second term,
w = (h, x) the other arguments of f and g and A = ∂w/∂x = [J; I].

CasADi's own derivatives of the whole graph differentiate every sample with respect to all
of x (its Hessian twice); here each sample is differentiated in its own 19 inputs (21 with
the radii) by one small function mapped over the samples, and the chain rule through the
head is applied once. The same matrices (tests hold them equal to 1e-12), built in a
fraction of the time and cheaper per call (``benchmarks/bench_optimize.py``). The two
per-sample functions run compiled where a C compiler is found (``biped.optimization.compiled``:
the same bits, ten times faster a call).
"""

from __future__ import annotations

import casadi as ca
import numpy as np

from biped.optimization.compiled import compiled
from biped.optimization.symbolic import StepGraph


def lagrangian_hessian(graph: StepGraph, x, p, head, f, g) -> ca.Function:
    """IPOPT's ``hess_lag``: (x, p, lam_f, lam_g) -> the upper triangle of ∇²_x L.

    Args:
        graph: the step (its ``sample`` function, ``basis``, ``quantities`` and
            ``head_symbol``).
        x, p: the NLP's variables and parameter (SX symbols).
        head: the step's head as an SX expression of x and p.
        f, g: the objective and constraints (SX) on ``graph.quantities`` (linearly),
            ``graph.head_symbol``, x and p.
    """
    lam_f, lam_g = ca.SX.sym("lam_f"), ca.SX.sym("lam_g", g.shape[0])
    lagrangian = lam_f * f + ca.dot(lam_g, g)
    quantities, head_symbol = graph.quantities, graph.head_symbol
    weights = ca.reshape(ca.gradient(lagrangian, ca.vec(quantities)), quantities.shape)
    if ca.depends_on(weights, ca.vertcat(ca.vec(quantities), head_symbol, x)):
        raise ValueError("the NLP is not linear in the samples' quantities")
    used = sorted({int(i) for i in weights.sparsity().get_triplet()[0]})
    weights = weights[used, :]
    samples = weights.shape[1]

    v = ca.SX.sym("v", graph.sample.size1_in(0))
    m = ca.SX.sym("m", len(used))
    one = ca.dot(m, graph.sample(v)[used])
    sample_hessian = ca.Function("sample_hessian", [v, m], list(ca.hessian(one, v)))

    rest = ca.vertcat(head_symbol, x)  # w: the arguments of f and g other than Q
    tail = ca.Function(
        "tail",
        [head_symbol, x, p, lam_f, lam_g],
        [weights, ca.gradient(lagrangian, head_symbol), ca.hessian(lagrangian, rest)[0]],
    )
    gradient_symbol = ca.SX.sym("gradient", head.shape[0])
    curvature = ca.Function(  # ∇²_x (G · h(x)), G held fixed
        "curvature", [x, p, gradient_symbol], [ca.hessian(ca.dot(gradient_symbol, head), x)[0]]
    )

    X, P, h, J, basis, inputs = _head(graph, x, p, head)
    LF, LG = ca.MX.sym("lam_f"), ca.MX.sym("lam_g", g.shape[0])
    M, dl_dh, hessian_rest = tail(h, X, P, LF, LG)
    blocks, gradients = compiled(sample_hessian).map(samples)(inputs, M)
    width = v.shape[0]
    sampled = basis.T @ ca.diagcat(*ca.horzsplit(blocks, width)) @ basis
    G = basis.T @ ca.vec(gradients) + dl_dh
    second = curvature(X, P, G)
    A = ca.vertcat(J, ca.MX(ca.DM.eye(x.shape[0])))
    total = J.T @ sampled @ J + second + A.T @ hessian_rest @ A
    return ca.Function(
        "nlp_hess_l",
        [X, P, LF, LG],
        [ca.triu(total)],
        ["x", "p", "lam_f", "lam_g"],
        ["hess_gamma_x_x"],
    )


def constraint_jacobian(graph: StepGraph, x, p, head, g) -> ca.Function:
    """IPOPT's ``jac_g``: (x, p) -> (g, ∂g/∂x), chained through the samples' Jacobians
    (forward) and the head.

    Args: as ``lagrangian_hessian``'s; ``g`` may be any expression of the samples'
    quantities, the head, x and p.
    """
    quantities = ca.vec(graph.quantities)
    v = ca.SX.sym("v", graph.sample.size1_in(0))
    sample = ca.Function("sample", [v], [graph.sample(v), ca.jacobian(graph.sample(v), v)])
    tail = ca.Function(
        "tail",
        [quantities, graph.head_symbol, x, p],
        [g, ca.jacobian(g, quantities), ca.jacobian(g, graph.head_symbol), ca.jacobian(g, x)],
    )
    X, P, h, J, basis, inputs = _head(graph, x, p, head)
    values, blocks = compiled(sample).map(inputs.shape[1])(inputs)
    per_sample = ca.diagcat(*ca.horzsplit(blocks, v.shape[0]))  # ∂Q/∂v, block-diagonal
    value, by_quantities, by_head, by_x = tail(ca.vec(values), h, X, P)
    jacobian = by_quantities @ (per_sample @ (basis @ J)) + by_head @ J + by_x
    return ca.Function("nlp_jac_g", [X, P], [value, jacobian], ["x", "p"], ["g", "jac_g_x"])


def _head(graph: StepGraph, x, p, head):
    """MX symbols X, P of the NLP's variables and parameter, the head h and J = ∂h/∂x on
    them, the samples' basis and their inputs (one column per sample)."""
    head_function = ca.Function("head", [x, p], [head, ca.jacobian(head, x)])
    X, P = ca.MX.sym("x", x.shape[0]), ca.MX.sym("p")
    h, J = head_function(X, P)
    basis = ca.sparsify(ca.DM(graph.basis))
    width = graph.sample.size1_in(0)
    inputs = ca.reshape(basis @ h, width, graph.basis.shape[0] // width)
    return X, P, h, J, basis, inputs


def full_hessian(x, p, f, g) -> ca.Function:
    """CasADi's own Hessian of the Lagrangian of the flat expressions f(x, p), g(x, p), as
    IPOPT's default would be: the reference a test holds ``lagrangian_hessian`` to."""
    lam_f, lam_g = ca.SX.sym("lam_f"), ca.SX.sym("lam_g", g.shape[0])
    hessian = ca.hessian(lam_f * f + ca.dot(lam_g, g), x)[0]
    return ca.Function("full_hessian", [x, p, lam_f, lam_g], [ca.triu(hessian)])


def dense(matrix) -> np.ndarray:
    """A CasADi matrix as a dense numpy array."""
    return np.asarray(ca.densify(ca.DM(matrix)))
