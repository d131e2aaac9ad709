"""The analytical model of the bipeds (the paper's section 2 and appendices A, B): the robot's
parameters and conventions (``robot``), geometry (``kinematics``), Lagrangian dynamics, ground
wrench and ZMP (``dynamics``), the force through each knee and its parts along and across the
rolling knee's line of centres (``knee_loads``), knee surfaces beyond circles (``profile``: a
family of profiles and their rolling; ``profile_biped``: the biped of such a knee), the
flat-foot impact (``impact``), the double support phase, a closed chain with both feet flat,
and the split of its load (``double_support``), a step of single then double support
(``two_phase``), the spline gait of one step (``gait``, section 3), the Bézier family the
paper names for its future work (``bezier``), their criteria and constraints (``criteria``,
section 4),
and the unit of every number, declared beside the fields of the records that hold them
(``units``); ours: the joints' motors and gears and what they draw (``actuators``), the
vendors' datasheets they are read from (``datasheets``, ``catalog.json``: the catalog, of
which the default set), and their sizing from a catalog (``sizing``).

May import: ``biped.errors``, numpy, scipy. Nothing here knows of solvers, files or MuJoCo.
"""
