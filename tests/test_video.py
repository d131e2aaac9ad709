"""Videos of the walk: frames that show the robot, its ghost and the verdict; H.264 MP4, GIF."""

import mujoco
import numpy as np
import pytest

from biped import Robot
from biped.records import gait_file
from biped.records.gait_file import Gait
from tests.conftest import small_optimum
from tests.test_mjcf import needs_gl

pytestmark = needs_gl


@pytest.fixture(scope="module")
def walk(tmp_path_factory):
    """Two steps of the rolling knee's gait at 0.3 m/s, validated (checks and simulation)."""
    from validate.checks.validation import validate

    path = tmp_path_factory.mktemp("gait") / "rolling.json"
    Gait.from_optimum(small_optimum("rolling"), Robot.paper()).write(path)
    return validate(gait_file.read(path), steps=2)


def band_colours(band: np.ndarray) -> dict:
    """Pixels of the caption band in the verdict's colours: green (pass), red (fail)."""
    r, g, b = (band[..., i].astype(int) for i in range(3))
    return {
        "green": int(((g - r > 60) & (g - b > 40)).sum()),
        "red": int(((r - g > 80) & (r - b > 80)).sum()),
    }


def test_first_frame_shows_the_robot_and_the_verdict(walk):
    """The first frame holds both legs in their colours under a caption band whose verdict
    is green for a gait that passed and red for one that failed."""
    from validate.outputs.video import (
        CAPTION_HEIGHT,
        SIZE,
        Captioned,
        WalkRenderer,
        leg_pixels,
        verdict_of,
    )

    renderer = WalkRenderer(walk.biped, walk.samples, walk.simulation)
    try:
        verdict, passed = verdict_of(walk.checks)
        frame = Captioned(renderer, verdict, passed).frame(0)
        failed = Captioned(renderer, "FAIL: forward", False).frame(0)
    finally:
        renderer.close()
    assert frame.shape == (SIZE[1] + CAPTION_HEIGHT, SIZE[0], 3) and frame.dtype == np.uint8
    seen = leg_pixels(frame[CAPTION_HEIGHT:])
    assert seen["left"] > 0.002 and seen["right"] > 0.002, seen
    assert frame[CAPTION_HEIGHT:].std() > 10  # not a flat colour
    band = band_colours(frame[:CAPTION_HEIGHT])
    assert walk.passed and band["green"] > 50 and band["red"] == 0, band
    band = band_colours(failed[:CAPTION_HEIGHT])
    assert band["red"] > 50 and band["green"] == 0, band
    # A blank frame, or the sky alone, shows no leg.
    assert max(leg_pixels(np.zeros_like(frame)).values()) == 0.0
    assert max(leg_pixels(frame[CAPTION_HEIGHT : CAPTION_HEIGHT + 100]).values()) < 1e-4


def test_ghost_stands_on_the_stance_foot_and_follows_the_walk(walk):
    """The gait's ghost has its stance ankle on MuJoCo's at the start of each step, and its
    hip within 3 cm of MuJoCo's all along the walk (the walk follows the gait)."""
    from validate.outputs.video import WalkRenderer

    sim = walk.simulation
    renderer = WalkRenderer(walk.biped, walk.samples, sim)
    model, data = sim.model, mujoco.MjData(sim.model)
    try:
        for j, start in enumerate(sim.step_starts):
            data.qpos[:] = renderer.ghost_qpos(start)
            mujoco.mj_kinematics(model, data)
            ankle = data.site(f"{sim.stances[j]}_ankle").xpos
            mujoco_ankle = sim.sensor(f"{sim.stances[j]}_ankle_pos")[start]
            assert ankle[0] == pytest.approx(mujoco_ankle[0], abs=1e-9)
            assert ankle[2] == pytest.approx(Robot.paper().ankle_height, abs=1e-9)
        gaps = []
        for k in range(0, len(sim.time), 50):
            data.qpos[:] = renderer.ghost_qpos(k)
            mujoco.mj_kinematics(model, data)
            ghost_hip = data.site("hip").xpos.copy()
            data.qpos[:] = sim.qpos[k]
            mujoco.mj_kinematics(model, data)
            gaps.append(np.linalg.norm(ghost_hip - data.site("hip").xpos))
    finally:
        renderer.close()
    assert max(gaps) < 0.03, max(gaps)


def test_video_is_h264_with_a_frame_per_thirtieth_of_a_second(walk, tmp_path):
    """The MP4 decodes as H.264 at 30 fps, one frame per 1/30 s of the walk, the legs in
    its first frame; the GIF has every other frame at half size."""
    import imageio_ffmpeg
    from PIL import Image

    from validate.outputs.video import (
        CAPTION_HEIGHT,
        FPS,
        SIZE,
        frame_states,
        leg_pixels,
        write_video,
    )

    mp4, gif = tmp_path / "walk.mp4", tmp_path / "walk.gif"
    written = write_video(mp4, walk, gif=gif)
    assert written == [mp4, gif]
    assert not [p for p in tmp_path.iterdir() if p.name.endswith(".tmp")]
    reader = imageio_ffmpeg.read_frames(str(mp4))
    meta = next(reader)
    assert meta["codec"] == "h264" and meta["fps"] == FPS
    assert meta["size"] == (SIZE[0], SIZE[1] + CAPTION_HEIGHT)
    frames = [
        np.frombuffer(f, np.uint8).reshape(SIZE[1] + CAPTION_HEIGHT, SIZE[0], 3) for f in reader
    ]
    states = frame_states(walk.simulation)
    assert len(frames) == len(states)
    assert len(states) == pytest.approx(
        (walk.simulation.time[-1] - walk.simulation.time[0]) * FPS, abs=1.5
    )
    seen = leg_pixels(frames[0][CAPTION_HEIGHT:])
    assert seen["left"] > 0.002 and seen["right"] > 0.002, seen
    with Image.open(gif) as image:
        assert image.n_frames == (len(states) + 1) // 2
        assert image.size == (SIZE[0] // 2, (SIZE[1] + CAPTION_HEIGHT) // 2)


def test_validate_command_writes_the_video_and_a_gif(tmp_path, capsys):
    """biped validate --video --gif writes both beside each other and names them in its
    report; --gif without --video, or --video with several gaits, is refused (exit 2)."""
    import json

    from biped_cli import main

    gait = tmp_path / "rolling.json"
    Gait.from_optimum(small_optimum("rolling"), Robot.paper()).write(gait)
    mp4 = tmp_path / "walk.mp4"
    args = ["validate", str(gait), "--steps", "1", "--rrd", str(tmp_path / "r.rrd")]
    assert main([*args, "--video", str(mp4), "--gif", "--json"]) in (0, 1)
    report = json.loads(capsys.readouterr().out)
    assert report["video"] == [str(mp4), str(mp4.with_suffix(".gif"))]
    assert mp4.stat().st_size > 10_000 and mp4.with_suffix(".gif").stat().st_size > 10_000
    assert main([*args, "--gif"]) == 2
    assert "--gif" in capsys.readouterr().err
    assert main(["validate", str(gait), str(gait), "--video", str(mp4)]) == 2


def test_frame_command_writes_a_png_of_the_walk(tmp_path):
    """python -m validate.outputs.video GAIT --frame FILE.png writes one captioned frame showing both
    legs; asked for nothing to write, it refuses."""
    from PIL import Image

    from validate.outputs.video import CAPTION_HEIGHT, leg_pixels, main

    gait = tmp_path / "rolling.json"
    Gait.from_optimum(small_optimum("rolling"), Robot.paper()).write(gait)
    png = tmp_path / "walk.png"
    assert main([str(gait), "--steps", "1", "--frame", str(png), "--at", "0"]) == 0
    image = np.asarray(Image.open(png).convert("RGB"))
    seen = leg_pixels(image[CAPTION_HEIGHT:])
    assert seen["left"] > 0.002 and seen["right"] > 0.002, seen
    with pytest.raises(SystemExit):
        main([str(gait)])
