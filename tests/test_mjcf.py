"""MJCF models: generated from Robot, committed up to date, mass properties read back."""

import mujoco
import numpy as np
import pytest

import biped
from validate.mjcf import FOLDER, KNEE_LINK_MASS, model_files

ROBOT = biped.Robot.paper()


def test_committed_models_are_up_to_date():
    """mjcf/*.xml equal what validate.mjcf generates from Robot.paper()."""
    for name, text in model_files().items():
        path = FOLDER / name
        assert path.exists(), f"{name} missing: run python -m validate.mjcf"
        assert path.read_text() == text, f"{name} is out of date: run python -m validate.mjcf"


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
def test_scene_steps_without_warnings(knee):
    """The scene loads and steps (robot held at home by its motors' zero torque falling)."""
    model = mujoco.MjModel.from_xml_path(str(FOLDER / f"scene_{knee}.xml"))
    data = mujoco.MjData(model)
    mujoco.mj_resetDataKeyframe(model, data, model.key("home").id)
    mujoco.mj_step(model, data, nstep=200)
    assert all(w.number == 0 for w in data.warning)
    assert np.all(np.isfinite(data.qpos))


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
