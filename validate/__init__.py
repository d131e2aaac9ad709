"""Physics validation of analytical gaits in MuJoCo, in layers, each a subpackage that imports
only those below it (and ``biped``, never ``biped_cli``):

    validate.scene     the MJCF written from ``biped.Robot``, the model a gait is validated on,
                       the maps between the paper's coordinates and MuJoCo's
    validate.walk      a gait file played in MuJoCo: its samples, the forward walk, the feet's
                       contact, one step replayed against the clock
    validate.checks    the verdicts: cross-checks, every check of a gait, the orbit, the
                       validation and its report's units
    validate.outputs   the recording, the video, where a gait's outputs go
    validate.studies   campaigns of walks: the orbit study, the robustness map, the atlas's
                       walks, the margins study

and above them ``validate.workflows`` (a gait to its file, to MuJoCo, to its recording).

MuJoCo picks its OpenGL backend when it is first imported: on Linux without a display, this
package asks for EGL (offscreen, Mesa or a GPU driver) unless ``MUJOCO_GL`` says otherwise,
so that videos render from a terminal or a CI job. Import it before ``mujoco``.
"""

import os
import sys

# Steps of a forward walk unless told otherwise (validate, pipeline, videos).
DEFAULT_STEPS = 20
# MuJoCo's physics step of the committed models [s] (``validate.scene.mjcf.TIMESTEP``; here
# so that the command line can say it without importing MuJoCo).
MODEL_TIMESTEP = 0.001
# The servos' stiffness in the walks [N·m/rad] (``validate.walk.simulate.KP``; here for the
# command line's help).
SERVO_KP = 2000.0

if sys.platform.startswith("linux") and not (
    os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY")
):
    os.environ.setdefault("MUJOCO_GL", "egl")
# The rerun SDK's own log lines (a viewer that does not answer) stay off the terminal: what
# fails reaches the user as one line of this package (``validate.outputs.record``).
os.environ.setdefault("RUST_LOG", "off")
