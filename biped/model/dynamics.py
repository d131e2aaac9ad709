"""Lagrangian dynamics of both bipeds, eq. (19), exact and vectorised.

    D(q) q̈ + H(q, q̇) + Q(q) = B Γ + A_cᵀ(q) F_e                                  (19)

Derivation. With the directions φ = Φ θ_angles of ``biped.model.kinematics`` (a constant matrix Φ),
the centre of mass of body i is p_H + Σ_k a_ik u(φ_k). Writing W = Σ_i m_i a_i a_iᵀ (a
constant K x K matrix), g = Σ_i m_i a_i, M the total mass and J_k the body inertias carried by
direction k, the kinetic and potential energies are

    T = ½ M |ṗ_H|² + ṗ_H · Σ_k g_k u'(φ_k) φ̇_k + ½ Σ_kl W_kl cos(φ_k - φ_l) φ̇_k φ̇_l + ½ Σ_k J_k φ̇_k²
    V = g₀ (M z_H - Σ_k g_k cos φ_k)

in the coordinates y = (φ, p_H) = P q, P constant. Lagrange's equations in q are Pᵀ times
those in y (the map is linear), so D = Pᵀ D_y P, H = Pᵀ H_y, Q = Pᵀ Q_y with

    D_y = [[W ∘ cos(φ_k - φ_l) + diag(J), Gᵀ], [G, M I₂]],   G = [g_k u'(φ_k)]_k
    H_y = [Σ_l W_kl sin(φ_k - φ_l) φ̇_l²]_k,  Σ_k g_k u''(φ_k) φ̇_k²]
    Q_y = [g₀ g_k sin φ_k]_k,  [0, g₀ M]]

which is what the Christoffel symbols of D give, in closed form. For inverse dynamics the
same terms regroup with the accelerations α_k = d²u(φ_k)/dt² of the unit vectors:

    τ_φk = u'(φ_k) · [(W α)_k + g_k (p̈_H + g₀ e_z)] + J_k φ̈_k
    τ_H  = M (p̈_H + g₀ e_z) + Σ_k g_k α_k

about 2 K² multiply-adds and K sines and cosines per sample.
"""

from __future__ import annotations

import numpy as np

from biped.model import impact
from biped.model.kinematics import NQ, Q1, Q2, Q3, Q4, Q5, QP1, QP2, XH, ZH, Chain
from biped.model.robot import Robot

# Relative joint angles θ = S q of eq. (32) (θ4 = q5 - q3; the print repeats q5 - q2):
# ankle, knee, hip of the stance leg, then hip, knee, ankle of the swing leg.
JOINTS = (
    "stance_ankle",
    "stance_knee",
    "stance_hip",
    "swing_hip",
    "swing_knee",
    "swing_ankle",
)
_JOINT_PAIRS = ((Q1, QP1), (Q2, Q1), (Q5, Q2), (Q5, Q3), (Q3, Q4), (Q4, QP2))
JOINT_MATRIX = np.zeros((6, NQ))
for _row, (_plus, _minus) in enumerate(_JOINT_PAIRS):
    JOINT_MATRIX[_row, _plus], JOINT_MATRIX[_row, _minus] = 1.0, -1.0
JOINT_MATRIX.setflags(write=False)


def zmp_from(torques, wrench, ankle_height):
    """Eq. (29): x_ZMP = (Γ1 - h_p Fx) / Fz [m], from the stance ankle.

    Exact for a flat, fixed stance foot whose centre of mass lies below the ankle: the foot's
    moment balance about the ankle gives Γ1 = x_ZMP Fz + h_p Fx.
    """
    return (torques[..., 0] - ankle_height * wrench[..., 0]) / wrench[..., 1]


class Biped(Chain):
    """Geometry and dynamics of one biped, in the paper's coordinates and order.

    Args:
        robot: the parameters (``Robot.paper()`` for Table 1).
        knee: ``"revolute"`` or ``"rolling"``.

    Every method takes leading batch dimensions: q, q̇, q̈ are (..., 9).

    Attributes (the constants of the module docstring, over the K directions; the symbolic
    graph, ``biped.optimization.symbolic``, is built from them):
        mass: M [kg], the total mass.
        gravity: g₀ [m/s²].
        second_moments: W = Σ_i m_i a_i a_iᵀ (K, K) [kg·m²].
        first_moments: g = Σ_i m_i a_i (K,) [kg·m].
        direction_inertias: J (K,) [kg·m²], the body inertias carried by each direction.
        coordinate_map: P (K + 2, 9) [-], y = (φ, x_H, z_H) = P q.
    """

    def __new__(cls, robot: Robot | None = None, knee: str = "rolling"):
        """A rolling knee whose surfaces are profiles (``Robot.profiled``) is a
        ``biped.model.profile_biped.ProfileBiped``; circles and the revolute knee are this
        class."""
        if cls is Biped and knee == "rolling" and robot is not None and robot.profiled:
            from biped.model.profile_biped import ProfileBiped

            return super().__new__(ProfileBiped)
        return super().__new__(cls)

    def __init__(self, robot: Robot, knee: str = "rolling"):
        super().__init__(robot, knee)
        k = len(self.direction_names)
        index = {name: i for i, name in enumerate(self.direction_names)}
        self.mass = robot.total_mass
        self.gravity = robot.gravity
        self.second_moments = np.zeros((k, k))
        self.first_moments = np.zeros(k)
        self.direction_inertias = np.zeros(k)
        for body in self.bodies:
            j = self.point_index(body.com)
            if np.any(self.point_b[:, j]):
                raise AssertionError(f"centre of mass {body.com} must lie on segment axes")
            a = self.point_a[:, j]
            self.second_moments += body.mass * np.outer(a, a)
            self.first_moments += body.mass * a
            self.direction_inertias[index[body.direction]] += body.inertia
        self.coordinate_map = np.zeros((k + 2, NQ))
        self.coordinate_map[:k, :7] = self.directions
        self.coordinate_map[k, XH] = self.coordinate_map[k + 1, ZH] = 1.0
        self._stance_leg = self.directions[:, [Q1, Q2]]

    # ------------------------------------------------------------------ matrices of eq. (19)
    def joint_angles(self, q):
        """θ (..., 6) of eq. (32) from q (..., 9); also maps q̇ to θ̇."""
        return np.asarray(q) @ JOINT_MATRIX.T

    def mass_matrix(self, q):
        """D(q) (..., 9, 9), symmetric positive definite [kg, kg·m, kg·m²]."""
        phi = self.direction_angles(q)
        s, c = np.sin(phi), np.cos(phi)
        k = phi.shape[-1]
        dy = np.zeros(phi.shape[:-1] + (k + 2, k + 2))
        cos_diff = c[..., :, None] * c[..., None, :] + s[..., :, None] * s[..., None, :]
        dy[..., :k, :k] = self.second_moments * cos_diff + np.diag(self.direction_inertias)
        dy[..., k, :k] = dy[..., :k, k] = self.first_moments * c
        dy[..., k + 1, :k] = dy[..., :k, k + 1] = self.first_moments * s
        dy[..., k, k] = dy[..., k + 1, k + 1] = self.mass
        return self.coordinate_map.T @ dy @ self.coordinate_map

    def bias_forces(self, q, qd):
        """H(q, q̇) (..., 9): Coriolis and centrifugal terms."""
        phi = self.direction_angles(q)
        rate2 = self.direction_angles(qd) ** 2
        s, c = np.sin(phi), np.cos(phi)
        w, g = self.second_moments, self.first_moments
        h_phi = s * ((c * rate2) @ w) - c * ((s * rate2) @ w)
        h_hip = np.stack([-(g * s * rate2).sum(-1), (g * c * rate2).sum(-1)], -1)
        return self._from_y(h_phi, h_hip)

    def gravity_forces(self, q):
        """Q(q) (..., 9): gradient of the potential energy."""
        phi = self.direction_angles(q)
        q_phi = self.gravity * self.first_moments * np.sin(phi)
        q_hip = np.zeros(phi.shape[:-1] + (2,))
        q_hip[..., 1] = self.gravity * self.mass
        return self._from_y(q_phi, q_hip)

    def _from_y(self, tau_phi, tau_hip):
        return np.concatenate([tau_phi @ self.directions, tau_hip], axis=-1)

    def generalized_forces(self, q, qd, qdd):
        """D q̈ + H + Q (..., 9) in one pass (see the module docstring)."""
        phi = self.direction_angles(q)
        phid = self.direction_angles(qd)
        return self._forces(qdd, phid, self.direction_angles(qdd), np.sin(phi), np.cos(phi))

    def _forces(self, qdd, phid, phidd, s, c):
        rate2 = phid * phid
        ax = c * phidd - s * rate2  # d²(sin φ)/dt²
        az = s * phidd + c * rate2  # d²(-cos φ)/dt²
        qdd = np.asarray(qdd)
        hip_x = qdd[..., XH, None]
        hip_z = qdd[..., ZH, None] + self.gravity
        w, g = self.second_moments, self.first_moments
        tau_phi = (
            c * (ax @ w + g * hip_x) + s * (az @ w + g * hip_z) + self.direction_inertias * phidd
        )
        tau_hip = np.concatenate(
            [self.mass * hip_x + ax @ g[:, None], self.mass * hip_z + az @ g[:, None]], axis=-1
        )
        return self._from_y(tau_phi, tau_hip)

    # ------------------------------------------------------------------ single support
    def inverse_dynamics(self, q, qd, qdd):
        """Motor torques Γ (..., 6) [N·m] and ground wrench F_e (..., 3) in single support.

        Solves eq. (19) with the stance foot flat and fixed: q, q̇, q̈ must satisfy eq. (16)
        (``stance_state`` builds such motions). F_e = [Fx, Fz, Cy] is the wrench of the ground
        on the stance foot: forces [N] (z up) and moment about the stance ankle [N·m],
        counter-clockwise positive. Γ_i is conjugate to θ_i of eq. (32), so Σ Γ_i θ̇_i is the
        motors' power.

        B Γ + A_cᵀ F_e = τ is solved in closed form: the hip rows of A_cᵀ are the identity
        and B has none, so (Fx, Fz) = τ_H; then the swing leg from the foot up, the trunk,
        and the stance leg down to the foot, whose row gives Cy.
        """
        phi = self.direction_angles(q)
        s, c = np.sin(phi), np.cos(phi)
        tau = self._forces(qdd, self.direction_angles(qd), self.direction_angles(qdd), s, c)
        return self._torques_and_wrench(tau, s, c)

    def _torques_and_wrench(self, tau, s, c):
        fx, fz = tau[..., XH], tau[..., ZH]
        # Stance-ankle Jacobian columns for q1 and q2: ∂(ankle)/∂φ = a u'(φ).
        weights = self._stance_ankle * (c * fx[..., None] + s * fz[..., None])
        work = weights @ self._stance_leg  # F · ∂ankle/∂q1, F · ∂ankle/∂q2
        g6 = -tau[..., QP2]
        g5 = g6 - tau[..., Q4]
        g4 = g5 - tau[..., Q3]
        g3 = tau[..., Q5] - g4
        g2 = tau[..., Q2] + g3 - work[..., 1]
        g1 = tau[..., Q1] + g2 - work[..., 0]
        cy = tau[..., QP1] + g1
        return np.stack([g1, g2, g3, g4, g5, g6], -1), np.stack([fx, fz, cy], -1)

    def single_support(self, angles, rates, accelerations, points=()):
        """``stance_state`` then ``inverse_dynamics`` and ``points`` sharing one evaluation
        of the sines and cosines: the inner loop of the gait criteria.

        Returns:
            q, q̇, q̈ (..., 9), torques (..., 6), wrench (..., 3), positions (..., P, 2).
        """
        q, qd, qdd, phid, phidd, s, c = self._stance_state(angles, rates, accelerations)
        torques, wrench = self._torques_and_wrench(self._forces(qdd, phid, phidd, s, c), s, c)
        return q, qd, qdd, torques, wrench, self._points(q, s, c, list(points))

    def zmp(self, q, qd, qdd):
        """x of the zero-moment point [m] from the stance ankle, eq. (29)."""
        torques, wrench = self.inverse_dynamics(q, qd, qdd)
        return zmp_from(torques, wrench, self.robot.ankle_height)

    # ------------------------------------------------------------------ energy
    def kinetic_energy(self, q, qd):
        """T = ½ q̇ᵀ D q̇ [J]."""
        qd = np.asarray(qd)
        return 0.5 * np.einsum("...i,...ij,...j->...", qd, self.mass_matrix(q), qd)

    def potential_energy(self, q):
        """V [J], zero at z = 0."""
        q = np.asarray(q)
        phi = self.direction_angles(q)
        return self.gravity * (self.mass * q[..., ZH] - (self.first_moments * np.cos(phi)).sum(-1))

    def motor_power(self, qd, torques):
        """Σ Γ_i θ̇_i [W]."""
        return (self.joint_angles(qd) * torques).sum(-1)

    # ------------------------------------------------------------------ impact
    def impact(self, q, qd_minus, foot: str = "swing"):
        """Flat-foot impact of ``foot``, eqs. (21)-(24); see ``biped.model.impact``."""
        return impact.flat_foot_impact(self, q, qd_minus, foot)
