"""Rerun recordings of a validation: the analytical gait and MuJoCo's walk side by side.

Entity paths, on the timeline ``time`` (seconds of simulation):

    analytic/robot/{links,feet,knees}   the gait, legs alternating, drawn in the x-z plane
    mujoco/robot/{links,feet,knees}     the MuJoCo simulation, drawn the same way
    torques/Γ{i}_{joint}/{analytic,mujoco}  motor torques [N·m] (MuJoCo: feedforward + feedback)
    ground/{Fx,Fz}/{analytic,mujoco}    ground reaction on the stance foot [N]
    zmp/{analytic,mujoco,heel,toe}      ZMP from the stance ankle and the foot's limits [m]
    phase                               the gait's time the controller follows, over T

The default blueprint puts the two robots side by side above the time series. Drawings use
(x, -z) so that the robot stands upright in rerun's 2D views (y down).
"""

from __future__ import annotations

import os
from pathlib import Path

import mujoco
import numpy as np
import rerun as rr
import rerun.blueprint as rrb

from biped.dynamics import JOINTS, Biped
from biped.gait import angles_at
from validate.mapping import mapping
from validate.mjcf import SIDES
from validate.simulate import Simulation, reference_along

FRAME_EVERY = 20  # draw the robots every 20 simulation steps (50 Hz)
CIRCLE = np.linspace(0.0, 2 * np.pi, 33)
ANALYTIC_COLOR = (80, 140, 230)
MUJOCO_COLOR = (230, 120, 60)


def blueprint() -> rrb.Blueprint:
    """Two robots side by side above torques, ground reaction and ZMP."""
    return rrb.Blueprint(
        rrb.Vertical(
            rrb.Horizontal(
                rrb.Spatial2DView(origin="analytic", name="analytical gait"),
                rrb.Spatial2DView(origin="mujoco", name="MuJoCo"),
            ),
            rrb.Horizontal(
                rrb.TimeSeriesView(origin="torques", name="torques [N·m]"),
                rrb.TimeSeriesView(origin="ground", name="ground reaction [N]"),
                rrb.TimeSeriesView(origin="zmp", name="ZMP [m]"),
                rrb.TimeSeriesView(origin="phase", name="phase [T]"),
            ),
            row_shares=[3, 2],
        ),
        collapse_panels=True,
    )


def _flip(points):
    points = np.asarray(points, dtype=float)
    return np.stack([points[..., 0], -points[..., 1]], axis=-1)


def _circle(centre, radius):
    return _flip(centre + radius * np.stack([np.cos(CIRCLE), np.sin(CIRCLE)], -1))


def _log_robot(rec, path, points: dict, radii, color):
    legs = [[points[f"{s}_hip"], points[f"{s}_knee"], points[f"{s}_ankle"]] for s in SIDES]
    links = [_flip(leg) for leg in legs] + [_flip([points["hip"], points["head"]])]
    feet = [
        _flip([points[f"{s}_ankle"], points[f"{s}_heel"], points[f"{s}_toe"], points[f"{s}_ankle"]])
        for s in SIDES
    ]
    rec.log(f"{path}/links", rr.LineStrips2D(links, colors=color, radii=0.012))
    rec.log(f"{path}/feet", rr.LineStrips2D(feet, colors=color, radii=0.006))
    r1, r2 = radii
    if r1 + r2 > 0.0:
        circles = [_circle(points[f"{s}_c2"], r2) for s in SIDES]
        circles += [_circle(points[f"{s}_c1"], r1) for s in SIDES]
        rec.log(f"{path}/knees", rr.LineStrips2D(circles, colors=color, radii=0.004))


def analytic_points(biped: Biped, step, sim: Simulation, k: int) -> dict:
    """Named points of the analytical gait at simulation state k (same step as MuJoCo)."""
    j = int(np.searchsorted(sim.step_starts, k, side="right") - 1)
    angles, rates, accel = angles_at(step, sim.phase[k] / step.period)
    q, *_ = biped.single_support(angles, rates, accel)
    stance = sim.stances[j]
    swing = SIDES[1 - SIDES.index(stance)]
    names = {
        "hip": "hip",
        "head": "head",
        **{
            f"{side}_{part}": f"{role}_{part}"
            for side, role in ((stance, "stance"), (swing, "swing"))
            for part in ("knee", "ankle", "heel", "toe")
        },
        **{
            f"{side}_c2": f"{role}_knee_thigh"
            for side, role in ((stance, "stance"), (swing, "swing"))
        },
        **{
            f"{side}_c1": f"{role}_knee_shank"
            for side, role in ((stance, "stance"), (swing, "swing"))
        },
    }
    xy = biped.points(q, list(names.values()))
    offset = np.array([j * step.step_length, 0.0])
    points = {key: xy[i] + offset for i, key in enumerate(names)}
    for side in SIDES:
        points[f"{side}_hip"] = points["hip"]
    return points


def mujoco_points(model: mujoco.MjModel, data: mujoco.MjData, biped: Biped) -> dict:
    """Named points of the MuJoCo robot in data (after mj_kinematics)."""
    xz = lambda v: np.asarray(v)[[0, 2]]  # noqa: E731
    points = {"hip": xz(data.site("hip").xpos)}
    top = data.xmat[model.body("trunk").id].reshape(3, 3) @ [0.0, 0.0, biped.robot.trunk_length]
    points["head"] = points["hip"] + top[[0, 2]]
    rolling = biped.knee == "rolling"
    for side in SIDES:
        points[f"{side}_hip"] = points["hip"]
        points[f"{side}_ankle"] = xz(data.site(f"{side}_ankle").xpos)
        points[f"{side}_heel"] = xz(data.site(f"{side}_heel").xpos)
        points[f"{side}_toe"] = xz(data.site(f"{side}_toe").xpos)
        shank = xz(data.body(f"{side}_shank").xpos)
        if rolling:
            c2 = xz(data.body(f"{side}_knee_link").xpos)
            points[f"{side}_c2"], points[f"{side}_c1"] = c2, shank
            r2 = biped.radii[1]
            points[f"{side}_knee"] = c2 + r2 * (shank - c2) / np.linalg.norm(shank - c2)
        else:
            points[f"{side}_knee"] = shank
    return points


def record(path: str | Path, biped: Biped, step, sim: Simulation, contact: dict) -> Path:
    """Write the recording of a validation to ``path`` (.rrd), atomically.

    Args:
        contact: MuJoCo's stance-foot force (N, 2) and centre of pressure (N,) as
            ``{"force": ..., "cop": ...}`` (NaN where not sampled or in double support).
    """
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_name(f".{path.name}.tmp")
    rec = rr.RecordingStream("biped_validation", recording_id=f"{biped.knee}-{path.stem}")
    try:
        rec.save(str(tmp), default_blueprint=blueprint())
    except RuntimeError as error:  # rerun reports an unwritable file this way
        raise OSError(f"cannot write the recording {str(path)!r}: {error}") from None
    model = sim.model
    data = mujoco.MjData(model)
    time_column = [rr.TimeColumn("time", duration=sim.time)]
    _, torques, wrench, zmp = reference_along(biped, step, sim)
    # MuJoCo's torques in the paper's order (stance, swing): motors plus feedback servos.
    stance_of = sim.stance_of()
    applied = sim.motors() + sim.feedback()  # JOINT_ORDER = motor order
    mj_torques = np.zeros_like(torques)
    for stance in SIDES:
        rows = stance_of == stance
        order = mapping(model, stance, biped.radii).actuator_order
        mj_torques[rows] = applied[np.ix_(rows, order)]
    for i, joint in enumerate(JOINTS):
        for source, values in (("analytic", torques[:, i]), ("mujoco", mj_torques[:, i])):
            rec.send_columns(
                f"torques/Γ{i + 1}_{joint}/{source}",
                indexes=time_column,
                columns=rr.Scalars.columns(scalars=values),
            )
    for i, name in enumerate(("Fx", "Fz")):
        rec.send_columns(
            f"ground/{name}/analytic",
            indexes=time_column,
            columns=rr.Scalars.columns(scalars=wrench[:, i]),
        )
        sampled = ~np.isnan(contact["force"][:, i])
        rec.send_columns(
            f"ground/{name}/mujoco",
            indexes=[rr.TimeColumn("time", duration=sim.time[sampled])],
            columns=rr.Scalars.columns(scalars=contact["force"][sampled, i]),
        )
    rec.send_columns("zmp/analytic", indexes=time_column, columns=rr.Scalars.columns(scalars=zmp))
    rec.send_columns(
        "phase", indexes=time_column, columns=rr.Scalars.columns(scalars=sim.phase / step.period)
    )
    sampled = ~np.isnan(contact["cop"])
    rec.send_columns(
        "zmp/mujoco",
        indexes=[rr.TimeColumn("time", duration=sim.time[sampled])],
        columns=rr.Scalars.columns(scalars=contact["cop"][sampled]),
    )
    robot = biped.robot
    for name, value in (("heel", -robot.foot_heel), ("toe", robot.foot_length - robot.foot_heel)):
        rec.send_columns(
            f"zmp/{name}",
            indexes=time_column,
            columns=rr.Scalars.columns(scalars=np.full(len(sim.time), value)),
        )
    for k in range(0, len(sim.time), FRAME_EVERY):
        rec.set_time("time", duration=float(sim.time[k]))
        _log_robot(
            rec, "analytic/robot", analytic_points(biped, step, sim, k), biped.radii, ANALYTIC_COLOR
        )
        data.qpos[:] = sim.qpos[k]
        mujoco.mj_kinematics(model, data)
        _log_robot(
            rec, "mujoco/robot", mujoco_points(model, data, biped), biped.radii, MUJOCO_COLOR
        )
    rec.flush()
    del rec
    os.replace(tmp, path)
    return path
