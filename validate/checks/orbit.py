"""Is the walk a stable orbit? The return map of MuJoCo's closed-loop walk and its multipliers.

A walking gait is a periodic orbit; the walk in MuJoCo (``validate.walk.simulate``: the file's
torques, the servos, the speed loop on the stance ankle) is stable when a small error in the
state at one step is smaller at the next. The map from the state at one step to the state at
the next (a Poincaré return map) says how much smaller: near its fixed point x*,
x_{k+1} - x* ≈ J (x_k - x*); the eigenvalues of J (the Floquet multipliers) are the factors
per step of its modes, the orbit is stable when all lie inside the unit circle, and the
largest modulus (the spectral radius ρ) is the factor of the slowest mode.

The section: just after each touchdown, once the legs are swapped, in the stance leg's
coordinates, the state the gait file starts from. MuJoCo's landing is soft: the foot lands
flat on its heel and toe spheres and rocks between them for about 10 ms (the checks leave out
the first ``LANDING`` of each step for that reason), so the state the gait file starts from,
right after a rigid impact, exists in MuJoCo once the landing has settled. The section is
where the hip's advance over the stance ankle reaches the gait's at ``LANDING`` of the period
(``section_advance``: x_H(0.1 T), 6 cm behind the ankle at 0.3 m/s), the state interpolated
between the two physics steps around the crossing, so that the section does not move with
MuJoCo's grid of 1 ms physics steps. The section must find the stance foot at rest (below):
the first of ``SECTION_PHASES`` where it is (``settled_section``). A gait of single support's
is at ``LANDING``; a two-phase gait's stance foot still rocks there from its double support
(its tilt rate spreading by 0.0085 rad/s from step to step for the rolling knee's optimum of
zero-speed landing at 0.3 m/s), and its section is later in the swing (0.3 T for that gait,
its tilt rate spreading by 2e-5 rad/s there).

The coordinates: with the stance foot flat on the floor the hip follows from the stance leg
(``Chain.stance_state``), and a state on the section has 12 coordinates, the free angles
[qp2, q1, q2, q3, q4, q5] [rad] and their rates [rad/s] (``COORDINATES``). The stance foot's
pose and velocity (its tilt and its sink into the soft floor, a few micrometres, which the
contact holds) and the rolling knee's equality are not coordinates: a perturbed state keeps
the reference state's (``ReturnMap.lift``: the walk's mean state on the section), so a
perturbation never lifts the stance foot or pushes it into the floor. That holds the walk's
state only where the foot is at rest: where its tilt rate spreads over the walk's steps by
more than a tenth of the map's rate step (``HELD_RATE_SPREAD``), the map restarted from the
walk's own states misses the walk's next ones (``restart_miss``: 1.25 central-difference
steps, root mean square, at 0.1 T of a two-phase walk, against 0.33 at its section at rest
and 0.03-0.07 at a single support's, beside ``RESTART_MISS``) and is not the walk's; the
orbit is then not measured (``UnsettledSection``, verdict undecided). The section fixes one
more direction, the flow along the orbit: a state moved along it reaches the same next state
(J f = 0, a structural multiplier 0, measured as ``Multipliers.flow_gain``: within about its
noise, ``Multipliers.flow_noise``, for the optimal gaits). The dynamic multipliers are those
of J on the 11 directions across the flow (``section_basis``), along which the map is
perturbed.

The closed loop carries nothing else across steps: the controller reads the phase from the
state at each reading (``RESYNC``), its speed loop is proportional (no memory), the gains
are the walk's, and on the section the swing foot is in the air. So the return map is of
the whole closed-loop state. A walk restarted on the section is the walk from there but for
the clock of its readings of the phase (the section's instead of the touchdown's).

MuJoCo's grid makes the map noisy. Which of the landing foot's two spheres touches first,
and on which physics step, is decided by micrometres (the optimal gaits land flat, heel and
toe within 10 µm, coming down 0.05 mm per 1 ms physics step), and each choice sends the next
step off with rates about a hundredth of a rad/s apart (the map's images over the grid
spread by 0.010-0.015 rad/s in the fastest rates): the map is piecewise smooth, and within
one piece its derivative is that of a landing pinned to one physics step, not the walk's. So
the map is averaged over ``PHASES`` positions of the grid (the start moved back along the
flow by (j + 1/2) / PHASES of a physics step), and the Jacobian is taken by central
differences of ``STEP`` [rad] and ``RATE_STEP`` [rad/s] over the coordinates (a unit step
along each of the 12 directions of ``section_basis`` in the coordinates over those steps,
both ways, at each grid position: 2 x 12 x PHASES one-step walks). The steps span many
pieces and are about the walk's own spread on the section, so that the map is linearised
over the states the walk visits: the rates' standard deviation over the walk's steps is at
most 0.011 rad/s for the optimal gaits at 0.3 m/s under the validation's controller (kp 2000
N·m/rad, 1 ms physics steps; it was 0.022-0.025 rad/s at kp 1000 and 2 ms, with steps of
3e-3 rad and 3e-2 rad/s, both halved since). The angles spread far less on the section (0.07
mrad: the section fixes the hip's advance); the angle step stays a tenth of the rate step,
the multipliers agreeing within their spreads for angle steps of 0.5 to 1.5 mrad. The map's
response is not linear far below or above the walk's spread: at twice the steps the slowest
multiplier of the default gains is a real 0.34 instead of a complex pair of modulus
0.23-0.25, and within one piece (1e-5 rad, one grid position) it is -1.84, the map being
kinked where the landing changes from heel-first to toe-first; so ``tests/test_orbit`` holds
the multipliers of two step sizes together and the decay of walked perturbations to the
multipliers. The spread of the central differences over the grid positions gives ρ's
uncertainty (``Multipliers.spread``: the standard deviation of a bootstrap over them).

The fixed point: the walk does not converge to one state, the landing's noise kicks it at
every step (the walk's steps last 598 or 599 physics steps, its rates on the section spread
as above, while its slowest modes, a complex pair of modulus 0.23-0.25 for the optimal gaits
at 0.3 m/s, turn by about 100° and shrink fourfold a step). Its states on the section over
``MEAN_STEPS`` steps after ``SETTLE_STEPS`` have a mean x̄, from which chord-Newton steps on
the averaged map, x <- x - (J - I)⁻¹ (F̄(x) - x) (``CHORD_STEPS`` at most, while the residual
falls), give the fixed point x*. It is reported with its residual |F̄(x*) - x*|, the noise of
F̄ (its standard error over the grid) and its distance from the gait file's state on the
section (the file's motion at ``LANDING`` of the period). For the optimal gaits at 0.3 m/s
the residual is 0.12 of a central-difference step (rolling knee) and 0.01 (revolute knee).

The verdict (``Orbit.verdict``): stable when ρ + ``MARGIN_SPREADS`` spreads < 1 (the orbit
is inside the unit circle by more than the landing's noise moves its estimate; the estimate
moves by about one spread from one machine to another, with the gait's last bits) and the
walk's steps last the gait's period within ``PERIOD_TOLERANCE`` (else it walks another
orbit: without the speed loop and with the servos at 0.75 of their stiffness, one at
1.13-1.14 T); unstable when ρ - as many spreads >= 1, or when a walk falls or misses the
section (``OrbitFailure``: an orbit that cannot be found is unstable, said loudly);
undecided between.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from biped.errors import BipedError
from biped.model.kinematics import QP1, XH, ZH
from validate.checks.checks import LANDING, Check
from validate.checks.units import OrbitFigures
from validate.scene.mapping import mapping, other
from validate.walk.simulate import (
    LANDING_WINDOW,
    LIFT_WINDOW,
    TOUCH_THRESHOLD,
    Simulation,
    Walker,
    WalkSettings,
)

# The 12 coordinates of a state on the section, in order: the free angles [rad], then their
# rates [rad/s] (``biped.model.kinematics``: qp2 swing foot, q1 stance shank, q2 stance thigh,
# q3 swing thigh, q4 swing shank, q5 trunk).
ANGLES = ("qp2", "q1", "q2", "q3", "q4", "q5")
COORDINATES = ANGLES + tuple(f"{name}_rate" for name in ANGLES)
FREE = slice(1, 7)  # the free angles' columns in the paper's q
HELD = [QP1, XH, ZH]  # what the stance foot's contact holds: not coordinates
# Central-difference steps: angles [rad] and rates [rad/s], about the walk's own spread on
# the section in the rates (see the module docstring).
STEP = 1.5e-3
RATE_STEP = 1.5e-2
# Positions of MuJoCo's physics-step grid the map is averaged over: for a walk of single
# support, and for a two-phase walk, whose landed foot bounces through the double support
# and whose map is noisier. Over 12 positions the zero-speed two-phase optima at 0.3 m/s (a
# tenth to a fifth of the step in double support, one start: ``tests.conftest``) read
# ρ = 0.863 ± 0.107 (rolling) and 0.872 ± 0.203 (revolute), undecided; over 24,
# 0.806 ± 0.045 and 0.814 ± 0.080; over 36, 0.819 ± 0.040 and 0.833 ± 0.075: the estimate
# stays, its spread falls as the square root of the positions' count.
PHASES = 12
TWO_PHASE_PHASES = 24
# Steps walked before the walk's states on the section are averaged, and how many are.
SETTLE_STEPS = 6
MEAN_STEPS = 24
# Chord-Newton steps at most from the walk's mean state to the fixed point.
CHORD_STEPS = 3
# The validation's controller (the forward check's walk).
NOMINAL = WalkSettings()
# Resamplings of the grid positions that give the spread of ρ.
BOOTSTRAP = 200
# The orbit check's margin: ρ plus this many spreads below 1 (see ``Orbit.verdict``): an
# error shrinks from step to step by more than the landing's noise moves the estimate of
# the factor (ρ + 2 spreads = 0.30 for the rolling knee's optimal gait at 0.3 m/s: an
# error halved within one step).
MARGIN_SPREADS = 2.0
# Where the section may lie, as fractions of the swing's time T after the step's start,
# tried in turn: the orbit's is the first where the stance foot is at rest on the floor
# (``HELD_RATE_SPREAD``). A gait of single support is at rest at the first, ``LANDING``; a
# two-phase gait's stance foot still rocks there from the double support.
SECTION_PHASES = (LANDING, 0.3, 0.5, 0.7)
# [rad/s] The largest spread, over the walk's steps, of the stance foot's tilt rate on the
# section: the return map holds the stance foot's pose and rates at the walk's mean
# (``ReturnMap.lift``), so what they vary by must be small beside the map's rate step (a
# tenth of it). The optimal gaits of single support: 2.6e-5 rad/s at 0.1 T; the rolling
# knee's two-phase gait of zero-speed landing at 0.3 m/s: 0.0085 rad/s at 0.1 T, 2e-5 rad/s
# at 0.3 T.
HELD_RATE_SPREAD = 0.1 * RATE_STEP
# The largest miss of the return map restarted from the walk's own states on the section
# (``restart_miss``: from the walk's next state to the nearest of the map's images over the
# grid, root mean square over the states tried) [central-difference steps]: half a step, as
# the fixed point's residual. Measured: 0.07 on the optimal gaits' section at 0.1 T; 0.33 on
# the rolling knee's two-phase gait at 0.3 T, where its stance foot is at rest, and 1.25 at
# 0.1 T, where it still rocks and the 12 coordinates do not hold the walk's state.
RESTART_MISS = 0.5
# Largest relative difference of the orbit's step duration from the gait's period (30 ms of
# the 0.59 s step at 0.3 m/s): the default walks' steps last 1.007 T; a walk that settles at
# another period walks another orbit (the speed loop off with the servos at 0.75 of their
# stiffness: 1.13-1.14 T).
PERIOD_TOLERANCE = 0.05


class OrbitFailure(BipedError):
    """A walk of the return map fell or did not reach the section: no orbit there."""


class UnsettledSection(OrbitFailure):
    """The stance foot is not at rest on the section: the 12 coordinates do not hold the
    walk's state there, and no return map of them is the walk's (the orbit not decided)."""


@dataclass(frozen=True)
class Steps:
    """Central-difference steps of the return map's Jacobian.

    Attributes:
        angle: [rad] on each free angle.
        rate: [rad/s] on each rate.
        phases: positions of the physics-step grid averaged over (None: the walk's own,
            ``walk_phases``).
    """

    angle: float = STEP
    rate: float = RATE_STEP
    phases: int | None = None

    def of_walk(self, walker: Walker) -> Steps:
        """These steps, their grid positions the walk's own where not given."""
        if self.phases is not None:
            return self
        return Steps(self.angle, self.rate, walk_phases(walker))

    def vector(self) -> np.ndarray:
        """(12,) the step on each coordinate."""
        return np.array([self.angle] * 6 + [self.rate] * 6)


def walk_phases(walker: Walker) -> int:
    """The grid positions a walk's map is averaged over: ``TWO_PHASE_PHASES`` for a two-phase
    gait's, else ``PHASES``."""
    return TWO_PHASE_PHASES if walker.samples.two_phase else PHASES


class ReturnMap:
    """The walk from one section of the orbit to the next (see the module docstring).

    Args:
        walker: the gait on its model.
        settings: gains of the walk (``WalkSettings``; friction and push as in it).
        reference: (q, q̇) (9,) each, a state on the section whose stance foot's pose and
            velocity every lifted state keeps (``lift``).
        flow: (12,) d/dt of the coordinates there [rad/s, rad/s²]: the direction along which
            a start is moved back to place MuJoCo's grid (``phases``).
        advance: [m] the section's (None: ``section_advance``).
    """

    def __init__(self, walker: Walker, settings: WalkSettings, reference, flow, advance=None):
        self.walker, self.settings = walker, settings
        self.biped = walker.biped
        self.advance = section_advance(walker) if advance is None else float(advance)
        self.dt = float(walker.model.opt.timestep)
        self.flow = np.asarray(flow, float)
        q, qd = reference
        q_free, qd_free, _ = self.biped.stance_state(q[FREE], qd[FREE])
        self.held_q, self.held_qd = np.zeros(9), np.zeros(9)
        self.held_q[HELD] = q[HELD] - q_free[HELD]
        self.held_qd[HELD] = qd[HELD] - qd_free[HELD]
        self.walks = 0

    def lift(self, x) -> tuple[np.ndarray, np.ndarray]:
        """(q, q̇) (9,) of the coordinates ``x`` (12,): the hip from the stance leg, the stance
        foot's pose and velocity those of the reference."""
        x = np.asarray(x, float)
        q, qd, _ = self.biped.stance_state(x[:6], x[6:])
        return q + self.held_q, qd + self.held_qd

    def walk(self, x, steps: int = 1) -> Simulation:
        """The walk of ``steps`` steps from ``x`` on the section, ended on the next section."""
        self.walks += 1
        return self.walker.walk(
            steps + 1, self.settings, start=self.lift(x), stop_advance=self.advance
        )

    def sections(self, sim: Simulation, steps) -> np.ndarray:
        """(len(steps), 12) the coordinates on the section in each of ``steps`` of ``sim``."""
        radii = self.biped.radii
        return np.array(
            [coordinates(*section_state(sim, self.advance, radii, k)[:2]) for k in steps]
        )

    def __call__(self, x, phase: float = 0.0) -> np.ndarray:
        """F(x) (12,): the walk of one step from ``x``, its start moved back along the flow
        by ``phase`` of a physics step."""
        sim = self.walk(np.asarray(x, float) - phase * self.dt * self.flow)
        return self.sections(sim, [1])[0]

    def at_phases(self, x, phases: int) -> np.ndarray:
        """(phases, 12): F(x) at each position (j + 1/2) / phases of the grid."""
        return np.array([self(x, (j + 0.5) / phases) for j in range(phases)])


def section_time(walker: Walker) -> float:
    """[s] the gait's time τ on the section: ``LANDING`` of the swing's time T after the
    step's start (``GaitSamples.landing_time``: the period of a gait of single support, its
    step starting at the touchdown; a two-phase gait's single support, its step starting at
    the rear foot's lift-off)."""
    return LANDING * walker.samples.landing_time


def section_advance(walker: Walker, tau: float | None = None) -> float:
    """[m] the hip's advance over the stance ankle on the section: the gait's at τ =
    ``tau`` [s] (None: ``section_time``). A section's state has the stance foot on the floor
    and the swing foot in the air (its 12 coordinates): a τ outside the swing, from
    ``LIFT_WINDOW`` to ``LANDING_WINDOW`` of T (a two-phase gait's double support, where
    both feet are held, included) is refused (BipedError)."""
    tau = section_time(walker) if tau is None else float(tau)
    swing = walker.samples.landing_time
    low, high = LIFT_WINDOW * swing, LANDING_WINDOW * swing
    if not low <= tau <= high:
        where = "in the double support" if tau > swing and walker.samples.two_phase else "not"
        raise BipedError(
            f"a section at τ = {tau:.4g} s is {where} in the swing: its state would hold "
            f"both feet on the floor, not 12 coordinates (allowed τ in [{low:.4g}, "
            f"{high:.4g}] s)"
        )
    return float(walker.samples.at("q", [tau])[0, XH])


def paper_state(sim: Simulation, row: int, stance: str, radii) -> tuple[np.ndarray, np.ndarray]:
    """(q, q̇) (9,) of MuJoCo's state at ``row`` in the paper's coordinates of ``stance`` in
    stance, x_H from the stance ankle."""
    to_paper = mapping(sim.model, stance, radii).to_paper
    q, qd = to_paper @ sim.qpos[row], to_paper @ sim.qvel[row]
    q[XH] -= sim.ankle_x(stance)[row]
    return q, qd


def section_state(sim: Simulation, advance: float, radii, step: int):
    """(q, q̇, q̈) (9,) each on the section in ``step`` of ``sim``, interpolated between the two
    physics steps around the crossing (q̈ their difference over the step); OrbitFailure if the
    walk did not get there."""
    if step >= len(sim.step_starts) or not all(sim.landed[:step]):
        fell = next((j for j, landed in enumerate(sim.landed) if not landed), len(sim.landed))
        raise OrbitFailure(f"the walk did not land step {fell + 1}: no orbit")
    stance, row = sim.stances[step], crossing(sim, advance, step) - 1
    (qa, qda), (qb, qdb) = (paper_state(sim, r, stance, radii) for r in (row, row + 1))
    share = (advance - qa[XH]) / (qb[XH] - qa[XH])
    dt = sim.time[row + 1] - sim.time[row]
    return qa + share * (qb - qa), qda + share * (qdb - qda), (qdb - qda) / dt


def crossing(sim: Simulation, advance: float, step: int) -> int:
    """The row of ``sim`` at which ``step`` first reaches the section (``advance`` [m]), its
    state's first at or past it; OrbitFailure if it does not."""
    rows = sim.step_slices()[step]
    after = np.flatnonzero(sim.hip_x()[rows] - sim.ankle_x(sim.stances[step])[rows] >= advance)
    if not len(after) or after[0] == 0:
        raise OrbitFailure(f"the walk did not reach the section in step {step + 1}: no orbit")
    return rows.start + int(after[0])


def swing_aloft(sim: Simulation, advance: float, step: int) -> None:
    """OrbitFailure unless the swing foot is off the floor where ``step`` crosses the section
    (both physics steps around it): a state with both feet on the floor (a section in a
    double support, or a foot dragged along) has fewer coordinates than the section's 12,
    and a perturbation of them would push a held foot into the floor or lift it."""
    row = crossing(sim, advance, step)
    swing = other(sim.stances[step])
    force = float(sim.touch(swing)[row - 1 : row + 1].max())
    if force > TOUCH_THRESHOLD:
        raise OrbitFailure(
            f"the {swing} (swing) foot is on the floor on the section in step {step + 1} "
            f"({force:.3g} N, allowed {TOUCH_THRESHOLD:g} N at most): no section of 12 "
            "coordinates there"
        )


def coordinates(q, qd) -> np.ndarray:
    """(12,) the section's coordinates of a state (q, q̇)."""
    return np.concatenate([np.asarray(q)[FREE], np.asarray(qd)[FREE]])


@dataclass(frozen=True)
class Settled:
    """The walk from the gait file's start state, on the section of each step.

    Attributes:
        states: (MEAN_STEPS, 12) its coordinates on the section after ``SETTLE_STEPS``.
        reference: (q, q̇) (9,) each, their mean in the paper's coordinates.
        flow: (12,) the mean d/dt of the coordinates there.
        period: [s] the mean duration of those steps.
        held_rate_spread: [rad/s] the spread (standard deviation) of the stance foot's tilt
            rate on the section over those steps, which the return map holds at its mean.
    """

    states: np.ndarray
    reference: tuple
    flow: np.ndarray
    period: float
    held_rate_spread: float = 0.0

    @property
    def mean(self) -> np.ndarray:
        return self.states.mean(axis=0)


def settle(walker: Walker, settings: WalkSettings, advance: float | None = None) -> Settled:
    """Walk ``SETTLE_STEPS + MEAN_STEPS`` steps from the file's start state and read the
    section (``advance`` [m], None: ``section_advance``) of the last ``MEAN_STEPS``;
    OrbitFailure if the walk falls first or crosses a section with both feet on the floor
    (``swing_aloft``)."""
    advance = section_advance(walker) if advance is None else float(advance)
    radii, steps = walker.biped.radii, SETTLE_STEPS + MEAN_STEPS
    sim = walker.walk(steps + 1, settings, stop_advance=advance)
    found = [section_state(sim, advance, radii, k) for k in range(SETTLE_STEPS, steps)]
    for k in range(SETTLE_STEPS, steps):
        swing_aloft(sim, advance, k)
    q, qd, qdd = (np.array([state[i] for state in found]) for i in range(3))
    states = np.hstack([q[:, FREE], qd[:, FREE]])
    flow = np.concatenate([qd[:, FREE].mean(axis=0), qdd[:, FREE].mean(axis=0)])
    starts = sim.time[sim.step_starts[SETTLE_STEPS : steps + 1]]
    period = float(np.diff(starts).mean())
    biped = walker.biped
    tilt = [
        qd_k[QP1] - biped.stance_state(q_k[FREE], qd_k[FREE])[1][QP1]
        for q_k, qd_k in zip(q, qd, strict=True)
    ]
    reference = (q.mean(axis=0), qd.mean(axis=0))
    return Settled(states, reference, flow, period, float(np.std(tilt)))


def settled_section(
    walker: Walker, settings: WalkSettings, tau=None
) -> tuple[float, Settled, float]:
    """The section of the orbit: (its advance [m], the walk settled on it, its τ as a
    fraction of T), the first of ``SECTION_PHASES`` (or the gait's time ``tau`` [s] alone)
    where the stance foot is at rest (``HELD_RATE_SPREAD``); UnsettledSection if it is at
    none, OrbitFailure if the walk falls first."""
    landing = walker.samples.landing_time
    phases = SECTION_PHASES if tau is None else (float(tau) / landing,)
    spreads = []
    for phase in phases:
        advance = section_advance(walker, phase * landing)
        settled = settle(walker, settings, advance)
        if settled.held_rate_spread < HELD_RATE_SPREAD:
            return advance, settled, phase
        spreads.append(f"{settled.held_rate_spread:.2g} rad/s at {phase:g} T")
    raise UnsettledSection(
        "the stance foot is not at rest on the section: its tilt rate spreads "
        f"{', '.join(spreads)} over the walk's steps (allowed < {HELD_RATE_SPREAD:g} rad/s, a "
        "tenth of the map's rate step): the 12 coordinates do not hold the walk's state, no "
        "return map"
    )


def section_basis(flow, steps: Steps = Steps()) -> np.ndarray:
    """(12, 12) an orthonormal basis of the coordinates over their steps (``Steps.vector``):
    the flow first, then 11 directions across it, along which the map is perturbed."""
    direction = np.asarray(flow, float) / steps.vector()
    direction /= np.linalg.norm(direction)
    basis = np.linalg.qr(np.column_stack([direction, np.eye(12)]))[0][:, :12]
    basis[:, 0] = direction  # QR may flip its sign
    return basis


def central_differences(returns: ReturnMap, x, directions, phases: int = PHASES) -> np.ndarray:
    """(phases, 12, m): (F(x + d) - F(x - d)) / 2 for each column d of ``directions`` (12, m),
    at each position of the physics-step grid."""
    directions = np.asarray(directions, float)
    out = np.empty((phases, 12, directions.shape[1]))
    for i, d in enumerate(directions.T):
        out[:, :, i] = 0.5 * (returns.at_phases(x + d, phases) - returns.at_phases(x - d, phases))
    return out


@dataclass(frozen=True)
class Multipliers:
    """The eigenvalues of the return map's Jacobian J (the Floquet multipliers).

    The section fixes one direction: a state moved along the flow of the orbit reaches the
    same next state, so J f = 0 for the flow f, a structural multiplier 0 (``flow_gain``,
    measured: |J f| / |f|). The dynamic multipliers are those of J on the states modulo the
    flow: the block of J on the 11 directions across it (``section_basis``).

    Attributes:
        values: (11,) complex, the dynamic multipliers by decreasing modulus.
        vectors: (12, 11) complex, the right eigenvector of each (columns), in the
            coordinates (rad, rad/s), scaled so that its largest component over its step
            (``Steps``) is 1: a perturbation of about one step.
        flow_gain: |J f| / |f| in the coordinates over their steps: the structural 0.
        flow_noise: what the grid's noise alone gives ``flow_gain`` (the root sum of squares
            of the standard errors of J f's components over the grid positions): a true 0
            measures about this.
        spread: the standard deviation of ``radius`` over ``BOOTSTRAP`` resamplings of the
            grid positions.
    """

    values: np.ndarray
    vectors: np.ndarray
    flow_gain: float
    spread: float
    flow_noise: float = float("nan")

    @property
    def radius(self) -> float:
        """ρ: the largest modulus."""
        return float(np.abs(self.values).max())

    @property
    def upper(self) -> float:
        """ρ + ``MARGIN_SPREADS`` spreads: what the orbit check holds below 1."""
        return self.radius + MARGIN_SPREADS * self.spread


def multipliers(responses: np.ndarray, basis: np.ndarray, steps: Steps, seed=0) -> Multipliers:
    """The multipliers from ``responses`` (phases, 12, 12) of ``central_differences`` along
    ``basis`` (``section_basis``, the flow first) times the steps; ``seed``: the bootstrap's."""
    scale = steps.vector()
    across = basis[:, 1:]

    def block(mean):  # J on the directions across the flow, modulo the flow
        return across.T @ (mean[:, 1:] / scale[:, None])

    values, vectors = np.linalg.eig(block(responses.mean(axis=0)))
    order = np.argsort(-np.abs(values), kind="stable")
    values, vectors = values[order], across @ vectors[:, order]
    vectors = vectors / vectors[np.abs(vectors).argmax(axis=0), np.arange(11)]
    flow = responses[:, :, 0] / scale  # (phases, 12): J f at each grid position
    flow_gain = float(np.linalg.norm(flow.mean(axis=0)))
    flow_noise = (  # one grid position has no spread to measure
        float(np.linalg.norm(flow.std(axis=0, ddof=1) / np.sqrt(len(flow))))
        if len(flow) > 1
        else float("nan")
    )
    rng = np.random.default_rng(seed)
    phases = len(responses)
    radii = [
        np.abs(np.linalg.eigvals(block(responses[rng.integers(0, phases, phases)].mean(0)))).max()
        for _ in range(BOOTSTRAP)
    ]
    return Multipliers(
        values, vectors * scale[:, None], flow_gain, float(np.std(radii)), flow_noise
    )


@dataclass(frozen=True)
class Orbit:
    """The orbit of a gait's walk under one controller, its fixed point and multipliers.

    Attributes:
        settings: the walk's (gains).
        steps: the central differences'.
        advance: [m] the hip's advance over the stance ankle on the section.
        failure: why there is no orbit (None: there is one; then every field below is set).
        phase: the section's τ as a fraction of the swing's time T (``SECTION_PHASES``).
        unsettled: no section tried has the stance foot at rest (``UnsettledSection``): the
            orbit is not measured, its verdict undecided.
        fixed_point: (12,) x* on the section (``COORDINATES``).
        file_state: (12,) the gait file's state on the section.
        residual: (12,) F̄(x*) - x*.
        noise: (12,) the standard error of F̄(x*) over the grid positions.
        period_ratio: the walk's mean step duration over the gait's period.
        multipliers: ``Multipliers``.
        walks: MuJoCo walks run.
        returns: the return map it was found on (``ReturnMap``).
    """

    settings: WalkSettings
    steps: Steps
    advance: float
    failure: str | None = None
    phase: float = LANDING
    unsettled: bool = False
    fixed_point: np.ndarray | None = None
    file_state: np.ndarray | None = None
    residual: np.ndarray | None = None
    noise: np.ndarray | None = None
    period_ratio: float | None = None
    multipliers: Multipliers | None = field(default=None, repr=False)
    walks: int = 0
    returns: ReturnMap | None = field(default=None, repr=False, compare=False)

    @property
    def radius(self) -> float:
        """ρ; infinity without an orbit (a walk that falls is unstable)."""
        return np.inf if self.multipliers is None else self.multipliers.radius

    @property
    def verdict(self) -> str:
        """'stable' (ρ + ``MARGIN_SPREADS`` spreads < 1, at the gait's period within
        ``PERIOD_TOLERANCE``), 'unstable' (ρ - as many spreads >= 1, or no orbit),
        'another orbit' (stable at another period), else 'undecided' (a section where the
        stance foot is not at rest, too: not measured)."""
        if self.multipliers is None:
            return "undecided" if self.unsettled else "unstable"
        m = self.multipliers
        if m.radius - MARGIN_SPREADS * m.spread >= 1.0:
            return "unstable"
        if m.upper >= 1.0:
            return "undecided"
        return "stable" if abs(self.period_ratio - 1.0) <= PERIOD_TOLERANCE else "another orbit"

    @property
    def stable(self) -> bool:
        return self.verdict == "stable"


def file_state(walker: Walker, phase: float = LANDING) -> np.ndarray:
    """(12,) the gait file's state on the section: its motion at ``phase`` of the swing's
    time T (``section_time`` by default)."""
    tau = [phase * walker.samples.landing_time]
    return coordinates(walker.samples.at("q", tau)[0], walker.samples.at("qd", tau)[0])


def orbit(
    walker: Walker, settings: WalkSettings = NOMINAL, steps: Steps = Steps(), tau=None
) -> Orbit:
    """The orbit of ``walker``'s walk under ``settings`` (see the module docstring): the walk
    settled from the file's start state, the Jacobian at its mean state on the section (at
    the gait's time ``tau`` [s], None: ``section_time``; one outside the swing refused,
    ``section_advance``; None: the first of ``SECTION_PHASES`` where the stance foot is at
    rest, ``settled_section``), chord-Newton steps to the fixed point, the multipliers. An
    ``Orbit`` whose ``failure`` says why when a walk falls or misses the section, or when the
    stance foot is at rest on no section (``unsettled``)."""
    steps = steps.of_walk(walker)
    advance = section_advance(walker, tau)
    phase = LANDING if tau is None else float(tau) / walker.samples.landing_time
    try:
        advance, settled, phase = settled_section(walker, settings, tau)
        returns = ReturnMap(walker, settings, settled.reference, settled.flow, advance)
        basis = section_basis(settled.flow, steps)
        directions = basis * steps.vector()[:, None]
        x = settled.mean
        responses = central_differences(returns, x, directions, steps.phases)
        found = multipliers(responses, basis, steps)
        jacobian = responses.mean(axis=0) @ np.linalg.inv(directions)
        x, images = _chord_steps(returns, x, jacobian, steps)
    except UnsettledSection as error:
        return Orbit(settings, steps, advance, failure=str(error), unsettled=True)
    except OrbitFailure as error:
        return Orbit(settings, steps, advance, failure=str(error), phase=phase)
    return Orbit(
        settings,
        steps,
        advance,
        phase=phase,
        fixed_point=x,
        file_state=file_state(walker, phase),
        residual=images.mean(axis=0) - x,
        noise=images.std(axis=0) / np.sqrt(steps.phases),
        period_ratio=settled.period / walker.period,
        multipliers=found,
        walks=returns.walks + 1,
        returns=returns,
    )


def _chord_steps(returns: ReturnMap, x, jacobian, steps: Steps):
    """Up to ``CHORD_STEPS`` steps x <- x - (J - I)⁻¹ (F̄(x) - x) from ``x``; the x of the
    lowest residual over the steps (``Steps.vector``), and F at it at each grid position
    (phases, 12)."""
    scale = steps.vector()
    best, best_images, best_norm = None, None, np.inf
    for _ in range(CHORD_STEPS + 1):
        images = returns.at_phases(x, steps.phases)
        residual = images.mean(axis=0) - x
        norm = np.linalg.norm(residual / scale)
        if norm >= best_norm:
            break
        best, best_images, best_norm = x, images, norm
        x = x - np.linalg.solve(jacobian - np.eye(12), residual)
    return best, best_images


def figures(result: Orbit) -> dict:
    """The orbit check's figures of ``result`` by name, those not measured left out."""
    return orbit_figures(result).to_dict()


def orbit_figures(result: Orbit) -> OrbitFigures:
    """The orbit check's figures (``validate.checks.units.OrbitFigures``) of ``result``."""
    settings, steps = result.settings, result.steps
    known = {
        "verdict": result.verdict,
        "kp": settings.kp,
        "kv": settings.kv,
        "speed_gain": settings.speed_gain,
        "step_angle": steps.angle,
        "step_rate": steps.rate,
        "phases": steps.phases,
        "section_advance": result.advance,
        "section_phase": result.phase,
        "walks": result.walks,
    }
    m = result.multipliers
    if m is None:
        return OrbitFigures(**known)
    mode = m.vectors[:, 0]
    distance = np.abs(result.fixed_point - result.file_state)
    return OrbitFigures(
        **known,
        spectral_radius=m.radius,
        spectral_radius_spread=m.spread,
        spectral_radius_upper=m.upper,
        multipliers_real=m.values.real.tolist(),
        multipliers_imag=m.values.imag.tolist(),
        multipliers_modulus=np.abs(m.values).tolist(),
        flow_multiplier=m.flow_gain,
        # not measured (None, left out of the JSON) on a single grid position
        flow_multiplier_noise=m.flow_noise if np.isfinite(m.flow_noise) else None,
        coordinates=list(COORDINATES),
        slowest_mode_real=mode.real.tolist(),
        slowest_mode_imag=mode.imag.tolist(),
        fixed_point=result.fixed_point.tolist(),
        file_state=result.file_state.tolist(),
        fixed_point_angle_distance=float(distance[:6].max()),
        fixed_point_rate_distance=float(distance[6:].max()),
        residual_angle=float(np.abs(result.residual[:6]).max()),
        residual_rate=float(np.abs(result.residual[6:]).max()),
        noise_rate=float(result.noise[6:].max()),
        period_ratio=result.period_ratio,
    )


def notes(result: Orbit) -> list[str]:
    """What the orbit check says of ``result``: its slowest mode and the verdict's reason."""
    if result.unsettled:
        return [f"{result.failure} (the orbit is not decided)"]
    if result.failure is not None:
        return [f"{result.failure} (an orbit that cannot be found is unstable)"]
    m = result.multipliers
    slowest = m.values[0]
    if abs(slowest.imag) > 1e-12:  # the pair written out: "±" is a spread elsewhere
        re, im = slowest.real, abs(slowest.imag)
        mode = (
            f"slowest multipliers {re:.3f} + {im:.3f}i and {re:.3f} - {im:.3f}i (a complex "
            "pair: oscillating over steps)"
        )
    elif slowest.real < 0:
        mode = f"slowest multiplier {slowest.real:.3f} (a flip: errors alternate from step to step)"
    else:
        mode = f"slowest multiplier {slowest.real:.3f} (errors keep their sign)"
    if m.upper < 1.0:  # the verdict's bound on a physical scale: steps to halve an error
        halved = f": an error shrinks to half within {np.log(0.5) / np.log(m.upper):.2g} steps"
    else:
        halved = ": an error may grow from step to step"
    said = [mode, f"ρ + {MARGIN_SPREADS:g} spreads = {m.upper:.3f}{halved}"]
    verdict = result.verdict
    if verdict == "stable":
        said.append("stable: below 1 by more than the landing's noise")
    elif verdict == "undecided":
        said.append("not shown stable: within the landing's noise of 1")
    elif verdict == "unstable":
        said.append("unstable: above 1 by more than the landing's noise")
    else:
        said.append(
            f"another orbit: its steps last {result.period_ratio:.2f} T (allowed within "
            f"{PERIOD_TOLERANCE:.0%} of T)"
        )
    return said


def check_orbit(walker: Walker, settings: WalkSettings = NOMINAL) -> tuple[Check, Orbit]:
    """The orbit check: the orbit of the forward check's walk is stable (``Orbit.verdict``)."""
    result = orbit(walker, settings)
    return orbit_check(result), result


def orbit_check(result: Orbit) -> Check:
    """The orbit check of ``result``: passed when stable, else the cause "unstable orbit"
    (an orbit not shown stable: unstable, undecided, another orbit, or none found)."""
    shown = (
        "spectral_radius",
        "spectral_radius_spread",
        "period_ratio",
        "fixed_point_rate_distance",
        "walks",
    )
    causes = [] if result.stable else ["unstable orbit"]
    return Check("orbit", result.stable, figures(result), notes(result), shown=shown, causes=causes)


def walked_decay(result: Orbit, direction, steps: int, phases: int) -> np.ndarray:
    """(phases, steps + 1, 12): a perturbation ``direction`` (12,) of the fixed point walked
    ``steps`` steps, one walk each way (x* ± direction) at each of ``phases`` grid positions:
    (x_k(+) - x_k(-)) / 2 after k steps at each (row 0: ``direction``)."""
    returns, x = result.returns, result.fixed_point
    direction = np.asarray(direction, float)
    walked = np.zeros((2, phases, steps, 12))
    for side, sign in enumerate((1.0, -1.0)):
        for j in range(phases):
            start = x + sign * direction - (j + 0.5) / phases * returns.dt * returns.flow
            sim = returns.walk(start, steps)
            walked[side, j] = returns.sections(sim, range(1, steps + 1))
    start = np.broadcast_to(direction, (phases, 1, 12))
    return np.concatenate([start, 0.5 * (walked[0] - walked[1])], axis=1)


def restart_miss(returns: ReturnMap, states, rows, steps: Steps = Steps()) -> float:
    """[central-difference steps] How far the return map restarted from the walk's own states
    on the section misses the walk: for each row k of ``rows``, the distance from the walk's
    next state ``states[k + 1]`` to the nearest of F(``states[k]``) over ``steps.phases``
    grid positions, in the coordinates over ``steps`` (``Steps.vector``); the root mean square
    over the rows. The walk's next state is one of the map's images, the one at the walk's own
    position on MuJoCo's grid (up to the grid's spacing), when the map is the walk: the
    distance to the images' mean would be the grid's spread, not a miss. A map that does not
    hold the walk's state (a stance foot still rocking, ``HELD_RATE_SPREAD``) misses by its
    bias, beyond ``RESTART_MISS``."""
    states, scale = np.asarray(states, float), steps.vector()
    steps = steps.of_walk(returns.walker)
    nearest = [
        np.linalg.norm(
            (returns.at_phases(states[k], steps.phases) - states[k + 1]) / scale, axis=1
        ).min()
        for k in rows
    ]
    return float(np.sqrt(np.mean(np.square(nearest))))
