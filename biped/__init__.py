"""Quasi-optimal gaits of planar bipeds with revolute or rolling knees, in layers, each a
subpackage that imports only those below it:

    biped.model         robot, kinematics, dynamics, impact, gait, criteria (the paper's model),
                        units
    biped.optimization  the step's NLP, its CasADi graph, IPOPT, multistarts, knee design,
                        the words of a comparison
    biped.records       gait files, provenance
    biped.studies       campaigns of optimizations: sweep, design map, the paper's method
    biped.pages         figures and Markdown pages
    biped.runtime       atomic files, interrupts, local or Dask task runner (used by all)

The model's public names are here:

import biped
model = biped.Biped(biped.Robot.paper(), knee="rolling")
torques, wrench = model.inverse_dynamics(q, qd, qdd)
"""

from biped.errors import BipedError, ParameterError, UnreachableError
from biped.model.dynamics import JOINTS, Biped
from biped.model.kinematics import COORDINATES, KNEES, swap_legs
from biped.model.robot import Robot

__all__ = [
    "COORDINATES",
    "JOINTS",
    "KNEES",
    "Biped",
    "BipedError",
    "ParameterError",
    "Robot",
    "UnreachableError",
    "swap_legs",
]
