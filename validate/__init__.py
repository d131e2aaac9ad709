"""Physics validation of analytical gaits in MuJoCo (models, cross-checks, recordings, videos).

MuJoCo picks its OpenGL backend when it is first imported: on Linux without a display, this
package asks for EGL (offscreen, Mesa or a GPU driver) unless ``MUJOCO_GL`` says otherwise,
so that videos render from a terminal or a CI job. Import it before ``mujoco``.
"""

import os
import sys

# Steps of a forward walk unless told otherwise (validate, pipeline, videos).
DEFAULT_STEPS = 20

if sys.platform.startswith("linux") and not (
    os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY")
):
    os.environ.setdefault("MUJOCO_GL", "egl")
# The rerun SDK's own log lines (a viewer that does not answer) stay off the terminal: what
# fails reaches the user as one line of this package (``validate.record``).
os.environ.setdefault("RUST_LOG", "off")
