"""The video of a two-phase walk: each frame says the step's support, single then double
from the touchdown, both legs drawn, the gait's ghost on the stance foot through both
phases."""

import mujoco
import numpy as np
import pytest

from tests.conftest import two_phase_gait
from tests.test_mjcf import needs_gl

pytestmark = needs_gl


@pytest.fixture(scope="module")
def walk():
    """Three steps of the rolling knee's zero-speed two-phase gait, validated."""
    from validate.checks.validation import validate

    return validate(two_phase_gait("rolling", "zero-speed"), steps=3)


def test_the_caption_says_the_support_and_both_legs_are_drawn(walk):
    """A state before its step's touchdown is captioned single support, one from the
    touchdown on double support, in a band of its own under the caption; a frame in double
    support shows both legs."""
    from validate.outputs.video import CAPTION_HEIGHT, SIZE, Captioned, WalkRenderer, leg_pixels

    sim = walk.simulation
    renderer = WalkRenderer(walk.biped, walk.samples, sim)
    try:
        captioned = Captioned(renderer, "FAIL", False)
        for rows, down in zip(sim.step_slices(), sim.touchdowns, strict=True):
            assert captioned.support(down - 1) == "single support"
            assert captioned.support(down) == "double support"
            assert captioned.support(rows.stop - 1) == "double support"
            assert captioned.support(rows.start) == "single support"
        middle = sim.step_slices()[1]
        frame = captioned.frame((sim.touchdowns[1] + middle.stop) // 2)
    finally:
        renderer.close()
    assert frame.shape[0] == 2 * CAPTION_HEIGHT + SIZE[1] and SIZE[1] % 2 == 0
    seen = leg_pixels(frame[2 * CAPTION_HEIGHT :])
    assert seen["left"] > 0.002 and seen["right"] > 0.002, seen


def test_the_ghost_follows_the_walk_through_both_phases(walk):
    """The gait's ghost has its stance ankle on MuJoCo's at the start of each step and its
    hip within 3 cm of MuJoCo's through the single and the double support."""
    from validate.outputs.video import WalkRenderer

    sim = walk.simulation
    renderer = WalkRenderer(walk.biped, walk.samples, sim)
    model, data = sim.model, mujoco.MjData(sim.model)
    gaps = {"single": [], "double": []}
    try:
        for j, rows in enumerate(sim.step_slices()):
            data.qpos[:] = renderer.ghost_qpos(rows.start)
            mujoco.mj_kinematics(model, data)
            ankle = sim.sensor(f"{sim.stances[j]}_ankle_pos")[rows.start]
            assert data.site(f"{sim.stances[j]}_ankle").xpos[0] == pytest.approx(ankle[0], abs=1e-9)
            for k in range(rows.start, rows.stop, 25):
                data.qpos[:] = renderer.ghost_qpos(k)
                mujoco.mj_kinematics(model, data)
                ghost_hip = data.site("hip").xpos.copy()
                data.qpos[:] = sim.qpos[k]
                mujoco.mj_kinematics(model, data)
                phase = "double" if k >= sim.touchdowns[j] else "single"
                gaps[phase].append(np.linalg.norm(ghost_hip - data.site("hip").xpos))
    finally:
        renderer.close()
    assert gaps["double"] and max(gaps["single"] + gaps["double"]) < 0.03, {
        phase: max(found) for phase, found in gaps.items()
    }


def test_validate_writes_the_video_of_a_two_phase_walk(tmp_path, capsys):
    """``biped validate F --video V`` writes the MP4 of a two-phase walk beside its
    recording (exit 0: every check passes)."""
    from biped_cli import main

    path = two_phase_gait("rolling", "zero-speed").write(tmp_path / "two.json")
    video = tmp_path / "walk.mp4"
    code = main(
        [
            "validate",
            str(path),
            "--steps",
            "2",
            "--rrd",
            str(tmp_path / "two.rrd"),
            "--video",
            str(video),
        ]
    )
    assert code == 0 and video.stat().st_size > 10_000
    assert str(video) in capsys.readouterr().out
