"""Analytical models of planar bipeds with revolute or rolling knees.

import biped
model = biped.Biped(biped.Robot.paper(), knee="rolling")
torques, wrench = model.inverse_dynamics(q, qd, qdd)
"""

from biped.dynamics import JOINTS, Biped
from biped.errors import BipedError, ParameterError, UnreachableError
from biped.kinematics import COORDINATES, KNEES, swap_legs
from biped.robot import Robot

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
