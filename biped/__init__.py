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

from biped.runtime.blas import pin_kernels

pin_kernels()  # OpenBLAS's kernels, the same on every x86-64 machine with AVX2: before numpy

from biped.errors import BipedError, ParameterError, UnreachableError  # noqa: E402
from biped.model.dynamics import JOINTS, Biped  # noqa: E402
from biped.model.kinematics import COORDINATES, KNEES, swap_legs  # noqa: E402
from biped.model.robot import Robot  # noqa: E402

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
