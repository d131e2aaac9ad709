"""What results are written as and compared with: the gait file (``gait_file``), the unit of
every number in it (``units``), what produced a file (``provenance``) and the words and sign
of every comparison between knees (``comparison``).

May import: ``biped.model``, ``biped.optimization``, ``biped.runtime``, ``biped.errors``.
"""
