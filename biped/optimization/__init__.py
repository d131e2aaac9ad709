"""Optimal gaits: the nonlinear program of one step (``problem``), its exact CasADi graph built
from the model's own constants (``symbolic``), IPOPT on it (``solver``), the paper's penalised
Nelder-Mead (``penalty``), the multistart optimizer (``optimize``) and the knee radii designed
with the gait (``design``).

May import: ``biped.model``, ``biped.runtime``, ``biped.errors``, casadi, and
``biped.records.comparison`` for the sign of a difference.
"""
