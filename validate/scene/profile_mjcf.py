"""The MJCF of a profiled rolling knee (``biped.model.profile``), for ``validate.scene.mjcf``.

The pose of the shank relative to the thigh (``biped.model.profile``): the point
C2' = C2 + k2 u'(q_thigh) of the thigh and the point C1' = C1 + k1 u'(q_shank) of the shank
are joined by a link of length Σ = ρ1 + ρ2 along the common normal u(γ), offset across it by
k1 − k2. Built as MuJoCo joints, every one turning or sliding by an exact function of the
flexion:

    thigh ─ knee_upper (hinge at C2', turns by −ψ2) ─ knee_link (the normal's frame)
          ─ knee_slide (slide along −z, k1 ψ1 + k2 ψ2 = Σ − r1 − r2; at (k1 − k2, −r1 − r2))
          ─ knee_lower (hinge at C1', turns by −ψ1) ─ shank (origin C1', C1 k1 behind it)
    thigh ─ knee_arc (slide of a weightless body: the arc length S the contact has run)

and coupled by equalities that are the rolling relation itself, not a fit of it:

    knee_arc = S2(ψ2) = −r2 knee_upper + (k2 / 2) knee_upper²      (a joint equality)
    knee_arc = S1(ψ1) = −r1 knee_lower + (k1 / 2) knee_lower²      (a joint equality)
    knee_slide + k1 knee_lower + k2 knee_upper = 0                  (a fixed tendon, pinned)

(ψ_i = −knee_upper, −knee_lower; S_i(ψ) = r_i ψ + k_i ψ² / 2, MuJoCo's quartic holds them
exactly; the equal arcs are rolling without slip.) The knee tendon upper + lower is the
flexion, as the circles'; the motor drives it. The knee link, the slider and the arc's body
carry ``KNEE_LINK_MASS`` (the arc's ``ARC_MASS``), the hinges and the arc ``KNEE_ARMATURE``;
the cross-check removes both (but the arc's mass). The slide has none: the lower leg it
carries is its inertia, and a rotor's there would weigh on the knee by its rate Σ', which a
large k2 makes metres a radian (8 m/rad: 0.16 kg·m² where the hinges' are 0.01).

The stretch. The slide carries the lower leg's load along the common normal, nearly the leg's
axis, where the circles have a rigid link; only its tendon equality holds it, and MuJoCo's
implicit step (``implicitfast``, which the walks use for the servos' damping) does not keep
an equality's rate: its velocity update (M − h D)⁻¹ M q̈ of the constraint solver's q̈ (D:
the servos' damping) adds a stretch rate wherever the landing leg's knee and ankle servos
brake large accelerations. At each landing the slide stretched by 17 µm (the circles'
optimal gait at the designed radii, 0.3 m/s, on this knee with k = 1e-9; 2.4 µm under the
walkable margins' softer landings), the micrometres that decide which sphere of the sole lands
first, and the orbit's ρ went from the circles' 0.73 to 0.94. The stretch tendon therefore
carries ``STRETCH_ARMATURE``, an inertia of its length: the stretch is zero with its rate and
acceleration on the rolling motion, so it never enters the knee's dynamics (the cross-check
removes it all the same), and it makes the slide too heavy for the implicit step to move (the
landing's stretch 0.5 µm; ρ back to the circles', ``tests/test_profile_orbit.py``).
"""

from __future__ import annotations

import mujoco
import numpy as np

from biped.model.profile import PROFILE_RANGE, KneeProfile, knee_vectors, rolling

# Segments of the drawn surfaces (visual capsules) over the knee's range.
DRAWN_SEGMENTS = 12
# Radius of the drawn surfaces' capsules [m].
DRAWN_RADIUS = 0.006
# The arc's body [kg, kg·m²]: it only carries the arc length, a leaf of the tree, so the
# cross-check's rigid copy keeps it (zero, its joint would have no inertia at all, and
# MuJoCo's factorisation would warn); 1e-12 kg moves the robot's torques by ~1e-11 N·m.
ARC_MASS, ARC_INERTIA = 1e-12, 1e-14
# Armature of the slide's stretch, the pinned tendon knee_slide + k1 knee_lower + k2 knee_upper
# [kg]: the stretch is 0 with its rate and acceleration on the rolling motion, so this inertia
# never enters the knee's dynamics; it holds the slide along the leg against MuJoCo's implicit
# step (module docstring, "The stretch"): 23 times the lower leg's 4.3 kg.
STRETCH_ARMATURE = 100.0


def _f(value: float) -> str:
    return f"{value:.10g}"


def ranges(profile: KneeProfile) -> dict[str, tuple[float, float]]:
    """The hinges' ranges [rad] over the knee's range of flexion (``PROFILE_RANGE``):
    knee_upper = −ψ2, knee_lower = −ψ1."""
    ends = [rolling(profile, theta) for theta in PROFILE_RANGE]
    return {
        "upper": (float(-ends[1].psi2), float(-ends[0].psi2)),
        "lower": (float(-ends[1].psi1), float(-ends[0].psi1)),
    }


def surfaces(profile: KneeProfile, count: int = DRAWN_SEGMENTS + 1) -> dict[str, np.ndarray]:
    """The two surfaces over the knee's range, (count, 2) points (x, z) [m]: the thigh's from
    C2 in the thigh's frame, the shank's from C1 in the shank's frame."""
    theta = np.linspace(*PROFILE_RANGE, count)
    vectors = knee_vectors(profile, np.zeros_like(theta), -theta)  # thigh 0, shank −θ
    contact = np.stack(vectors["contact"].position, -1)
    shank = contact - np.stack(vectors["link"].position, -1)
    c, s = np.cos(theta), np.sin(theta)  # turned by +θ into the shank's frame
    turned = np.stack([c * shank[:, 0] - s * shank[:, 1], s * shank[:, 0] + c * shank[:, 1]], -1)
    return {"thigh": contact, "shank": turned}


def _drawn(points: np.ndarray, origin_z: float, material: str, pad: str) -> list[str]:
    """Visual capsules along ``points`` (x, z), shifted by ``origin_z`` along z."""
    lines = []
    for (x0, z0), (x1, z1) in zip(points[:-1], points[1:], strict=True):
        lines.append(
            f'{pad}<geom class="visual" type="capsule" size="{_f(DRAWN_RADIUS)}" '
            f'fromto="{_f(x0)} 0 {_f(origin_z + z0)} {_f(x1)} 0 {_f(origin_z + z1)}" '
            f'material="{material}"/>'
        )
    return lines


def knee_bodies(profile: KneeProfile, side: str, thigh: float, pad: str, parts: dict) -> list:
    """The knee's bodies inside the thigh's (``pad`` its indentation), opened down to the
    shank's (its knee_lower joint written; ``validate.scene.mjcf`` writes the rest and closes the
    three bodies). ``parts``: the link's mass and inertia line, the armature attribute."""
    drawn = surfaces(profile)
    hinge, ends = parts["armature"], ranges(profile)
    link = profile.r1 + profile.r2
    return [
        *_drawn(drawn["thigh"], -thigh, f"{side}_disc", f"{pad}  "),
        f'{pad}  <body name="{side}_knee_arc" pos="0 0 {_f(-thigh)}">',
        f'{pad}    <joint name="{side}_knee_arc" type="slide" axis="1 0 0" {hinge}/>',
        f'{pad}    <inertial pos="0 0 0" mass="{_f(ARC_MASS)}" diaginertia="{_f(ARC_INERTIA)} '
        f'{_f(ARC_INERTIA)} {_f(ARC_INERTIA)}"/>',
        f"{pad}  </body>",
        f'{pad}  <body name="{side}_knee_link" pos="{_f(profile.k2)} 0 {_f(-thigh)}">',
        f'{pad}    <joint name="{side}_knee_upper" range="{_f(ends["upper"][0])} '
        f'{_f(ends["upper"][1])}" {hinge}/>',
        f"{pad}    {parts['inertial']}",
        f'{pad}    <body name="{side}_knee_slider" pos="{_f(profile.k1 - profile.k2)} 0 '
        f'{_f(-link)}">',
        f'{pad}      <joint name="{side}_knee_slide" type="slide" axis="0 0 -1"/>',  # no armature
        f"{pad}      {parts['inertial']}",
        f'{pad}      <body name="{side}_shank">',
        f'{pad}        <joint name="{side}_knee_lower" '
        f'range="{_f(ends["lower"][0])} {_f(ends["lower"][1])}" {hinge}/>',
        *_drawn(drawn["shank"] - [profile.k1, 0.0], 0.0, f"{side}_disc", f"{pad}        "),
    ]


def couplings(profile: KneeProfile, sides, solref: str, solimp: str) -> list[str]:
    """The equalities and tendons of the module docstring, for each side: the arc-length's
    two joint equalities, the pinned tendon of the slide, the knee's flexion tendon."""
    r1, r2, k1, k2 = profile.vector
    soft = f'solref="{solref}" solimp="{solimp}"'
    lines = ["  <equality>"]
    for side in sides:
        lines += [
            f'    <joint name="{side}_knee_thigh_arc" joint1="{side}_knee_arc" '
            f'joint2="{side}_knee_upper" polycoef="0 {_f(-r2)} {_f(k2 / 2)} 0 0" {soft}/>',
            f'    <joint name="{side}_knee_shank_arc" joint1="{side}_knee_arc" '
            f'joint2="{side}_knee_lower" polycoef="0 {_f(-r1)} {_f(k1 / 2)} 0 0" {soft}/>',
            f'    <tendon name="{side}_knee_stretch" tendon1="{side}_knee_stretch" {soft}/>',
        ]
    lines += ["  </equality>", "", "  <tendon>"]
    for side in sides:
        lines += [
            f'    <fixed name="{side}_knee">',
            *(f'      <joint joint="{side}_knee_{part}" coef="1"/>' for part in ("upper", "lower")),
            "    </fixed>",
            f'    <fixed name="{side}_knee_stretch" armature="{_f(STRETCH_ARMATURE)}">',
            f'      <joint joint="{side}_knee_slide" coef="1"/>',
            f'      <joint joint="{side}_knee_lower" coef="{_f(k1)}"/>',
            f'      <joint joint="{side}_knee_upper" coef="{_f(k2)}"/>',
            "    </fixed>",
        ]
    return lines + ["  </tendon>", ""]


def model_profile(model: mujoco.MjModel, side: str = "left") -> KneeProfile | None:
    """The knee profile ``side``'s equalities hold (``validate.scene.profile_mjcf``: knee_arc =
    −r2 upper + k2/2 upper², = −r1 lower + k1/2 lower²), None without a knee_arc joint or
    without those equalities."""
    if mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, f"{side}_knee_arc") < 0:
        return None
    found = {}
    arc, upper, lower = (model.joint(f"{side}_knee_{p}").id for p in ("arc", "upper", "lower"))
    for k in range(model.neq):
        if model.eq_type[k] == mujoco.mjtEq.mjEQ_JOINT and model.eq_obj1id[k] == arc:
            data = model.eq_data[k]
            found[int(model.eq_obj2id[k])] = (-float(data[1]), 2.0 * float(data[2]))
    if upper not in found or lower not in found:
        return None
    (r2, k2), (r1, k1) = found[upper], found[lower]
    return KneeProfile(r1, r2, k1, k2)
