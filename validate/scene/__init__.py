"""The MuJoCo scene a gait is played in: the MJCF of both bipeds written from ``biped.Robot``
(``mjcf``, the profiled knee's joints and equalities: ``profile_mjcf``), the model a gait is
validated on and what the validation needs to find in it (``model``), the maps between the
paper's coordinates and MuJoCo's (``mapping``) and where each quantity lives in a compiled
model (``layout``).

May import: ``biped.model``, ``biped.runtime``, ``biped.errors``, ``validate`` (its
``__init__``), numpy, mujoco. Nothing here walks, checks or writes a result.
"""
