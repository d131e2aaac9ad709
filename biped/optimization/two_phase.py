"""The gait of two phases, single then double support, as one NLP (``biped.model.two_phase``).

What is built: the sthenic criterion over both phases; the paper's single support with the
impact landing that holds both feet, or the zero-speed landing; the double support phase of
``biped.model.double_support`` with the front foot's wrench chosen by the criterion within
both feet's constraints; IPOPT on a CasADi graph with exact derivatives, started from the
single-support optimum of the same problem. What is not: the energy and electrical criteria,
richer spline families, the walkable constraints and the actuator limits, a knee design
(``TwoPhaseProblem`` refuses them by name).

Variables z (``variable_names``): the single-support problem's 21 (``problem.VARIABLES``: the
knee bends and the trunk at lift-off, the rates before the landing, the accelerations, T),
then

    lift_rate_x_hip, _z_hip, _trunk   the hip's and the trunk's rates at lift-off [m/s, rad/s]
    landing_rear_bend, _front_bend    the knee bends at landing [rad] (hip by eq. * of
                                      ``biped.optimization.problem``, the ankles at 0 and S)
    landing_trunk                     [rad]
    double_support                    T_ds [s]
    landing_rate_x_hip, _z_hip, _trunk (zero-speed landing only) the chain's rates at landing
                                      [m/s, rad/s]; the rates before it (end_rate_*) held at 0
    rear_bend_j, front_bend_j         the knee bends at the double support's interior samples
                                      j = 1 .. n − 1 [rad], each tied to the hip's cubic by an
                                      equality: reach²(bend) = |hip − ankle|²
    rear_bend_j_k, front_bend_j_k     the same at the fine grid's points between samples j and
                                      j + 1, k = 1 .. f − 1 (f = ``per_interval``, 10)
    front_fx_j, _fz_j, _cy_j          the front foot's wrench at sample j = 0 .. n [N, N, N·m]

(the legs' angles then follow by forward geometry, no inverse model in the graph). The step
length is S = V (T + T_ds) and the double support's share T_ds / (T + T_ds) is held in the
problem's range by two linear constraints.

Criterion: C_Γ = (∫ ΓᵀΓ dt over both phases) / S [N²·m·s], Simpson's rule on each phase (the
double support's on its n + 1 samples).
Constraints: the single support's as the single-support problem's (``StepGraph``), and both
knees' bends also on its check grid between the solver's samples (``_knees_between``); in
double support at each point of the fine grid (f points per interval of the n samples, the
gait file's 101, the front wrench linear in time between its samples: the file's rule) each
foot's normal force, friction cone (μ = ``FOOT_FRICTION``) and ZMP in its sole with the
single support's margins, both knees' bends >= δ (held at the n + 1 samples alone, the
rolling knee's impact optimum at 0.3 m/s put the rear foot's ZMP 0.39 m ahead of its ankle
between them, 0.22 m beyond its toe); at the landing's impact
both feet pushed (I_z >= δ) and within the friction cone |I_x| <= μ I_z (μ = ``FOOT_FRICTION``
at the single-support problem's 1 % margin, ``biped.model.two_phase.landing_margins``; the
zero-speed landing has no impulse); the hip at landing at least ``MIN_HIP_HEIGHT`` above the
ankles.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, replace

import casadi as ca
import numpy as np

from biped.errors import BipedError, UnreachableError
from biped.model import double_support, walkable
from biped.model import two_phase as two_phase_model
from biped.model.criteria import (
    CONSTRAINT_SCALES,
    MARGINS,
    Safety,
    StepEvaluation,
    evaluate_step,
    simpson_weights,
)
from biped.model.double_support import B5_INVERSE, B5_SWING, JOINTS5
from biped.model.dynamics import Biped
from biped.model.gait import hermite, piece_grid, spline_basis
from biped.model.kinematics import LEG_SWAP, NQ, Q1, Q2, Q3, Q4, Q5, QP1, QP2, XH, ZH
from biped.model.robot import FOOT_FRICTION
from biped.model.two_phase import check_landing
from biped.optimization.optimize import perturbed
from biped.optimization.problem import (
    CHECK_SAMPLES_PER_HALF,
    MIN_HIP_HEIGHT,
    RATE_BOUND,
    SOLVER_SAMPLES_PER_HALF,
    VARIABLES,
    GaitProblem,
    bounds,
    index,
    scales,
)
from biped.optimization.solver import IPOPT_OPTIONS
from biped.optimization.symbolic import (
    Constants,
    StepGraph,
    leg_angles,
    mass_matrix,
    reach_squared,
    stance_state,
)
from biped.runtime.interrupts import kept_interrupts

N_SINGLE = len(VARIABLES)  # 21: the single-support problem's variables come first
# Samples of the double support phase (even: Simpson's rule), each end included.
DOUBLE_SUPPORT_SAMPLES = 10
# Samples of the feet's constraints per interval of the solver's samples: the gait file's fine
# grid, the front wrench linear in time between its variables (the file's rule), so that the
# solver holds the constraints where the file judges them.
FINE = double_support.FINE_PER_INTERVAL
EXTRAS = (
    "lift_rate_x_hip",
    "lift_rate_z_hip",
    "lift_rate_trunk",
    "landing_rear_bend",
    "landing_front_bend",
    "landing_trunk",
    "double_support",
)
# The closed chain's rates at a zero-speed landing [m/s, m/s, rad/s].
LANDING_RATES = ("landing_rate_x_hip", "landing_rate_z_hip", "landing_rate_trunk")
# The front foot's wrench at each double support sample, the redundancy's three numbers
# (``biped.model.double_support.split_with_swing_wrench``) [N, N, N·m], their scales and bounds.
WRENCH = ("fx", "fz", "cy")
_WRENCH_SCALES = (100.0, 100.0, 10.0)
_WRENCH_BOUNDS = ((-5000.0, 5000.0), (0.0, 5000.0), (-500.0, 500.0))
# Scales of the extras in the solver's space and their bounds [m/s, rad/s, rad, s].
_EXTRA_SCALES = {"rate": 0.3, "bend": 0.03, "landing_trunk": 0.03, "double_support": 0.05}
_BEND_BOUNDS = (0.0, 1.5)
_TRUNK_BOUNDS = (-0.6, 0.6)
_DWELL_BOUNDS = (0.0, 3.0)
# Scales of the double support's constraints: the landing's impulse [N·s], the closure [m²].
IMPULSE_SCALE = 10.0
IMPULSE_MARGIN = 1e-3  # [N·s] δ of each foot's normal impulse at an impact landing
MOMENT_SCALE = 100.0  # [N·m] the ZMP's constraints times Fz
# [N²·m·s] The criterion is divided by this in the solver: the two-phase optima lie near
# 1000, where IPOPT's tolerance on the dual infeasibility, 1e-9, is below the rounding of
# the derivatives (it ended at its acceptable level without the division).
OBJECTIVE_SCALE = 1000.0
# [rad] Least knee bend at lift-off of the start (``start_from_single``): the single-support
# optimum's legs are almost straight there (0.02 rad), where the double support's hip has no
# room between the two legs' reaches.
START_BEND = 0.2
CLOSURE_SCALE = 0.01
# [m/s] The swing foot's speed straight down at an impact landing of the start
# (``gentle_landing``).
LANDING_DESCENT = 0.05
# The free coordinates of the closed chain and the six others (``biped.model.double_support``).
FREE = [XH, ZH, Q5]
BOUND = [QP1, QP2, Q1, Q2, Q3, Q4]


def variable_names(
    samples: int = DOUBLE_SUPPORT_SAMPLES, landing: str = "impact", per_interval: int = FINE
) -> tuple:
    """The two-phase NLP's variables, in order (module docstring); with the zero-speed
    landing the closed chain's rates at landing follow ``EXTRAS`` (the rates before the
    landing, ``end_rate_*``, are then held at 0 and unused); the knee bends between the
    solver's samples (``rear_bend_j_k``, k = 1 .. ``per_interval`` − 1) follow the bends at
    them."""
    rates = LANDING_RATES if check_landing(landing) == "zero-speed" else ()
    interior = tuple(f"{leg}_bend_{j}" for j in range(1, samples) for leg in ("rear", "front"))
    between = tuple(
        f"{leg}_bend_{j}_{k}"
        for j in range(samples)
        for k in range(1, per_interval)
        for leg in ("rear", "front")
    )
    wrenches = tuple(f"front_{part}_{j}" for j in range(samples + 1) for part in WRENCH)
    return VARIABLES + EXTRAS + rates + interior + between + wrenches


def parse_share(text: str) -> tuple[float, float]:
    """(least, largest) share of the step in double support from ``"LOW:HIGH"`` or one number
    (both ends), each in [0, 0.5) with LOW <= HIGH and HIGH > 0."""
    parts = text.split(":")
    try:
        values = [float(part) for part in parts]
    except ValueError:
        values = []
    if len(values) == 1:
        values = values * 2
    if len(values) != 2 or not all(0.0 <= v < 0.5 for v in values) or values[0] > values[1]:
        raise BipedError(
            f"double support share = {text!r}: allowed LOW:HIGH with 0 <= LOW <= HIGH < 0.5 "
            "(a share of the step), or one such number"
        )
    if values[1] == 0.0:
        raise BipedError(f"double support share = {text!r}: allowed a largest share above 0")
    return values[0], values[1]


@dataclass(frozen=True)
class TwoPhaseProblem:
    """The best two-phase gait of ``single``'s robot, knee and speed (module docstring).

    Attributes:
        single: the single-support problem (its criterion, safety, samples).
        share: (least, largest) T_ds / (T + T_ds) [-].
        samples: samples of the double support phase (even).
        landing: ``"impact"`` (both feet stopped by it) or ``"zero-speed"`` (the swing foot
            arrives at rest, no impact; ``biped.model.two_phase``).
        per_interval: samples of the feet's constraints per interval of ``samples``: the
            gait file's fine grid (``FINE``) by default; 1 holds them at the samples only,
            where the file's linear rule lets a foot's ZMP leave its sole in between.
    """

    single: GaitProblem
    share: tuple
    samples: int = DOUBLE_SUPPORT_SAMPLES
    landing: str = "impact"
    per_interval: int = FINE

    @property
    def names(self) -> tuple:
        """The NLP's variables (``variable_names``)."""
        return variable_names(self.samples, self.landing, self.per_interval)

    def __post_init__(self):
        check_landing(self.landing)
        p = self.single
        refused = []
        if p.criterion != "sthenic":
            refused.append(f"criterion = {p.criterion!r} (allowed 'sthenic')")
        if p.knots != 1:
            refused.append(f"knots = {p.knots} (allowed 1)")
        if p.safety.walkable or p.safety.actuator_limits:
            refused.append("walkable constraints or actuator limits (allowed none)")
        if p.model.robot.profiled:
            refused.append("a profiled knee (allowed circles)")
        if p.samples_per_half != SOLVER_SAMPLES_PER_HALF:
            refused.append(f"samples_per_half = {p.samples_per_half}")
        if refused:
            raise BipedError("double support is not built for " + "; ".join(refused))
        low, high = self.share
        if not (0.0 <= low <= high < 0.5 and high > 0.0):
            raise BipedError(
                f"double support share = {self.share!r}: allowed 0 <= low <= high < 0.5"
            )
        if self.samples < 2 or self.samples % 2:
            raise BipedError(f"samples = {self.samples!r}: allowed an even number >= 2")
        if not (isinstance(self.per_interval, int) and self.per_interval >= 1):
            raise BipedError(f"per_interval = {self.per_interval!r}: allowed an integer >= 1")


class TwoPhaseGraph(StepGraph):
    """The graph of ``StepGraph`` for the single support phase, its start and its landing
    replaced by the two-phase step's, and the double support phase's samples added.

    Attributes beyond ``StepGraph``'s (SX expressions of z, speed): sthenic (both phases),
    ds_inequalities (>= 0 when met), ds_equalities (= 0), dwell T_ds, ds_torques (6, n + 1),
    ds_stance_wrench, ds_swing_wrench (3, n + 1), ds_q (9, n + 1), landing_impulse (6,).
    """

    def __init__(
        self,
        model: Biped,
        safety: Safety,
        samples: int,
        landing: str = "impact",
        per_interval: int = FINE,
    ):
        self.model, self.samples_per_half = model, SOLVER_SAMPLES_PER_HALF
        self.safety, self.design, self.knots = safety, False, 1
        self.motors, self.profile, self.radii = False, False, None
        self.ds_samples, self.landing_kind, self.per_interval = samples, landing, per_interval
        self.names = variable_names(samples, landing, per_interval)
        c = Constants(model)
        self._contacts = _contact_functions(c)
        self.z = ca.SX.sym("z", len(self.names))
        self.speed = ca.SX.sym("speed")
        self.period = self.z[index("period")]
        self.dwell = self._extra("double_support")
        self.length = self.speed * (self.period + self.dwell)
        start_angles = self._start_posture(c)
        end_angles, end_rates, start_rates = self._landing(c, start_angles)
        coefficients = self._splines(start_angles, start_rates, end_angles, end_rates)
        self.knees_between = _knees_between(coefficients, safety)
        self._samples(c, coefficients)
        # Structural zeros (the lift-off's foot rates) would not substitute for the symbols.
        self.head = ca.densify(self.head)
        self._flat_quantities = ca.densify(self._flat_quantities)
        self.on_symbols = self._criteria_and_constraints()
        for name, value in self.on_symbols.items():
            setattr(self, name, self.flat(value))
        single = self.flat(self.weights @ self.rows("squared").T) * self.period
        self._double_support(c)
        self.sthenic = (single + self.ds_squared) / self.length

    def _extra(self, name: str):
        """The variable ``name`` of ``EXTRAS``."""
        return self.z[N_SINGLE + EXTRAS.index(name)]

    def _landing(self, c, start_angles):
        """The landing posture from its bends, the rates before it, the impact holding both
        feet, and the start rates of the single support (the chain's at lift-off)."""
        z, length = self.z, self.length
        bend_r, bend_f = self._extra("landing_rear_bend"), self._extra("landing_front_bend")
        x, lift, self.landing_height = _hip_between(c, bend_r, bend_f, length)
        q1, q2 = leg_angles(c, bend_r, ca.vertcat(x, lift))
        q4, q3 = leg_angles(c, bend_f, ca.vertcat(x - length, lift))
        end_angles = ca.vertcat(0.0, q1, q2, q3, q4, self._extra("landing_trunk"))
        if self.landing_kind == "zero-speed":  # the chain's rates: both feet at rest
            q_end, *_ = stance_state(c, end_angles, ca.SX.zeros(6), ca.SX.zeros(6))
            rates = ca.vertcat(*[z[self.names.index(name)] for name in LANDING_RATES])
            qd_end = _chain_rates(self._contacts["rows"](q_end), rates)
            end_rates = qd_end[1:7]
            self.landing_impulse = ca.SX.zeros(6)
            self.impulse, self.touchdown = ca.SX.zeros(3), ca.SX.zeros(2)
            self.landing = (q_end, qd_end)
        else:
            end_rates = ca.vertcat(0.0, z[index("end_rate_q1") : index("end_rate_q5") + 1])
            q_end, qd_end, *_ = stance_state(c, end_angles, end_rates, ca.SX.zeros(6))
            rows = self._contacts["rows"](q_end)
            d_inv_rt = ca.solve(mass_matrix(c, q_end), rows.T)
            impulse = -ca.solve(rows @ d_inv_rt, rows @ qd_end)
            self.landing_impulse = impulse
            self.impulse = impulse[3:]  # the landing foot's (``StepGraph``'s name)
            self.touchdown = (rows @ qd_end)[3:5]
            self.landing = (q_end, qd_end + d_inv_rt @ impulse)
        # Lift-off, in the single support's labels: both feet at rest, ṡ given.
        q_start, *_ = stance_state(c, start_angles, ca.SX.zeros(6), ca.SX.zeros(6))
        lift_rates = ca.vertcat(
            *[self._extra(f"lift_rate_{a}") for a in ("x_hip", "z_hip", "trunk")]
        )
        qd_start = _chain_rates(self._contacts["rows"](q_start), lift_rates)
        start_rates = qd_start[1:7]
        # The same state in the double support's labels (legs swapped back, hip S ahead).
        q_lift = ca.vertcat(*[q_start[LEG_SWAP[i]] for i in range(NQ)])
        q_lift[XH] = q_lift[XH] + length
        qd_lift = ca.vertcat(*[qd_start[LEG_SWAP[i]] for i in range(NQ)])
        self.lift = (q_lift, qd_lift)
        return end_angles, end_rates, start_rates

    def _double_support(self, c):
        """The phase's samples: the hip's and trunk's cubics, the legs from each sample's
        bends, the chain's rates and accelerations, the load split; its criterion part at
        the solver's samples and both feet's constraints on the fine grid (``per_interval``
        points per interval, the front wrench linear between its variables)."""
        n, f, dwell = self.ds_samples, self.per_interval, self.dwell
        (q0, qd0), (q1, qd1) = self.landing, self.lift
        cubic = hermite(dwell, q0[FREE], qd0[FREE], q1[FREE], qd1[FREE])
        bends = self._fine_bends()
        wrenches = [
            ca.vertcat(*[self.z[self.names.index(f"front_{part}_{j}")] for part in WRENCH])
            for j in range(n + 1)
        ]
        weights = _simpson(n)
        squared, inequalities, equalities = 0, [], []
        # (foot, point) where a foot hands its load over (``double_support.HANDOVERS``):
        # with the zero-speed landing, the front wrench's first sample fixed at 0 and the
        # rear wrench at lift-off held at 0; the impact landing jumps the loads as it jumps
        # the velocities, at both ends
        smooth = self.landing_kind == "zero-speed"
        handovers = {("stance", n * f), ("swing", 0)} if smooth else set()
        self.ds_torques, self.ds_stance_wrench, self.ds_swing_wrench, self.ds_q = [], [], [], []
        for i in range(n * f + 1):
            j, k = divmod(i, f)
            swing = wrenches[j] if k == 0 else wrenches[j] + (wrenches[j + 1] - wrenches[j]) * k / f
            point = self._chain_point(c, cubic, dwell * i / (n * f), bends[i], swing, smooth)
            if 0 < i < n * f:
                equalities += point["closure"]
            inequalities += point["knees"]
            for foot, margins in zip(double_support.FEET, point["margins"], strict=True):
                if (foot, i) in handovers:  # the foot carries nothing there: held below
                    continue
                inequalities += margins
            if i == n * f and smooth:  # the rear foot hands its load over at lift-off
                equalities += [point["stance"][k] / _WRENCH_SCALES[k] for k in range(3)]
            if k == 0:
                squared = squared + weights[j] * ca.sumsqr(point["torques"])
                self.ds_torques.append(point["torques"])
                self.ds_stance_wrench.append(point["stance"])
                self.ds_swing_wrench.append(swing)
                self.ds_q.append(point["q"])
        self.ds_squared = dwell * squared
        if self.landing_kind == "impact":  # both feet pushed, within the friction cone
            inequalities += _landing_rows(self.landing_impulse)
        inequalities.append(self.landing_height)
        self.ds_inequalities = ca.vertcat(*inequalities)
        self.ds_equalities = ca.vertcat(*equalities)
        for name in ("ds_torques", "ds_stance_wrench", "ds_swing_wrench", "ds_q"):
            setattr(self, name, ca.horzcat(*getattr(self, name)))

    def _fine_bends(self) -> list:
        """(rear, front) knee bends at each point of the fine grid: the landing's, the
        variables between, the lift-off's."""
        n, f, z, names = self.ds_samples, self.per_interval, self.z, self.names

        def pair(suffix):
            return tuple(z[names.index(f"{leg}_bend_{suffix}")] for leg in ("rear", "front"))

        bends = []
        for i in range(n * f + 1):
            j, k = divmod(i, f)
            if i == 0:
                bends.append((self._extra("landing_rear_bend"), self._extra("landing_front_bend")))
            elif i == n * f:  # lift-off: the single support's swing leg is the rear one
                bends.append((z[index("swing_knee_bend")], z[index("stance_knee_bend")]))
            else:
                bends.append(pair(f"{j}_{k}" if k else f"{j}"))
        return bends

    def _chain_point(self, c, cubic, t, bends, swing, relative=False) -> dict:
        """One point of the phase at time ``t`` [s]: the chain's q, q̇, q̈ from the cubics
        and the knee ``bends`` (rear, front), the split with the front wrench ``swing``; its
        closure equalities and both feet's and knees' constraints (scaled, >= 0)."""
        hp, length, robot = c.hp, self.length, self.model.robot
        s = sum(cubic[k] * t**k for k in range(4))
        sd = sum(k * cubic[k] * t ** (k - 1) for k in range(1, 4))
        sdd = 2 * cubic[2] + 6 * cubic[3] * t
        rear, front = bends
        hip_rear = ca.vertcat(s[0], s[1] - hp)
        hip_front = ca.vertcat(s[0] - length, s[1] - hp)
        closure = [
            (reach_squared(c, bend) - ca.sumsqr(hip)) / CLOSURE_SCALE
            for bend, hip in ((rear, hip_rear), (front, hip_front))
        ]
        a1, a2 = leg_angles(c, rear, hip_rear)
        a4, a3 = leg_angles(c, front, hip_front)
        q = ca.vertcat(0.0, 0.0, a1, a2, a3, a4, s[2], s[0], s[1])
        rows = self._contacts["rows"](q)
        qd = _chain_rates(rows, sd)
        qdd = _chain_rates(rows, sdd, self._contacts["bias"](q, qd))
        torques, stance = _split(_generalized_forces(c, q, qd, qdd), rows, swing)
        margins = []
        for wrench in (stance, swing):
            values = _foot_margins(robot, wrench, FOOT_FRICTION, self.safety.zmp_margin)
            scale = [CONSTRAINT_SCALES[0]] * 3 + [MOMENT_SCALE] * 2
            # ``relative``: the cone's margin a share of the load; near a handover, where the
            # load tends to 0, a floor in newtons met with the normal force's made the active
            # set degenerate (IPOPT ended at its acceptable level)
            cone = walkable.RELATIVE_MARGIN * FOOT_FRICTION * wrench[1] if relative else MARGINS[0]
            floor = [MARGINS[0], cone, cone] + [MARGINS[1] * wrench[1]] * 2
            margins.append([(m - lo) / k for m, lo, k in zip(values, floor, scale, strict=True)])
        knee = MARGINS[3]
        knees = [rear - knee - self.safety.knee_bend, front - knee]
        return {"q": q, "torques": torques, "stance": stance, "closure": closure,
                "margins": margins, "knees": knees}  # fmt: skip


def _knees_between(coefficients, safety: Safety):
    """Both knees' bends in single support (Ψ4 less ``safety.knee_bend``, Ψ5), less their
    margins δ, at every sample of the check grid between the solver's, scaled (>= 0): on the
    solver's samples alone a knee held at its stop may dip past it between them (the rolling
    knee's stance knee at 0.3 m/s, an impact landing: 3.6e-6 rad below 0, refused by the
    check). Linear in the spline's ``coefficients`` (its angles qp2, q1 .. q5)."""
    t_check, (values, _, _) = spline_basis(CHECK_SAMPLES_PER_HALF, 1)
    t_solver = np.concatenate(piece_grid(SOLVER_SAMPLES_PER_HALF, 1))
    taken = [j for j, t in enumerate(t_check) if np.min(np.abs(t_solver - t)) > 1e-12]
    angles = ca.DM(values[taken, :]) @ coefficients  # (n, 6)
    stance = angles[:, Q2 - 1] - angles[:, Q1 - 1] - safety.knee_bend - MARGINS[3]
    swing = angles[:, Q3 - 1] - angles[:, Q4 - 1] - MARGINS[4]
    return ca.vertcat(stance / CONSTRAINT_SCALES[3], swing / CONSTRAINT_SCALES[4])


def _landing_rows(impulse) -> list:
    """The landing's constraints in the solver (``two_phase_model.landing_margins`` with the
    solver's margins: I_z − ``IMPULSE_MARGIN``, the cone at 0.99 μ as the single-support
    problem's impact friction), each foot's, scaled."""
    rows = []
    for normal, *cone in two_phase_model.landing_margins(impulse, FOOT_FRICTION, solver=True):
        rows.append((normal - IMPULSE_MARGIN) / IMPULSE_SCALE)
        rows += [margin / walkable.SCALES["impact_friction"] for margin in cone]
    return rows


def _hip_between(c, bend_rear, bend_front, length):
    """Eq. (*) with the rear ankle at 0 and the front one at S: the hip (x, z − h_p) and the
    hip-height constraint (>= 0)."""
    d_r2, d_f2 = reach_squared(c, bend_rear), reach_squared(c, bend_front)
    x = (d_r2 - d_f2 + length**2) / (2 * length)
    height2 = d_r2 - x**2
    lift = ca.sqrt(ca.fmax(height2, 1e-6))
    return x, lift, (height2 - MIN_HIP_HEIGHT**2) / MIN_HIP_HEIGHT**2


def _contact_functions(c) -> dict:
    """A (6, 9) of both feet (stance rows, then swing) and the bias H_c (6,) of
    A q̈ + H_c = 0, as CasADi functions of q (and q̇)."""
    q, qd = ca.SX.sym("q", NQ), ca.SX.sym("qd", NQ)
    phi = c.phi @ q[:7]
    s, co = ca.sin(phi), ca.cos(phi)
    places = []
    for foot, angle in (("stance", QP1), ("swing", QP2)):
        a, b = c.point(f"{foot}_ankle")
        x = q[XH] + ca.dot(s, a) + ca.dot(co, b)
        z = q[ZH] - ca.dot(co, a) + ca.dot(s, b)
        places += [x, z, q[angle]]
    places = ca.vertcat(*places)
    rows = ca.jacobian(places, q)
    bias = ca.jacobian(rows @ qd, q) @ qd
    return {
        "rows": ca.Function("contact_rows", [q], [rows]),
        "bias": ca.Function("contact_bias", [q, qd], [bias]),
    }


def _chain_rates(rows, free, bias=None):
    """q̇ (or q̈ with ``bias``) (9,) of the closed chain from ṡ (s̈) (3,): A x = −bias."""
    bound, given = rows[:, BOUND], rows[:, FREE]
    right = given @ free + (bias if bias is not None else 0)
    solved = -ca.solve(bound, right)
    x = ca.SX.zeros(NQ)
    for i, k in enumerate(BOUND):
        x[k] = solved[i]
    for i, k in enumerate(FREE):
        x[k] = free[i]
    return x


def _generalized_forces(c, q, qd, qdd):
    """D q̈ + H + Q (9,) (``Biped.generalized_forces``)."""
    phi, phid, phidd = c.phi @ q[:7], c.phi @ qd[:7], c.phi @ qdd[:7]
    s, co = ca.sin(phi), ca.cos(phi)
    rate2 = phid * phid
    ax = co * phidd - s * rate2
    az = s * phidd + co * rate2
    hip_x, hip_z = qdd[XH], qdd[ZH] + c.gravity
    tau_phi = co * (c.w @ ax + c.g * hip_x) + s * (c.w @ az + c.g * hip_z) + c.inertia * phidd
    return ca.vertcat(
        c.phi.T @ tau_phi, c.mass * hip_x + ca.dot(ax, c.g), c.mass * hip_z + ca.dot(az, c.g)
    )


def _split(tau, rows, swing):
    """Γ (6,) and the stance foot's wrench (3,) given the swing foot's (3,)
    (``biped.model.double_support.split_with_swing_wrench``, on expressions)."""
    g6 = swing[2] - tau[QP2]
    rear_xz = ca.vertcat(tau[XH], tau[ZH]) - swing[:2]
    contact = rows[0:2, JOINTS5].T @ rear_xz + rows[3:5, JOINTS5].T @ swing[:2]
    rest = ca.vertcat(*[tau[k] for k in JOINTS5]) - contact - ca.DM(B5_SWING) * g6
    torques = ca.vertcat(ca.DM(B5_INVERSE) @ rest, g6)
    return torques, ca.vertcat(rear_xz, tau[QP1] + torques[0])


def _foot_margins(robot, wrench, friction, zmp_margin):
    """``biped.model.double_support.foot_margins`` on expressions, the ZMP's two multiplied by
    Fz (> 0 by the first): C_y − h_p Fx + (l_p − margin) Fz and (L_p − l_p − margin) Fz −
    C_y + h_p Fx [N·m], smooth where Fz vanishes."""
    fx, fz, cy = wrench[0], wrench[1], wrench[2]
    moment = cy - robot.ankle_height * fx  # x_ZMP Fz
    return [
        fz,
        friction * fz - fx,
        friction * fz + fx,
        moment + (robot.foot_heel - zmp_margin) * fz,
        (robot.foot_length - robot.foot_heel - zmp_margin) * fz - moment,
    ]


def _simpson(n: int) -> np.ndarray:
    """Simpson's weights on n + 1 equally spaced samples of [0, 1] (n even)."""
    w = np.ones(n + 1)
    w[1:-1:2], w[2:-1:2] = 4.0, 2.0
    return w / (3.0 * n)


@dataclass(frozen=True)
class TwoPhaseOptimum:
    """IPOPT's answer for a ``TwoPhaseProblem``.

    Attributes:
        variables: z (``variable_names``) at the end.
        value: C_Γ over both phases [N²·m·s] on the solver's samples.
        status: IPOPT's return status (``Solve_Succeeded`` when converged).
        iterations: IPOPT's iterations.
        constraint_violation: largest violation of a constraint or bound at the end, in the
            solver's scaled units.
        seconds: the solve's time [s], the graph's building not counted.
        setup_seconds: the graph's and IPOPT's building [s].
        single_value: the single-support optimum's C_Γ it started from [N²·m·s].
    """

    variables: np.ndarray
    value: float
    status: str
    iterations: int
    constraint_violation: float
    seconds: float
    setup_seconds: float
    single_value: float
    # the first stage's answer (the feet's constraints at the solver's samples alone) of a
    # two-stage solve (``TwoPhaseSolver.solve``); None for one stage
    first_stage: TwoPhaseOptimum | None = None

    @property
    def converged(self) -> bool:
        return self.status == "Solve_Succeeded"

    @property
    def share(self) -> float:
        """T_ds / (T + T_ds) [-]."""
        period = self.variables[index("period")]
        dwell = self.variables[N_SINGLE + EXTRAS.index("double_support")]
        return float(dwell / (period + dwell))


class TwoPhaseSolver:
    """IPOPT on ``TwoPhaseGraph``: the objective, the single support's constraints and hip
    height, the double support's inequalities and the share's two bounds (>= 0), the
    closure's equalities (= 0); CasADi's exact derivatives of the whole graph.

    With the feet's constraints on a fine grid (``per_interval`` > 1) each start is solved
    in two stages (``solve``): the problem with them at the solver's samples only (``coarse``,
    a tenth of the points), then this one from its answer. At 0.3 m/s, a share of 0.1-0.2
    and an impact landing, IPOPT from the start itself ran out of its 1000 iterations
    (rolling knee: 233 s); from the coarse answer it converged in 107 iterations, 4.8 s.
    """

    def __init__(self, problem: TwoPhaseProblem):
        began = time.perf_counter()
        self.problem = problem
        coarse = problem.per_interval > 1
        self.coarse = TwoPhaseSolver(replace(problem, per_interval=1)) if coarse else None
        with kept_interrupts():
            graph = self.graph = TwoPhaseGraph(
                problem.single.model,
                problem.single.safety,
                problem.samples,
                problem.landing,
                problem.per_interval,
            )
            low, high = problem.share
            total = graph.period + graph.dwell
            share = ca.vertcat(graph.dwell - low * total, high * total - graph.dwell)
            inequalities = ca.vertcat(
                graph.constraints,
                graph.hip_height,
                graph.knees_between,
                graph.ds_inequalities,
                share,
            )
            self.n_inequalities = inequalities.shape[0]
            g = ca.vertcat(inequalities, graph.ds_equalities)
            self.scales = _scales(problem)
            y = ca.SX.sym("y", len(self.scales))
            objective = graph.sthenic / OBJECTIVE_SCALE
            scaled = ca.substitute([objective, g], [graph.z], [ca.DM(self.scales) * y])
            options = {f"ipopt.{k}": v for k, v in IPOPT_OPTIONS.items()}
            self.nlp = ca.nlpsol(
                "two_phase",
                "ipopt",
                {"x": y, "p": graph.speed, "f": scaled[0], "g": scaled[1]},
                {**options, "print_time": False},
            )
            self.evaluate = ca.Function(
                "two_phase_step",
                [graph.z, graph.speed],
                [graph.sthenic, g, graph.ds_torques, graph.ds_stance_wrench,
                 graph.ds_swing_wrench, graph.ds_q, graph.landing_impulse],
            )  # fmt: skip
        self.lower, self.upper = _bounds(problem)
        self.setup_seconds = time.perf_counter() - began

    def solve(self, start, single_value: float) -> TwoPhaseOptimum:
        """IPOPT from the variables ``start``: first the ``coarse`` problem's (when there is
        one), then this problem's from the coarse answer (its bends between the samples
        those of the closed chain, ``closed_bends``), even unconverged (IPOPT's last point
        is as near as the start); iterations and seconds are both stages', the first
        stage's answer kept (``first_stage``)."""
        if self.coarse is None:
            return self.solve_once(start, single_value)
        first = self.coarse.solve(_renamed(start, self.problem, self.coarse.problem), single_value)
        warm = _renamed(first.variables, self.coarse.problem, self.problem)
        try:
            warm = closed_bends(self.problem, warm)
        except BipedError as error:  # e.g. the answer's step out of the legs' reach
            return replace(first, variables=warm, status=f"{first.status}, then {error}")
        answer = self.solve_once(warm, single_value)
        return replace(
            answer,
            iterations=first.iterations + answer.iterations,
            seconds=first.seconds + answer.seconds,
            first_stage=first,
        )

    def solve_once(self, start, single_value: float) -> TwoPhaseOptimum:
        """IPOPT on this problem from the variables ``start``, clipped into the bounds."""
        began = time.perf_counter()
        z0 = np.clip(np.asarray(start, dtype=float), self.lower, self.upper)
        n_eq = self.graph.ds_equalities.shape[0]
        lbg = np.concatenate([np.zeros(self.n_inequalities), np.zeros(n_eq)])
        ubg = np.concatenate([np.full(self.n_inequalities, np.inf), np.zeros(n_eq)])
        with kept_interrupts():
            answer = self.nlp(
                x0=z0 / self.scales,
                p=self.problem.single.speed,
                lbx=self.lower / self.scales,
                ubx=self.upper / self.scales,
                lbg=lbg,
                ubg=ubg,
            )
        stats = self.nlp.stats()
        z = np.asarray(answer["x"]).ravel() * self.scales
        g = np.asarray(answer["g"]).ravel()
        violation = max(
            float(np.max(np.maximum(lbg - g, 0.0))),
            float(np.max(np.maximum(g - ubg, 0.0))),
            float(np.max(np.maximum(self.lower - z, 0.0) / self.scales)),
            float(np.max(np.maximum(z - self.upper, 0.0) / self.scales)),
        )
        return TwoPhaseOptimum(
            variables=z,
            value=float(answer["f"]) * OBJECTIVE_SCALE,
            status=str(stats["return_status"]),
            iterations=int(stats["iter_count"]),
            constraint_violation=violation,
            seconds=time.perf_counter() - began,
            setup_seconds=self.setup_seconds,
            single_value=single_value,
        )


def _scales(problem: TwoPhaseProblem) -> np.ndarray:
    samples, landing = problem.samples, problem.landing
    extra = [_EXTRA_SCALES["rate"]] * 3 + [_EXTRA_SCALES["bend"]] * 2
    extra += [_EXTRA_SCALES["landing_trunk"], _EXTRA_SCALES["double_support"]]
    if landing == "zero-speed":
        extra += [_EXTRA_SCALES["rate"]] * len(LANDING_RATES)
    interior = [_EXTRA_SCALES["bend"]] * (2 * (samples - 1) + _between(problem))
    wrenches = list(_WRENCH_SCALES) * (samples + 1)
    return np.concatenate([scales(1), extra, interior, wrenches])


def _renamed(variables, source: TwoPhaseProblem, target: TwoPhaseProblem) -> np.ndarray:
    """``source``'s ``variables`` as ``target``'s, by name: those ``source`` lacks (the
    bends between the samples) 0, those ``target`` lacks dropped."""
    named = dict(zip(source.names, np.asarray(variables, dtype=float), strict=True))
    return np.array([named.get(name, 0.0) for name in target.names])


def _between(problem: TwoPhaseProblem) -> int:
    """The count of knee bends between the solver's samples (``rear_bend_j_k``, front)."""
    return 2 * problem.samples * (problem.per_interval - 1)


def _bounds(problem: TwoPhaseProblem) -> tuple[np.ndarray, np.ndarray]:
    samples, landing = problem.samples, problem.landing
    lower, upper = bounds(1)
    extra = [(-RATE_BOUND, RATE_BOUND)] * 3 + [_BEND_BOUNDS] * 2 + [_TRUNK_BOUNDS, _DWELL_BOUNDS]
    if landing == "zero-speed":  # the rates before the landing are the chain's: unused
        unused = slice(index("end_rate_q1"), index("end_rate_q5") + 1)
        lower[unused] = upper[unused] = 0.0
        extra += [(-RATE_BOUND, RATE_BOUND)] * len(LANDING_RATES)
    extra += [_BEND_BOUNDS] * (2 * (samples - 1) + _between(problem))
    wrenches = [list(_WRENCH_BOUNDS) for _ in range(samples + 1)]
    if landing == "zero-speed":  # the front foot lands carrying nothing: its load grows
        wrenches[0] = [(0.0, 0.0)] * len(WRENCH)
    extra += [bound for sample in wrenches for bound in sample]
    low, high = np.array(extra).T
    return np.concatenate([lower, low]), np.concatenate([upper, high])


def start_from_single(problem: TwoPhaseProblem, variables) -> np.ndarray:
    """Two-phase variables from the single-support optimum's ``variables`` (21): its lift-off
    posture (knee bends, trunk), rates before the landing, accelerations and T; T_ds at the
    largest share; the hip moving at V through the double support (lift-off
    rates (V, 0, 0), the landing's hip V T_ds behind the lift-off's, its knee bends from the
    inverse geometric model) so that the phase's cubics start near a uniform motion; the
    interior bends of the closed chain (``closed_bends``)."""
    single = problem.single
    model, speed = single.model, single.speed
    z = np.array(variables, dtype=float)
    for name in ("stance_knee_bend", "swing_knee_bend"):  # room for the hip's cubic
        z[index(name)] = max(z[index(name)], START_BEND)
    period = z[index("period")]
    share = problem.share[1]
    dwell = share * period / (1.0 - share)
    length = speed * (period + dwell)
    stance_bend, swing_bend = z[index("stance_knee_bend")], z[index("swing_knee_bend")]
    # Lift-off in the double support's labels (rear ankle at 0, front at S): eq. (*).
    d_r2, d_f2 = model.reach_squared(swing_bend), model.reach_squared(stance_bend)
    x = (d_r2 - d_f2 + length**2) / (2 * length)
    back = x - speed * dwell
    longest = np.sqrt(model.reach_squared(START_BEND))  # both legs bent at landing
    height = min(np.sqrt(d_r2 - x**2), np.sqrt(longest**2 - max(back, length - back) ** 2))
    hip = np.array([back, height])
    rear = model.leg_angles(hip)
    front = model.leg_angles(hip - np.array([length, 0.0]))
    extras = [speed, 0.0, 0.0, rear[1] - rear[0], front[1] - front[0], z[index("trunk")], dwell]
    n = problem.samples
    if problem.landing == "zero-speed":
        z[index("end_rate_q1") : index("end_rate_q5") + 1] = 0.0
        extras += [speed, 0.0, 0.0]  # the hip at V through the landing
    bends = 2 * (n - 1) + _between(problem)
    guess = np.concatenate([z, extras, np.zeros(bends + len(WRENCH) * (n + 1))])
    if problem.landing == "impact":
        guess = gentle_landing(problem, guess)
    try:  # the lift-off's rates those after the landing: no jump to bridge
        step = two_phase_model.build_two_phase(
            model, speed, to_parameters(problem, guess), problem.landing
        )
        guess[N_SINGLE : N_SINGLE + 3] = step.double.start[1][FREE]
    except UnreachableError:
        pass
    guess = closed_bends(problem, guess)
    try:
        return shifted_weight(problem, guess)
    except UnreachableError:
        return guess


def gentle_landing(problem: TwoPhaseProblem, variables) -> np.ndarray:
    """``variables`` (impact landing) with the rates before the landing those of the closed
    chain, its hip moving at (V, 0) and its trunk still: both feet at rest, no impulse. The
    single-support optimum's touchdown slides forward (the rolling knee's at 1.82 m/s), far
    outside the landing's friction cone, and IPOPT does not find its way in from there
    (1000 iterations at 0.3 m/s, 0.1-0.2); from a landing at rest it need only grow one."""
    z = np.array(variables, dtype=float)
    model, speed = problem.single.model, problem.single.speed
    names = two_phase_model.parameter_names(problem.landing)
    value = dict(zip(names, to_parameters(problem, z), strict=True))
    length = speed * (value["period"] + value["double_support"])
    landing = [value["landing_x_hip"], value["landing_z_hip"], value["landing_trunk"]]
    try:
        _, qd, _ = double_support.chain_state(model, length, landing, [speed, 0.0, 0.0])
    except UnreachableError:
        return z
    rates = qd[Q1 : Q5 + 1]
    # The swing ankle's velocity (2,) is linear in the rates: add the least ones that bring it
    # down at LANDING_DESCENT, a landing inside the cone rather than at its apex.
    q = double_support.chain_posture(model, length, landing)
    angles = q[QP2 : Q5 + 1]

    def touchdown(end_rates):
        q_end, qd_end, _ = model.stance_state(angles, np.concatenate([[0.0], end_rates]))
        return model.point_jacobian(q_end, "swing_ankle") @ qd_end

    jacobian = np.column_stack([touchdown(e) for e in np.eye(len(rates))])
    wanted = np.array([0.0, -LANDING_DESCENT]) - touchdown(rates)
    rates = rates + np.linalg.lstsq(jacobian, wanted, rcond=None)[0]
    z[index("end_rate_q1") : index("end_rate_q5") + 1] = rates
    return z


def closed_bends(problem: TwoPhaseProblem, variables) -> np.ndarray:
    """``variables`` with the double support's bends, at the solver's interior samples and
    between them, those of the closed chain (``biped.model.double_support``: the inverse
    geometric model at the hip's cubic), which meet the closure's equalities; where the
    cubic's hip is beyond a leg's reach, the ends' bends interpolated."""
    z = np.array(variables, dtype=float)
    model, n, f = problem.single.model, problem.samples, problem.per_interval
    parameters = to_parameters(problem, z)
    step = two_phase_model.build_two_phase(model, problem.single.speed, parameters, problem.landing)
    times = np.linspace(0.0, step.double.duration, n * f + 1)
    try:
        s, _, _ = double_support.phase_coordinates(step.double, times)
        q = double_support.chain_posture(model, step.step_length, s)
        bends = np.column_stack([q[:, Q2] - q[:, Q1], q[:, Q3] - q[:, Q4]])
    except UnreachableError:
        ends = np.array([z[N_SINGLE + 3 : N_SINGLE + 5], z[[index("swing_knee_bend"), 0]]])
        share = np.linspace(0.0, 1.0, n * f + 1)[:, None]
        bends = ends[0] + (ends[1] - ends[0]) * share
    at = {name: k for k, name in enumerate(problem.names)}
    for i in range(1, n * f):
        j, k = divmod(i, f)
        suffix = f"{j}_{k}" if k else f"{j}"
        for leg, bend in zip(("rear", "front"), bends[i], strict=True):
            z[at[f"{leg}_bend_{suffix}"]] = bend
    return z


def shifted_weight(problem: TwoPhaseProblem, variables) -> np.ndarray:
    """``variables`` with the front foot's wrench carrying a share of the load growing
    linearly from 0 at the landing to all of it at lift-off, its ZMP below its ankle: a
    first guess of the split (the variables' double support phase, its bends closed)."""
    z = np.array(variables, dtype=float)
    model = problem.single.model
    parameters = to_parameters(problem, z)
    step = two_phase_model.build_two_phase(model, problem.single.speed, parameters, problem.landing)
    samples = double_support.sample_phase(model, step.double, problem.samples)
    tau = model.generalized_forces(samples.q, samples.qd, samples.qdd)
    share = np.linspace(0.0, 1.0, problem.samples + 1)
    fx, fz = share * tau[:, XH], share * tau[:, ZH]
    front = np.column_stack([fx, fz, model.robot.ankle_height * fx])
    z[-front.size :] = front.ravel()
    return z


def to_parameters(problem: TwoPhaseProblem, variables) -> np.ndarray:
    """The parameters of ``biped.model.two_phase`` (the problem's landing) of the variables: the
    hips at lift-off and landing from the knee bends (eq. *), the rest as they are."""
    model, speed = problem.single.model, problem.single.speed
    z = np.asarray(variables, dtype=float)
    value = dict(zip(problem.names, z, strict=True))
    period, dwell = value["period"], value["double_support"]
    length = speed * (period + dwell)
    hp = model.robot.ankle_height

    def hip(rear_bend, front_bend):  # eq. (*), the rear ankle at 0 and the front at S
        d_r2, d_f2 = model.reach_squared(rear_bend), model.reach_squared(front_bend)
        x = (d_r2 - d_f2 + length**2) / (2 * length)
        return x, hp + np.sqrt(d_r2 - x**2)

    # At lift-off the single support's stance leg is the front one, its ankle at x = 0.
    x_lift, z_lift = hip(value["swing_knee_bend"], value["stance_knee_bend"])
    x_land, z_land = hip(value["landing_rear_bend"], value["landing_front_bend"])
    named = {
        "x_hip": x_lift - length,
        "z_hip": z_lift,
        "landing_x_hip": x_land,
        "landing_z_hip": z_land,
        **value,
    }
    names = two_phase_model.parameter_names(problem.landing)
    return np.array([named[name] for name in names])


@dataclass(frozen=True)
class TwoPhaseCheck:
    """A two-phase optimum on the numeric model (``biped.model.two_phase``).

    Attributes:
        single: the single support phase on the check grid (``CHECK_SAMPLES_PER_HALF`` per
            piece, 202 samples): its constraints and criteria, as a single-support gait's.
        double_margins: (n f + 1, 2, 5) both feet's Ψ (stance, swing; ``FOOT_CONSTRAINTS``
            [N, N, N, m, m]) on the double support's fine grid (f = ``FINE_PER_INTERVAL``
            samples per interval of the solver's), the front foot's wrench linear in time
            between its variables: the gait file's rule and its ``feasible``.
        handover: the feet's wrenches where they hand their load over (the rear foot's at
            lift-off, the front foot's at a zero-speed landing): name -> largest component
            [N or N·m] (``biped.model.double_support.handover_loads``); there the foot's Ψ
            are not judged (+inf in ``double_margins``).
        landing_margins: (2, 3) each foot's (rear, front) landing constraints
            (``biped.model.two_phase.LANDING_CONSTRAINTS`` [N·s]: I_z, μ I_z ∓ I_x, μ =
            ``FOOT_FRICTION``), all 0 for the zero-speed landing.
        value: C_Γ [N²·m·s], the single support's integral on the check grid, the double
            support's on its samples.
    """

    single: StepEvaluation
    double_margins: np.ndarray
    landing_margins: np.ndarray
    value: float
    # the largest component of each judged handover's wrench [N or N·m]
    # (``biped.model.double_support.handover_loads``), <= ``HANDOVER_TOLERANCE`` when met
    handover: dict

    @property
    def feasible(self) -> bool:
        return self.single.feasible and not self.violations()

    def violations(self) -> dict:
        """The double support's violated constraints: name -> worst value."""
        found = {}
        for side, foot in enumerate(("rear", "front")):
            for k, name in enumerate(double_support.FOOT_CONSTRAINTS):
                worst = float(np.min(self.double_margins[:, side, k]))
                if not worst >= 0.0:
                    found[f"{foot} {name}"] = worst
        for side, foot in enumerate(two_phase_model.FEET):
            for k, name in enumerate(two_phase_model.LANDING_CONSTRAINTS):
                value = float(self.landing_margins[side, k])
                if not value >= 0.0:
                    found[f"{foot} {name}"] = value
        for name, load in self.handover.items():
            if not load <= double_support.HANDOVER_TOLERANCE:
                found[f"load {name.replace('_', ' ')}"] = load
        return found

    def violations_line(self) -> str:
        """The violated constraints of both phases, one line."""
        parts = [self.single.violations_line()] if not self.single.feasible else []
        parts += [f"{k} = {v:.3g}" for k, v in self.violations().items()]
        return ", ".join(parts)


def check(problem: TwoPhaseProblem, variables) -> TwoPhaseCheck:
    """``variables`` on the numeric model: the single support on the check grid with the
    single-support problem's safety, the double support on its fine grid (the file's rule for
    the front wrench between the solver's samples, ``double_support.sample_split``), the
    landing's impulses (both feet pushed, within the friction cone, no margin)."""
    single, model = problem.single, problem.single.model
    z = np.asarray(variables, dtype=float)
    parameters = to_parameters(problem, z)
    step = two_phase_model.build_two_phase(model, single.speed, parameters, problem.landing)
    evaluation = evaluate_step(model, step.single, CHECK_SAMPLES_PER_HALF, safety=single.safety)
    front = z[-len(WRENCH) * (problem.samples + 1) :].reshape(-1, len(WRENCH))
    fine = double_support.sample_split(model, step.double, front)  # the file's rule
    zero_speed = problem.landing == "zero-speed"
    margins = fine.margins(model.robot, zero_speed=True if zero_speed else None)
    torques = fine.torques[:: double_support.FINE_PER_INTERVAL]  # the solver's samples
    weights = step.single.period * simpson_weights(CHECK_SAMPLES_PER_HALF)
    single_part = float(weights @ (evaluation.torques**2).sum(-1))
    double_part = step.double.duration * float(_simpson(problem.samples) @ (torques**2).sum(-1))
    return TwoPhaseCheck(
        single=evaluation,
        double_margins=margins,
        landing_margins=np.array(two_phase_model.landing_margins(step.impulse)),
        value=(single_part + double_part) / step.step_length,
        handover=double_support.handover_loads(fine.handover(zero_speed), zero_speed),
    )


@dataclass(frozen=True)
class TwoPhaseResult:
    """The best of several starts (``optimize_two_phase``).

    Attributes:
        best: the converged start of least C_Γ among those feasible on the numeric model,
            None when none is.
        checked: its check on the numeric model.
        starts: starts solved; converged: those IPOPT converged from; feasible: of those,
            the ones feasible on the numeric model; at_best: those within 1e-6 (relative)
            of the best value.
        seconds: [s] all the solves, the solver's building not counted.
        outcomes: each start's end, one line: IPOPT's status, and for a converged start
            infeasible on the numeric model its violated constraints.
    """

    best: TwoPhaseOptimum | None
    checked: TwoPhaseCheck | None
    starts: int
    converged: int
    feasible: int
    at_best: int
    seconds: float
    outcomes: tuple = ()


def optimize_two_phase(
    solver: TwoPhaseSolver, single_variables, single_value: float, starts: int, seed: int
) -> TwoPhaseResult:
    """IPOPT from ``starts`` starts: the single-support optimum's ``single_variables`` and
    ``starts`` − 1 of its perturbations (``biped.optimization.optimize.perturbed``, seeded),
    each made a two-phase start by ``start_from_single``; the best feasible converged one.

    One start is not enough: at 0.3 m/s and a share of 0.01-0.45 the rolling knee's problem,
    its landing not yet held in the friction cone, had optima at 826.47 and 736.78 N²·m·s,
    each reached from half the perturbed starts.
    """
    began = time.perf_counter()
    problem = solver.problem
    rng = np.random.default_rng(seed)
    z = np.asarray(single_variables, dtype=float)
    candidates = [z] + [perturbed(z, rng) for _ in range(starts - 1)]
    answers, converged, outcomes = [], 0, []
    for candidate in candidates:
        try:
            start = start_from_single(problem, candidate)
        except BipedError as error:  # a perturbed posture out of the legs' reach
            outcomes.append(f"no start ({error})")
            continue
        answer = solver.solve(start, single_value)
        outcomes.append(f"{answer.status} at {answer.value:.6g} N²·m·s")
        if not answer.converged:
            continue
        converged += 1
        checked = check(problem, answer.variables)
        if checked.feasible:
            answers.append((answer, checked))
        else:
            outcomes[-1] += f", infeasible: {checked.violations_line()}"
    outcomes = tuple(outcomes)
    if not answers:
        seconds = time.perf_counter() - began
        return TwoPhaseResult(None, None, starts, converged, 0, 0, seconds, outcomes)
    best, checked = min(answers, key=lambda pair: pair[0].value)
    at_best = sum(abs(a.value - best.value) <= 1e-6 * abs(best.value) for a, _ in answers)
    return TwoPhaseResult(
        best,
        checked,
        starts,
        converged,
        len(answers),
        at_best,
        time.perf_counter() - began,
        outcomes,
    )
