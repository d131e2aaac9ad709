"""Videos of MuJoCo's walk: the tracking camera, the floor, the analytical gait as a ghost and a
caption band with the step, the time and the verdict of the validation.

    python -m validate.outputs.video GAIT.json --out walk.mp4 [--gif walk.gif] [--steps 20]
    python -m validate.outputs.video GAIT.json --frame docs/walk.png [--at 2.0]

The frames are the states that ``validate.walk.simulate.simulate`` recorded (no simulation of
its own): one every 1 / ``FPS`` s, drawn by MuJoCo's offscreen renderer (set
``MUJOCO_GL=egl`` on a machine without a display) from the model's ``track`` camera. The
ghost is the gait at the phase the controller followed, its stance foot on MuJoCo's stance
foot, drawn as translucent copies of the model's geoms (``mjv_addGeoms``) a little behind the
robot. The MP4 is H.264
(yuv420p) written by imageio-ffmpeg's ffmpeg; the GIF, smaller and slower, by Pillow. A path
whose suffix is not that of the file written there (``walk.avi`` for the MP4) is refused
before any work (``check_suffix``).
"""

from __future__ import annotations

import argparse
import contextlib
import sys
from functools import lru_cache
from pathlib import Path

import mujoco
import numpy as np

from biped.model.dynamics import Biped
from biped.runtime.files import atomic_path
from validate import DEFAULT_STEPS
from validate.scene.mapping import mapping
from validate.scene.mjcf import SIDES
from validate.walk.simulate import Simulation

# Frames per second of the video (simulated time runs at real time).
FPS = 30
# Rendered image [px] (width, height), multiples of 16 as H.264 encoders prefer; the caption
# band adds CAPTION_HEIGHT above it.
SIZE = (768, 432)
CAPTION_HEIGHT = 48
# The GIF: every GIF_EVERY-th frame, scaled by GIF_SCALE.
GIF_EVERY = 2
GIF_SCALE = 0.5
# Colour (RGBA) of the analytical gait's ghost, and its offset behind the robot (+y, away
# from the camera) [m]: beside the robot, not through it.
GHOST_RGBA = (0.95, 0.95, 1.0, 0.4)
GHOST_OFFSET = 0.35
# Offscreen rendering on a CPU (llvmpipe): shadows from a 1024 px map and no multisampling
# draw a frame in about 45 ms instead of 110 ms.
SHADOW_SIZE = 1024
OFFSCREEN_SAMPLES = 0
# A pixel shows a leg when its colour's dominant channel (blue for the left leg, red for the
# right one) exceeds the other two by these margins [0-255]: grey floor, sky and trunk do not.
LEG_MARGIN = (40, 60)
PASS_COLOR, FAIL_COLOR, TEXT_COLOR = (90, 210, 110), (240, 80, 70), (235, 235, 235)
# What each writer produces, by the suffix of its path (any case).
WRITTEN = {".mp4": "an H.264 MP4 video", ".gif": "an animated GIF", ".png": "a PNG image"}


def check_suffix(path: str | Path, option: str, suffix: str, hint: str = "") -> None:
    """Refuse (BipedError naming ``option`` and ``path``) a path whose suffix is not
    ``suffix``, that of the file written there; ``hint`` ends the message."""
    from biped.errors import BipedError

    found = Path(path).suffix
    if found.lower() != suffix:
        named = f"named {found}" if found else "without a suffix"
        raise BipedError(
            f"{option} {str(path)!r}: would be {WRITTEN[suffix]} {named}; allowed a path "
            f"ending in {suffix}{hint}"
        )


def leg_pixels(image: np.ndarray) -> dict:
    """Fraction of the image's pixels (0-1) in the colour of each leg: {'left': .., 'right': ..}.

    The left leg is blue (blue above green and red), the right one orange (red above green
    and blue); the floor, the sky and the trunk are grey and count for neither.
    """
    rgb = np.asarray(image, dtype=np.int16)[..., :3]
    r, g, b = rgb[..., 0], rgb[..., 1], rgb[..., 2]
    near, far = LEG_MARGIN
    left = (b - g > near) & (b - r > far)
    right = (r - g > near) & (r - b > far)
    return {"left": float(left.mean()), "right": float(right.mean())}


class WalkRenderer:
    """Frames of a simulated walk, with the gait's ghost, from the model's tracking camera."""

    def __init__(self, biped: Biped, step, sim: Simulation, ghost: bool = True):
        self.biped, self.step, self.sim = biped, step, sim
        self.model = sim.model
        self.data = mujoco.MjData(self.model)
        self.ghost_data = mujoco.MjData(self.model) if ghost else None
        quality = self.model.vis.quality
        kept = quality.shadowsize, quality.offsamples
        quality.shadowsize, quality.offsamples = SHADOW_SIZE, OFFSCREEN_SAMPLES
        try:
            self.renderer = mujoco.Renderer(self.model, height=SIZE[1], width=SIZE[0])
        finally:
            quality.shadowsize, quality.offsamples = kept
        self.option = mujoco.MjvOption()
        self.perturb = mujoco.MjvPerturb()
        self.maps = {side: mapping(self.model, side, biped.radii) for side in SIDES}
        # MuJoCo's ankles [m]
        self.ankle_x = {side: sim.sensor(f"{side}_ankle_pos")[:, 0] for side in SIDES}

    def close(self) -> None:
        self.renderer.close()

    def step_of(self, k: int) -> int:
        """Index of the step that state k belongs to."""
        return int(np.searchsorted(self.sim.step_starts, k, side="right") - 1)

    def ghost_qpos(self, k: int) -> np.ndarray:
        """MuJoCo's qpos of the gait at the phase of state k, with its stance ankle at MuJoCo's
        stance ankle at the start of the step."""
        sim = self.sim
        j = self.step_of(k)
        stance = sim.stances[j]
        q = self.step.at("q", sim.phase[k : k + 1])[0]
        qpos = self.maps[stance].qpos(q)
        qpos[self.model.joint("rootx").qposadr[0]] += self.ankle_x[stance][sim.step_starts[j]]
        return qpos

    def render(self, k: int) -> np.ndarray:
        """The image (height, width, 3) of simulation state k."""
        self.data.qpos[:] = self.sim.qpos[k]
        self.data.qvel[:] = self.sim.qvel[k]
        mujoco.mj_forward(self.model, self.data)
        self.renderer.update_scene(self.data, camera="track", scene_option=self.option)
        if self.ghost_data is not None:
            self.ghost_data.qpos[:] = self.ghost_qpos(k)
            mujoco.mj_kinematics(self.model, self.ghost_data)
            scene = self.renderer.scene
            first = scene.ngeom
            dynamic = mujoco.mjtCatBit.mjCAT_DYNAMIC
            mujoco.mjv_addGeoms(
                self.model, self.ghost_data, self.option, self.perturb, dynamic, scene
            )
            for i in range(first, scene.ngeom):
                scene.geoms[i].rgba[:] = GHOST_RGBA
                scene.geoms[i].matid = -1
                scene.geoms[i].pos[1] += GHOST_OFFSET
        return self.renderer.render()


@lru_cache(maxsize=8)
def _font(size: int):
    from matplotlib import font_manager
    from PIL import ImageFont

    return ImageFont.truetype(font_manager.findfont("DejaVu Sans"), size)


@lru_cache(maxsize=64)
def caption_band(left: str, right: str, passed: bool | None, width: int) -> np.ndarray:
    """A dark band (CAPTION_HEIGHT, width, 3) with ``left`` at its left and ``right`` at its
    right, the latter green if ``passed``, red if not, grey if None."""
    from PIL import Image, ImageDraw

    band = Image.new("RGB", (width, CAPTION_HEIGHT), (28, 30, 34))
    draw = ImageDraw.Draw(band)
    font = _font(20)
    middle = CAPTION_HEIGHT // 2
    draw.text((14, middle), left, fill=TEXT_COLOR, font=font, anchor="lm")
    color = TEXT_COLOR if passed is None else PASS_COLOR if passed else FAIL_COLOR
    draw.text((width - 14, middle), right, fill=color, font=font, anchor="rm")
    return np.asarray(band)


def frame_states(sim: Simulation) -> np.ndarray:
    """Indices of the simulation states shown at ``FPS`` frames per second."""
    times = np.arange(sim.time[0], sim.time[-1] + 1e-9, 1.0 / FPS)
    return np.minimum(np.searchsorted(sim.time, times), len(sim.time) - 1)


class Captioned:
    """Frames with the caption: knee, speed, step j of n and the time at the left, the
    verdict at the right.

    Args:
        verdict: the text at the right (e.g. "validation PASS: 20 steps walked").
        passed: colours the verdict (green, red; None: grey).
    """

    def __init__(self, renderer: WalkRenderer, verdict: str, passed: bool | None):
        self.renderer, self.verdict, self.passed = renderer, verdict, passed

    def frame(self, k: int) -> np.ndarray:
        """State k's image under its caption (a two-phase walk's: a second band, the
        support and the verdict)."""
        image, support = self.renderer.render(k), self.support(k)
        width = image.shape[1]
        if support is None:
            bands = [caption_band(self.caption(k), self.verdict, self.passed, width)]
        else:  # the verdict beside the support, clear of the longer caption
            bands = [
                caption_band(self.caption(k), "", None, width),
                caption_band(support, self.verdict, self.passed, width),
            ]
        return np.concatenate([*bands, image], axis=0)

    def caption(self, k: int) -> str:
        """The left of state k's caption: knee, speed, step j of n, the time."""
        r = self.renderer
        steps = len(r.sim.stances)
        speed = r.step.step_length / r.step.period
        return (
            f"{r.biped.knee} knee, {speed:.2f} m/s   step {r.step_of(k) + 1} / {steps}   "
            f"t = {r.sim.time[k]:5.2f} s"
        )

    def support(self, k: int) -> str | None:
        """A two-phase walk's support at state k: double from the step's touchdown to its
        end (``Simulation.touchdowns``), else single; None for a walk of single support."""
        sim = self.renderer.sim
        if not sim.double_support:
            return None
        down = sim.touchdowns[self.renderer.step_of(k)]
        return "double support" if down is not None and k >= down else "single support"


def verdict_of(checks) -> tuple[str, bool]:
    """Caption of a list of ``validate.checks.validation.Check``: PASS or the failed checks, and the
    steps walked."""
    passed = all(check.passed for check in checks)
    failed = [check.name for check in checks if not check.passed]
    text = "PASS" if passed else "FAIL: " + ", ".join(failed)
    for check in checks:
        if check.name == "forward":
            text += f"   walked {check.figures['steps']} steps"
    return text, passed


def write_mp4(path: str | Path, frames) -> Path:
    """Write frames (iterable of equal (H, W, 3) uint8 arrays) as an H.264 MP4, atomically
    (its missing folders created)."""
    import imageio_ffmpeg

    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    frames = iter(frames)
    first = next(frames)
    height, width = first.shape[:2]
    with atomic_path(path) as tmp:
        writer = imageio_ffmpeg.write_frames(
            str(tmp),
            (width, height),
            fps=FPS,
            codec="libx264",
            pix_fmt_out="yuv420p",
            quality=7,
            macro_block_size=16,
            output_params=["-f", "mp4", "-movflags", "+faststart"],
        )
        writer.send(None)  # start ffmpeg
        try:
            writer.send(np.ascontiguousarray(first))
            for frame in frames:
                writer.send(np.ascontiguousarray(frame))
        finally:
            writer.close()
    return path


def write_gif(path: str | Path, frames) -> Path:
    """Write frames as an animated GIF (every GIF_EVERY-th, scaled by GIF_SCALE), atomically
    (its missing folders created)."""
    from PIL import Image

    images = []
    for i, frame in enumerate(frames):
        if i % GIF_EVERY == 0:
            image = Image.fromarray(frame)
            size = (round(image.width * GIF_SCALE), round(image.height * GIF_SCALE))
            images.append(image.resize(size, Image.Resampling.BILINEAR))
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    with atomic_path(path) as tmp:
        images[0].save(
            tmp,
            format="GIF",
            save_all=True,
            append_images=images[1:],
            duration=round(1000 * GIF_EVERY / FPS),
            loop=0,
        )
    return path


@contextlib.contextmanager
def _captioned(validation, ghost: bool):
    """The walk of a validation (``validate.checks.validation.Validation``) captioned with its
    verdict, its renderer closed after the block."""
    verdict, passed = verdict_of(validation.checks) if validation.checks else ("", None)
    renderer = WalkRenderer(
        validation.biped, validation.samples, validation.simulation, ghost=ghost
    )
    try:
        yield Captioned(renderer, verdict, passed)
    finally:
        renderer.close()


def write_video(
    path: str | Path | None, validation, gif: str | Path | None = None, ghost: bool = True
) -> list[Path]:
    """Render the walk of a validation (``validate.checks.validation.Validation``) to an MP4 at
    ``path`` and/or a GIF at ``gif`` (their missing folders created); returns the files
    written. Its checks give the verdict in the caption."""
    states = frame_states(validation.simulation)
    written = []
    with _captioned(validation, ghost) as captioned:
        if gif is not None:
            frames = [captioned.frame(k) for k in states]
            if path is not None:
                written.append(write_mp4(path, frames))
            written.append(write_gif(gif, frames))
        elif path is not None:
            written.append(write_mp4(path, (captioned.frame(k) for k in states)))
    return written


def frame_index(validation, at: float) -> int:
    """The recorded state at ``at`` seconds of the walk; BipedError naming ``at`` and the
    walk's span if it lies outside it."""
    from biped.errors import BipedError

    time = validation.simulation.time
    span = float(time[-1] - time[0])
    if not 0.0 <= at <= span:
        raise BipedError(f"--at {at!r} s: allowed 0 to {span:.2f} s, the walk's span")
    return int(min(np.searchsorted(time, time[0] + at), len(time) - 1))


def write_frame(path: str | Path, validation, at: float, ghost: bool = True) -> Path:
    """One captioned frame of a validation's walk, at ``at`` seconds of simulation, as a PNG
    (its missing folders created)."""
    from PIL import Image

    k = frame_index(validation, at)
    with _captioned(validation, ghost) as captioned:
        frame = captioned.frame(k)
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    with atomic_path(path) as tmp:
        Image.fromarray(frame).save(tmp, format="PNG")
    return path


def main(argv=None) -> int:
    """Validate a gait file and write the video, GIF or one frame of its walk in MuJoCo."""
    from biped.errors import BipedError
    from biped.records import gait_file
    from validate.checks.validation import validate

    parser = argparse.ArgumentParser(
        prog="python -m validate.outputs.video", description=main.__doc__
    )
    parser.add_argument("gait", metavar="GAIT.json", help="a gait file (optimize, pipeline)")
    parser.add_argument("--out", metavar="FILE.mp4", help="the video (H.264)")
    parser.add_argument("--gif", metavar="FILE.gif", help="an animated GIF of the walk")
    parser.add_argument("--frame", metavar="FILE.png", help="one frame of the walk (PNG)")
    parser.add_argument(
        "--at", type=float, default=2.0, help="time of --frame [s of simulation] (default 2)"
    )
    parser.add_argument(
        "--steps", type=int, default=DEFAULT_STEPS, help=f"steps walked (default {DEFAULT_STEPS})"
    )
    parser.add_argument("--no-ghost", action="store_true", help="leave out the gait's ghost")
    args = parser.parse_args(argv)
    if not (args.out or args.gif or args.frame):
        parser.error("nothing to write: give --out, --gif or --frame")
    try:
        for option, path, suffix in (
            ("--out", args.out, ".mp4"),
            ("--gif", args.gif, ".gif"),
            ("--frame", args.frame, ".png"),
        ):
            if path is not None:
                check_suffix(path, option, suffix)
        gait = gait_file.read_consistent(args.gait, two_phase=True)
        result = validate(gait, steps=args.steps)
        ghost = not args.no_ghost
        if args.frame:
            frame_index(result, args.at)  # before anything is written
        written = []
        if args.out or args.gif:
            written += write_video(args.out, result, gif=args.gif, ghost=ghost)
        if args.frame:
            written.append(write_frame(args.frame, result, args.at, ghost))
    except (BipedError, OSError) as error:
        print(f"error: {error}", file=sys.stderr)
        return 2
    for path in written:
        print(f"wrote {path}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
