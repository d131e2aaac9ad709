"""The machinery under long commands: files written atomically (``files``), one run at a time
on an output (``claims``), Ctrl-C and SIGTERM (``interrupts``), tasks on local processes or a
Dask cluster (``runner``), and the BLAS kernels every process computes with (``blas``, run
by ``import biped``).

May import: ``biped.errors``, the standard library, numpy, and dask (``--dask`` only).
"""
