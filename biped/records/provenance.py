"""Provenance: what produced an output file, to tell outputs of different runs apart.

Versions are read from the installed packages' metadata (``importlib.metadata``), so asking
for MuJoCo's version does not import MuJoCo. Nothing here depends on the time or the host's
state beyond the installed software and the BLAS kernels asked for (``biped.runtime.blas``),
so two runs of the same command give the same record.
"""

from __future__ import annotations

import contextlib
import importlib.metadata
import platform
import shlex
import sys
from collections.abc import Iterator, Sequence

from biped.runtime.blas import kernels

# The distribution name of this project (pyproject.toml).
PACKAGE = "biped-rolling-knee"
# Packages whose versions shape the numbers: the analytical side, then the simulator.
DEPENDENCIES = ("numpy", "scipy", "casadi", "mujoco")

_command: list[str] | None = None


def version(distribution: str = PACKAGE) -> str | None:
    """The installed version of ``distribution``; None when it is not installed."""
    try:
        return importlib.metadata.version(distribution)
    except importlib.metadata.PackageNotFoundError:
        return None


@contextlib.contextmanager
def command_line(argv: Sequence[str]) -> Iterator[None]:
    """Within the block, ``provenance()`` records ``argv`` as the command line.

    For a command run in-process (``biped_cli.main(argv)``), where ``sys.argv`` is that of
    the caller.
    """
    global _command
    previous, _command = _command, [str(a) for a in argv]
    try:
        yield
    finally:
        _command = previous


def provenance(argv: Sequence[str] | None = None) -> dict:
    """Versions of this project, its numerical dependencies and Python, and the command line.

    Args:
        argv: the command line; default: the one of the enclosing ``command_line`` block,
            else ``sys.argv``.

    Returns:
        ``{"package", "version", "python", "platform", "numpy", "scipy", "casadi", "mujoco",
        "blas_kernels", "command"}``: versions are strings, None for a package that is not
        installed; ``blas_kernels`` the OpenBLAS kernels asked for
        (``biped.runtime.blas``); ``command`` is the command line as one shell-quoted string.
    """
    if argv is None:
        argv = _command if _command is not None else sys.argv
    return {
        "package": PACKAGE,
        "version": version(),
        "python": platform.python_version(),
        "platform": platform.platform(),
        **{name: version(name) for name in DEPENDENCIES},
        "blas_kernels": kernels(),
        "command": shlex.join(str(a) for a in argv),
    }
