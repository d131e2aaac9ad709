"""Impact of a foot landing flat, eqs. (21)-(24), and the leg swap that follows it.

The landing foot is stopped dead by an impulsive ground wrench I_R; the other foot leaves
the ground. With D = D(q⁻) and A the contact Jacobian of the landing foot (rows ankle x,
ankle z, foot angle, as ``Chain.contact_jacobian``):

    D (q̇⁺ - q̇⁻) = Aᵀ I_R,   A q̇⁺ = 0                                   (21), (22)
    q̇⁺ = [I - D⁻¹Aᵀ (A D⁻¹ Aᵀ)⁻¹ A] q̇⁻                                 (23)
    I_R = -(A D⁻¹ Aᵀ)⁻¹ A q̇⁻                                           (24)

I_R is the impulse of the ground on the landing foot [N·s, N·s, N·m·s] (Iz > 0 for a foot
moving down); the printed eq. (24) drops the minus sign of this convention.
"""

from __future__ import annotations

import numpy as np


def flat_foot_impact(model, q, qd_minus, foot: str = "swing"):
    """Velocities after the impact q̇⁺ (..., 9) and the ground impulse I_R (..., 3).

    Args:
        model: a ``biped.Biped``.
        q: configuration at touchdown (..., 9), the landing foot flat on the ground.
        qd_minus: velocities just before touchdown (..., 9).
        foot: the landing foot, ``"swing"`` (end of a step) or ``"stance"``.

    q̇⁺ is in the same labelling as q̇⁻: apply ``biped.model.kinematics.swap_legs`` to start the
    next step.
    """
    q = np.asarray(q, dtype=float)
    qd_minus = np.asarray(qd_minus, dtype=float)
    return _stopped(model.mass_matrix(q), model.contact_jacobian(q, foot), qd_minus)


def both_feet_impact(model, q, qd_minus):
    """Impact of the swing foot landing flat while the stance foot stays flat on the ground:
    the start of a double support phase (``biped.model.double_support``).

    Eqs. (21)-(24) with A the six rows of both feet's contact Jacobians (stance first): both
    feet are at rest after it, A q̇⁺ = 0, and I_R (..., 6) holds the impulse of the ground on
    the stance foot, then on the swing foot [N·s, N·s, N·m·s]. The stance foot stays on the
    ground only if the ground pushes it, I_R,z >= 0 (index 1): its callers check that.
    Returns q̇⁺ (..., 9) and I_R (..., 6).
    """
    q = np.asarray(q, dtype=float)
    qd_minus = np.asarray(qd_minus, dtype=float)
    jac = np.concatenate(
        [model.contact_jacobian(q, "stance"), model.contact_jacobian(q, "swing")], axis=-2
    )
    return _stopped(model.mass_matrix(q), jac, qd_minus)


def _stopped(mass, jac, qd_minus):
    """q̇⁺ and I_R of eqs. (23)-(24) for the mass matrix D and the contact rows A."""
    # D⁻¹ Aᵀ through one factorisation of the symmetric positive-definite D.
    d_inv_jt = np.linalg.solve(mass, np.swapaxes(jac, -1, -2))
    gram = jac @ d_inv_jt  # A D⁻¹ Aᵀ (..., k, k), k contact rows
    approach = (jac @ qd_minus[..., None])[..., 0]  # A q̇⁻
    impulse = -np.linalg.solve(gram, approach[..., None])[..., 0]
    qd_plus = qd_minus + (d_inv_jt @ impulse[..., None])[..., 0]
    return qd_plus, impulse


def trailing_foot_lift(model, q, qd_plus) -> np.ndarray:
    """Vertical velocities (..., 2) [m/s] of the heel and toe of the foot that leaves the
    ground (the stance foot before the swap) just after the impact.

    The flat-foot impact model holds only if the landing foot is pushed (I_R,z > 0) and this
    foot lifts (both velocities >= 0); the paper's constraints do not impose it.
    """
    return np.stack(
        [
            (model.point_jacobian(q, name)[..., 1, :] * qd_plus).sum(-1)
            for name in ("stance_heel", "stance_toe")
        ],
        axis=-1,
    )
