"""The profiled rolling knee (``biped.model.profile_biped.ProfileBiped``) as CasADi
expressions: the same model written a second time, for the step's graph
(``biped.optimization.symbolic``), with the profile's parameters (r1, r2, k1, k2) as numbers
or, in a design, as symbols.

The constants (W, G, M, J and the point coefficients) come from the numeric model's own
point table (``biped.model.profile_biped.profile_points``) and the same sums over the bodies;
the knee's vectors from ``biped.model.profile.knee_vectors`` with ``xp = casadi``. Each
function mirrors one of the numeric model's methods (named in its docstring); a test holds
the graph equal to the numeric model to 1e-12.
"""

from __future__ import annotations

import casadi as ca
import numpy as np

from biped.model.kinematics import BODY_DIRECTIONS, NQ, Q1, Q2, Q3, Q4, Q5, QP2, XH, ZH
from biped.model.profile import knee_vectors
from biped.model.profile_biped import KNEE_ANGLES, TRANSLATIONS, VECTORS, profile_points


class ProfileConstants:
    """The constants of the profiled knee's model as CasADi matrices.

    Args:
        model: the robot (every parameter but the profile's, when ``parameters`` given).
        parameters: an SX (4,) of the profile's symbols (r1, r2, k1, k2); None: ``model``'s
            numbers (a ``ProfileBiped``).
    """

    profile = True

    def __init__(self, model, parameters=None):
        self.model = model
        robot = model.robot
        self.hp, self.gravity, self.mass = robot.ankle_height, robot.gravity, robot.total_mass
        self.design = parameters is not None
        if self.design:
            self.parameters = tuple(parameters[i] for i in range(4))
        else:
            self.parameters = model.profile.vector
        r1, r2 = self.parameters[:2]
        self.radii = (r1, r2)
        index = {name: k for k, name in enumerate(BODY_DIRECTIONS)}
        self._points = {}
        for name, (a, b, vectors) in profile_points(robot, r1, r2).items():
            columns = []
            for coefficients in (a, b):
                column = ca.SX(7, 1)
                for key, value in coefficients.items():
                    column[index[key]] = value
                columns.append(column)
            flags = tuple(VECTORS.index(v) for v in vectors)
            self._points[name] = (*columns, flags)
        w, g, m = ca.SX(7, 7), ca.SX(7, len(TRANSLATIONS)), ca.SX(len(TRANSLATIONS), 3)
        inertia = np.zeros(7)
        for body in model.bodies:  # as ProfileBiped._moments
            a, _, flags = self._points[body.com]
            carried = ca.DM([1.0] + [float(2 * t in flags) for t in range(2)])
            w = w + body.mass * (a @ a.T)
            g = g + body.mass * (a @ carried.T)
            m = m + body.mass * (carried @ carried.T)
            inertia[index[body.direction]] += body.inertia
        self.w, self.g, self.m = w, g, m
        self.inertia = ca.DM(inertia)
        self.ankle = self._points["stance_ankle"][0]

    def point(self, name):
        """(a, b, vector indices) of a named point."""
        return self._points[name]


def _vectors(c: ProfileConstants, q, qd=None) -> dict:
    """The knees' vectors by name (``VECTORS``) at q (9,) (``ProfileBiped.knee_vectors``)."""
    found = {}
    for side, (thigh, shank) in KNEE_ANGLES.items():
        rates = (None, None) if qd is None else (qd[thigh], qd[shank])
        for name, vector in knee_vectors(c.parameters, q[thigh], q[shank], *rates, xp=ca).items():
            found[f"{side}_{name}"] = vector
    return found


def _moved(vector, qdd, thigh, shank):
    """J q̈ + J̇ q̇ (x, z) of a knee vector."""
    return [
        vector.by_thigh[i] * qdd[thigh] + vector.by_shank[i] * qdd[shank] + vector.bias[i]
        for i in range(2)
    ]


def stance_state(c: ProfileConstants, angles, rates, accels):
    """q, q̇, q̈ (9,) of a stance-foot-fixed motion (``ProfileBiped._stance_state``)."""
    zero = ca.SX.zeros(1)
    q7, qd7, qdd7 = (ca.vertcat(zero, v) for v in (angles, rates, accels))
    s, co = ca.sin(q7), ca.cos(q7)
    rate2 = qd7 * qd7
    link = knee_vectors(c.parameters, q7[Q2], q7[Q1], qd7[Q2], qd7[Q1], xp=ca)["link"]
    rate = [link.by_thigh[i] * qd7[Q2] + link.by_shank[i] * qd7[Q1] for i in range(2)]
    accel = _moved(link, qdd7, Q2, Q1)
    a = c.ankle
    q = ca.vertcat(q7, -ca.dot(s, a) - link.position[0], c.hp + ca.dot(co, a) - link.position[1])
    qd = ca.vertcat(qd7, -ca.dot(co * qd7, a) - rate[0], -ca.dot(s * qd7, a) - rate[1])
    qdd = ca.vertcat(
        qdd7,
        -ca.dot(co * qdd7 - s * rate2, a) - accel[0],
        -ca.dot(s * qdd7 + co * rate2, a) - accel[1],
    )
    return q, qd, qdd


def generalized_forces(c: ProfileConstants, q, qd, qdd):
    """D q̈ + H + Q (9,) (``ProfileBiped.generalized_forces``) and the knees' vectors."""
    phi, phid, phidd = q[:7], qd[:7], qdd[:7]
    s, co = ca.sin(phi), ca.cos(phi)
    rate2 = phid * phid
    ax, az = co * phidd - s * rate2, s * phidd + co * rate2
    vectors = _vectors(c, q, qd)
    moves_x, moves_z = [qdd[XH]], [qdd[ZH] + c.gravity]
    for side, (thigh, shank) in KNEE_ANGLES.items():
        x, z = _moved(vectors[f"{side}_link"], qdd, thigh, shank)
        moves_x.append(x)
        moves_z.append(z)
    moves_x, moves_z = ca.vertcat(*moves_x), ca.vertcat(*moves_z)
    tau_phi = co * (c.w @ ax + c.g @ moves_x) + s * (c.w @ az + c.g @ moves_z)
    tau_phi = tau_phi + c.inertia * phidd
    tau_x, tau_z = c.m @ moves_x + c.g.T @ ax, c.m @ moves_z + c.g.T @ az
    tau = [tau_phi[i] for i in range(7)] + [tau_x[0], tau_z[0]]
    for t, (side, (thigh, shank)) in enumerate(KNEE_ANGLES.items(), start=1):
        link = vectors[f"{side}_link"]
        for i, force in enumerate((tau_x[t], tau_z[t])):
            tau[thigh] = tau[thigh] + link.by_thigh[i] * force
            tau[shank] = tau[shank] + link.by_shank[i] * force
    return ca.vertcat(*tau), vectors


def torques_and_wrench(c: ProfileConstants, q, qd, qdd):
    """Γ (6,) and F_e (3,) (``ProfileBiped.inverse_dynamics``)."""
    tau, vectors = generalized_forces(c, q, qd, qdd)
    link = vectors["stance_link"]
    a = c.ankle
    fx, fz = tau[XH], tau[ZH]
    columns = [
        (a[Q1] * ca.cos(q[Q1]) + link.by_shank[0], a[Q1] * ca.sin(q[Q1]) + link.by_shank[1]),
        (a[Q2] * ca.cos(q[Q2]) + link.by_thigh[0], a[Q2] * ca.sin(q[Q2]) + link.by_thigh[1]),
    ]
    work = [fx * dx + fz * dz for dx, dz in columns]
    g6 = -tau[QP2]
    g5 = g6 - tau[Q4]
    g4 = g5 - tau[Q3]
    g3 = tau[Q5] - g4
    g2 = tau[Q2] + g3 - work[1]
    g1 = tau[Q1] + g2 - work[0]
    cy = tau[0] + g1
    return ca.vertcat(g1, g2, g3, g4, g5, g6), ca.vertcat(fx, fz, cy)


def point_height(c: ProfileConstants, q, name: str, vectors=None):
    """z [m] of a named point at q (9,) (``ProfileBiped.points``)."""
    a, b, flags = c.point(name)
    s, co = ca.sin(q[:7]), ca.cos(q[:7])
    height = q[ZH] - ca.dot(co, a) + ca.dot(s, b)
    vectors = _vectors(c, q) if vectors is None and flags else vectors
    for flag in flags:
        height = height + vectors[VECTORS[flag]].position[1]
    return height


def sole_heights(c: ProfileConstants, angles):
    """Heights (n, 2) [m] of the swing heel and toe at the free angles (n, 6), the stance
    foot flat and fixed (``biped.optimization.symbolic._sole_heights``)."""
    rows = []
    for j in range(angles.shape[0]):
        zero = ca.SX.zeros(6)
        q = stance_state(c, angles[j, :].T, zero, zero)[0]
        vectors = _vectors(c, q)
        rows.append(
            ca.horzcat(*(point_height(c, q, f"swing_{e}", vectors) for e in ("heel", "toe")))
        )
    return ca.vertcat(*rows)


def mass_matrix(c: ProfileConstants, q):
    """D(q) (9, 9) = J_Yᵀ D_y J_Y (``ProfileBiped.mass_matrix``)."""
    s, co = ca.sin(q[:7]), ca.cos(q[:7])
    n = len(TRANSLATIONS)
    top = c.w * (co @ co.T + s @ s.T) + ca.diag(c.inertia)
    rows = [ca.horzcat(top, *[ca.horzcat(c.g[:, t] * co, c.g[:, t] * s) for t in range(n)])]
    for t in range(n):
        for axis in (co, s):
            block = [(c.g[:, t] * axis).T]
            for t2 in range(n):
                mass = c.m[t, t2]
                block.append(ca.horzcat(mass, 0.0) if axis is co else ca.horzcat(0.0, mass))
            rows.append(ca.horzcat(*block))
    dy = ca.vertcat(*rows)
    jy = ca.SX(7 + 2 * n, NQ)
    for i in range(7):
        jy[i, i] = 1.0
    jy[7, XH] = jy[8, ZH] = 1.0
    vectors = _vectors(c, q)
    for t, (side, (thigh, shank)) in enumerate(KNEE_ANGLES.items(), start=1):
        link = vectors[f"{side}_link"]
        for i in range(2):
            jy[7 + 2 * t + i, thigh] = link.by_thigh[i]
            jy[7 + 2 * t + i, shank] = link.by_shank[i]
    return jy.T @ dy @ jy


def swing_contact_jacobian(c: ProfileConstants, q):
    """A_c (3, 9) of the swing foot (``Chain.contact_jacobian(q, "swing")``)."""
    a, b, _ = c.point("swing_ankle")
    s, co = ca.sin(q[:7]), ca.cos(q[:7])
    link = _vectors(c, q)["swing_link"]
    dx, dz = a * co - b * s, a * s + b * co
    for i, column in enumerate((dx, dz)):
        column[Q3] = column[Q3] + link.by_thigh[i]
        column[Q4] = column[Q4] + link.by_shank[i]
    row_angle = ca.DM.zeros(9)
    row_angle[QP2] = 1.0
    return ca.horzcat(ca.vertcat(dx, 1.0, 0.0), ca.vertcat(dz, 0.0, 1.0), row_angle).T


def _hanging_leg(c: ProfileConstants, bend):
    """v(θ) (``ProfileBiped._hanging_leg``)."""
    r1, r2 = c.radii
    link = knee_vectors(c.parameters, bend, 0.0 * bend, xp=ca)["link"].position
    thigh = c.model.robot.thigh_length - r2
    shank = c.model.robot.shank_length - r1
    return thigh * ca.sin(bend) + link[0], -shank - thigh * ca.cos(bend) + link[1]


def leg_angles(c: ProfileConstants, bend, hip_from_ankle):
    """(shank, thigh) angles of a leg with knee flexion ``bend`` and the hip at
    ``hip_from_ankle`` (``Chain.leg_angles`` with the flexion known)."""
    vx, vz = _hanging_leg(c, bend)
    angle = ca.atan2(hip_from_ankle[1], hip_from_ankle[0]) - ca.atan2(-vz, -vx)
    return angle, angle + bend


def reach_squared(c: ProfileConstants, bend):
    """|hip − ankle|² at knee flexion ``bend`` (``ProfileBiped.reach_squared``)."""
    vx, vz = _hanging_leg(c, bend)
    return vx * vx + vz * vz
