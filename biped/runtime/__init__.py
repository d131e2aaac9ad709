"""The machinery under long commands: files written atomically (``files``), Ctrl-C and
SIGTERM (``interrupts``), tasks on local processes or a Dask cluster (``runner``).

May import: ``biped.errors`` and the standard library only.
"""
