"""The gait problem as a CasADi expression graph: exact derivatives for the solvers.

The graph is built from the public constants of the numeric model (``biped.model.dynamics.Biped``:
the directions Φ, W, g, J, P and the point coefficients; ``biped.model.gait``: the spline bases
and the leg swap), so the symbolic and the numeric criterion are one model written twice with
the same numbers (a test holds them equal to 1e-12). From the variables z
(``biped.optimization.problem.VARIABLES``) and the speed, in the stages of ``StepGraph``:

1. hip at the start of the step from the knee bends (``biped.optimization.problem``, eq. *), the
   legs' angles by the forward geometry of each leg (no inverse model, no square root at a
   straight knee);
2. the end state (legs swapped), the impact map (23) and the start velocities;
3. the spline coefficients (25)-(26), then at each sample the stance state, the one-pass
   inverse dynamics and the swing foot's heel and toe;
4. the criterion (Simpson's rule per piece) and the constraints Ψ_i − δ_i.

The speed is a parameter of the graph, so one built graph serves every speed of a sweep.
With ``design=True`` the knee radii (r1, r2) are symbols too: the constants that depend on
them (directions, point coefficients, W, g) are built by the numeric model's own point table
(``biped.model.kinematics.point_table``) from the symbols, so the knee can be optimised with
the gait (``biped.optimization.design``).
"""

from __future__ import annotations

import casadi as ca
import numpy as np

from biped.model import walkable
from biped.model.actuators import LIMITS, drive, limit_margins
from biped.model.bezier import Bezier, control_points
from biped.model.criteria import (
    ACTUATOR_MARGIN,
    CONSTRAINT_SCALES,
    CONSTRAINTS,
    checked_mask,
    clearance_envelope,
    clearance_profile,
    margin_profile,
    simpson_weights,
)
from biped.model.dynamics import JOINT_MATRIX, Biped
from biped.model.gait import FREE_ANGLES, FREE_SWAP, hermite, piece_grid, spline_basis
from biped.model.kinematics import (
    BODY_DIRECTIONS,
    LEG_SWAP,
    LINK_DIRECTIONS,
    NQ,
    Q1,
    Q2,
    Q3,
    Q4,
    Q5,
    QP1,
    QP2,
    XH,
    ZH,
    point_table,
)
from biped.model.profile_biped import ProfileBiped
from biped.optimization import profile_graph
from biped.optimization.problem import CHECK_SAMPLES, MIN_HIP_HEIGHT, index, variable_names

# [m] What the solver keeps above the clearance at the check grid's samples between its own:
# the check's rounding (the solver meets its constraints to 1e-9 of their scale).
BETWEEN_SAMPLES_MARGIN = 1e-6
# [rad] What the solver keeps inside the knees' Ψ4, Ψ5 at the check grid's samples between its
# own, in a Bézier family (``_knees_between_samples``): the check's rounding, as above.
KNEE_BETWEEN_SAMPLES_MARGIN = 1e-6
# The knees' constraints, in ``CONSTRAINTS``' order.
KNEES = ("stance_knee", "swing_knee")


class Constants:
    """The numeric model's constants as CasADi matrices.

    With ``radii`` (an SX of two symbols r1, r2) the constants that depend on the knee
    radii are SX expressions of them, built by the same point table as the numeric model
    (``biped.model.kinematics.point_table``) and the same sums over the bodies as
    ``biped.model.dynamics.Biped``; the rolling knee's two links C1C2 are always present (of
    length r1 + r2, so at r1 = r2 = 0 they carry nothing: the revolute knee).
    """

    profile = False  # the circles (``profile_graph.ProfileConstants``: the profiles)

    def __init__(self, model: Biped, radii=None):
        self.model = model
        self.hp = model.robot.ankle_height
        self.gravity = model.gravity
        self.mass = model.mass
        self.design = radii is not None
        if self.design:
            self._symbolic(model, radii)
        else:
            self.radii = model.radii
            self.phi = _sparse(model.directions)  # (K, 7)
            self.w = _sparse(model.second_moments)
            self.g = _sparse(model.first_moments)
            self.inertia = _sparse(model.direction_inertias)
            self.p = _sparse(model.coordinate_map)  # y = P q
            self.k = model.directions.shape[0]
        self.ankle = self.point("stance_ankle")[0]
        self.stance_leg = self.phi[:, [Q1, Q2]]  # (K, 2)

    def _symbolic(self, model: Biped, radii):
        r1, r2 = radii[0], radii[1]
        link = r1 + r2
        self.radii = (r1, r2)
        # r1 / l and r2 / l: the hinges' shares of the knee flexion (any value at l = 0,
        # where the links have no length).
        self.shares = tuple(ca.if_else(link > 0.0, r / link, 0.5) for r in (r1, r2))
        names = BODY_DIRECTIONS + LINK_DIRECTIONS
        index = {name: k for k, name in enumerate(names)}
        k = self.k = len(names)
        phi = ca.SX(k, 7)
        for i in range(7):
            phi[i, i] = 1.0
        row = index["stance_knee_link"]  # γ1 = (r1 q1 + r2 q2) / l
        phi[row, Q1], phi[row, Q2] = self.shares
        row = index["swing_knee_link"]  # γ2 = (r1 q4 + r2 q3) / l
        phi[row, Q4], phi[row, Q3] = self.shares
        self.phi = phi
        table = point_table(model.robot, r1, r2, links=True)
        self._points = {}
        for name, (a, b) in table.items():
            columns = []
            for coefficients in (a, b):
                column = ca.SX(k, 1)
                for key, value in coefficients.items():
                    column[index[key]] = value
                columns.append(column)
            self._points[name] = tuple(columns)
        w, g = ca.SX(k, k), ca.SX(k, 1)
        inertia = np.zeros(k)
        for body in model.bodies:  # as biped.model.dynamics.Biped
            a = self._points[body.com][0]
            w = w + body.mass * (a @ a.T)
            g = g + body.mass * a
            inertia[index[body.direction]] += body.inertia
        self.w, self.g, self.inertia = w, g, _sparse(inertia)
        p = ca.SX(k + 2, NQ)  # y = P q, as Biped.coordinate_map
        p[:k, :7] = phi
        p[k, XH] = p[k + 1, ZH] = 1.0
        self.p = p

    def point(self, name):
        if self.design:
            return self._points[name]
        j = self.model.point_index(name)
        return _sparse(self.model.point_a[:, j]), _sparse(self.model.point_b[:, j])


def _sparse(array):
    """A constant matrix without its structural zeros, so the graph holds no product by 0."""
    return ca.sparsify(ca.DM(np.asarray(array, dtype=float)))


def stance_state(c: Constants, angles, rates, accels):
    """q, q̇, q̈ (9,) and φ̇, φ̈, sin φ, cos φ of a stance-foot-fixed motion
    (``Chain.stance_state``); a profiled knee's q, q̇, q̈ and None."""
    if c.profile:
        return (*profile_graph.stance_state(c, angles, rates, accels), None, None, None, None)
    zero = ca.SX.zeros(1)
    q7, qd7, qdd7 = (ca.vertcat(zero, v) for v in (angles, rates, accels))
    phi, phid, phidd = c.phi @ q7, c.phi @ qd7, c.phi @ qdd7
    s, co = ca.sin(phi), ca.cos(phi)
    rate2 = phid * phid
    a = c.ankle
    q = ca.vertcat(q7, -ca.dot(s, a), c.hp + ca.dot(co, a))
    qd = ca.vertcat(qd7, -ca.dot(co * phid, a), -ca.dot(s * phid, a))
    qdd = ca.vertcat(qdd7, -ca.dot(co * phidd - s * rate2, a), -ca.dot(s * phidd + co * rate2, a))
    return q, qd, qdd, phid, phidd, s, co


def _torques_and_wrench(c: Constants, qdd, phid, phidd, s, co):
    """Γ (6,) and F_e (3,) in one pass, as ``Biped.inverse_dynamics``."""
    rate2 = phid * phid
    ax = co * phidd - s * rate2
    az = s * phidd + co * rate2
    hip_x = qdd[XH]
    hip_z = qdd[ZH] + c.gravity
    tau_phi = co * (c.w @ ax + c.g * hip_x) + s * (c.w @ az + c.g * hip_z) + c.inertia * phidd
    tau = ca.vertcat(c.phi.T @ tau_phi, c.mass * hip_x + ca.dot(ax, c.g))
    tau = ca.vertcat(tau, c.mass * hip_z + ca.dot(az, c.g))
    fx, fz = tau[XH], tau[ZH]
    weights = c.ankle * (co * fx + s * fz)
    work = c.stance_leg.T @ weights
    g6 = -tau[QP2]
    g5 = g6 - tau[Q4]
    g4 = g5 - tau[Q3]
    g3 = tau[Q5] - g4
    g2 = tau[Q2] + g3 - work[1]
    g1 = tau[Q1] + g2 - work[0]
    cy = tau[QP1] + g1
    return ca.vertcat(g1, g2, g3, g4, g5, g6), ca.vertcat(fx, fz, cy)


def _sole_heights(c: Constants, angles):
    """Heights (n, 2) [m] of the swing heel and toe at the free angles ``angles`` (n, 6),
    the stance foot flat and fixed (``sample_function``'s Ψ6, Ψ7 without the margins)."""
    if c.profile:
        return profile_graph.sole_heights(c, angles)
    rows = []
    zero = ca.SX.zeros(angles.shape[0], 1)
    phi = ca.horzcat(zero, angles) @ c.phi.T  # (n, K) the directions' angles
    s, co = ca.sin(phi), ca.cos(phi)
    hip = c.hp + co @ c.ankle  # z_H (n, 1)
    for name in ("swing_heel", "swing_toe"):
        a, b = c.point(name)
        rows.append(hip - co @ a + s @ b)
    return ca.horzcat(*rows)


def mass_matrix(c: Constants, q):
    """D(q) (9, 9) (``Biped.mass_matrix``)."""
    if c.profile:
        return profile_graph.mass_matrix(c, q)
    phi = c.phi @ q[:7]
    s, co = ca.sin(phi), ca.cos(phi)
    k = c.k
    top = c.w * (co @ co.T + s @ s.T) + ca.diag(c.inertia)
    gx, gz = (c.g * co).T, (c.g * s).T
    dy = ca.blockcat(
        [
            [top, gx.T, gz.T],
            [gx, ca.DM(c.mass).reshape((1, 1)), ca.DM.zeros(1, 1)],
            [gz, ca.DM.zeros(1, 1), ca.DM(c.mass).reshape((1, 1))],
        ]
    )
    assert dy.shape == (k + 2, k + 2)
    return c.p.T @ dy @ c.p


def _swing_contact_jacobian(c: Constants, q):
    """A_c (3, 9) of the swing foot (``Chain.contact_jacobian(q, "swing")``)."""
    if c.profile:
        return profile_graph.swing_contact_jacobian(c, q)
    a, b = c.point("swing_ankle")
    phi = c.phi @ q[:7]
    s, co = ca.sin(phi), ca.cos(phi)
    dx = ((a * co - b * s).T @ c.phi).T
    dz = ((a * s + b * co).T @ c.phi).T
    row_x = ca.vertcat(dx, 1.0, 0.0)
    row_z = ca.vertcat(dz, 0.0, 1.0)
    row_angle = ca.DM.zeros(9)
    row_angle[QP2] = 1.0
    return ca.horzcat(row_x, row_z, row_angle).T


def leg_angles(c: Constants, bend, hip_from_ankle):
    """(shank, thigh) angles of a leg with knee flexion ``bend`` and the hip at
    ``hip_from_ankle`` (``Chain.leg_angles`` with the flexion known)."""
    if c.profile:
        return profile_graph.leg_angles(c, bend, hip_from_ankle)
    r1, r2 = c.radii
    link = r1 + r2
    shank = c.model.robot.shank_length - r1
    thigh = c.model.robot.thigh_length - r2
    if c.design:
        gamma = c.shares[1] * bend
    else:
        gamma = r2 * bend / link if link > 0.0 else 0.0
    vx = link * ca.sin(gamma) + thigh * ca.sin(bend)
    vz = -shank - link * ca.cos(gamma) - thigh * ca.cos(bend)
    angle = ca.atan2(hip_from_ankle[1], hip_from_ankle[0]) - ca.atan2(-vz, -vx)
    return angle, angle + bend


def reach_squared(c: Constants, bend):
    """|hip − ankle|² at knee flexion ``bend`` (``Chain.reach_squared``)."""
    if c.profile:
        return profile_graph.reach_squared(c, bend)
    r1, r2 = c.radii
    link = r1 + r2
    shank = c.model.robot.shank_length - r1
    thigh = c.model.robot.thigh_length - r2
    value = shank**2 + thigh**2 + link**2 + 2 * shank * thigh * ca.cos(bend)
    if c.design:
        share1, share2 = c.shares
        value = value + 2 * link * (shank * ca.cos(share2 * bend) + thigh * ca.cos(share1 * bend))
    elif link > 0.0:
        value = value + 2 * link * (
            shank * ca.cos(r2 * bend / link) + thigh * ca.cos(r1 * bend / link)
        )
    return value


# The quantities of one sample (``sample_function``), in order, with their row counts: the
# stance state, the inverse dynamics, Ψ1-Ψ7 with the ZMP margin (the swing foot's clearance,
# which varies over the step, is taken off afterwards), ΓᵀΓ and the joints' powers Γ_i θ̇_i;
# with the motors (``biped.model.actuators``), their electrical powers P_i = u_i i_i and
# voltages u_i.
QUANTITIES = (
    ("q", 9),
    ("qd", 9),
    ("torques", 6),
    ("wrench", 3),
    ("psi", 7),
    ("squared", 1),
    ("power", 6),
)
MOTOR_QUANTITIES = (("electrical", 6), ("voltage", 6))
_ROWS, _COUNT = {}, 0
for _name, _n in QUANTITIES + MOTOR_QUANTITIES:
    _ROWS[_name], _COUNT = slice(_COUNT, _COUNT + _n), _COUNT + _n
N_QUANTITIES = _ROWS["power"].stop  # 41; 53 with the motors'
N_MOTOR_QUANTITIES = _COUNT
# A sample's inputs: the free angles and their first and second derivatives in normalised
# time (6 each), then the period T [s], then (design) the knee radii.
SAMPLE_MOTION = 18


def sample_function(c: Constants, robot, safety, radii=None, motors=False) -> ca.Function:
    """One sample of the step as a CasADi function: v = [angles, d/dt_n, d²/dt_n² (6 each),
    T (, r1, r2)] -> the ``QUANTITIES`` (41,), with ``motors`` also the ``MOTOR_QUANTITIES``
    of ``robot.drive_actuators`` (53,). Every sample of a step is this function of a
    linear map of the step's head (``StepGraph.basis``), which lets the solver build the
    Hessian of its Lagrangian sample by sample (``biped.optimization.derivatives``)."""
    motion, period = ca.SX.sym("motion", SAMPLE_MOTION), ca.SX.sym("period")
    angles = motion[:6]
    rates, accels = motion[6:12] / period, motion[12:] / period**2
    q, qd, qdd, phid, phidd, s, co = stance_state(c, angles, rates, accels)
    if c.profile:
        torques, wrench = profile_graph.torques_and_wrench(c, q, qd, qdd)
        heel, toe = (profile_graph.point_height(c, q, f"swing_{e}") for e in ("heel", "toe"))
    else:
        torques, wrench = _torques_and_wrench(c, qdd, phid, phidd, s, co)
        heel_a, heel_b = c.point("swing_heel")
        toe_a, toe_b = c.point("swing_toe")
        heel = q[ZH] - ca.dot(co, heel_a) + ca.dot(s, heel_b)
        toe = q[ZH] - ca.dot(co, toe_a) + ca.dot(s, toe_b)
    zmp = (torques[0] - robot.ankle_height * wrench[0]) / wrench[1]
    psi = ca.vertcat(
        wrench[1],
        zmp + robot.foot_heel - safety.zmp_margin,
        robot.foot_length - robot.foot_heel - zmp - safety.zmp_margin,
        q[Q2] - q[Q1] - safety.knee_bend,
        q[Q3] - q[Q4],
        heel,
        toe,
    )
    rates = ca.DM(JOINT_MATRIX) @ qd
    power = torques * rates
    quantities = ca.vertcat(q, qd, torques, wrench, psi, ca.sumsqr(torques), power)
    if motors:  # the same formulas as the numeric model's (``biped.model.actuators.drive``)
        constants = {k: ca.DM(v) for k, v in robot.drive_actuators.constants().items()}
        state = drive(constants, torques, rates, ca.DM(JOINT_MATRIX) @ qdd, tanh=ca.tanh)
        quantities = ca.vertcat(quantities, state.power, state.voltage)
    inputs = [motion, period] + ([radii] if radii is not None else [])
    return ca.Function("sample", [ca.vertcat(*inputs)], [quantities], ["v"], ["quantities"])


class StepGraph:
    """One step of one robot as a CasADi graph of the variables z and the speed V.

    Args:
        model: robot and knee.
        samples_per_half: samples per spline piece (constraints and Simpson's rule).
        safety: margins of ours (``biped.model.criteria.Safety``).
        design: the knee radii (r1, r2) are symbols too (``radii``), the rolling knee's
            links always present: ``model`` gives every other constant (its radii and knee
            are not used). At r1 = r2 = 0 the graph is the revolute knee's.

    The graph has two parts. The head, SX expressions of ``z`` (21), ``speed`` (1) and, with
    ``design``, ``radii`` (2) [m]: ``head`` = [the spline coefficients (8 x 6, column by
    column), T (, r1, r2), the hip height constraint]. The samples: sample j is
    ``sample_function`` of v_j = ``basis_j`` @ head (a constant matrix), giving the
    ``QUANTITIES`` of the samples, ``quantities`` (41, N) as a symbol. The criteria and
    constraints are written on the symbols ``quantities`` and ``head_symbol`` (``on_symbols``,
    linear in the quantities) and, substituted (``flat``), as expressions of the variables:

    Attributes (SX expressions of z, speed (, radii)):
        parameters (21): the paper's parameters; torques (6, N); wrench (3, N); q (9, N);
        qd (9, N); power (6, N) Γ_i θ̇_i; sthenic, energy: eqs. (30)-(31) without penalty;
        constraints (M): (Ψ_i − δ_i − safety) / scale at the checked samples, >= 0 when met;
        hip_height: hip above the ankles at the start less ``MIN_HIP_HEIGHT`` (>= 0);
        period T [s], length S = V T [m], impulse (3,) of the landing, psi (7, N): Ψ_i with
        the margins, weights (1, N): Simpson's. Built in the module docstring's stages, one
        method each.
    """

    def __init__(
        self,
        model: Biped,
        samples_per_half: int,
        safety,
        design: bool = False,
        knots: int = 1,
        motors: bool = False,
        profile: bool = False,
    ):
        self.model, self.samples_per_half = model, samples_per_half
        self.safety, self.design, self.knots = safety, design, knots
        # The motors' quantities, for the electrical criterion or the actuator limits.
        self.motors = motors or safety.actuator_limits
        # A profiled knee (``biped.model.profile``): ``model``'s, or a design's of (r1, r2,
        # k1, k2) with ``profile``.
        self.profile = profile if design else isinstance(model, ProfileBiped)
        self.radii = ca.SX.sym("radii", 4 if self.profile else 2) if design else None
        c = (profile_graph.ProfileConstants if self.profile else Constants)(model, self.radii)
        self.z = ca.SX.sym("z", len(variable_names(knots)))
        self.speed = ca.SX.sym("speed")
        self.period = self.z[-1]  # T [s]
        self.length = self.speed * self.period  # S [m]
        start_angles = self._start_posture(c)
        end_angles, end_rates, start_rates = self._impact(c, start_angles)
        coefficients = self._splines(start_angles, start_rates, end_angles, end_rates)
        self._samples(c, coefficients)
        self.on_symbols = self._criteria_and_constraints()
        for name, value in self.on_symbols.items():
            setattr(self, name, self.flat(value))

    def _start_posture(self, c: Constants):
        """1. The hip at the start of the step from the knee bends (``biped.optimization.problem``,
        eq. *), the legs' angles by the forward geometry of each leg (no inverse model, no
        square root at a straight knee): the six free angles at the start. Sets
        ``hip_height`` and ``parameters``."""
        z, length = self.z, self.length
        bend_s, bend_w = z[index("stance_knee_bend")], z[index("swing_knee_bend")]
        d_s2, d_w2 = reach_squared(c, bend_s), reach_squared(c, bend_w)
        x_hip = (d_w2 - d_s2 - length**2) / (2 * length)
        height2 = d_s2 - x_hip**2
        self.hip_height = (height2 - MIN_HIP_HEIGHT**2) / MIN_HIP_HEIGHT**2
        lift = ca.sqrt(ca.fmax(height2, 1e-6))
        q1, q2 = leg_angles(c, bend_s, ca.vertcat(x_hip, lift))
        q4, q3 = leg_angles(c, bend_w, ca.vertcat(x_hip + length, lift))
        self.parameters = ca.vertcat(x_hip, c.hp + lift, z[index("trunk") :])
        return ca.vertcat(0.0, q1, q2, q3, q4, z[index("trunk")])

    def _impact(self, c: Constants, start_angles):
        """2. The end state (the start posture with the legs swapped, ``FREE_SWAP``), the
        impact map (23) and the start velocities, the legs swapped again (``LEG_SWAP``):
        (end angles, end rates, start rates), each (6,). Sets ``impulse``."""
        z = self.z
        end_angles = ca.vertcat(*[start_angles[i] for i in FREE_SWAP])
        end_rates = ca.vertcat(0.0, z[index("end_rate_q1") : index("end_rate_q5") + 1])
        q_end, qd_end, *_ = stance_state(c, end_angles, end_rates, ca.SX.zeros(6))
        mass = mass_matrix(c, q_end)
        jac = _swing_contact_jacobian(c, q_end)
        d_inv_jt = ca.solve(mass, jac.T)
        gram = jac @ d_inv_jt
        self.impulse = -ca.solve(gram, jac @ qd_end)
        self.touchdown = (jac @ qd_end)[:2]  # the swing ankle's (vx, vz): every sole point's
        qd_plus = qd_end + d_inv_jt @ self.impulse
        start_rates = ca.vertcat(*[qd_plus[LEG_SWAP[i]] for i in range(1, 7)])
        return end_angles, end_rates, start_rates

    def _splines(self, start_angles, start_rates, end_angles, end_rates):
        """3. The spline coefficients (``biped.model.gait.Step.coefficients``, 4 (K + 1) x 6)
        of the free angles in normalised time, as in ``biped.model.gait.build_step``: eqs.
        (25)-(26) [a0..a3, b0..b3] for the paper's spline, the Hermite pieces of a richer
        family's, the control points (n + 1) x 6 of a Bézier family's
        (``biped.model.bezier.control_points``)."""
        z, period = self.z, self.period
        if isinstance(self.knots, Bezier):
            degree = self.knots.degree
            interior = [z[8 + 6 * i : 8 + 6 * (i + 1)] for i in range(self.knots.interior)]
            ends = (start_angles, start_rates, end_angles, end_rates)
            return ca.horzcat(*control_points(degree, period, *ends, interior)).T
        if self.knots != 1:
            knots = [z[8 + 12 * k : 8 + 12 * (k + 1)] for k in range(self.knots)]
            values = [start_angles, *(knot[:6] for knot in knots), end_angles]
            slopes = [period * start_rates, *(period * knot[6:] for knot in knots)]
            slopes.append(period * end_rates)
            h = 1.0 / (self.knots + 1)
            pieces = [
                ca.horzcat(*hermite(h, values[j], slopes[j], values[j + 1], slopes[j + 1])).T
                for j in range(self.knots + 1)
            ]
            return ca.vertcat(*pieces)
        acc0 = z[index("start_accel_qp2") : index("start_accel_q5") + 1]
        acc1 = z[index("end_accel_qp2") : index("end_accel_q5") + 1]
        a0, a1, a2 = start_angles, period * start_rates, 0.5 * period**2 * acc0
        b0, b1, b2 = end_angles, -period * end_rates, 0.5 * period**2 * acc1
        r1 = b0 + b1 / 2 + b2 / 4 - a0 - a1 / 2 - a2 / 4
        r2 = -(b1 + b2) - a1 - a2
        a3 = 4 * r1 + 2 * r2 / 3
        b3 = 2 * r2 / 3 - 4 * r1
        return ca.horzcat(a0, a1, a2, a3, b0, b1, b2, b3).T

    def _samples(self, c: Constants, coefficients):
        """3. The head (coefficients, T (, radii), hip height), the constant ``basis`` that
        maps it to each sample's inputs, the ``sample`` function, and the samples'
        ``QUANTITIES`` as a symbol (``quantities``) and as expressions (``flat``)."""
        radii = [self.radii] if self.design else []
        # The landing's quantities join the head only where a constraint asks for them (the
        # paper's problem keeps its graph).
        walkable = self.safety.walkable
        events = [("touchdown", self.touchdown, "landing" in walkable)]
        events.append(("impulse", self.impulse, "impact_friction" in walkable))
        self.period_index = coefficients.numel()
        self.hip_height_index = self.period_index + 1 + sum(r.numel() for r in radii)
        parts, self.head_slices, at = [], {}, self.hip_height_index + 1
        for name, value, asked in events:
            if asked:
                parts.append(value)
                self.head_slices[name] = slice(at, at + value.shape[0])
                at += value.shape[0]
        self.head = ca.vertcat(ca.vec(coefficients), self.period, *radii, self.hip_height, *parts)
        self.head_symbol = ca.SX.sym("head", self.head.shape[0])
        self._constants = c
        self.sample = sample_function(c, self.model.robot, self.safety, self.radii, self.motors)
        self.basis = _sample_basis(
            self.samples_per_half, self.knots, self.head.shape[0], len(radii) and radii[0].numel()
        )
        n = self.basis.shape[0] // self.sample.size1_in(0)
        count = N_MOTOR_QUANTITIES if self.motors else N_QUANTITIES
        self.quantities = ca.SX.sym("quantities", count, n)
        inputs = ca.reshape(ca.DM(self.basis) @ self.head, self.sample.size1_in(0), n)
        self._flat_quantities = self.sample.map(n)(inputs)

    def flat(self, expression):
        """``expression`` of the symbols ``quantities`` and ``head_symbol`` as an expression of
        the variables (z, speed (, radii))."""
        return ca.substitute(
            expression,
            ca.vertcat(ca.vec(self.quantities), self.head_symbol),
            ca.vertcat(ca.vec(self._flat_quantities), self.head),
        )

    def rows(self, name: str):
        """The rows of the quantity ``name`` (``QUANTITIES``) of ``quantities`` (symbols)."""
        return self.quantities[_ROWS[name], :]

    def _criteria_and_constraints(self) -> dict:
        """4. On the symbols: the criteria (Simpson's rule per piece, eqs. (30)-(31) without
        penalty) and the constraints Ψ_i − δ_i (``psi``: Ψ_i with the safety margins,
        without δ_i), scaled by ``CONSTRAINT_SCALES``, at the checked samples in
        constraint-major order; the samples' quantities by name."""
        samples, knots = self.samples_per_half, self.knots
        period = self.head_symbol[self.period_index]
        self.weights = ca.DM(simpson_weights(samples, knots)).T  # (1, N)
        power = self.rows("power")
        psi = self.rows("psi")
        if self.safety.clearance:
            profile = clearance_profile(
                samples, self.safety.clearance, knots, self.safety.clearance_window
            )
            required = ca.DM(profile).T
            psi = ca.vertcat(psi[:5, :], psi[5:, :] - ca.repmat(required, 2, 1))
        n = psi.shape[1]
        margins = ca.DM(margin_profile(samples, knots)).T
        scaled = (psi - margins) / ca.repmat(ca.DM(CONSTRAINT_SCALES), 1, n)
        rows, cols = np.nonzero(checked_mask(samples, knots).T)  # constraint-major order
        self.constraint_names = [CONSTRAINTS[i] for i in rows]
        named = {name: self.rows(name) for name in ("q", "qd", "torques", "wrench")}
        constraints = [scaled[i, j] for i, j in zip(rows, cols, strict=True)]
        motors = {}
        if self.motors:
            electrical = self.rows("electrical")
            motors = {
                "electrical_power": electrical,
                "voltage": self.rows("voltage"),
                # E / S = T Σ_j w_j Σ_i max(P_ij, 0) / (V T) [J/m]
                "electrical": (self.weights @ ca.sum1(ca.fmax(electrical, 0.0)).T) / self.speed,
            }
        if self.safety.actuator_limits:
            constraints += self._actuator_limits()
        constraints += self._walkable()
        if self.safety.clearance:
            constraints += self._clearance_between_samples()
        if isinstance(knots, Bezier):
            constraints += self._knees_between_samples()
        return {
            **named,
            **motors,
            "power": power,
            "psi": psi,
            "sthenic": (self.weights @ self.rows("squared").T) / self.speed,
            "energy": period * (self.weights @ ca.sum1(ca.fabs(power)).T),
            "constraints": ca.vertcat(*constraints),
        }

    def _actuator_limits(self) -> list:
        """The actuator limits (``biped.model.actuators.limit_margins``: shares of each
        joint's peak torque, top speed and supply voltage, >= 0 when met) less their margin
        ``ACTUATOR_MARGIN`` at every sample,
        sample-major, then limit, then joint; their names join ``constraint_names``."""
        constants = {k: ca.DM(v) for k, v in self.model.robot.drive_actuators.constants().items()}
        torques, voltage = self.rows("torques"), self.rows("voltage")
        rates = ca.DM(JOINT_MATRIX) @ self.rows("qd")
        limits = []
        for j in range(torques.shape[1]):  # sample j, its six joints
            margins = limit_margins(constants, torques[:, j], rates[:, j], voltage[:, j])
            limits.append(ca.vertcat(*margins) - ACTUATOR_MARGIN)
        names = [f"{limit} {side}" for limit in LIMITS for side in "-+"]
        per_sample = len(names) * 6
        self.constraint_names += [
            f"actuator {names[i // 6]}" for _ in limits for i in range(per_sample)
        ]
        return [ca.vertcat(*limits)]

    def _walkable(self) -> list:
        """The walkable constraints ``safety`` asks (``biped.model.walkable``, the formulas of
        the numeric check with the solver's margins), each divided by its scale: the
        landing's and the impact's once, the others at every sample, sample-major; their
        names join ``constraint_names``."""
        safety, rows = self.safety, []
        head = self.head_symbol
        per_sample = {}
        if "landing" in safety.walkable:
            touchdown = head[self.head_slices["touchdown"]]
            bound = walkable.landing_bound(safety, self.speed)
            margins = walkable.landing_margins(touchdown, bound, True)
            rows.append(("landing", margins))
        if "impact_friction" in safety.walkable:
            impulse = head[self.head_slices["impulse"]]
            margins = walkable.impact_friction_margins(impulse, safety.friction, True)
            rows.append(("impact_friction", margins))
            wrench = self.rows("wrench")
            per_sample["friction"] = walkable.friction_margins(
                wrench[0, :], wrench[1, :], safety.friction, True
            )
        if "joint_stops" in safety.walkable:
            theta = self._joint_angles()  # linear in the head: sparse rows, no curvature
            per_sample["joint_stops"] = walkable.joint_stop_margins(
                theta, safety.joint_margin, True
            )
        if "progress" in safety.walkable:
            hip_rate = self.rows("qd")[XH, :]
            per_sample["progress"] = walkable.progress_margins(
                hip_rate, safety.hip_progress, self.speed, True
            )
        constraints = []
        for name, margins in rows:
            constraints += [m / walkable.SCALES[name] for m in margins]
            self.constraint_names += [name] * len(margins)
        for name, margins in per_sample.items():
            stacked = ca.vertcat(*margins) / walkable.SCALES[name]  # (k, N)
            constraints.append(ca.vec(stacked))  # sample-major
            self.constraint_names += [name] * stacked.numel()
        return constraints

    def _joint_angles(self) -> list:
        """The joints' angles θ (eq. 32) at the solver's samples, each a row (1, N), from the
        head's spline coefficients (the stance foot's angle 0): the same numbers as from the
        samples' q, linear in the head."""
        _, (values, _, _) = spline_basis(self.samples_per_half, self.knots)
        coefficients = ca.reshape(self.head_symbol[: self.period_index], self.period_index // 6, 6)
        angles = ca.DM(values) @ coefficients  # (N, 6): qp2, q1, ..., q5
        q7 = ca.horzcat(ca.SX.zeros(angles.shape[0], 1), angles)  # qp1 = 0
        theta = (q7 @ ca.DM(JOINT_MATRIX[:, :7]).T).T  # (6, N)
        return [theta[i, :] for i in range(6)]

    def _between_samples(self) -> tuple:
        """The check grid's normalised times strictly inside the step and not the solver's
        samples (n,), and the free angles there (n, 6) from the head's coefficients."""
        knots = self.knots
        t_check, (values, _, _) = spline_basis(CHECK_SAMPLES[knots], knots)
        t_solver = np.concatenate(piece_grid(self.samples_per_half, knots))
        inside = (t_check > 0.0) & (t_check < 1.0)  # both feet on the ground at 0 and T
        taken = [
            j for j, t in enumerate(t_check) if inside[j] and np.min(np.abs(t_solver - t)) > 1e-12
        ]
        coefficients = ca.reshape(self.head_symbol[: self.period_index], self.period_index // 6, 6)
        return t_check[taken], ca.DM(values[taken, :]) @ coefficients

    def _clearance_between_samples(self) -> list:
        """The swing heel's and toe's clearance (``clearance_envelope``: 0 within the lift-off
        and touchdown windows, the sole above the floor) at every sample of the check grid
        between the solver's, less ``BETWEEN_SAMPLES_MARGIN``: on the solver's samples alone
        the sole may dip below it between them (δ of Ψ6, Ψ7 is 1 mm there, ramping from 0 at
        the step's ends: a fast gait's toe went 0.025-0.06 mm into the floor near landing).
        Functions of the head's spline coefficients (the sole's height at a time is a
        function of the angles alone)."""
        safety = self.safety
        t_between, angles = self._between_samples()
        required = clearance_envelope(t_between, safety.clearance, safety.clearance_window)
        heights = _sole_heights(self._constants, angles)  # (n, 2): heel, toe
        if self.design:  # the radii as the head holds them
            at = self.period_index + 1
            size = self.radii.numel()
            heights = ca.substitute(heights, self.radii, self.head_symbol[at : at + size])
        floor = required + BETWEEN_SAMPLES_MARGIN
        scale = CONSTRAINT_SCALES[CONSTRAINTS.index("swing_heel")]
        margins = (heights - ca.repmat(ca.DM(floor), 1, 2)) / scale
        taken = len(t_between)
        self.constraint_names += ["swing_heel"] * taken + ["swing_toe"] * taken
        return [ca.vec(margins)]

    def _knees_between_samples(self) -> list:
        """The knees' Ψ4 = q2 − q1 − (the least stance bend) and Ψ5 = q3 − q4 at every sample
        of the check grid between the solver's, less ``KNEE_BETWEEN_SAMPLES_MARGIN``: a
        Bézier family's. Its one curve of degree n over the step has 51 solver samples (a
        spline's cubic 6 to 26 per piece), and near lift-off its swing knee dipped 1.1e-3 rad
        between two of them (the optimum at 0.2 m/s with 2 cm of clearance, degree 11: Ψ5 =
        −1.05e-5 rad at t = 0.01 T, 1e-3 at the samples at 0 and 0.02 T). Linear in the
        head's control points: 2 rows per sample, no dynamics."""
        _, angles = self._between_samples()
        q1, q2, q3, q4 = (angles[:, FREE_ANGLES.index(name)] for name in ("q1", "q2", "q3", "q4"))
        stance = q2 - q1 - self.safety.knee_bend - KNEE_BETWEEN_SAMPLES_MARGIN
        swing = q3 - q4 - KNEE_BETWEEN_SAMPLES_MARGIN
        constraints = []
        for name, margins in zip(KNEES, (stance, swing), strict=True):
            constraints.append(margins / CONSTRAINT_SCALES[CONSTRAINTS.index(name)])
            self.constraint_names += [name] * angles.shape[0]
        return constraints

    @property
    def inputs(self) -> list:
        """The graph's symbols: [z, speed], then radii with ``design``."""
        return [self.z, self.speed] + ([self.radii] if self.design else [])

    def function(self) -> ca.Function:
        """A CasADi function (z, speed[, radii]) -> every quantity of the step, for checks."""
        names = "parameters torques wrench q qd psi sthenic energy constraints hip_height impulse"
        names = tuple(names.split())
        return ca.Function(
            "step",
            self.inputs,
            [getattr(self, name) for name in names],
            ["z", "speed", "radii"][: len(self.inputs)],
            list(names),
        )


def _sample_basis(samples_per_half: int, knots: int, head_size: int, knee: int) -> np.ndarray:
    """The constant matrix (N · inputs, head) that maps the head to the stacked inputs of
    the samples (``sample_function``): the spline bases (``biped.model.gait.spline_basis``)
    on each angle's coefficients, then T and the ``knee`` parameters of a design (the radii,
    2, or a profile's, 4; 0 without) passed on."""
    _, bases = spline_basis(samples_per_half, knots)
    n, rows = bases[0].shape  # rows: the coefficients of one angle, 4 per piece
    width = SAMPLE_MOTION + 1 + knee
    matrix = np.zeros((n, width, head_size))
    for k, basis in enumerate(bases):  # values, rates, accels
        for angle in range(6):
            matrix[:, 6 * k + angle, rows * angle : rows * (angle + 1)] = basis
    for extra in range(width - SAMPLE_MOTION):  # T (, r1, r2)
        matrix[:, SAMPLE_MOTION + extra, 6 * rows + extra] = 1.0
    return matrix.reshape(n * width, head_size)
