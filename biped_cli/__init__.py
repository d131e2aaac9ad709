"""The ``biped`` command line: optimize, sweep, validate and compare gaits.

Kept apart from the ``biped`` package, which holds the analytical models and never imports
the MuJoCo validation (``validate``); this package may import both.
"""

from biped_cli.main import build_parser, main

__all__ = ["build_parser", "main"]
