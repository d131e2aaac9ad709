"""Tests of the project, one file per module."""

import validate  # noqa: F401  (picks MuJoCo's offscreen GL backend before mujoco is imported)
