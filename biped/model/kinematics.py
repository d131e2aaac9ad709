"""Geometry of both bipeds (paper, section 2, eqs. 1-12) in the paper's coordinates.

Generalized coordinates, in the paper's order (eq. 19)::

    q = [qp1, qp2, q1, q2, q3, q4, q5, xH, zH]

``qp1``/``qp2`` stance/swing foot, ``q1`` stance shank, ``q2`` stance thigh, ``q3`` swing
thigh, ``q4`` swing shank, ``q5`` trunk (absolute angles from the vertical, counter-clockwise
from +x towards +z), ``xH, zH`` the hip [m].

Every point of the robot is the hip plus a sum over *directions* φ_k, each a fixed linear
combination of the seven angles: the body angles themselves and, for the rolling knee, the
angles γ1 = (r1 q1 + r2 q2) / l and γ2 = (r1 q4 + r2 q3) / l of the segments C1C2 that join
the centres of the two rolling circles (l = r1 + r2)::

    p(q) = p_H + Σ_k a_k u(φ_k) + b_k u'(φ_k),   u(φ) = (sin φ, -cos φ),  u'(φ) = (cos φ, sin φ)

u(φ) points down a segment hanging with angle φ; u'(φ) along a foot sole. This one form
gives positions, Jacobians and the Lagrangian dynamics in closed form (``biped.model.dynamics``).
All functions take leading batch dimensions.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from biped.errors import BipedError, UnreachableError
from biped.model.robot import Robot

# The C library's arc cosine and arc tangent element by element: numpy's own have other
# kernels on other CPUs (AVX-512 or not) that differ in the last bit, and these angles start
# the solver (``biped.optimization.problem``) and build every step.
_acos = np.vectorize(math.acos, otypes=[float])
_atan2 = np.vectorize(math.atan2, otypes=[float])

KNEES = ("revolute", "rolling")

ANGLES = ("qp1", "qp2", "q1", "q2", "q3", "q4", "q5")
COORDINATES = ANGLES + ("xH", "zH")
NQ = len(COORDINATES)

# Index of each coordinate in q.
QP1, QP2, Q1, Q2, Q3, Q4, Q5, XH, ZH = range(NQ)
# The leg swap at the end of a step (``swap_legs``): the same posture with the swing leg as
# the new stance leg is q[LEG_SWAP] (feet, shanks and thighs exchanged; trunk and hip kept).
LEG_SWAP = (QP2, QP1, Q4, Q3, Q2, Q1, Q5, XH, ZH)

# Direction names in the order of the rows of ``Chain.directions``; the rolling knee adds
# the two knee links.
BODY_DIRECTIONS = (
    "stance_foot",  # qp1
    "swing_foot",  # qp2
    "stance_shank",  # q1
    "stance_thigh",  # q2
    "swing_thigh",  # q3
    "swing_shank",  # q4
    "trunk",  # q5
)
LINK_DIRECTIONS = ("stance_knee_link", "swing_knee_link")  # γ1, γ2


def check_knee(knee: str) -> str:
    """Return ``knee`` if it names a knee kinematic, raise a clear error otherwise."""
    if knee not in KNEES:
        raise BipedError(f"knee = {knee!r} is not a knee kinematic: allowed 'revolute', 'rolling'")
    return knee


def point_table(robot: Robot, r1, r2, links: bool) -> dict[str, tuple[dict, dict]]:
    """Every named point as its coefficients over the directions: ``name -> (a, b)``, with
    p = p_H + Σ_k a[k] u(φ_k) + b[k] u'(φ_k) over the direction names k of ``a`` and ``b``.

    The one statement of the robot's geometry: ``Chain`` fills its tables from it with the
    radii as numbers, the symbolic graph (``biped.optimization.symbolic``) with the radii as CasADi
    symbols. Only sums and products of ``r1``, ``r2`` and ``robot``'s lengths appear.

    Args:
        robot: lengths and centres of mass.
        r1, r2: [m] radii of the shank's and the thigh's rolling circles (0 for the
            revolute knee).
        links: include the knee links C1C2 (directions ``LINK_DIRECTIONS``, length
            r1 + r2); without them the radii must be 0.
    """
    r = robot
    link = r1 + r2
    shank, thigh = r.shank_length - r1, r.thigh_length - r2  # l'1, l'2
    points: dict[str, tuple[dict, dict]] = {"hip": ({}, {})}

    def add(name, base, a=None, b=None):
        a0, b0 = points[base]
        a_new, b_new = dict(a0), dict(b0)
        for target, extra in ((a_new, a or {}), (b_new, b or {})):
            for key, value in extra.items():
                target[key] = target.get(key, 0.0) + value
        points[name] = (a_new, b_new)

    for side in ("stance", "swing"):
        add(f"{side}_thigh_com", "hip", {f"{side}_thigh": r.thigh_com})
        add(f"{side}_knee_thigh", "hip", {f"{side}_thigh": thigh})  # C2
        knee_link = {f"{side}_knee_link": link} if links else {}
        add(f"{side}_knee_shank", f"{side}_knee_thigh", knee_link)  # C1
        contact = {f"{side}_knee_link": r2} if links else {}
        add(f"{side}_knee", f"{side}_knee_thigh", contact)  # rolling contact point
        add(f"{side}_shank_com", f"{side}_knee_shank", {f"{side}_shank": r.shank_com - r1})
        add(f"{side}_ankle", f"{side}_knee_shank", {f"{side}_shank": shank})
        foot = f"{side}_foot"
        add(f"{side}_foot_com", f"{side}_ankle", {foot: r.foot_com})
        add(f"{side}_heel", f"{side}_ankle", {foot: r.ankle_height}, {foot: -r.foot_heel})
        add(
            f"{side}_toe",
            f"{side}_ankle",
            {foot: r.ankle_height},
            {foot: r.foot_length - r.foot_heel},
        )
    add("trunk_com", "hip", {"trunk": -r.trunk_com})
    add("head", "hip", {"trunk": -r.trunk_length})
    return points


@dataclass(frozen=True)
class Body:
    """A rigid body of the dynamic model."""

    name: str
    mass: float  # [kg]
    inertia: float  # [kg·m²] about the centre of mass
    direction: str  # direction whose angle is the body's orientation
    com: str  # name of the point at the centre of mass


class Chain:
    """The planar tree of one robot: directions, named points and bodies.

    Args:
        robot: parameters (the single source of truth).
        knee: ``"revolute"`` or ``"rolling"``. The revolute knee ignores ``robot.r1``,
            ``robot.r2``; the rolling knee with r1 = r2 = 0 is the revolute knee exactly.
    """

    def __init__(self, robot: Robot, knee: str):
        self.robot = robot
        self.knee = check_knee(knee)
        r = robot
        r1, r2 = (r.r1, r.r2) if knee == "rolling" else (0.0, 0.0)
        link = r1 + r2
        self.radii = (r1, r2)
        names = list(BODY_DIRECTIONS)
        rows = list(np.eye(7))
        if link > 0.0:
            names += LINK_DIRECTIONS
            gamma1 = np.zeros(7)
            gamma1[Q1], gamma1[Q2] = r1 / link, r2 / link
            gamma2 = np.zeros(7)
            gamma2[Q4], gamma2[Q3] = r1 / link, r2 / link
            rows += [gamma1, gamma2]
        self.direction_names = tuple(names)
        self.directions = np.array(rows)  # (K, 7): φ = directions @ angles
        index = {name: k for k, name in enumerate(names)}

        points = point_table(r, r1, r2, links=link > 0.0)

        self.point_names = tuple(points)
        k = len(names)
        self.point_a = np.zeros((k, len(points)))  # coefficients of u(φ_k)
        self.point_b = np.zeros((k, len(points)))  # coefficients of u'(φ_k)
        for j, (a, b) in enumerate(points.values()):
            for key, value in a.items():
                self.point_a[index[key], j] = value
            for key, value in b.items():
                self.point_b[index[key], j] = value
        self._point_index = {name: j for j, name in enumerate(points)}
        self._stance_ankle = self.point_a[:, self._point_index["stance_ankle"]].copy()
        self._reach = (
            float(np.sqrt(self.reach_squared(np.pi))),
            float(np.sqrt(self.reach_squared(0.0))),
        )
        # Table of the monotone reach |hip - ankle|² over the knee flexion [0, π], to start
        # the Newton iterations of the inverse geometric model next to the root.
        self._flexion_table = np.linspace(0.0, np.pi, 1025)
        self._reach_table = self.reach_squared(self._flexion_table)

        self.bodies = tuple(
            Body(f"{side}_{segment}", mass, inertia, f"{side}_{segment}", f"{side}_{segment}_com")
            for side in ("stance", "swing")
            for segment, mass, inertia in (
                ("foot", r.foot_mass, r.foot_inertia),
                ("shank", r.shank_mass, r.shank_inertia),
                ("thigh", r.thigh_mass, r.thigh_inertia),
            )
        ) + (Body("trunk", r.trunk_mass, r.trunk_inertia, "trunk", "trunk_com"),)

    # ------------------------------------------------------------------ helpers
    def point_index(self, name: str) -> int:
        try:
            return self._point_index[name]
        except KeyError:
            raise BipedError(
                f"point {name!r} is unknown: allowed {', '.join(self.point_names)}"
            ) from None

    def direction_angles(self, q):
        """φ (..., K) from q (..., 9) or from the seven angles (..., 7)."""
        q = np.asarray(q)
        return q[..., :7] @ self.directions.T

    # ------------------------------------------------------------------ geometry
    def points(self, q, names=None):
        """Positions of named points, (..., P, 2) [m], in the order of ``names``.

        Args:
            q: generalized coordinates (..., 9).
            names: point names (default: all, in ``point_names`` order).
        """
        q = np.asarray(q)
        phi = self.direction_angles(q)
        return self._points(q, np.sin(phi), np.cos(phi), names)

    def _points(self, q, s, c, names=None):
        cols = slice(None) if names is None else [self.point_index(name) for name in names]
        a, b = self.point_a[:, cols], self.point_b[:, cols]
        x = q[..., XH, None] + s @ a + c @ b
        z = q[..., ZH, None] - c @ a + s @ b
        return np.stack([x, z], axis=-1)

    def point(self, q, name: str):
        """Position (..., 2) [m] of one named point."""
        return self.points(q, [name])[..., 0, :]

    def point_jacobian(self, q, name: str):
        """∂p/∂q (..., 2, 9) of one named point."""
        q = np.asarray(q)
        j = self.point_index(name)
        a, b = self.point_a[:, j], self.point_b[:, j]
        phi = self.direction_angles(q)
        s, c = np.sin(phi), np.cos(phi)
        # ∂u/∂φ = u', ∂u'/∂φ = -u
        dx = (a * c - b * s) @ self.directions
        dz = (a * s + b * c) @ self.directions
        jac = np.zeros(q.shape[:-1] + (2, NQ), dtype=np.result_type(q, float))
        jac[..., 0, :7], jac[..., 1, :7] = dx, dz
        jac[..., 0, XH] = jac[..., 1, ZH] = 1.0
        return jac

    def point_bias_acceleration(self, q, qd, name: str):
        """(dJ/dt) q̇ (..., 2) of a named point: its acceleration when q̈ = 0."""
        j = self.point_index(name)
        a, b = self.point_a[:, j], self.point_b[:, j]
        phi = self.direction_angles(q)
        rate2 = self.direction_angles(qd) ** 2
        s, c = np.sin(phi), np.cos(phi)
        # ∂²u/∂φ² = -u, ∂²u'/∂φ² = -u'
        return np.stack([(-a * s - b * c) * rate2, (a * c - b * s) * rate2], axis=-2).sum(axis=-1)

    def contact_jacobian(self, q, foot: str = "stance"):
        """A_c (..., 3, 9): rows [ankle x, ankle z, foot angle] of the ``foot`` on the ground.

        The rows of eqs. (13)-(15): holding the foot flat and fixed is holding its ankle
        position and its angle. The conjugate wrench F_e = [Fx, Fz, Cy] is then the force of
        the ground on the foot and its moment about the ankle (counter-clockwise positive).
        """
        if foot not in ("stance", "swing"):
            raise BipedError(f"foot = {foot!r} is not a foot: allowed 'stance', 'swing'")
        q = np.asarray(q)
        jac = np.zeros(q.shape[:-1] + (3, NQ), dtype=np.result_type(q, float))
        jac[..., :2, :] = self.point_jacobian(q, f"{foot}_ankle")
        jac[..., 2, QP1 if foot == "stance" else QP2] = 1.0
        return jac

    def contact_bias(self, q, qd, foot: str = "stance"):
        """H_c (..., 3) of eq. (16): A_c q̈ + H_c = 0 along motions that keep the foot fixed."""
        bias = self.point_bias_acceleration(q, qd, f"{foot}_ankle")
        return np.concatenate([bias, np.zeros(bias.shape[:-1] + (1,))], axis=-1)

    # ------------------------------------------------------------------ stance leg
    def stance_state(self, angles, rates=None, accelerations=None):
        """q, q̇, q̈ (..., 9) of a motion with the stance foot flat and fixed.

        Args:
            angles: the six free angles [qp2, q1, q2, q3, q4, q5] (..., 6) [rad]; qp1 = 0.
            rates, accelerations: their derivatives (..., 6) [rad/s, rad/s²]; default zero.

        The hip follows from eqs. (1)-(2) (revolute) or (7)-(8) (rolling): the stance ankle
        stays at x = 0, z = h_p, the ground at z = 0.
        """
        return self._stance_state(angles, rates, accelerations)[:3]

    def _stance_state(self, angles, rates=None, accelerations=None):
        """``stance_state`` plus φ̇, φ̈, sin φ, cos φ, for callers that go on to dynamics."""
        free = np.asarray(angles, dtype=float)
        shape = free.shape[:-1] + (NQ,)
        q, qd, qdd = np.zeros(shape), np.zeros(shape), np.zeros(shape)
        q[..., 1:7] = free
        if rates is not None:
            qd[..., 1:7] = rates
        if accelerations is not None:
            qdd[..., 1:7] = accelerations
        a = self._stance_ankle  # ankle = hip + Σ a u(φ)  =>  hip = ankle - Σ a u(φ)
        phi = self.direction_angles(q)
        phid = self.direction_angles(qd)
        phidd = self.direction_angles(qdd)
        s, c = np.sin(phi), np.cos(phi)
        rate2 = phid * phid
        q[..., XH] = -(s @ a)
        q[..., ZH] = self.robot.ankle_height + c @ a
        qd[..., XH] = -((c * phid) @ a)
        qd[..., ZH] = -((s * phid) @ a)
        qdd[..., XH] = -((c * phidd - s * rate2) @ a)
        qdd[..., ZH] = -((s * phidd + c * rate2) @ a)
        return q, qd, qdd, phid, phidd, s, c

    def leg_reach(self):
        """[m] Shortest and longest ankle-to-hip distance (knee flexion π and 0)."""
        return self._reach

    def reach_squared(self, flexion):
        """|hip - ankle|² [m²] of a leg at knee flexion θ = q_thigh - q_shank ≥ 0 [rad]."""
        r1, r2 = self.radii
        link = r1 + r2
        shank, thigh = self.robot.shank_length - r1, self.robot.thigh_length - r2
        value = shank**2 + thigh**2 + link**2 + 2 * shank * thigh * np.cos(flexion)
        if link > 0.0:
            value = value + 2 * link * (
                shank * np.cos(r2 * flexion / link) + thigh * np.cos(r1 * flexion / link)
            )
        return value

    def _reach_squared_derivative(self, flexion):
        r1, r2 = self.radii
        link = r1 + r2
        shank, thigh = self.robot.shank_length - r1, self.robot.thigh_length - r2
        value = -2 * shank * thigh * np.sin(flexion)
        if link > 0.0:
            value = value - 2 * (
                shank * r2 * np.sin(r2 * flexion / link) + thigh * r1 * np.sin(r1 * flexion / link)
            )
        return value

    def leg_angles(self, hip_from_ankle):
        """Inverse geometric model: (shank, thigh) angles (..., 2) [rad] of one leg.

        Args:
            hip_from_ankle: hip position relative to the ankle (..., 2) [m], foot flat.

        The knee is bent forward (flexion θ = q_thigh - q_shank in [0, π]). |hip - ankle|
        depends on θ alone and decreases strictly on [0, π], so θ is its unique root there;
        the shank angle then aligns the leg with ``hip_from_ankle``.

        Raises:
            UnreachableError: the distance is outside the leg's reach.
        """
        d = np.asarray(hip_from_ankle, dtype=float)
        if not np.all(np.isfinite(d)):
            raise UnreachableError(f"hip position {d.tolist()!r} m: allowed finite numbers")
        dist2 = (d**2).sum(-1)
        low, high = self.leg_reach()
        bad = (dist2 > high**2 * (1 + 1e-12)) | (dist2 < low**2)
        if np.any(bad):
            worst = float(np.sqrt(np.atleast_1d(dist2)[np.atleast_1d(bad)][0]))
            raise UnreachableError(
                f"hip at {worst:.6g} m from the ankle is out of reach: "
                f"allowed {low:.6g} m to {high:.6g} m"
            )
        dist2 = np.minimum(dist2, high**2)  # rounding above the straight leg
        r1, r2 = self.radii
        if r1 + r2 == 0.0:  # revolute: closed form
            l1, l2 = self.robot.shank_length, self.robot.thigh_length
            flexion = _acos(np.clip((dist2 - l1**2 - l2**2) / (2 * l1 * l2), -1.0, 1.0))
        else:  # Newton on the monotone f(θ) from the tabulated inverse
            flexion = np.interp(dist2, self._reach_table[::-1], self._flexion_table[::-1])
            for _ in range(20):
                residual = self.reach_squared(flexion) - dist2
                if np.all(np.abs(residual) < 1e-13):
                    break
                slope = self._reach_squared_derivative(flexion)
                step = np.where(slope < 0.0, residual / np.where(slope < 0.0, slope, -1.0), 0.0)
                flexion = np.clip(flexion - step, 0.0, self._flexion_table[-1])
            else:
                raise UnreachableError("inverse geometric model did not converge")
        vx, vz = self._hanging_leg(flexion)
        shank_angle = _atan2(d[..., 1], d[..., 0]) - _atan2(-vz, -vx)
        shank_angle = (shank_angle + np.pi) % (2 * np.pi) - np.pi
        return np.stack([shank_angle, shank_angle + flexion], axis=-1)

    def _hanging_leg(self, flexion):
        """v(θ) = (vx, vz) [m]: the hip is −R(q1) v(θ) from the ankle, the leg a chain hanging
        from it with shank angle 0 and knee flexion θ (``leg_angles``)."""
        r1, r2 = self.radii
        link = r1 + r2
        shank, thigh = self.robot.shank_length - r1, self.robot.thigh_length - r2
        gamma = r2 * flexion / link if link > 0.0 else 0.0
        vx = link * np.sin(gamma) + thigh * np.sin(flexion)
        vz = -shank - link * np.cos(gamma) - thigh * np.cos(flexion)
        return vx, vz


def swap_legs(chain: Chain, q, qd=None):
    """Relabel the legs at the end of a step: the swing leg becomes the stance leg.

    Returns q (and q̇) of the same posture in the new labelling, translated along x so that
    the new stance ankle is at x = 0. Angles and velocities are only permuted.
    """
    q = np.asarray(q, dtype=float)
    new_q = q[..., LEG_SWAP].copy()
    new_q[..., XH] -= chain.point(q, "swing_ankle")[..., 0]
    if qd is None:
        return new_q
    return new_q, np.asarray(qd, dtype=float)[..., LEG_SWAP]
