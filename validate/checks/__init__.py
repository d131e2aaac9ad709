"""The verdicts on a gait in MuJoCo: the analytical model against MuJoCo's dynamics
(``crosscheck``) and its profiled knee (``knee_fit``), every check of a gait file, each a
``Check`` (``checks``), the stability of its walk's orbit (``orbit``), the validation that
runs them all on one model and its report (``validation``), and the unit of each of the
report's figures (``units``).

May import: ``validate.walk``, ``validate.scene``, ``biped.model``, ``biped.records``,
``biped.errors``, ``validate`` (its ``__init__``), numpy, mujoco.
"""
