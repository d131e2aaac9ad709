"""MJCF models of both bipeds, generated from ``biped.Robot`` (the single source of truth).

    python -m validate.scene.mjcf            # rewrite mjcf/*.xml from Robot.paper()

Layout (mujoco_menagerie style): the trunk is the root body, at the hip, with the planar base
``rootx``, ``rootz`` (slides, equal to the paper's x_H, z_H) and ``rooty`` (hinge, equal to
the trunk angle q5). The trunk body stands at the hip height of the straight robot and
``rootz`` has that height as its ``ref``, so qpos0 (all joints 0 but rootz = that height) is
the robot standing straight with its soles on the floor, the ``home`` key, and qpos still
equals x_H, z_H, q5 (MuJoCo moves a body by qpos - ref). Every hinge turns about "0 -1 0", so a positive angle is
counter-clockwise in the x-z plane like the paper's angles: a child's absolute angle is its
parent's plus the joint angle. The legs are ``left`` and ``right``; which one is the stance leg
changes every step (``validate.scene.mapping``). Every hinge but ``rooty`` stops at a human's range
(``HIP_RANGE``, ``KNEE_RANGE``, ``ANKLE_RANGE``: the knee never inverted beyond 0.05 rad, the
paper's Ψ4, Ψ5 >= 0) and the trunk, thighs and shanks collide with the floor as the soles do,
so that the robot left without control (``python -m mujoco.viewer``) folds and lies down like
one; the gaits never come near the stops or touch the floor with a link.

The MJCF holds every field of ``biped.Robot`` (``validate.scene.model.model_parameters`` reads them
back): segment lengths as the bodies' places, masses, inertias and centres of mass as their
``inertial``, the sole as the heel and toe sites and contact points, the knee radii as the
rolling knee's link (r1 + r2) and equality (r2 / r1), the trunk's length as its ``head`` site,
gravity as the option's.

Rolling knee: thigh, then a near-massless link of length r1 + r2 between two hinges at the
centres C2 and C1 of the rolling circles, then the shank. Rolling without slip turns the two
hinges by r1 θ / l and r2 θ / l for a knee flexion θ, so a joint equality holds
``knee_lower = (r2 / r1) knee_upper``; a fixed tendon over both hinges measures θ and carries
the knee motor.

Motors have gear -1: the paper's Γ_i is conjugate to θ_i of eq. (32), which is minus the
MuJoCo joint angle of the same joint (θ1 = q1 - qp1 = -ankle, θ3 = q5 - q2 = -hip, ...), so a
motor's control is the paper's torque Γ_i [N·m].

For the eye: the left leg is blue, the right one orange (their knee discs darker), the trunk
grey; the camera ``track`` follows the robot's centre of mass from its right side (-y).
"""

from __future__ import annotations

import sys
from pathlib import Path

from biped.model.kinematics import check_knee
from biped.model.profile import KneeProfile
from biped.model.robot import FOOT_FRICTION as SLIDING_FRICTION
from biped.model.robot import JOINT_STOPS, SOLE_EDGES, Robot
from biped.runtime.files import atomic_write_text
from validate import MODEL_TIMESTEP
from validate.scene import profile_mjcf

SIDES = ("left", "right")
# Near-massless knee link of the rolling knee (MuJoCo needs mass on a moving body) [kg, kg·m²].
KNEE_LINK_MASS = 1e-6
KNEE_LINK_INERTIA = 1e-10
# Armature on the rolling-knee hinges [kg·m²] (a knee drive's rotor, 0.01 kg·m² on the knee's
# flexion): with a stiff equality, it keeps the coupling tight under load and through the
# landings (0.24 mrad at most over a 20-step walk at the 1 ms step, 0.8 mrad at 2 ms; at
# 2 ms, 4.6 mrad with 1e-3). It enters
# MuJoCo's mass matrix; the cross-check removes it, the forward simulation's motors turn it.
KNEE_ARMATURE = 0.02
# Armature on the ankles [kg·m²], the rotor inertia of an ankle drive seen through its
# gearbox. Without it the foot (0.002 kg·m² about the ankle) under a stiff joint feedback
# oscillates at about 1000 rad/s, beyond what a 1 ms explicit step resolves, and rocks itself
# across the floor. It enters MuJoCo's mass matrix; the cross-check removes it.
ANKLE_ARMATURE = 0.02
# Equality constraint of the rolling knee: stiff and hard (solimp close to 1); its time
# constant is the shortest MuJoCo allows at the time step (2 steps).
KNEE_SOLREF = "0.002 1"
KNEE_SOLIMP = "0.9999 0.99999 0.0001 0.5 2"
# Foot box (drawn): width and sole thickness [m]; friction (sliding, torsional, rolling).
FOOT_WIDTH = 0.10
SOLE_THICKNESS = 0.02
FOOT_FRICTION = f"{SLIDING_FRICTION!r} 0.02 0.0001"  # μ from biped.model.robot
# The sole touches the floor at its heel and its toe: two small spheres on the sole's
# bottom ends (the motion is planar: the sole is the segment between them). Two contact
# points per foot instead of a box's four make the physics step cheaper, and any centre of
# pressure along the sole is still a split of the normal force between them. Radius [m].
SOLE_CONTACT_RADIUS = 0.002
# Stiff contact, the same on the soles and the floor (MuJoCo averages the two geoms'
# parameters): the gaits clear the ground by about a millimetre, so the stance foot must not
# sink into it. The time constant is the shortest MuJoCo allows at the time step (2 steps).
FOOT_SOLREF = "0.002 1"
FOOT_SOLIMP = "0.99 0.999 0.0005 0.5 2"
TIMESTEP = MODEL_TIMESTEP  # [s]
# Elliptic friction cones, friction as soft as the normal force (MuJoCo's default impedance
# ratio). The stiff contact above already holds a loaded foot (the gaits need |Fx| / Fz of
# about 0.1 at most). Against friction 50 times harder (``IMPRATIO_HARD``), the 20-step
# walks of the optimal gaits at 0.3 m/s slip 0.08 and 0.12 mm instead of 0.09 and 0.13,
# every check of the 52 sweep optima keeps its verdict, the robustness limits move by one
# bisection step at most, and the solver's line search takes half the evaluations.
IMPRATIO = 1.0
# The harder friction: the finer reference model that the test of the committed settings
# walks against, and the benchmark's previous settings.
IMPRATIO_HARD = 50.0
# No constraint islands: the robot is one kinematic tree (its planar base hangs from the
# world), so every contact and knee equality acts on the same island, and finding it at each
# step is work for nothing (4 % of a step; the walks are the same to the bit).
# Ranges of the joints [rad], in MuJoCo's joint angles (a child's absolute angle minus its
# parent's, the paper's sign: hip q_thigh - q_trunk, knee q_shank - q_thigh, ankle
# q_foot - q_shank): a human's anatomical stops, so that a robot left without control folds
# like one instead of through itself. The knee's stop is the paper's constraint that it never
# inverts (Ψ4 = q2 - q1 >= 0, Ψ5 = q3 - q4 >= 0: its angle here is -Ψ <= 0), a little past
# straight: the optimal gaits keep the stance knee straight to the solver's 1 mrad margin
# and their walks to 0.3 mrad. MuJoCo's limit acts only beyond its range (margin 0), and the
# optimal gaits of 0.15-0.45 m/s stay far inside every range (hip -0.17 to 0.22, knee
# -0.18 to 0, ankle -0.15 to 0.19 rad), their walks too: they play as without limits. A
# rolling knee's two hinges share the range as they share the flexion (r1 / l and r2 / l).
HIP_RANGE = JOINT_STOPS["hip"]  # extension 29°, flexion 115°
KNEE_RANGE = JOINT_STOPS["knee"]  # flexion 138°, 3° past straight
ANKLE_RANGE = JOINT_STOPS["ankle"]  # plantar flexion 46°, dorsiflexion 34°
# The stops are as stiff as the contacts (a stop hit by a falling robot gives by a few
# hundredths of a radian; at MuJoCo's default, 0.02 s, by 0.13 rad).
LIMIT_SOLREF = "0.002 1"
LIMIT_SOLIMP = "0.99 0.999 0.001 0.5 2"
# The links collide with the floor too (capsules as drawn, group 3), so that a robot that
# falls lies on it; a walk never brings them near it (the knees stay 0.4 m up).
# Legs side by side, for the eye only: the motion is planar (slides along x, z and hinges
# about y), so offsets along y change nothing in it. Links collide with the floor, not with
# each other (contype / conaffinity).
HIP_OFFSET = 0.09  # [m]
# Colours (RGBA) of the trunk and of each leg, and of each leg's knee discs.
TRUNK_RGBA = "0.62 0.62 0.66 1"
LEG_RGBA = {"left": "0.16 0.42 0.86 1", "right": "0.93 0.52 0.12 1"}
DISC_RGBA = {"left": "0.08 0.2 0.45 1", "right": "0.5 0.25 0.04 1"}
# Radii of the drawn segments [m] and half-width of the knee discs [m], wider than the links
# so that the rolling circles show from the side.
THIGH_RADIUS, SHANK_RADIUS, DISC_HALF_WIDTH = 0.04, 0.032, 0.05
# Tracking camera: from the robot's right side (-y), this far from its centre of mass and
# this high above it [m], looking slightly down.
CAMERA_DISTANCE, CAMERA_HEIGHT = 2.8, 0.25
# Largest offscreen image [px] (width, height): the video's frames.
OFFSCREEN = (1280, 720)


def _models_folder() -> Path:
    """Where the committed models are: ``mjcf/`` of a source checkout (editable installs
    too), else the copy an installed package carries (``validate/models``, pyproject.toml)."""
    package = Path(__file__).resolve().parents[1]  # validate/, above this scene/
    source = package.parent / "mjcf"
    return source if source.is_dir() else package / "models"


FOLDER = _models_folder()


def _f(value: float) -> str:
    return f"{value:.10g}"


def _inertial(pos_z: float, mass: float, inertia: float, pos_x: float = 0.0) -> str:
    i = _f(inertia)
    at = f"{_f(pos_x)} 0 {_f(pos_z)}"
    return f'<inertial pos="{at}" mass="{_f(mass)}" diaginertia="{i} {i} {i}"/>'


def _range(limits: tuple[float, float], share: float = 1.0) -> str:
    return f'range="{_f(share * limits[0])} {_f(share * limits[1])}"'


def robot_xml(robot: Robot, knee: str, servos: tuple[float, float] | None = None) -> str:
    """The robot's MJCF (no floor), for one knee kinematic: every field of ``robot`` the
    dynamics use (lengths, masses, inertias, centres of mass, the sole, the knee radii of a
    rolling knee, gravity) and the trunk's length as its ``head`` site.

    Args:
        servos: (kp [N·m/rad], kv [N·m·s/rad]) adds, after the six motors, a position and a
            velocity actuator on each joint (the knee tendon for the rolling knee), in MuJoCo's
            joint coordinates: the joint-space feedback of the forward simulation.
    """
    check_knee(knee)
    rolling = knee == "rolling"
    r1, r2 = (robot.r1, robot.r2) if rolling else (0.0, 0.0)
    if rolling and (r1 <= 0.0 or r2 <= 0.0):
        raise ValueError(f"a rolling-knee MJCF needs r1, r2 > 0 (got r1 = {r1}, r2 = {r2})")
    stand = robot.ankle_height + robot.shank_length + robot.thigh_length
    lines = _header(robot, knee) + _trunk(robot, stand)
    for side in SIDES:
        lines += _leg(robot, side, r1, r2)
    lines += ["    </body>", "  </worldbody>", ""]
    if rolling and robot.profiled:
        solref, solimp = KNEE_SOLREF, KNEE_SOLIMP
        lines += profile_mjcf.couplings(KneeProfile.of(robot), SIDES, solref, solimp)
    elif rolling:
        lines += _knee_coupling(r1, r2)
    lines += _actuators(rolling, servos)
    lines += ["  <sensor>"]
    for side in SIDES:
        lines += [
            f'    <touch name="{side}_touch" site="{side}_sole_touch"/>',
            *(
                f'    <framepos name="{side}_{site}_pos" objtype="site" objname="{side}_{site}"/>'
                for site in ("ankle", "heel", "toe")
            ),
        ]
    nq = 3 + 2 * ((6 if robot.profiled else 4) if rolling else 3)
    home = ["0", _f(stand)] + ["0"] * (nq - 2)  # qpos0: standing straight on the floor
    lines += ["  </sensor>", "", "  <keyframe>", f'    <key name="home" qpos="{" ".join(home)}"/>']
    return "\n".join(lines + ["  </keyframe>", "</mujoco>", ""])


def _header(robot: Robot, knee: str) -> list[str]:
    """``robot_xml``'s compiler, option, assets and defaults."""
    return [
        f'<mujoco model="biped_{knee}">',
        '  <compiler angle="radian" autolimits="true" inertiafromgeom="false"/>',
        f'  <option timestep="{_f(TIMESTEP)}" integrator="implicitfast" cone="elliptic" '
        f'impratio="{_f(IMPRATIO)}" gravity="0 0 {_f(-robot.gravity)}">',
        '    <flag island="disable"/>',
        "  </option>",
        "",
        "  <asset>",
        f'    <material name="trunk" rgba="{TRUNK_RGBA}"/>',
        *(f'    <material name="{side}" rgba="{LEG_RGBA[side]}"/>' for side in SIDES),
        *(f'    <material name="{side}_disc" rgba="{DISC_RGBA[side]}"/>' for side in SIDES),
        "  </asset>",
        "",
        "  <default>",
        f'    <joint type="hinge" axis="0 -1 0" solreflimit="{LIMIT_SOLREF}" '
        f'solimplimit="{LIMIT_SOLIMP}"/>',
        '    <motor ctrlrange="-400 400" gear="-1"/>',
        '    <default class="visual">',
        '      <geom contype="0" conaffinity="0" group="2"/>',
        "    </default>",
        '    <default class="collision">',
        f'      <geom group="3" friction="{FOOT_FRICTION}" condim="3" contype="1" conaffinity="0" '
        f'solref="{FOOT_SOLREF}" solimp="{FOOT_SOLIMP}"/>',
        "    </default>",
        '    <site size="0.01" group="4" rgba="1 0.2 0.2 1"/>',
        "  </default>",
        "",
    ]


def _trunk(r: Robot, stand: float) -> list[str]:
    """The trunk's body, opened: camera, planar base, inertia, capsule and sites."""
    return [
        "  <worldbody>",
        f'    <body name="trunk" pos="0 0 {_f(stand)}">',
        f'      <camera name="track" mode="trackcom" pos="0 {_f(-CAMERA_DISTANCE)} {_f(CAMERA_HEIGHT)}" xyaxes="1 0 0 0 0.1 1"/>',
        '      <joint name="rootx" type="slide" axis="1 0 0"/>',
        f'      <joint name="rootz" type="slide" axis="0 0 1" ref="{_f(stand)}"/>',
        '      <joint name="rooty"/>',
        f"      {_inertial(r.trunk_com, r.trunk_mass, r.trunk_inertia)}",
        f'      <geom class="visual" type="capsule" size="0.08" fromto="0 0 0.1 0 0 {_f(r.trunk_length - 0.1)}" material="trunk"/>',
        f'      <geom name="trunk_contact" class="collision" type="capsule" size="0.08" fromto="0 0 0.1 0 0 {_f(r.trunk_length - 0.1)}"/>',
        '      <site name="hip"/>',
        f'      <site name="head" pos="0 0 {_f(r.trunk_length)}"/>',
    ]


def _leg(r: Robot, side: str, r1: float, r2: float) -> list[str]:
    """One leg's bodies, from the thigh down to the foot; a rolling knee (r1, r2 > 0) is a
    link between two hinges."""
    shank, thigh, link = r.shank_length - r1, r.thigh_length - r2, r1 + r2
    pad = "      "
    y = HIP_OFFSET if side == "left" else -HIP_OFFSET
    lines = [
        f'{pad}<body name="{side}_thigh" pos="0 {_f(y)} 0">',
        f'{pad}  <joint name="{side}_hip" {_range(HIP_RANGE)}/>',
        f"{pad}  {_inertial(-r.thigh_com, r.thigh_mass, r.thigh_inertia)}",
        f'{pad}  <geom class="visual" type="capsule" size="{_f(THIGH_RADIUS)}" fromto="0 0 0 0 0 {_f(-thigh)}" material="{side}"/>',
        f'{pad}  <geom name="{side}_thigh_contact" class="collision" type="capsule" size="{_f(THIGH_RADIUS)}" fromto="0 0 0 0 0 {_f(-thigh)}"/>',
    ]
    if link > 0.0 and r.profiled:  # four joints (``validate.scene.profile_mjcf``)
        parts = {
            "armature": f'armature="{_f(KNEE_ARMATURE)}"',
            "inertial": _inertial(0.0, KNEE_LINK_MASS, KNEE_LINK_INERTIA),
        }
        lines += profile_mjcf.knee_bodies(KneeProfile.of(r), side, thigh, pad, parts)
        pad += "    "  # inside the knee link and the slider
        # The shank's origin is C1' (its hinge), k1 ahead of C1 across the shank: its
        # contents k1 behind (and its centre of mass never within MuJoCo's 1e-6 m of the
        # origin, where MuJoCo puts it on the origin).
        across = -r.k1 + 0.0
    elif link > 0.0:
        disc = f'class="visual" type="cylinder" size="{{}} {_f(DISC_HALF_WIDTH)}"'
        hinge = f'armature="{_f(KNEE_ARMATURE)}"'
        lines += [
            f'{pad}  <geom name="{side}_thigh_disc" {disc.format(_f(r2))} pos="0 0 {_f(-thigh)}" zaxis="0 1 0" material="{side}_disc"/>',
            f'{pad}  <body name="{side}_knee_link" pos="0 0 {_f(-thigh)}">',
            f'{pad}    <joint name="{side}_knee_upper" {_range(KNEE_RANGE, r1 / link)} {hinge}/>',
            f"{pad}    {_inertial(-link / 2, KNEE_LINK_MASS, KNEE_LINK_INERTIA)}",
            f'{pad}    <body name="{side}_shank" pos="0 0 {_f(-link)}">',
            f'{pad}      <joint name="{side}_knee_lower" {_range(KNEE_RANGE, r2 / link)} {hinge}/>',
            f'{pad}      <geom name="{side}_shank_disc" {disc.format(_f(r1))} zaxis="0 1 0" material="{side}_disc"/>',
        ]
        pad += "  "  # inside the knee link and the shank
    else:
        lines += [
            f'{pad}  <body name="{side}_shank" pos="0 0 {_f(-thigh)}">',
            f'{pad}    <joint name="{side}_knee" {_range(KNEE_RANGE)}/>',
        ]
    x = _f(across) if link > 0.0 and r.profiled else "0"
    lines += [
        f"{pad}    {_inertial(-(r.shank_com - r1), r.shank_mass, r.shank_inertia, float(x))}",
        f'{pad}    <geom class="visual" type="capsule" size="{_f(SHANK_RADIUS)}" fromto="{x} 0 0 {x} 0 {_f(-shank)}" material="{side}"/>',
        f'{pad}    <geom name="{side}_shank_contact" class="collision" type="capsule" size="{_f(SHANK_RADIUS)}" fromto="{x} 0 0 {x} 0 {_f(-shank)}"/>',
        f'{pad}    <body name="{side}_foot" pos="{x} 0 {_f(-shank)}">',
        *_foot(r, side, f"{pad}      "),
        f"{pad}    </body>",
        f"{pad}  </body>",
    ]
    closing = ["          </body>"] if r.profiled and link > 0.0 else []  # the slider
    closing += ["        </body>"] if link > 0.0 else []
    return lines + closing + ["      </body>"]


def _foot(r: Robot, side: str, pad: str) -> list[str]:
    """Inside a foot's body: its ankle, inertia, contact points, drawn sole and sites."""
    sole_x, sole_z = r.foot_length / 2 - r.foot_heel, -r.ankle_height + SOLE_THICKNESS / 2
    half = (r.foot_length / 2, FOOT_WIDTH / 2, SOLE_THICKNESS / 2)
    return [
        f'{pad}<joint name="{side}_ankle" {_range(ANKLE_RANGE)} armature="{_f(ANKLE_ARMATURE)}"/>',
        f"{pad}{_inertial(-r.foot_com, r.foot_mass, r.foot_inertia)}",
        *(
            f'{pad}<geom name="{side}_{end}_contact" class="collision" type="sphere" size="{_f(SOLE_CONTACT_RADIUS)}" pos="{_f(x)} 0 {_f(-r.ankle_height + SOLE_CONTACT_RADIUS)}"/>'
            for end, x in r.sole_edges().items()
        ),
        f'{pad}<geom class="visual" type="box" size="{" ".join(_f(h) for h in half)}" pos="{_f(sole_x)} 0 {_f(sole_z)}" material="{side}"/>',
        f'{pad}<site name="{side}_ankle"/>',
        f'{pad}<site name="{side}_sole_touch" type="box" size="{" ".join(_f(h + 0.005) for h in half)}" pos="{_f(sole_x)} 0 {_f(sole_z)}" rgba="0 0 0 0"/>',
        f'{pad}<site name="{side}_heel" pos="{_f(-r.foot_heel)} 0 {_f(-r.ankle_height)}"/>',
        f'{pad}<site name="{side}_toe" pos="{_f(r.foot_length - r.foot_heel)} 0 {_f(-r.ankle_height)}"/>',
    ]


def _knee_coupling(r1: float, r2: float) -> list[str]:
    """The rolling knees' equalities (knee_lower = r2 / r1 knee_upper) and their tendons (the
    flexion, which the knee motor drives)."""
    lines = ["  <equality>"]
    lines += [
        f'    <joint name="{side}_knee_coupling" joint1="{side}_knee_lower" joint2="{side}_knee_upper" polycoef="0 {_f(r2 / r1)} 0 0 0" solref="{KNEE_SOLREF}" solimp="{KNEE_SOLIMP}"/>'
        for side in SIDES
    ]
    lines += ["  </equality>", "", "  <tendon>"]
    for side in SIDES:
        lines += [
            f'    <fixed name="{side}_knee">',
            *(f'      <joint joint="{side}_knee_{part}" coef="1"/>' for part in ("upper", "lower")),
            "    </fixed>",
        ]
    return lines + ["  </tendon>", ""]


def _actuators(rolling: bool, servos: tuple[float, float] | None) -> list[str]:
    """The six motors, and the servos (``robot_xml``) when given."""

    def target(side: str, joint: str) -> str:
        knee = rolling and joint == "knee"
        return f'tendon="{side}_knee"' if knee else f'joint="{side}_{joint}"'

    joints = [(side, joint) for side in SIDES for joint in ("hip", "knee", "ankle")]
    lines = ["  <actuator>", *(f'    <motor name="{s}_{j}" {target(s, j)}/>' for s, j in joints)]
    if servos is not None:
        kp, kv = servos
        for kind, gain in (("position", f'kp="{_f(kp)}"'), ("velocity", f'kv="{_f(kv)}"')):
            lines += [
                f'    <{kind} name="{s}_{j}_{kind}" {target(s, j)} {gain} gear="1" ctrllimited="false"/>'
                for s, j in joints
            ]
    return lines + ["  </actuator>", ""]


def with_box_soles(spec, robot: Robot, solref=None):
    """A copy of the model ``spec`` (``mujoco.MjSpec``) whose soles touch the floor as boxes
    (four contact points each) instead of at their heel and toe points: the finer contact
    the committed models' two points a sole stand for (the benchmark and the test of their
    settings compare the two). ``solref`` (time constant, damping ratio): the boxes' contact
    (None: MuJoCo's default)."""
    import mujoco

    spec = spec.copy()
    for side in SIDES:
        for end in SOLE_EDGES:
            spec.delete(spec.geom(f"{side}_{end}_contact"))
        sole = spec.body(f"{side}_foot").add_geom(
            name=f"{side}_sole",
            type=mujoco.mjtGeom.mjGEOM_BOX,
            size=[robot.foot_length / 2, FOOT_WIDTH / 2, SOLE_THICKNESS / 2],
            pos=[
                robot.foot_length / 2 - robot.foot_heel,
                0.0,
                -robot.ankle_height + SOLE_THICKNESS / 2,
            ],
            friction=[float(v) for v in FOOT_FRICTION.split()],
            solimp=[float(v) for v in FOOT_SOLIMP.split()],
            condim=3,
            contype=1,
            conaffinity=0,
        )
        if solref is not None:
            sole.solref = list(solref)
    return spec


def scene_model(robot: Robot, knee: str, servos=None):
    """Compiled MuJoCo model of the scene (floor and robot) from ``robot``, in memory."""
    import mujoco

    return mujoco.MjModel.from_xml_string(
        scene_xml(knee), assets={f"biped_{knee}.xml": robot_xml(robot, knee, servos).encode()}
    )


def scene_xml(knee: str) -> str:
    """A scene that includes the robot file and adds the floor, a sky and a light."""
    return "\n".join(
        [
            f'<mujoco model="scene_{knee}">',
            f'  <include file="biped_{knee}.xml"/>',
            "",
            "  <visual>",
            '    <headlight diffuse="0.5 0.5 0.5" ambient="0.3 0.3 0.3" specular="0 0 0"/>',
            f'    <global azimuth="90" elevation="-10" offwidth="{OFFSCREEN[0]}" '
            f'offheight="{OFFSCREEN[1]}"/>',
            "  </visual>",
            "",
            "  <asset>",
            # A smooth gradient: a small texture looks the same, and every copy of the
            # model (one a walk) copies it.
            '    <texture type="skybox" builtin="gradient" rgb1="0.86 0.88 0.9" '
            'rgb2="0.6 0.63 0.67" width="64" height="384"/>',
            '    <texture name="grid" type="2d" builtin="checker" width="512" height="512" '
            'rgb1="0.42 0.43 0.45" rgb2="0.32 0.33 0.35"/>',
            '    <material name="grid" texture="grid" texrepeat="1 1" texuniform="true"/>',
            "  </asset>",
            "",
            "  <worldbody>",
            '    <light name="sun" type="directional" dir="0.3 0.6 -1" diffuse="0.6 0.6 0.6"/>',
            '    <geom name="floor" type="plane" size="0 0 0.05" material="grid" '
            f'friction="{FOOT_FRICTION}" solref="{FOOT_SOLREF}" solimp="{FOOT_SOLIMP}" '
            'contype="0" conaffinity="1"/>',
            "  </worldbody>",
            "</mujoco>",
            "",
        ]
    )


def model_files(robot: Robot | None = None) -> dict[str, str]:
    """File name -> content of every committed model."""
    robot = Robot.paper() if robot is None else robot
    files = {}
    for knee in ("revolute", "rolling"):
        files[f"biped_{knee}.xml"] = robot_xml(robot, knee)
        files[f"scene_{knee}.xml"] = scene_xml(knee)
    return files


def write_models(folder: Path = FOLDER, robot: Robot | None = None) -> list[Path]:
    folder.mkdir(parents=True, exist_ok=True)
    paths = []
    for name, text in model_files(robot).items():
        paths.append(atomic_write_text(folder / name, text))
    return paths


def stale_models(folder: Path = FOLDER, robot: Robot | None = None) -> list[Path]:
    """The model files in ``folder`` that are missing or differ from what ``robot`` gives."""
    stale = []
    for name, text in model_files(robot).items():
        path = folder / name
        try:
            current = path.read_text(encoding="utf-8")
        except (OSError, UnicodeDecodeError):
            current = None
        if current != text:
            stale.append(path)
    return stale


def main(argv: list[str] | None = None) -> int:
    """``python -m validate.scene.mjcf [--check]``; returns the exit status."""
    import argparse

    parser = argparse.ArgumentParser(
        prog="python -m validate.scene.mjcf",
        description=f"Write the MJCF models of both knees ({FOLDER}/*.xml) from "
        "biped.Robot.paper(), or check that they are up to date.",
        epilog="Exit status: 0 written or up to date, 1 out of date (--check), 2 error.",
    )
    parser.add_argument(
        "--check",
        action="store_true",
        help="report the files that are missing or out of date, rewrite nothing; exit 1 if any",
    )
    args = parser.parse_args(argv)
    try:
        if args.check:
            stale = stale_models(FOLDER)
            for path in stale:
                print(f"out of date: {path} (run: python -m validate.scene.mjcf)")
            if not stale:
                print(f"up to date: {len(model_files())} files in {FOLDER}")
            return 1 if stale else 0
        for written in write_models(FOLDER):
            print(f"wrote {written}", file=sys.stderr)
    except OSError as error:
        print(f"python -m validate.scene.mjcf: error: {error}", file=sys.stderr)
        return 2
    return 0


if __name__ == "__main__":
    sys.exit(main())
