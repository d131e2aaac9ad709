"""Campaigns of many walks in MuJoCo: the orbit's stability as a knob varies
(``orbit_study``; run over gait files and written, the knees compared: ``orbit_files``), how
far from its nominal conditions a gait still walks (``robustness``; run over gait files and
written: ``robustness_files``), every certified optimum of an atlas walked
(``atlas_walks``), and the study that chose the walkable margins (``margins_study``).

May import: ``validate.outputs``, ``validate.checks``, ``validate.walk``, ``validate.scene``,
every layer of ``biped``, ``validate`` (its ``__init__``), numpy, mujoco, matplotlib.
"""
