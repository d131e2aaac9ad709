"""The force through each knee in single support: what the thigh exerts on the lower leg.

Derivation. Cut each leg at the knee. The bodies below a knee, its shank and its foot, touch
the rest of the robot only through the knee, and the knee's motor acts on them with a couple
(no net force), so Newton's law on them, with g = (0, -g₀) and a_i the acceleration of body
i's centre of mass,

    F + Σ_i m_i g + F_ground = Σ_i m_i a_i

gives the force F of the thigh on the lower leg:

    swing knee:   F_sw = Σ_{swing shank, swing foot} m_i (a_i - g)
    stance knee:  F_st = Σ_{stance shank, stance foot} m_i (a_i - g) - (Fx, Fz)

with (Fx, Fz) the ground's force on the stance foot (``Biped.inverse_dynamics``; the fixed
foot's a_i is 0). The accelerations follow from the model's own kinematics:
a_i = J_i(q) q̈ + J̇_i(q) q̇ (``Chain.point_jacobian``, ``Chain.point_bias_acceleration``).

Decomposition (a profiled knee's, ``biped.model.profile``: along its common normal u(γ) at
the contact and across it, as the circles' below). The rolling knee's thigh (circle of
radius r2, centre C2) and shank (radius r1, centre C1) touch at one point of the line of
their centres, which is the surfaces' common normal there: along the unit vector e from C2
towards C1 (e = u(γ), γ = (r1 q_shank + r2 q_thigh) / l, ``biped.model.kinematics``) and
across it, e' = e turned +90°
(counter-clockwise, e' = u'(γ)),

    N = F · e,   T = F · e'

N > 0 presses the surfaces together (compression); N < 0 pulls them apart (tension), which
two surfaces in contact cannot carry: a real knee needs ligaments (straps or crossed cables)
that carry -N. T keeps them rolling without slip, by friction if |T| / N stays below its
coefficient where N > 0, else by the ligaments' crossing. The revolute knee's pin carries F
whole; it is decomposed the same way along its shank, e from the knee to the ankle (the
rolling knee's e has no limit as r1, r2 → 0; its F tends to the revolute knee's).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from biped.model.dynamics import Biped
from biped.model.profile_biped import ProfileBiped

# The knees, in the order of the last axis of every array here: the stance leg's, the swing
# leg's (each one leg's knee during that leg's stance, resp. swing).
KNEE_SIDES = ("stance", "swing")


@dataclass(frozen=True, eq=False)
class KneeForces:
    """The force of the thigh on the lower leg through each knee (``KNEE_SIDES``), over the
    samples' leading dimensions (...), and its decomposition (see the module)."""

    force: np.ndarray  # [N] (..., 2, 2): knee, (x, z)
    axis: np.ndarray  # [-] (..., 2, 2): knee, the unit vector e (x, z)
    normal: np.ndarray  # [N] (..., 2): N = F · e, > 0 compression, < 0 tension
    tangential: np.ndarray  # [N] (..., 2): T = F · e'

    @property
    def tension(self) -> np.ndarray:
        """[N] (..., 2): max(-N, 0), what ligaments must carry."""
        return np.maximum(-self.normal, 0.0)

    @property
    def compression(self) -> np.ndarray:
        """[N] (..., 2): max(N, 0), what the surfaces carry pressed together."""
        return np.maximum(self.normal, 0.0)

    @property
    def slip_ratio(self) -> np.ndarray:
        """[-] (..., 2): |T| / N where N > 0 (the friction coefficient rolling without slip
        needs), NaN where the knee is not compressed."""
        pressed = self.normal > 0.0
        return np.where(
            pressed, np.abs(self.tangential) / np.where(pressed, self.normal, 1.0), np.nan
        )


def momentum_rate(model: Biped, q, qd, qdd, bodies) -> np.ndarray:
    """Σ m_i (a_i - g) (..., 2) [N] over the named ``bodies`` (``Chain.bodies``): the force the
    rest of the robot and the ground apply to them."""
    by_name = {body.name: body for body in model.bodies}
    total = 0.0
    for name in bodies:
        body = by_name[name]
        jacobian = model.point_jacobian(q, body.com)
        acceleration = np.einsum("...ij,...j->...i", jacobian, qdd)
        acceleration = acceleration + model.point_bias_acceleration(q, qd, body.com)
        acceleration[..., 1] += model.gravity
        total = total + body.mass * acceleration
    return total


def knee_axes(model: Biped, q) -> np.ndarray:
    """The unit vectors e (..., 2, 2) of each knee (``KNEE_SIDES``): from C2 towards C1 for
    the rolling knee, from the knee to the ankle for the revolute knee; the common normal
    u(γ) at the contact of a profiled knee (``ProfileBiped.contact_normals``)."""
    if isinstance(model, ProfileBiped):
        return model.contact_normals(q)
    axes = []
    for side in KNEE_SIDES:
        if sum(model.radii) > 0.0:
            start, end = f"{side}_knee_thigh", f"{side}_knee_shank"  # C2, C1
        else:
            start, end = f"{side}_knee_shank", f"{side}_ankle"
        points = model.points(q, [start, end])
        vector = points[..., 1, :] - points[..., 0, :]
        axes.append(vector / np.linalg.norm(vector, axis=-1, keepdims=True))
    return np.stack(axes, axis=-2)


def knee_forces(model: Biped, q, qd, qdd, wrench=None) -> KneeForces:
    """The force of the thigh on the lower leg through both knees along a single-support
    motion (q, q̇, q̈ (..., 9), the stance foot fixed: ``Chain.stance_state``).

    Args:
        wrench: the ground's wrench on the stance foot [Fx, Fz, Cy] (..., 3) of the motion
            (``Biped.inverse_dynamics``'s, which computes it when None).
    """
    q, qd, qdd = (np.asarray(x, dtype=float) for x in (q, qd, qdd))
    if wrench is None:
        wrench = model.inverse_dynamics(q, qd, qdd)[1]
    ground = np.asarray(wrench, dtype=float)[..., :2]
    force = np.stack(
        [
            momentum_rate(model, q, qd, qdd, ("stance_shank", "stance_foot")) - ground,
            momentum_rate(model, q, qd, qdd, ("swing_shank", "swing_foot")),
        ],
        axis=-2,
    )
    axis = knee_axes(model, q)
    across = np.stack([-axis[..., 1], axis[..., 0]], axis=-1)  # e turned +90°
    return KneeForces(
        force=force,
        axis=axis,
        normal=(force * axis).sum(-1),
        tangential=(force * across).sum(-1),
    )
