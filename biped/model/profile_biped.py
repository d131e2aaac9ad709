"""The biped whose rolling knee has profiled surfaces (``biped.model.profile``): geometry and
Lagrangian dynamics, exact, in the paper's coordinates and order.

``biped.Biped(robot, "rolling")`` is this model when ``robot.k1`` or ``robot.k2`` is not 0
(``Robot.profiled``); the circles keep ``biped.model.dynamics.Biped`` and its numbers.

Geometry. Every point is p = p_H + Σ_k a_k u(q_k) + b_k u'(q_k) over the seven body angles
(the point table of the circles without their links, ``point_table(..., links=False)``) plus,
for the points at and below a knee's C1, that knee's link V = C1 − C2 and, for its contact
point, its contact K − C2 (``biped.model.profile.knee_vectors``). V depends on the thigh's and
the shank's angles nonlinearly: its length Σ(θ) and its angle γ = q_shank + ψ1(θ).

Dynamics. Take as coordinates y = (φ, T) with φ the seven body angles and T = (p_H, V_stance,
V_swing) three plane vectors ("translations"); a body's centre of mass is
p_i = Σ_t c_it T_t + Σ_k a_ik u(φ_k) with c_it ∈ {0, 1} (c_i,hip = 1). In y the robot is the
circles' model with more translations than the hip: with W = Σ_i m_i a_i a_iᵀ (7 x 7),
G = Σ_i m_i a_i c_iᵀ (7 x 3), M = Σ_i m_i c_i c_iᵀ (3 x 3) and J the body inertias,

    T = ½ Σ_tt' M_tt' Ṫ_t·Ṫ_t' + Σ_kt G_kt φ̇_k u'(φ_k)·Ṫ_t + ½ Σ_kl W_kl cos(φ_k − φ_l) φ̇_k φ̇_l
        + ½ Σ_k J_k φ̇_k²,          V = g₀ Σ_t M_t,hip T_t,z − g₀ Σ_k G_k,hip cos φ_k

and the forces that make the accelerations ÿ are, with α_k = d²u(φ_k)/dt² and
A_t = T̈_t + g₀ e_z [t = hip] (every body hangs from the hip: gravity is an acceleration of it),

    τ_φk = u'(φ_k) · [(W α)_k + Σ_t G_kt A_t] + J_k φ̈_k,     τ_t = Σ_t' M_tt' A_t' + Σ_k G_kt α_k

y = Y(q) is a nonlinear map (V(q_thigh, q_shank)); for any smooth map, the Lagrangian
L(q, q̇) = L_y(Y(q), J_Y q̇) has Euler-Lagrange forces τ_q = J_Yᵀ τ_y evaluated at
ÿ = J_Y q̈ + J̇_Y q̇ (the terms in ∂(J_Y q̇)/∂q = J̇_Y cancel), hence

    D(q) = J_Yᵀ D_y J_Y,   D q̈ + H + Q = J_Yᵀ τ_y(y, ẏ, J_Y q̈ + J̇_Y q̇)

with D_y the circles' block form over (φ, T): W ∘ cos(φ_k − φ_l) + diag(J), G_kt u'(φ_k), M_tt' I₂.
The stance foot's constraints, the impact (``biped.model.impact``) and the motors' torques
follow from D, the forces and the point Jacobians as for the circles.
"""

from __future__ import annotations

import numpy as np

from biped.errors import BipedError
from biped.model.dynamics import Biped
from biped.model.kinematics import (
    BODY_DIRECTIONS,
    NQ,
    Q1,
    Q2,
    Q3,
    Q4,
    Q5,
    QP2,
    XH,
    ZH,
    Body,
    point_table,
)
from biped.model.profile import PROFILE_RANGE, KneeProfile, rolling
from biped.model.profile import knee_vectors as profile_vectors

SIDES = ("stance", "swing")
# The thigh's and the shank's angles of each side's knee.
KNEE_ANGLES = {"stance": (Q2, Q1), "swing": (Q3, Q4)}
# The knees' vectors a point may carry, by name: each side's link and contact.
VECTORS = tuple(f"{side}_{name}" for side in SIDES for name in ("link", "contact"))
# The points that hang below each knee's C1 (they carry its link).
_BELOW_KNEE = ("knee_shank", "shank_com", "ankle", "foot_com", "heel", "toe")
# Translations of the dynamics (module docstring): the hip, then each knee's link.
TRANSLATIONS = ("hip", "stance_link", "swing_link")


def profile_points(robot, r1=None, r2=None) -> dict[str, tuple[dict, dict, tuple]]:
    """Every named point as (a, b, vectors): its coefficients over the body angles and the
    knee vectors (``VECTORS``) it adds (module docstring); the radii ``robot``'s unless given
    (numbers or the symbolic graph's symbols, ``biped.optimization.profile_graph``)."""
    r1, r2 = (robot.r1, robot.r2) if r1 is None else (r1, r2)
    table = point_table(robot, r1, r2, links=False)
    points = {}
    for name, (a, b) in table.items():
        vectors = ()
        for side in SIDES:
            if name in (f"{side}_{below}" for below in _BELOW_KNEE):
                vectors = (f"{side}_link",)
            if name == f"{side}_knee":
                vectors = (f"{side}_contact",)
        points[name] = (a, b, vectors)
    return points


class ProfileBiped(Biped):
    """``biped.Biped`` of a rolling knee with profiled surfaces (module docstring): the same
    methods and batch dimensions.

    Attributes beyond the circles': profile (``KneeProfile``), point_vectors (4, P) [-]: which
    knee vectors each point adds, translation_moments G (7, 3) [kg·m], translation_masses M
    (3, 3) [kg]."""

    def __init__(self, robot, knee: str = "rolling"):
        if knee != "rolling" or robot.r1 <= 0.0 or robot.r2 <= 0.0:
            raise BipedError(
                f"knee = {knee!r}, r1 = {robot.r1!r} m, r2 = {robot.r2!r} m: allowed a rolling "
                "knee of radii > 0 (constant curvature, k1 = k2 = 0, is the circles')"
            )
        self.robot, self.knee = robot, knee
        self.profile = KneeProfile.of(robot)
        self.radii = (robot.r1, robot.r2)
        self.direction_names = BODY_DIRECTIONS
        self.directions = np.eye(7)
        points = profile_points(robot)
        self.point_names = tuple(points)
        self._point_index = {name: j for j, name in enumerate(points)}
        index = {name: k for k, name in enumerate(BODY_DIRECTIONS)}
        self.point_a, self.point_b = np.zeros((2, 7, len(points)))
        self.point_vectors = np.zeros((len(VECTORS), len(points)))
        for j, (a, b, vectors) in enumerate(points.values()):
            for key, value in a.items():
                self.point_a[index[key], j] = value
            for key, value in b.items():
                self.point_b[index[key], j] = value
            for name in vectors:
                self.point_vectors[VECTORS.index(name), j] = 1.0
        self.bodies = tuple(
            Body(f"{side}_{segment}", mass, inertia, f"{side}_{segment}", f"{side}_{segment}_com")
            for side in SIDES
            for segment, mass, inertia in (
                ("foot", robot.foot_mass, robot.foot_inertia),
                ("shank", robot.shank_mass, robot.shank_inertia),
                ("thigh", robot.thigh_mass, robot.thigh_inertia),
            )
        ) + (Body("trunk", robot.trunk_mass, robot.trunk_inertia, "trunk", "trunk_com"),)
        self._moments()
        self._stance_ankle = self.point_a[:, self._point_index["stance_ankle"]].copy()
        self._flexion_table = np.linspace(0.0, PROFILE_RANGE[1], 1025)
        self._reach_table = self.reach_squared(self._flexion_table)
        if np.any(np.diff(self._reach_table) >= 0.0):
            raise BipedError(
                f"knee profile {self.profile}: the hip's distance from the ankle does not "
                "shrink as the knee bends over its range: allowed a profile whose leg shortens"
            )
        self._reach = tuple(float(np.sqrt(self._reach_table[i])) for i in (-1, 0))

    def _moments(self) -> None:
        """M, the mass, gravity, W, G (``translation_moments``) and the translations' masses
        over the bodies (module docstring)."""
        self.mass, self.gravity = self.robot.total_mass, self.robot.gravity
        self.second_moments = np.zeros((7, 7))
        self.translation_moments = np.zeros((7, len(TRANSLATIONS)))
        self.translation_masses = np.zeros((len(TRANSLATIONS), len(TRANSLATIONS)))
        self.direction_inertias = np.zeros(7)
        for body in self.bodies:
            j = self.point_index(body.com)
            if np.any(self.point_b[:, j]) or np.any(self.point_vectors[1::2, j]):
                raise AssertionError(f"centre of mass {body.com} must lie on segment axes")
            a = self.point_a[:, j]
            carried = np.concatenate([[1.0], self.point_vectors[0::2, j]])  # hip, links
            self.second_moments += body.mass * np.outer(a, a)
            self.translation_moments += body.mass * np.outer(a, carried)
            self.translation_masses += body.mass * np.outer(carried, carried)
            self.direction_inertias[BODY_DIRECTIONS.index(body.direction)] += body.inertia
        self.first_moments = self.translation_moments[:, 0]

    # ------------------------------------------------------------------ the knees' vectors
    def knee_vectors(self, q, qd=None) -> dict:
        """Each knee's ``KneeVector``s by name (``VECTORS``) at q (..., 9) (with q̇ their bias
        accelerations)."""
        q = np.asarray(q)
        found = {}
        for side, (thigh, shank) in KNEE_ANGLES.items():
            rates = (None, None) if qd is None else (qd[..., thigh], qd[..., shank])
            vectors = profile_vectors(self.profile, q[..., thigh], q[..., shank], *rates)
            for name, vector in vectors.items():
                found[f"{side}_{name}"] = vector
        return found

    def contact_normals(self, q):
        """The knees' common normals u(γ) at their contact (..., 2, 2): stance, swing."""
        q = np.asarray(q)
        normals = []
        for thigh, shank in KNEE_ANGLES.values():
            gamma = q[..., shank] + rolling(self.profile, q[..., thigh] - q[..., shank]).psi1
            normals.append(np.stack([np.sin(gamma), -np.cos(gamma)], axis=-1))
        return np.stack(normals, axis=-2)

    # ------------------------------------------------------------------ geometry
    def points(self, q, names=None):
        q = np.asarray(q)
        cols = slice(None) if names is None else [self.point_index(name) for name in names]
        phi = q[..., :7]
        s, c = np.sin(phi), np.cos(phi)
        a, b = self.point_a[:, cols], self.point_b[:, cols]
        x = q[..., XH, None] + s @ a + c @ b
        z = q[..., ZH, None] - c @ a + s @ b
        flags = self.point_vectors[:, cols]
        vectors = self.knee_vectors(q)
        for i, name in enumerate(VECTORS):
            if np.any(flags[i]):
                vx, vz = vectors[name].position
                x = x + vx[..., None] * flags[i]
                z = z + vz[..., None] * flags[i]
        return np.stack([x, z], axis=-1)

    def point_jacobian(self, q, name: str):
        q = np.asarray(q)
        j = self.point_index(name)
        a, b = self.point_a[:, j], self.point_b[:, j]
        s, c = np.sin(q[..., :7]), np.cos(q[..., :7])
        jac = np.zeros(q.shape[:-1] + (2, NQ), dtype=np.result_type(q, float))
        jac[..., 0, :7], jac[..., 1, :7] = a * c - b * s, a * s + b * c
        jac[..., 0, XH] = jac[..., 1, ZH] = 1.0
        vectors = self.knee_vectors(q)
        for i, vector in enumerate(VECTORS):
            if self.point_vectors[i, j]:
                thigh, shank = KNEE_ANGLES[vector.split("_")[0]]
                for axis in range(2):
                    jac[..., axis, thigh] += vectors[vector].by_thigh[axis]
                    jac[..., axis, shank] += vectors[vector].by_shank[axis]
        return jac

    def point_bias_acceleration(self, q, qd, name: str):
        q, qd = np.asarray(q), np.asarray(qd)
        j = self.point_index(name)
        a, b = self.point_a[:, j], self.point_b[:, j]
        s, c = np.sin(q[..., :7]), np.cos(q[..., :7])
        rate2 = qd[..., :7] ** 2
        bias = np.stack([(-a * s - b * c) * rate2, (a * c - b * s) * rate2], axis=-2).sum(-1)
        vectors = self.knee_vectors(q, qd)
        for i, vector in enumerate(VECTORS):
            if self.point_vectors[i, j]:
                bias = bias + np.stack(vectors[vector].bias, axis=-1)
        return bias

    def _hanging_leg(self, flexion):
        """v(θ) (``Chain._hanging_leg``): thigh (l2 − r2) u(θ), the link V(θ, 0), shank
        (l1 − r1) u(0), the shank angle 0 and the thigh's θ."""
        flexion = np.asarray(flexion, dtype=float)
        link = profile_vectors(self.profile, flexion, np.zeros_like(flexion))["link"].position
        thigh = self.robot.thigh_length - self.robot.r2
        shank = self.robot.shank_length - self.robot.r1
        return thigh * np.sin(flexion) + link[0], -shank - thigh * np.cos(flexion) + link[1]

    def reach_squared(self, flexion):
        vx, vz = self._hanging_leg(flexion)
        return vx * vx + vz * vz

    def _reach_squared_derivative(self, flexion):
        flexion = np.asarray(flexion, dtype=float)
        vx, vz = self._hanging_leg(flexion)
        link = profile_vectors(self.profile, flexion, np.zeros_like(flexion))["link"]
        thigh = self.robot.thigh_length - self.robot.r2
        dx = thigh * np.cos(flexion) + link.by_thigh[0]
        dz = thigh * np.sin(flexion) + link.by_thigh[1]
        return 2.0 * (vx * dx + vz * dz)

    # ------------------------------------------------------------------ dynamics
    def _translation_accelerations(self, q, qd, qdd):
        """A_t (..., 3, 2) of the module docstring: the hip's acceleration plus g₀ e_z, each
        link's V̈ = J_V q̈ + J̇_V q̇; and the links' ``KneeVector``s."""
        vectors = self.knee_vectors(q, qd)
        rows = [np.stack([qdd[..., XH], qdd[..., ZH] + self.gravity], axis=-1)]
        for side, (thigh, shank) in KNEE_ANGLES.items():
            link = vectors[f"{side}_link"]
            rows.append(
                np.stack(
                    [
                        link.by_thigh[i] * qdd[..., thigh]
                        + link.by_shank[i] * qdd[..., shank]
                        + link.bias[i]
                        for i in range(2)
                    ],
                    axis=-1,
                )
            )
        return np.stack(rows, axis=-2), vectors

    def generalized_forces(self, q, qd, qdd):
        """D q̈ + H + Q (..., 9) = J_Yᵀ τ_y (module docstring), in one pass."""
        q, qd, qdd = (np.asarray(x, dtype=float) for x in (q, qd, qdd))
        phi, phid, phidd = q[..., :7], qd[..., :7], qdd[..., :7]
        s, c = np.sin(phi), np.cos(phi)
        rate2 = phid * phid
        ax, az = c * phidd - s * rate2, s * phidd + c * rate2
        moves, vectors = self._translation_accelerations(q, qd, qdd)
        w, g, m = self.second_moments, self.translation_moments, self.translation_masses
        tau_phi = (
            c * (ax @ w + moves[..., 0] @ g.T)
            + s * (az @ w + moves[..., 1] @ g.T)
            + self.direction_inertias * phidd
        )
        tau_t = np.stack([moves[..., 0] @ m + ax @ g, moves[..., 1] @ m + az @ g], axis=-1)
        tau = np.zeros(q.shape[:-1] + (NQ,))
        tau[..., :7] = tau_phi
        tau[..., XH], tau[..., ZH] = tau_t[..., 0, 0], tau_t[..., 0, 1]
        for t, (side, (thigh, shank)) in enumerate(KNEE_ANGLES.items(), start=1):
            link = vectors[f"{side}_link"]
            for i in range(2):
                tau[..., thigh] += link.by_thigh[i] * tau_t[..., t, i]
                tau[..., shank] += link.by_shank[i] * tau_t[..., t, i]
        return tau

    def gravity_forces(self, q):
        q = np.asarray(q, dtype=float)
        return self.generalized_forces(q, np.zeros_like(q), np.zeros_like(q))

    def bias_forces(self, q, qd):
        q = np.asarray(q, dtype=float)
        return self.generalized_forces(q, qd, np.zeros_like(q)) - self.gravity_forces(q)

    def mass_matrix(self, q):
        """D(q) = J_Yᵀ D_y J_Y (..., 9, 9) (module docstring)."""
        q = np.asarray(q, dtype=float)
        phi = q[..., :7]
        s, c = np.sin(phi), np.cos(phi)
        n = 7 + 2 * len(TRANSLATIONS)
        dy = np.zeros(q.shape[:-1] + (n, n))
        cos_diff = c[..., :, None] * c[..., None, :] + s[..., :, None] * s[..., None, :]
        dy[..., :7, :7] = self.second_moments * cos_diff + np.diag(self.direction_inertias)
        for t in range(len(TRANSLATIONS)):
            x, z = 7 + 2 * t, 8 + 2 * t
            g = self.translation_moments[:, t]
            dy[..., x, :7] = dy[..., :7, x] = g * c
            dy[..., z, :7] = dy[..., :7, z] = g * s
            for t2 in range(len(TRANSLATIONS)):
                dy[..., x, 7 + 2 * t2] = dy[..., z, 8 + 2 * t2] = self.translation_masses[t, t2]
        jy = np.zeros(q.shape[:-1] + (n, NQ))
        jy[..., :7, :7] = np.eye(7)
        jy[..., 7, XH] = jy[..., 8, ZH] = 1.0
        vectors = self.knee_vectors(q)
        for t, (side, (thigh, shank)) in enumerate(KNEE_ANGLES.items(), start=1):
            link = vectors[f"{side}_link"]
            for i in range(2):
                jy[..., 7 + 2 * t + i, thigh] = link.by_thigh[i]
                jy[..., 7 + 2 * t + i, shank] = link.by_shank[i]
        return np.swapaxes(jy, -1, -2) @ dy @ jy

    def potential_energy(self, q):
        """V [J] (module docstring), zero at z = 0."""
        q = np.asarray(q, dtype=float)
        height = self.mass * q[..., ZH] - (self.first_moments * np.cos(q[..., :7])).sum(-1)
        vectors = self.knee_vectors(q)
        for t, side in enumerate(SIDES, start=1):
            height = height + self.translation_masses[0, t] * vectors[f"{side}_link"].position[1]
        return self.gravity * height

    # ------------------------------------------------------------------ single support
    def _stance_state(self, angles, rates=None, accelerations=None):
        """``Chain._stance_state``: the hip from the fixed stance ankle, through the stance
        knee's link; φ = q[:7]."""
        free = np.asarray(angles, dtype=float)
        shape = free.shape[:-1] + (NQ,)
        q, qd, qdd = np.zeros(shape), np.zeros(shape), np.zeros(shape)
        q[..., 1:7] = free
        if rates is not None:
            qd[..., 1:7] = rates
        if accelerations is not None:
            qdd[..., 1:7] = accelerations
        a = self._stance_ankle
        phi, phid, phidd = q[..., :7], qd[..., :7], qdd[..., :7]
        s, c = np.sin(phi), np.cos(phi)
        rate2 = phid * phid
        link = profile_vectors(self.profile, q[..., Q2], q[..., Q1], qd[..., Q2], qd[..., Q1])
        link = link["link"]
        rate = [link.by_thigh[i] * qd[..., Q2] + link.by_shank[i] * qd[..., Q1] for i in range(2)]
        accel = [
            link.by_thigh[i] * qdd[..., Q2] + link.by_shank[i] * qdd[..., Q1] + link.bias[i]
            for i in range(2)
        ]
        q[..., XH] = -(s @ a) - link.position[0]
        q[..., ZH] = self.robot.ankle_height + c @ a - link.position[1]
        qd[..., XH] = -((c * phid) @ a) - rate[0]
        qd[..., ZH] = -((s * phid) @ a) - rate[1]
        qdd[..., XH] = -((c * phidd - s * rate2) @ a) - accel[0]
        qdd[..., ZH] = -((s * phidd + c * rate2) @ a) - accel[1]
        return q, qd, qdd, phid, phidd, s, c

    def inverse_dynamics(self, q, qd, qdd):
        """``Biped.inverse_dynamics``: the closed form with the stance ankle's Jacobian
        columns of q1, q2 through the knee's link."""
        tau = self.generalized_forces(q, qd, qdd)
        ankle = self.point_jacobian(q, "stance_ankle")
        fx, fz = tau[..., XH], tau[..., ZH]
        work = [fx * ankle[..., 0, col] + fz * ankle[..., 1, col] for col in (Q1, Q2)]
        g6 = -tau[..., QP2]
        g5 = g6 - tau[..., Q4]
        g4 = g5 - tau[..., Q3]
        g3 = tau[..., Q5] - g4
        g2 = tau[..., Q2] + g3 - work[1]
        g1 = tau[..., Q1] + g2 - work[0]
        cy = tau[..., 0] + g1
        return np.stack([g1, g2, g3, g4, g5, g6], -1), np.stack([fx, fz, cy], -1)

    def single_support(self, angles, rates, accelerations, points=()):
        q, qd, qdd = self._stance_state(angles, rates, accelerations)[:3]
        torques, wrench = self.inverse_dynamics(q, qd, qdd)
        return q, qd, qdd, torques, wrench, self.points(q, list(points))
