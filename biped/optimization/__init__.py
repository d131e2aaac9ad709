"""Optimal gaits: the nonlinear program of one step (``problem``), its exact CasADi graph built
from the model's own constants (``symbolic``) and its derivatives sample by sample
(``derivatives``, compiled to machine code and cached on disk where a C compiler is found:
``compiled``), IPOPT on it (``solver``), the paper's penalised Nelder-Mead (``penalty``),
the multistart optimizer (``optimize``) with the shipped table of optima among its starts
(``table``), the knee radii designed with the gait (``design``), a profiled knee written in
CasADi (``profile_graph``) and its surfaces designed with the gait (``profile_design``), and
the words and sign with
which optima are compared (``comparison``: a difference between knees, "certified", the two
grids of a criterion), and the two knees' optima compared, each difference with what moves it
and a verdict (``knees``), and one problem's optima over a ladder of nested gait families
(``ladder``).

May import: ``biped.model``, ``biped.runtime``, ``biped.errors``, numpy, scipy, casadi.
"""
