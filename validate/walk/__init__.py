"""MuJoCo playing a gait file: its samples as functions of time (``samples``), the forward
walk with contact, legs alternating every step (``simulate``), what the walk did with its
feet read after the fact (``contact``) and one step replayed against the clock with the
file's torques (``replay``), a two-phase gait's double support closed on the landed feet
(``anchor``).

May import: ``validate.scene``, ``biped.model``, ``biped.records``, ``biped.errors``,
``validate`` (its ``__init__``), numpy, mujoco.
"""
