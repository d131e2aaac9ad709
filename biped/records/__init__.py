"""What results are written as: the gait file (``gait_file``), the unit of every number in it
(``units``) and what produced a file (``provenance``).

May import: ``biped.model``, ``biped.optimization``, ``biped.runtime``, ``biped.errors``, numpy.
"""
