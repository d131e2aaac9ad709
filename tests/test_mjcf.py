"""MJCF models: generated from Robot, committed up to date, mass properties read back, standing
on the floor at qpos0 and seen by their camera."""

import functools

import mujoco
import numpy as np
import pytest

import biped
from validate.scene.mjcf import FOLDER, KNEE_LINK_MASS, model_files, scene_model
from validate.walk.simulate import JOINT_ORDER, joint_matrix

ROBOT = biped.Robot.paper()


def test_committed_models_are_up_to_date():
    """mjcf/*.xml equal what validate.scene.mjcf generates from Robot.paper()."""
    for name, text in model_files().items():
        path = FOLDER / name
        assert path.exists(), f"{name} missing: run python -m validate.scene.mjcf"
        assert path.read_text() == text, f"{name} is out of date: run python -m validate.scene.mjcf"


@pytest.mark.parametrize("knee", biped.KNEES)
def test_mass_properties_match_robot(knee):
    """Masses, inertias, centres of mass and lengths of the compiled model match Robot."""
    model = mujoco.MjModel.from_xml_path(str(FOLDER / f"scene_{knee}.xml"))
    r1, r2 = (ROBOT.r1, ROBOT.r2) if knee == "rolling" else (0.0, 0.0)
    links = 2 * KNEE_LINK_MASS if knee == "rolling" else 0.0
    assert model.body_subtreemass[model.body("trunk").id] == pytest.approx(ROBOT.total_mass + links)
    expected = {
        "trunk": (ROBOT.trunk_mass, ROBOT.trunk_inertia, ROBOT.trunk_com),
        "thigh": (ROBOT.thigh_mass, ROBOT.thigh_inertia, -ROBOT.thigh_com),
        "shank": (ROBOT.shank_mass, ROBOT.shank_inertia, -(ROBOT.shank_com - r1)),
        "foot": (ROBOT.foot_mass, ROBOT.foot_inertia, -ROBOT.foot_com),
    }
    for side in ("left", "right"):
        for segment, (mass, inertia, com) in expected.items():
            name = segment if segment == "trunk" else f"{side}_{segment}"
            body = model.body(name)
            assert body.mass[0] == pytest.approx(mass)
            assert body.inertia[1] == pytest.approx(inertia)  # about y
            np.testing.assert_allclose(body.ipos, [0.0, 0.0, com], atol=1e-12)
    data = mujoco.MjData(model)
    mujoco.mj_resetDataKeyframe(model, data, model.key("home").id)
    mujoco.mj_forward(model, data)
    # Standing straight: ankle, heel and toe at the paper's geometry, sole on the floor.
    for side in ("left", "right"):
        ankle = data.site(f"{side}_ankle").xpos
        np.testing.assert_allclose(ankle[[0, 2]], [0.0, ROBOT.ankle_height], atol=1e-12)
        np.testing.assert_allclose(
            data.site(f"{side}_heel").xpos[[0, 2]], [-ROBOT.foot_heel, 0.0], atol=1e-12
        )
        np.testing.assert_allclose(
            data.site(f"{side}_toe").xpos[[0, 2]],
            [ROBOT.foot_length - ROBOT.foot_heel, 0.0],
            atol=1e-12,
        )
    hip = data.site("hip").xpos
    assert hip[2] == pytest.approx(ROBOT.ankle_height + ROBOT.shank_length + ROBOT.thigh_length)
    if knee == "rolling":
        link = data.body("left_knee_link").xpos - data.body("left_shank").xpos
        assert np.linalg.norm(link) == pytest.approx(r1 + r2)


@pytest.mark.parametrize("knee", biped.KNEES)
def test_soles_and_floor_have_the_robot_modules_friction(knee):
    """The friction coefficient of the soles and the floor is biped.model.robot.FOOT_FRICTION, the
    one the figures draw (MuJoCo takes the larger of the two geoms' coefficients)."""
    from biped.model.robot import FOOT_FRICTION

    model = mujoco.MjModel.from_xml_path(str(FOLDER / f"scene_{knee}.xml"))
    colliding = [
        g for g in range(model.ngeom) if model.geom_contype[g] or model.geom_conaffinity[g]
    ]
    assert colliding and model.geom("floor").id in colliding
    for g in colliding:
        assert model.geom_friction[g, 0] == FOOT_FRICTION


@pytest.mark.parametrize("knee", biped.KNEES)
def test_scene_steps_without_warnings(knee):
    """The scene loads and steps (robot held at home by its motors' zero torque falling)."""
    model = mujoco.MjModel.from_xml_path(str(FOLDER / f"scene_{knee}.xml"))
    data = mujoco.MjData(model)
    mujoco.mj_resetDataKeyframe(model, data, model.key("home").id)
    mujoco.mj_step(model, data, nstep=200)
    assert all(w.number == 0 for w in data.warning)
    assert np.all(np.isfinite(data.qpos))


@pytest.mark.parametrize("knee", biped.KNEES)
def test_a_robot_left_without_control_folds_at_its_stops_onto_the_floor(knee):
    """Dropped from standing with no control for 2 s, the robot folds like one: every hinge
    has a range, knees not inverted (their range stops 0.05 rad past straight), none passes
    its range by more than 0.02 rad, and no joint (hip, knees, ankles) goes into the floor."""
    from validate.scene.mjcf import KNEE_RANGE

    model = mujoco.MjModel.from_xml_path(str(FOLDER / f"scene_{knee}.xml"))
    hinges = [j for j in range(model.njnt) if model.jnt_type[j] == mujoco.mjtJoint.mjJNT_HINGE]
    limited = [j for j in hinges if model.jnt_limited[j]]
    assert limited == [j for j in hinges if j != model.joint("rooty").id]
    for side in ("left", "right"):
        knees = (
            [f"{side}_knee"]
            if knee == "revolute"
            else [f"{side}_knee_{p}" for p in ("upper", "lower")]
        )
        assert sum(model.joint(name).range[1] for name in knees) == pytest.approx(KNEE_RANGE[1])
    data = mujoco.MjData(model)
    mujoco.mj_resetDataKeyframe(model, data, model.key("home").id)
    low, lowest, past = model.jnt_range[limited, 0], np.inf, 0.0
    high, angles = model.jnt_range[limited, 1], model.jnt_qposadr[limited]
    points = [
        model.body(f"{side}_{body}").id for side in ("left", "right") for body in ("shank", "foot")
    ]
    for _ in range(round(2.0 / model.opt.timestep)):
        mujoco.mj_step(model, data)
        q = data.qpos[angles]
        past = max(past, float(np.max(np.maximum(low - q, q - high))))
        lowest = min(lowest, float(data.xpos[[model.body("trunk").id, *points], 2].min()))
    assert past < 0.02 and lowest > 0.02, (past, lowest)
    assert all(w.number == 0 for w in data.warning)


def test_rolling_knee_equality_and_tendon():
    """The knee hinges turn in the ratio r2 : r1 and the tendon measures the flexion."""
    model = mujoco.MjModel.from_xml_path(str(FOLDER / "scene_rolling.xml"))
    data = mujoco.MjData(model)
    for side in ("left", "right"):
        eq = model.equality(f"{side}_knee_coupling")
        assert eq.data[1] == pytest.approx(ROBOT.r2 / ROBOT.r1)
        data.joint(f"{side}_knee_upper").qpos = 0.2
        data.joint(f"{side}_knee_lower").qpos = 0.3
    mujoco.mj_forward(model, data)
    for side in ("left", "right"):
        assert data.tendon(f"{side}_knee").length[0] == pytest.approx(0.5)
        assert model.actuator(f"{side}_knee").trntype[0] == mujoco.mjtTrn.mjTRN_TENDON


def standing(model: mujoco.MjModel, qpos, seconds: float = 0.5) -> dict:
    """Hold ``qpos`` with the position servos for ``seconds``: deepest penetration of a sole
    into the floor [m], hip travel [m], largest contact force [N] and MuJoCo warnings."""
    data = mujoco.MjData(model)
    data.qpos[:] = qpos
    mujoco.mj_forward(model, data)
    hip = data.site("hip").xpos.copy()
    targets = joint_matrix(model) @ qpos
    position = [model.actuator(f"{name}_position").id for name in JOINT_ORDER]
    data.ctrl[position] = targets
    depth, force, wrench = 0.0, 0.0, np.zeros(6)
    for _ in range(round(seconds / model.opt.timestep)):
        mujoco.mj_step(model, data)
        for i in range(data.ncon):
            depth = max(depth, -data.contact[i].dist)
            mujoco.mj_contactForce(model, data, i, wrench)
            force = max(force, float(np.abs(wrench[:3]).max()))
    return {
        "depth": depth,
        "travel": float(np.linalg.norm(data.site("hip").xpos - hip)),
        "force": force,
        "warnings": int(sum(w.number for w in data.warning)),
    }


@pytest.mark.parametrize("knee", biped.KNEES)
def test_qpos0_stands_on_the_floor(knee):
    """qpos0 is the home key and the robot standing straight, its soles on the floor."""
    model = mujoco.MjModel.from_xml_path(str(FOLDER / f"scene_{knee}.xml"))
    np.testing.assert_array_equal(model.key("home").qpos, model.qpos0)
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    for side in ("left", "right"):
        for site in ("heel", "toe"):
            assert abs(data.site(f"{side}_{site}").xpos[2]) < 1e-12
    height = ROBOT.ankle_height + ROBOT.shank_length + ROBOT.thigh_length
    assert data.site("hip").xpos[2] == pytest.approx(height)


@pytest.mark.parametrize("knee", biped.KNEES)
def test_robot_held_at_qpos0_stays_on_the_floor(knee):
    """Held at qpos0 by its servos for 0.5 s, the robot sinks under 1 mm, moves under 1 cm,
    with finite contact forces near its weight; started 5 cm into the floor, it is thrown."""
    model = scene_model(ROBOT, knee, servos=(1000.0, 40.0))
    held = standing(model, model.qpos0)
    weight = ROBOT.total_mass * ROBOT.gravity
    assert held["depth"] < 1e-3, held
    assert held["travel"] < 1e-2, held
    assert np.isfinite(held["force"]) and held["force"] < weight, held
    assert held["warnings"] == 0, held
    sunk = model.qpos0.copy()
    sunk[model.joint("rootz").qposadr[0]] -= 0.05
    thrown = standing(model, sunk)
    assert thrown["depth"] > 1e-3 or thrown["travel"] > 1e-2, thrown


def render(model: mujoco.MjModel, data: mujoco.MjData, camera: str = "track") -> np.ndarray:
    renderer = mujoco.Renderer(model, height=240, width=320)
    try:
        renderer.update_scene(data, camera=camera)
        return renderer.render()
    finally:
        renderer.close()


def _can_render() -> bool:
    try:
        mujoco.Renderer(mujoco.MjModel.from_xml_string("<mujoco/>"), 8, 8).close()
    except Exception:  # no OpenGL context on this machine
        return False
    return True


needs_gl = pytest.mark.skipif(
    not _can_render(), reason="no offscreen OpenGL (MUJOCO_GL=egl or osmesa, or a display)"
)


@needs_gl
@pytest.mark.parametrize("knee", biped.KNEES)
def test_tracking_camera_sees_both_legs(knee):
    """From the scene's tracking camera at qpos0, both legs' colours fill part of the frame and
    the robot's middle is in its middle third; a robot made invisible leaves none."""
    from validate.outputs.video import leg_pixels

    model = mujoco.MjModel.from_xml_path(str(FOLDER / f"scene_{knee}.xml"))
    data = mujoco.MjData(model)
    # Legs apart, so that the far (left) leg shows beside the near one.
    data.qpos[model.joint("left_hip").qposadr[0]] = 0.4
    data.qpos[model.joint("right_hip").qposadr[0]] = -0.3
    mujoco.mj_forward(model, data)
    image = render(model, data)
    seen = leg_pixels(image)
    assert seen["left"] > 0.003 and seen["right"] > 0.003, seen
    blue = np.argwhere((image[..., 2].astype(int) - image[..., 0]) > 60)
    assert 320 / 3 < blue[:, 1].mean() < 2 * 320 / 3
    model.mat_rgba[:, 3] = 0.0  # every material transparent: the legs vanish
    seen = leg_pixels(render(model, data))
    assert seen["left"] < 1e-4 and seen["right"] < 1e-4, seen


@pytest.mark.parametrize("knee", ["rolling"])
def test_rolling_knee_discs_are_drawn(knee):
    """The rolling knee's discs have the radii r2 (thigh) and r1 (shank) and stand out of the
    links' side faces, where a side camera sees them."""
    from validate.scene.mjcf import SHANK_RADIUS, THIGH_RADIUS

    model = mujoco.MjModel.from_xml_path(str(FOLDER / f"scene_{knee}.xml"))
    for side in ("left", "right"):
        thigh, shank = model.geom(f"{side}_thigh_disc"), model.geom(f"{side}_shank_disc")
        assert thigh.size[0] == pytest.approx(ROBOT.r2)
        assert shank.size[0] == pytest.approx(ROBOT.r1)
        for disc in (thigh, shank):
            assert disc.size[1] > max(THIGH_RADIUS, SHANK_RADIUS)
            assert model.geom_group[disc.id] == 2  # shown by default


def fine_spec(gait, factor: int = 2) -> mujoco.MjSpec:
    """The committed scene of ``gait``'s knee at 1/``factor`` of its time step, each sole a box
    on the floor (four contact points) instead of its heel and toe points, the contacts and
    the knee equality as stiff as that step allows, friction harder than the normal force
    (``IMPRATIO_HARD``): the physics the committed model's cheaper settings (1 ms, two points
    a sole, friction as soft as the normal force) stand for."""
    from validate.scene import mjcf
    from validate.scene.model import model_spec

    spec = mjcf.with_box_soles(model_spec(gait.biped), ROBOT)
    step = mjcf.TIMESTEP / factor
    spec.option.timestep = step
    spec.option.impratio = mjcf.IMPRATIO_HARD
    for geom in spec.geoms:
        if geom.contype or geom.conaffinity:
            geom.solref = [2 * step, 1.0]
            geom.solimp = [float(v) for v in mjcf.FOOT_SOLIMP.split()]
    for equality in spec.equalities:
        equality.solref = [2 * step, 1.0]
    return spec


def _physics(knee: str, spec_of) -> tuple:
    """MuJoCo's inverse-dynamics torques of the optimal gait's samples and the figures of
    its 10-step walk (``validate.checks.checks.walk_figures``) on the model ``spec_of(gait)``."""
    from tests.conftest import gait_of, optimal_gait
    from validate.checks.checks import walk_figures
    from validate.checks.crosscheck import mujoco_inverse_dynamics, rigid_copy
    from validate.scene.model import compile_spec
    from validate.walk.contact import ground_reaction
    from validate.walk.samples import GaitSamples
    from validate.walk.simulate import Walker

    optimum = optimal_gait(knee)
    gait = gait_of(optimum)
    model = gait.biped
    samples = GaitSamples.from_gait(gait)
    spec = spec_of(gait)
    exact = rigid_copy(compile_spec(spec))
    torques = mujoco_inverse_dynamics(exact, model, samples.q, samples.qd, samples.qdd).torques
    sim = Walker(gait, spec).walk(10)
    figures = walk_figures(model, samples, sim, optimum.costs()["energy"], ground_reaction(sim))
    return torques, figures, samples.torques


@functools.cache
def _fine_physics(knee: str) -> tuple:
    return _physics(knee, fine_spec)


def settings_differences(knee: str, spec_of) -> list[str]:
    """What tells the model ``spec_of(gait)`` from the finer one (``fine_spec``) on the
    optimal gait of ``knee``: inverse dynamics other than the finer model's (1e-9 N·m) or
    the gait's (1e-6 N·m); a 10-step walk that fails, slips by 1 mm or more, or differs from
    the finer model's by more than 1 % in distance, 2 % of a period in a step's duration,
    0.2 mm in the swing foot's clearance or 0.5 mm in the RMS of the centre of pressure
    against the gait's ZMP."""
    from validate.checks.checks import MAX_SLIP, walks

    torques, ours, gait_torques = _physics(knee, spec_of)
    fine_torques, fine, _ = _fine_physics(knee)
    differences = []
    if not np.allclose(torques, fine_torques, rtol=1e-7, atol=1e-9):
        differences.append("inverse dynamics other than the finer model's")
    if not np.allclose(torques, gait_torques, rtol=1e-7, atol=1e-6):
        differences.append("inverse dynamics other than the gait's")
    if not walks(ours, 10):
        differences.append("the walk fails")
    if not ours["max_slip"] < MAX_SLIP:
        differences.append(f"the stance foot slips {ours['max_slip'] * 1e3:.2f} mm")
    if not abs(ours["distance"] - fine["distance"]) <= 0.01 * abs(fine["distance"]):
        differences.append(f"distance {ours['distance']:.4f} m, finer {fine['distance']:.4f} m")
    if not np.allclose(
        ours["step_duration_range"], fine["step_duration_range"], rtol=1e-7, atol=0.02
    ):
        differences.append(
            f"step durations {ours['step_duration_range']}, finer {fine['step_duration_range']}"
        )
    if not abs(ours["swing_clearance"] - fine["swing_clearance"]) <= 2e-4:
        differences.append("swing-foot clearance")
    if not abs(ours["zmp_rms_error"] - fine["zmp_rms_error"]) < 5e-4:
        differences.append("centre of pressure against the ZMP")
    return differences


@pytest.mark.parametrize("knee", biped.KNEES)
def test_cheaper_settings_leave_the_physics(knee):
    """The committed model's 1 ms step, two contact points a sole and soft friction against
    the same robot at 0.5 ms with box soles and hard friction: nothing tells them apart
    (``settings_differences``: the same inverse dynamics, the rigid bodies being one robot,
    and the same 10-step walk within stated bounds), and the finer model walks without
    slipping."""
    from validate.checks.checks import MAX_SLIP, walks
    from validate.scene.model import model_spec

    _, fine, _ = _fine_physics(knee)
    assert walks(fine, 10) and fine["max_slip"] < MAX_SLIP, fine
    assert settings_differences(knee, lambda gait: model_spec(gait.biped)) == []


def test_settings_too_coarse_are_told_from_the_finer_model():
    """The comparison of settings can fail: a 5 ms step with contacts and knee equality of a
    20 ms time constant lets the rolling knee's stance foot slip (3 mm) and the walk go 5 %
    further. (As stiff as the 5 ms step allows, 10 ms, the slip lies at the 1 mm bound: 0.73
    mm on an optimum that differs from another by 1e-10 of its value, over 1 mm on that one.)"""
    from validate.scene.model import model_spec

    def coarse(gait):
        spec = model_spec(gait.biped)
        spec.option.timestep = 0.005
        for geom in spec.geoms:
            if geom.contype or geom.conaffinity:
                geom.solref = [0.02, 1.0]
        for equality in spec.equalities:
            equality.solref = [0.02, 1.0]
        return spec

    differences = settings_differences("rolling", coarse)
    assert any("slips" in d for d in differences), differences
    assert any(d.startswith("distance") for d in differences), differences
