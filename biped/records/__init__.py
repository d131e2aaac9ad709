"""What results are written as: the gait file (``gait_file``: the ``Gait`` record and its
inner records, each field with its unit) and what produced a file (``provenance``).

May import: ``biped.model``, ``biped.optimization``, ``biped.runtime``, ``biped.errors``, numpy.
"""
