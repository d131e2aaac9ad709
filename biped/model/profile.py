"""Knee surfaces beyond circles: two convex profiles that roll on each other without slip.

The family ("linear"). Each surface's radius of curvature is linear in its own tangent angle
ψ, measured from the contact of the straight knee::

    ρ_i(ψ) = r_i + k_i ψ          (i = 1: the shank's surface, i = 2: the thigh's)

r_i [m] is the radius of curvature at the straight knee's contact (the circles' radius) and
k_i [m/rad] its rate; the surface is convex while ρ_i > 0. k_1 = k_2 = 0 are the circles of
``biped.model.robot`` (the paper's Fig. 3), and r_i = k_i = 0 the revolute knee.

Rolling without slip. The knee flexion θ = q_thigh − q_shank is shared by the two surfaces,
θ = ψ1 + ψ2, and the contact runs the same arc length S_i(ψ) = r_i ψ + k_i ψ² / 2 on both,
S1(ψ1) = S2(θ − ψ1): a quadratic in ψ1,

    a ψ1² + b ψ1 − c = 0,   a = (k1 − k2) / 2,  b = r1 + r2 + k2 θ,  c = r2 θ + k2 θ² / 2,

whose root of positive slope is ψ1 = 2c / (b + Σ), Σ = √(b² + 4ac) (finite as a → 0, the
circles' ψ1 = r2 θ / l). Its slope 2aψ1 + b = Σ is ρ1(ψ1) + ρ2(ψ2), so that

    ψ1' = ρ2 / Σ,   ψ1'' = (k2 ρ1² − k1 ρ2²) / Σ³          (' = d/dθ)

Relative pose. With u(φ) = (sin φ, −cos φ), u'(φ) = (cos φ, sin φ) (``biped.model.kinematics``),
the thigh's surface point of outward normal u(φ) is C2 + ∫ ρ2 u' dφ from the straight contact;
writing it out (∫ v u'(q − v) dv = −v u(q − v) + u'(q − v)) and the shank's alike, the two
touch where their normals agree, at the common normal u(γ), γ = q_shank + ψ1 = q_thigh − ψ2:

    contact  K = C2 + ρ2(ψ2) u(γ) − k2 u'(γ) + k2 u'(q_thigh)
    link     V = C1 − C2 = Σ u(γ) + (k1 − k2) u'(γ) + k2 u'(q_thigh) − k1 u'(q_shank)

C2 = hip + (l2 − r2) u(q_thigh) and C1 (the shank's: C1 + (l1 − r1) u(q_shank) is the ankle)
are the centres of the circles of curvature at the straight knee's contact; at k = 0, V is
the circles' (r1 + r2) u(γ). The points C2' = C2 + k2 u'(q_thigh) and C1' = C1 + k1 u'(q_shank)
are fixed in the thigh and the shank and V' = C1' − C2' = Σ u(γ) + (k1 − k2) u'(γ): a link of
length Σ(θ) at angle γ with a constant offset across it, which the MJCF builds
(``validate.scene.mjcf``).

Bounds (``surface_margins``). Over the knee's range of flexion ``PROFILE_RANGE`` (its stops,
``biped.model.robot.JOINT_STOPS``: a machined knee rolls over all of it) each surface is convex,
ρ_i >= ``MIN_CURVATURE_RADIUS``, and stays inside the disc of radius ``limit_i`` about its
centre C_i, |K − C_i| <= limit_i (the largest circle the segment holds:
``biped.optimization.design.radius_limits``). Since ρ_i is linear in ψ_i and
d|K − C_i|²/dψ_i = 2 k_i (1 − cos ψ_i) ρ_i has the sign of k_i, both are extreme at the ends of
the range: four numbers per surface.

The formulas take an array namespace ``xp`` (numpy, or casadi for the symbolic graph) for
``sqrt``, ``sin`` and ``cos``, so that the numeric and the symbolic model share them.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from biped.model.robot import JOINT_STOPS

# The families of knee profiles: "linear", the radius of curvature linear in the tangent angle.
FAMILIES = ("linear",)
# The profile's parameters, in the order of every vector of them (``KneeProfile.vector``).
PARAMETERS = ("r1", "r2", "k1", "k2")
PARAMETER_UNITS = {"r1": "m", "r2": "m", "k1": "m/rad", "k2": "m/rad"}
# [rad] The knee flexion θ = q_thigh − q_shank over which a profile is defined, convex and
# inside its segments: the knee's stops (3° past straight to 138° of flexion).
PROFILE_RANGE = (-JOINT_STOPS["knee"][1], -JOINT_STOPS["knee"][0])
# [m] The smallest radius of curvature of a surface over the range (as ``MIN_RADIUS``, the
# smallest designed circle, ``biped.optimization.design``).
MIN_CURVATURE_RADIUS = 1e-3


@dataclass(frozen=True)
class KneeProfile:
    """The two surfaces of a rolling knee (module docstring)."""

    r1: float  # [m] the shank's radius of curvature at the straight knee's contact
    r2: float  # [m] the thigh's
    k1: float = 0.0  # [m/rad] the rate of the shank's radius of curvature with its tangent angle
    k2: float = 0.0  # [m/rad] the thigh's

    @classmethod
    def of(cls, robot) -> KneeProfile:
        """The profile of a ``biped.model.robot.Robot``."""
        return cls(robot.r1, robot.r2, robot.k1, robot.k2)

    @property
    def circles(self) -> bool:
        """Constant curvature: the circles of radii r1, r2."""
        return self.k1 == 0.0 and self.k2 == 0.0

    @property
    def vector(self) -> tuple:
        return (self.r1, self.r2, self.k1, self.k2)


@dataclass(frozen=True)
class Rolling:
    """The rolling relation at flexions θ (module docstring), each an array of θ's shape."""

    psi1: np.ndarray  # [rad] the shank's tangent angle ψ1
    psi2: np.ndarray  # [rad] the thigh's ψ2 = θ − ψ1
    total: np.ndarray  # [m] Σ = ρ1(ψ1) + ρ2(ψ2), the length of the link C1'C2'
    rate: np.ndarray  # [-] ψ1' = dψ1/dθ
    curvature: np.ndarray  # [1/rad] ψ1'' = d²ψ1/dθ²


def rolling(profile, theta, xp=np) -> Rolling:
    """ψ1, ψ2, Σ, ψ1', ψ1'' at the knee flexion ``theta`` [rad] of ``profile`` (a
    ``KneeProfile`` or (r1, r2, k1, k2), numbers or casadi symbols)."""
    r1, r2, k1, k2 = profile.vector if isinstance(profile, KneeProfile) else profile
    a = 0.5 * (k1 - k2)
    b = r1 + r2 + k2 * theta
    c = r2 * theta + 0.5 * k2 * theta * theta
    total = xp.sqrt(b * b + 4.0 * a * c)
    psi1 = 2.0 * c / (b + total)
    psi2 = theta - psi1
    rho1, rho2 = r1 + k1 * psi1, r2 + k2 * psi2
    rate = rho2 / total
    curvature = (k2 * rho1 * rho1 - k1 * rho2 * rho2) / (total * total * total)
    return Rolling(psi1, psi2, total, rate, curvature)


def surface_distance_squared(r, k, psi, xp=np):
    """|K − C|² [m²] of a surface of ρ = r + k ψ at its tangent angle ψ from its centre C:
    r² + 2 r k (ψ − sin ψ) + k² (ψ² − 2 ψ sin ψ + 2 − 2 cos ψ)."""
    sine = xp.sin(psi)
    square = psi * psi - 2.0 * psi * sine + 2.0 - 2.0 * xp.cos(psi)
    return r * r + 2.0 * r * k * (psi - sine) + k * k * square


# The bounds of ``surface_margins``, in its order (per surface: shank, then thigh).
MARGINS = tuple(
    f"{surface} {what} at {end}"
    for surface in ("shank", "thigh")
    for what in ("convex", "inside")
    for end in ("extension", "flexion")
)


def surface_margins(profile, limits, xp=np, span=PROFILE_RANGE, least=MIN_CURVATURE_RADIUS) -> list:
    """The bounds of the module docstring as margins >= 0 when met, in the order of
    ``MARGINS``: ρ_i − ``least`` [m] and limit_i² − |K − C_i|² [m²] at both ends of ``span``
    (the flexion's range [rad]); ``limits``: (limit_1, limit_2) [m]."""
    r1, r2, k1, k2 = profile.vector if isinstance(profile, KneeProfile) else profile
    ends = [rolling((r1, r2, k1, k2), theta, xp) for theta in span]
    margins = []
    for r, k, limit, angle in ((r1, k1, limits[0], "psi1"), (r2, k2, limits[1], "psi2")):
        psis = [getattr(end, angle) for end in ends]
        margins += [r + k * psi - least for psi in psis]
        margins += [limit * limit - surface_distance_squared(r, k, psi, xp) for psi in psis]
    return margins


def check_profile(profile: KneeProfile) -> None:
    """Raise ValueError naming the first surface of a profile with a non-zero k that is not
    convex (ρ_i > 0) over the knee's range ("rolling": the two have no rolling relation
    there, the quadratic no real root)."""
    if profile.circles:
        return
    with np.errstate(invalid="ignore"):  # no real rolling relation: NaN, said below
        margins = surface_margins(profile, (math.inf, math.inf), least=0.0)
    if any(math.isnan(float(m)) for m in margins):
        raise ValueError("rolling")
    for name, margin in zip(MARGINS, margins, strict=True):
        if "convex" in name and not float(margin) > 0.0:
            raise ValueError(name)


@dataclass(frozen=True)
class KneeVector:
    """A vector of one knee that depends on the thigh's and the shank's angles alone, over
    their leading dimensions: its (x, z) components, their partial derivatives in q_thigh
    and q_shank, and with the rates its bias acceleration (dJ/dt) q̇ (q̈ = 0)."""

    position: tuple  # [m] (x, z)
    by_thigh: tuple  # [m/rad] ∂/∂q_thigh (x, z)
    by_shank: tuple  # [m/rad] ∂/∂q_shank (x, z)
    bias: tuple | None  # [m/s²] (x, z), None without the rates


# The vectors of a knee (``knee_vectors``): the link V = C1 − C2 that carries the lower leg,
# the contact K − C2.
KNEE_VECTORS = ("link", "contact")


def knee_vectors(profile, thigh, shank, thigh_rate=None, shank_rate=None, xp=np) -> dict:
    """The link V = C1 − C2 and the contact K − C2 (module docstring) of a knee whose thigh
    and shank have the angles ``thigh``, ``shank`` [rad] (and rates [rad/s]), by name
    (``KNEE_VECTORS``).

    Each is X = A(θ) u(γ) + B u'(γ) + c_t u'(q_thigh) + c_s u'(q_shank), γ = q_shank + ψ1(θ):
    for the link A = Σ, B = k1 − k2, c_t = k2, c_s = −k1; for the contact A = ρ2(ψ2), B = −k2,
    c_t = k2, c_s = 0. With θ̇ = q̇_t − q̇_s and γ̇ = q̇_s + ψ1' θ̇,

        ∂X/∂q_t =  A' u + (A u' − B u) ψ1' − c_t u(q_t)
        ∂X/∂q_s = −A' u + (A u' − B u)(1 − ψ1') − c_s u(q_s)
        bias    = (A'' θ̇² − A γ̇² − B ψ1'' θ̇²) u + (2 A' θ̇ γ̇ + A ψ1'' θ̇² − B γ̇²) u'
                  − c_t q̇_t² u'(q_t) − c_s q̇_s² u'(q_s)

    (d u(φ)/dφ = u'(φ), d u'(φ)/dφ = −u(φ); A' = dA/dθ: Σ' = (k1 ρ2 + k2 ρ1) / Σ,
    Σ'' = (k1 − k2) ψ1''; ρ2' = k2 ρ1 / Σ, ρ2'' = −k2 ψ1'')."""
    r1, r2, k1, k2 = profile.vector if isinstance(profile, KneeProfile) else profile
    roll = rolling((r1, r2, k1, k2), thigh - shank, xp)
    rho1, rho2 = r1 + k1 * roll.psi1, r2 + k2 * roll.psi2
    gamma = shank + roll.psi1
    terms = {
        "link": (
            roll.total,
            (k1 * rho2 + k2 * rho1) / roll.total,
            (k1 - k2) * roll.curvature,
            k1 - k2,
            k2,
            -k1,
        ),
        "contact": (rho2, k2 * rho1 / roll.total, -k2 * roll.curvature, -k2, k2, 0.0),
    }
    angles = {"gamma": gamma, "thigh": thigh, "shank": shank}
    sines = {name: xp.sin(value) for name, value in angles.items()}
    cosines = {name: xp.cos(value) for name, value in angles.items()}

    def u(name):  # u(φ) = (sin φ, −cos φ)
        return sines[name], -cosines[name]

    def u_prime(name):  # u'(φ) = (cos φ, sin φ)
        return cosines[name], sines[name]

    ug, upg, ut, us = u("gamma"), u_prime("gamma"), u("thigh"), u("shank")
    upt, ups = u_prime("thigh"), u_prime("shank")
    vectors = {}
    for name, (a, a1, a2, b, ct, cs) in terms.items():
        turn = [a * upg[i] - b * ug[i] for i in range(2)]  # ∂X/∂γ
        position = tuple(a * ug[i] + b * upg[i] + ct * upt[i] + cs * ups[i] for i in range(2))
        by_thigh = tuple(a1 * ug[i] + turn[i] * roll.rate - ct * ut[i] for i in range(2))
        by_shank = tuple(-a1 * ug[i] + turn[i] * (1.0 - roll.rate) - cs * us[i] for i in range(2))
        bias = None
        if thigh_rate is not None:
            flex = thigh_rate - shank_rate
            turning = shank_rate + roll.rate * flex
            flex2, bend = flex * flex, roll.curvature * flex * flex
            along = a2 * flex2 - a * turning * turning - b * bend
            across = 2.0 * a1 * flex * turning + a * bend - b * turning * turning
            bias = tuple(
                along * ug[i]
                + across * upg[i]
                - ct * thigh_rate * thigh_rate * upt[i]
                - cs * shank_rate * shank_rate * ups[i]
                for i in range(2)
            )
        vectors[name] = KneeVector(position, by_thigh, by_shank, bias)
    return vectors
