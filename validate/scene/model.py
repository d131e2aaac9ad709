"""The MuJoCo model a gait is validated on, and what the validation needs to find in it.

    model_spec(biped, path)  the MJCF to play the gait on: ``path`` if given; otherwise the
                             committed ``mjcf/scene_<knee>.xml`` when the gait's robot is
                             Table 1 (``Robot.paper()``), the model generated from the gait's
                             robot when it is another robot
    with_servos(spec, ...)   the same model with the joint-space feedback of the forward
                             simulation: a position and a velocity actuator on each joint (the
                             knee tendon for the rolling knee), after the model's own actuators

A model the validation cannot read at all (a file that does not compile, a knee of the other
kind, a joint, site, actuator or sensor missing by name) is refused (``BipedError``: one line,
exit status 2). A model it can read but that is not the gait's robot (a rolling knee without
its rolling equality, or with another ratio r2/r1; a field of the gait's ``biped.Robot`` that
the model holds with another value: ``parameter_differences``) is reported by the model check
as a FAIL line naming what differs (``model_problems``); a ``ModelError`` when the harness
trips on it.
"""

from __future__ import annotations

import dataclasses
import math
from pathlib import Path

import mujoco
import numpy as np

from biped.errors import BipedError
from biped.model.dynamics import Biped
from biped.model.profile import KneeProfile
from biped.model.robot import SOLE_EDGES, Robot
from biped.model.units import robot_unit
from validate.scene.mjcf import FOLDER, FOOT_FRICTION, SIDES, robot_xml, scene_xml
from validate.scene.profile_mjcf import model_profile

# Names of the six actuated joints, in the order of every (N, 6) array of the validation.
JOINT_ORDER = tuple(f"{side}_{joint}" for side in SIDES for joint in ("hip", "knee", "ankle"))
# What the validation reads by name (as ``validate.scene.mjcf`` writes it).
BASE_JOINTS = ("rootx", "rootz", "rooty")
SITES = ("ankle", *SOLE_EDGES)  # per side
SENSORS = ("touch", "ankle_pos", "heel_pos", "toe_pos")  # per side
# Largest relative error of a rolling-knee equality's ratio against r2 / r1.
RATIO_TOLERANCE = 1e-9
# Largest relative difference of a robot's parameter read back from a model against the
# gait's robot: the MJCF holds 10 significant digits, and a knee radius is read from two
# numbers (the knee link's length r1 + r2 and the equality's r2 / r1).
PARAMETER_TOLERANCE = 1e-8


class ModelError(BipedError):
    """The model is readable but is not the gait's robot in a way the harness relies on."""


def knee_of(model: mujoco.MjModel, source: str = "the model") -> str:
    """'revolute' or 'rolling': the knee kind of a model, from its joint names; a BipedError
    naming ``source`` (the model's file) for a model of neither."""
    names = {model.joint(i).name for i in range(model.njnt)}
    if all(f"{side}_knee" in names for side in SIDES):
        return "revolute"
    if all(f"{side}_knee_{part}" in names for side in SIDES for part in ("upper", "lower")):
        return "rolling"
    raise BipedError(
        f"{source} has neither the joints left_knee, right_knee (revolute knee) nor "
        "left_knee_upper, left_knee_lower, right_knee_upper, right_knee_lower (rolling knee): "
        "allowed an MJCF of this biped (mjcf/scene_<knee>.xml, validate.scene.mjcf)"
    )


def committed_model(biped: Biped) -> Path | None:
    """The committed scene of ``biped``'s knee (``mjcf/scene_<knee>.xml``) when its robot's
    body is Table 1's (``Robot.paper()``; the actuators are not in the model); None for
    another robot (its model is generated)."""
    body = dataclasses.replace(biped.robot, actuators=None)
    return FOLDER / f"scene_{biped.knee}.xml" if body == Robot.paper() else None


def at_timestep(spec: mujoco.MjSpec, timestep: float) -> mujoco.MjSpec:
    """``spec`` (copied) integrated at ``timestep`` [s]: the same model with its contacts, its
    joints' stops and its equalities (the rolling knee's coupling) at two steps' time
    constant, the shortest MuJoCo allows, as the committed model is at its own step
    (``validate.scene.mjcf``). A shorter step is a finer model of the same robot, what the
    committed step's verdicts can be held against (``biped validate --timestep``)."""
    spec = spec.copy()
    spec.option.timestep = timestep
    solref = [2.0 * timestep, 1.0]
    for geom in spec.geoms:
        if geom.contype or geom.conaffinity:
            geom.solref = solref
    for joint in spec.joints:
        joint.solref_limit = solref
    for equality in spec.equalities:
        equality.solref = solref
    return spec


def model_spec(biped: Biped, path: str | Path | None = None) -> mujoco.MjSpec:
    """The MJCF to play a gait of ``biped`` on (see the module docstring), as a spec to add to.

    Raises BipedError naming the file if it cannot be read or compiled, or if its knee is not
    the gait's.
    """
    if path is None:
        path = committed_model(biped)
    if path is None:
        spec = mujoco.MjSpec.from_string(
            scene_xml(biped.knee),
            include={f"biped_{biped.knee}.xml": robot_xml(biped.robot, biped.knee).encode()},
        )
        source = "the model generated from the gait's robot"
    else:
        source = f"model {str(path)!r}"
        if Path(path).suffix.lower() != ".xml" or not Path(path).is_file():
            raise BipedError(f"{source} is not an MJCF file: allowed an existing .xml file")
        try:
            spec = mujoco.MjSpec.from_file(str(path))
        except (ValueError, OSError) as error:  # MuJoCo's parse errors are ValueErrors
            raise BipedError(f"{source} cannot be read: {_one_line(error)}") from None
    if not any(geom.type == mujoco.mjtGeom.mjGEOM_PLANE for geom in spec.geoms):
        _add_floor(spec)
    model = compile_spec(spec, source)
    kind = knee_of(model, source)
    if kind != biped.knee:
        raise BipedError(
            f"{source} has a {kind} knee, the gait a {biped.knee} knee: allowed a model of "
            f"the gait's knee (mjcf/scene_{biped.knee}.xml)"
        )
    _check_names(model, source)
    return spec


def compile_spec(spec: mujoco.MjSpec, source: str = "the model") -> mujoco.MjModel:
    """Compile; a model MuJoCo refuses is a BipedError naming it."""
    try:
        return spec.compile()
    except ValueError as error:
        raise BipedError(f"{source} does not compile: {_one_line(error)}") from None


def _one_line(error: Exception) -> str:
    return " ".join(str(error).split())


def _add_floor(spec: mujoco.MjSpec) -> None:
    """The floor of ``validate.scene.mjcf.scene_xml`` under a robot file given without it."""
    spec.worldbody.add_geom(
        name="floor",
        type=mujoco.mjtGeom.mjGEOM_PLANE,
        size=[0.0, 0.0, 0.05],
        friction=[float(value) for value in FOOT_FRICTION.split()],
        contype=0,
        conaffinity=1,
    )


def _check_names(model: mujoco.MjModel, source: str) -> None:
    """Refuse a model that lacks a joint, body, site, actuator or sensor read by name."""
    wanted = [(mujoco.mjtObj.mjOBJ_JOINT, name) for name in BASE_JOINTS]
    for side in SIDES:
        wanted += [(mujoco.mjtObj.mjOBJ_JOINT, f"{side}_{joint}") for joint in ("hip", "ankle")]
        wanted += [(mujoco.mjtObj.mjOBJ_BODY, f"{side}_foot")]
        wanted += [(mujoco.mjtObj.mjOBJ_SITE, f"{side}_{site}") for site in SITES]
        wanted += [(mujoco.mjtObj.mjOBJ_SENSOR, f"{side}_{sensor}") for sensor in SENSORS]
    wanted += [(mujoco.mjtObj.mjOBJ_ACTUATOR, name) for name in JOINT_ORDER]
    for kind, name in wanted:
        if mujoco.mj_name2id(model, kind, name) < 0:
            what = kind.name.removeprefix("mjOBJ_").lower()
            raise BipedError(
                f"{source} has no {what} named {name!r}: allowed a model with the names of "
                "validate.scene.mjcf (mjcf/biped_<knee>.xml)"
            )


def model_problems(model: mujoco.MjModel, biped: Biped) -> list[str]:
    """What makes ``model`` another robot than ``biped``'s: the rolling knee's equalities
    (one per side, knee_lower = (r2 / r1) knee_upper), then the first field of the robot that
    the model holds with another value, with both values (``parameter_differences``; the
    other differing fields named after it). Empty when none."""
    problems = []
    if biped.knee == "rolling" and (biped.robot.profiled or model_profile(model) is not None):
        problems += _profile_problems(model, biped)
    elif biped.knee == "rolling":
        ratio = biped.robot.r2 / biped.robot.r1
        for side in SIDES:
            seen = _knee_ratio(model, side)
            if seen is None:
                problems.append(f"{side} knee: no equality between knee_upper and knee_lower")
            elif not seen or abs(seen / ratio - 1) > RATIO_TOLERANCE:
                shown = "not a ratio" if not seen else f"{seen:.6g} knee_upper"
                problems.append(
                    f"{side} knee: knee_lower = {shown}, the gait's robot r2 / r1 = {ratio:.6g}"
                )
    differences = parameter_differences(model, biped)
    if differences:
        first, *others = differences
        also = f" (differing too: {', '.join(d.split(':')[0] for d in others)})" if others else ""
        problems.append(first + also)
    return problems


def _profile_problems(model: mujoco.MjModel, biped: Biped) -> list[str]:
    """A profiled knee's equalities (``validate.scene.profile_mjcf``) on each side, against the
    gait's robot: the arc's two, the slide's tendon and its pin; a profile against circles."""
    problems = []
    wanted = KneeProfile.of(biped.robot)
    for side in SIDES:
        held = model_profile(model, side)
        if held is None:
            problems.append(
                f"{side} knee: no profiled knee's equalities (knee_arc on knee_upper and "
                f"knee_lower), the gait's robot has k1 = {wanted.k1:.6g}, k2 = {wanted.k2:.6g}"
            )
            continue
        if not biped.robot.profiled:
            problems.append(
                f"{side} knee: a profile (k1 = {held.k1:.6g}, k2 = {held.k2:.6g}) in the "
                "model, circles in the gait's robot"
            )
        stretch = _stretch(model, side)
        expected = {"slide": 1.0, "lower": wanted.k1, "upper": wanted.k2}
        if stretch is None or any(
            not math.isclose(stretch.get(p, 0.0), v, rel_tol=PARAMETER_TOLERANCE, abs_tol=1e-12)
            for p, v in expected.items()
        ):
            problems.append(
                f"{side} knee: no pinned tendon knee_slide + k1 knee_lower + k2 knee_upper "
                f"(k1 = {wanted.k1:.6g}, k2 = {wanted.k2:.6g}) of the gait's robot"
            )
    return problems


def _stretch(model: mujoco.MjModel, side: str) -> dict | None:
    """The coefficients of the pinned tendon of ``side``'s knee slide, by joint part
    (slide, lower, upper); None without it or its equality."""
    tendon = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_TENDON, f"{side}_knee_stretch")
    if tendon < 0:
        return None
    pinned = any(
        model.eq_type[k] == mujoco.mjtEq.mjEQ_TENDON
        and model.eq_obj1id[k] == tendon
        and model.eq_obj2id[k] < 0
        and model.eq_active0[k]
        for k in range(model.neq)
    )
    if not pinned:
        return None
    parts = {}
    start, count = model.tendon_adr[tendon], model.tendon_num[tendon]
    for w in range(start, start + count):
        name = model.joint(model.wrap_objid[w]).name
        parts[name.removeprefix(f"{side}_knee_")] = float(model.wrap_prm[w])
    return parts


def _knee_ratio(model: mujoco.MjModel, side: str) -> float | None:
    """The ratio knee_lower / knee_upper of the active joint equality of ``side``'s rolling
    knee; None without one, 0.0 if it is not a plain ratio (an offset or a polynomial)."""
    upper, lower = (model.joint(f"{side}_knee_{part}").id for part in ("upper", "lower"))
    for k in range(model.neq):
        if (
            model.eq_type[k] == mujoco.mjtEq.mjEQ_JOINT
            and {model.eq_obj1id[k], model.eq_obj2id[k]} == {upper, lower}
            and model.eq_active0[k]
        ):
            data = model.eq_data[k]
            if data[0] != 0.0 or np.any(data[2:5] != 0.0) or data[1] == 0.0:
                return 0.0
            return float(data[1] if model.eq_obj1id[k] == lower else 1.0 / data[1])
    return None


def model_parameters(model: mujoco.MjModel, knee: str) -> dict[str, list[tuple[str, float]]]:
    """The fields of ``biped.Robot`` that ``model`` holds, each as the (where, value) pairs of
    every place that holds it, read back through ``validate.scene.mjcf``'s layout (bodies from the
    hip down each leg, sites of the ankle, heel, toe and head, the soles' contact spheres, the
    knee link and equality of a rolling knee, gravity). Fields the model does not hold (the
    radii of a revolute knee, the trunk's length without a ``head`` site; a rolling knee's
    radii, and the lengths and shank centre of mass they enter, without the equality whose
    ratio splits the link into r1 and r2) are left out."""
    values: dict[str, list[tuple[str, float]]] = {}

    def add(name: str, where: str, value: float):
        values.setdefault(name, []).append((where, float(value)))

    def masses(part: str, body) -> None:
        add(f"{part}_mass", body.name, body.mass[0])
        add(f"{part}_inertia", body.name, _inertia_about_y(model, body.id))

    trunk = model.body("trunk")
    masses("trunk", trunk)
    add("trunk_com", "trunk's centre of mass", trunk.ipos[2])
    head = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_SITE, "head")
    if head >= 0:
        add("trunk_length", "site head", model.site_pos[head][2])
    add("gravity", "the model's gravity", -model.opt.gravity[2])
    for side in SIDES:
        thigh, shank, foot = (model.body(f"{side}_{part}") for part in ("thigh", "shank", "foot"))
        for part, b in (("thigh", thigh), ("shank", shank), ("foot", foot)):
            masses(part, b)
        add("thigh_com", f"{side}_thigh's centre of mass", -thigh.ipos[2])
        add("foot_com", f"{side}_foot's centre of mass", -foot.ipos[2])
        sites = {end: model.site(f"{side}_{end}").pos for end in SOLE_EDGES}
        heel, toe = sites["heel"], sites["toe"]
        add("foot_heel", f"site {side}_heel", -heel[0])
        add("foot_length", f"sites {side}_heel, {side}_toe", toe[0] - heel[0])
        for end in SOLE_EDGES:
            add("ankle_height", f"site {side}_{end}", -sites[end][2])
        spheres = {}
        for end in SOLE_EDGES:
            g = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_GEOM, f"{side}_{end}_contact")
            if g >= 0 and model.geom_type[g] == mujoco.mjtGeom.mjGEOM_SPHERE:
                spheres[end] = g
                where = f"geom {side}_{end}_contact"
                radius = model.geom_size[g][0]
                add("ankle_height", where, radius - model.geom_pos[g][2])
        if len(spheres) == len(SOLE_EDGES):
            heel, toe = (model.geom_pos[spheres[end]][0] for end in SOLE_EDGES)
            add("foot_heel", f"geom {side}_heel_contact", -heel)
            add("foot_length", f"geoms {side}_heel_contact, {side}_toe_contact", toe - heel)
        r1 = r2 = 0.0
        below_thigh = shank
        profile = model_profile(model, side) if knee == "rolling" else None
        if profile is not None:  # validate.scene.profile_mjcf
            below_thigh = model.body(f"{side}_knee_link")
            r1, r2 = profile.r1, profile.r2
            where = f"equalities {side}_knee_thigh_arc, {side}_knee_shank_arc"
            for name in ("r1", "r2", "k1", "k2"):
                add(name, where, getattr(profile, name))
            add("k2", f"position of {side}_knee_link", below_thigh.pos[0])
            add("k1", f"position of {side}_foot", -foot.pos[0])
            slider = model.body(f"{side}_knee_slider")
            add("k1", f"position of {side}_knee_slider", slider.pos[0] + below_thigh.pos[0])
        elif knee == "rolling":
            below_thigh = model.body(f"{side}_knee_link")
            ratio = _knee_ratio(model, side)  # r2 / r1
            if not ratio:  # None or not a ratio (model_problems says so)
                continue
            link = -shank.pos[2]  # r1 + r2, from C2 to C1
            r1, r2 = link / (1.0 + ratio), link * ratio / (1.0 + ratio)
            where = f"length of {side}_knee_link, ratio of {side}_knee_coupling"
            add("r1", where, r1)
            add("r2", where, r2)
        add("shank_com", f"{side}_shank's centre of mass", -shank.ipos[2] + r1)
        add("thigh_length", f"position of {below_thigh.name}", -below_thigh.pos[2] + r2)
        add("shank_length", f"position of {side}_foot", -foot.pos[2] + r1)
    return values


def _inertia_about_y(model: mujoco.MjModel, body: int) -> float:
    """[kg·m²] A body's moment of inertia about the y axis through its centre of mass (the
    axis of the planar motion), from its principal moments and axes."""
    axes = np.empty(9)
    mujoco.mju_quat2Mat(axes, model.body_iquat[body])
    return float(np.square(axes.reshape(3, 3)[1]) @ model.body_inertia[body])


def parameter_differences(model: mujoco.MjModel, biped: Biped) -> list[str]:
    """The fields of ``biped``'s robot that ``model`` holds with another value
    (``model_parameters``, relative ``PARAMETER_TOLERANCE``), one line each in the order of
    ``biped.Robot``'s fields: the field, the model's value and where it is, the robot's."""
    held = model_parameters(model, biped.knee)
    lines = []
    for field in Robot.body_fields():
        wanted = getattr(biped.robot, field.name)
        unit = robot_unit(field.name)
        for where, value in held.get(field.name, []):
            if not math.isclose(value, wanted, rel_tol=PARAMETER_TOLERANCE, abs_tol=1e-12):
                lines.append(
                    f"{field.name}: {value:.6g} {unit} in the model ({where}), "
                    f"{wanted:.6g} {unit} in the gait's robot"
                )
                break
    return lines


def with_servos(spec: mujoco.MjSpec, knee: str, kp: float, kv: float) -> mujoco.MjModel:
    """Compile ``spec`` with a position (``kp`` [N·m/rad]) and a velocity (``kv`` [N·m·s/rad])
    actuator on each joint of ``JOINT_ORDER`` named ``<joint>_position``, ``<joint>_velocity``
    (the knee tendon for the rolling knee), gear 1, in MuJoCo's joint coordinates.

    The spec is copied: the caller's stays as it was.
    """
    spec = spec.copy()
    for kind in ("position", "velocity"):
        for name in JOINT_ORDER:
            tendon = knee == "rolling" and name.endswith("_knee")
            actuator = spec.add_actuator(
                name=f"{name}_{kind}",
                target=name,
                trntype=mujoco.mjtTrn.mjTRN_TENDON if tendon else mujoco.mjtTrn.mjTRN_JOINT,
            )
            if kind == "position":
                actuator.set_to_position(kp=kp)
            else:
                actuator.set_to_velocity(kv=kv)
            actuator.gear = [1.0, 0, 0, 0, 0, 0]
            actuator.ctrllimited = mujoco.mjtLimited.mjLIMITED_FALSE
            actuator.forcelimited = mujoco.mjtLimited.mjLIMITED_FALSE
    return compile_spec(spec)
