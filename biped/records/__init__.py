"""What results are written as: the gait file (``gait_file``: the ``Gait`` record and its
inner records, each field with its unit), what the atlas keeps of an optimization
(``atlas_optimum``), a sweep with double support's summary (``two_phase_sweep``), an atlas
with double support's (``atlas_two_phase``) and what produced a file (``provenance``).

May import: ``biped.model``, ``biped.optimization``, ``biped.runtime``, ``biped.errors``, numpy.
"""
