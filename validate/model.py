"""The MuJoCo model a gait is validated on, and what the validation needs to find in it.

    model_spec(gait, path)   the MJCF to play the gait on: ``path`` if given; otherwise the
                             committed ``mjcf/scene_<knee>.xml`` when the gait's robot is
                             Table 1 (``Robot.paper()``), the model generated from the gait's
                             robot when it is another robot
    with_servos(spec, ...)   the same model with the joint-space feedback of the forward
                             simulation: a position and a velocity actuator on each joint (the
                             knee tendon for the rolling knee), after the model's own actuators

A model the validation cannot read at all (a file that does not compile, a knee of the other
kind, a joint, site, actuator or sensor missing by name) is refused (``BipedError``: one line,
exit status 2). A model it can read but that is not the gait's robot in a way the harness
would trip on (a rolling knee without its rolling equality, or with another ratio r2/r1) is a
``ModelError``: the checks report it as a FAIL line (``model_problems``).
"""

from __future__ import annotations

from pathlib import Path

import mujoco
import numpy as np

from biped.dynamics import Biped
from biped.errors import BipedError
from biped.robot import SOLE_EDGES, Robot
from validate.mjcf import FOLDER, FOOT_FRICTION, SIDES, robot_xml, scene_xml

# Names of the six actuated joints, in the order of every (N, 6) array of the validation.
JOINT_ORDER = tuple(f"{side}_{joint}" for side in SIDES for joint in ("hip", "knee", "ankle"))
# What the validation reads by name (as ``validate.mjcf`` writes it).
BASE_JOINTS = ("rootx", "rootz", "rooty")
SITES = ("ankle", *SOLE_EDGES)  # per side
SENSORS = ("touch", "ankle_pos", "heel_pos", "toe_pos")  # per side
# Largest relative error of a rolling-knee equality's ratio against r2 / r1.
RATIO_TOLERANCE = 1e-9


class ModelError(BipedError):
    """The model is readable but is not the gait's robot in a way the harness relies on."""


def knee_of(model: mujoco.MjModel) -> str:
    """'revolute' or 'rolling': the knee kind of a model, from its joint names."""
    names = {model.joint(i).name for i in range(model.njnt)}
    if all(f"{side}_knee" in names for side in SIDES):
        return "revolute"
    if all(f"{side}_knee_{part}" in names for side in SIDES for part in ("upper", "lower")):
        return "rolling"
    raise BipedError(
        "the model has neither the joints left_knee, right_knee (revolute knee) nor "
        "left_knee_upper, left_knee_lower, right_knee_upper, right_knee_lower (rolling knee)"
    )


def committed_model(biped: Biped) -> Path | None:
    """The committed scene of ``biped``'s knee (``mjcf/scene_<knee>.xml``) when its robot is
    Table 1 (``Robot.paper()``); None for another robot (its model is generated)."""
    return FOLDER / f"scene_{biped.knee}.xml" if biped.robot == Robot.paper() else None


def model_spec(gait: dict, biped: Biped, path: str | Path | None = None) -> mujoco.MjSpec:
    """The MJCF to play ``gait`` on (see the module docstring), as a spec to add to.

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
    kind = knee_of(model)
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
    """The floor of ``validate.mjcf.scene_xml`` under a robot file given without it."""
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
                "validate.mjcf (mjcf/biped_<knee>.xml)"
            )


def model_problems(model: mujoco.MjModel, biped: Biped) -> list[str]:
    """What makes ``model`` another robot than ``biped`` in a way the harness relies on: the
    rolling knee's equalities (one per side, knee_lower = (r2 / r1) knee_upper). Empty when
    none."""
    if biped.knee != "rolling":
        return []
    ratio = biped.robot.r2 / biped.robot.r1
    problems = []
    for side in SIDES:
        upper, lower = (model.joint(f"{side}_knee_{part}").id for part in ("upper", "lower"))
        found = [
            k
            for k in range(model.neq)
            if model.eq_type[k] == mujoco.mjtEq.mjEQ_JOINT
            and {model.eq_obj1id[k], model.eq_obj2id[k]} == {upper, lower}
            and model.eq_active0[k]
        ]
        if not found:
            problems.append(f"{side} knee: no equality between knee_upper and knee_lower")
            continue
        k = found[0]
        data = model.eq_data[k]
        seen = data[1] if model.eq_obj1id[k] == lower else 1.0 / data[1]
        if data[0] != 0.0 or np.any(data[2:5] != 0.0) or abs(seen / ratio - 1) > RATIO_TOLERANCE:
            problems.append(
                f"{side} knee: knee_lower = {seen:.6g} knee_upper, the gait's robot "
                f"r2 / r1 = {ratio:.6g}"
            )
    return problems


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
