"""The BLAS kernels every process computes with: the same on every x86-64 machine with AVX2,
whatever was imported first.

numpy's OpenBLAS (and scipy's) picks its kernels by the CPU it finds when it loads:
Haswell's on an AMD EPYC without AVX-512, SkylakeX's on a CPU with AVX-512, others
elsewhere. Their sums come in other orders, so a figure's last digits differ (1e-14
relative: a gait's costs, samples, impact), and where a solver's path is sensitive to them,
so does a result. On one AMD EPYC the atlas's richer-family solve of the revolute knee at
1 m/s and 5 cm stops at IPOPT's acceptable level with Haswell's kernels and converges with
Sandybridge's or Nehalem's (``OPENBLAS_CORETYPE``). CasADi's own OpenBLAS (under MUMPS) is
built for one CPU (Core 2) and computes alike everywhere.

``pin_kernels`` (run by ``import biped``) asks for Haswell's kernels (AVX2 and FMA: most
x86-64 CPUs since 2013 have them) through ``OPENBLAS_CORETYPE``, which every process started
from this one inherits (a campaign's workers), and switches an OpenBLAS that loaded before
``biped`` (a program or test that imported numpy first) to the same kernels, so that a
figure is the same bits whichever process computed it and whatever was imported first. A
``OPENBLAS_CORETYPE`` already set is kept (and applied to the OpenBLAS loaded already); a
CPU without AVX2 and FMA, another architecture or a system without ``/proc/cpuinfo`` keeps
its own kernels. ``kernels`` says which are asked for; gait files record it
(``biped.records.provenance``).

May import: the standard library only (it runs before numpy loads).
"""

from __future__ import annotations

import ctypes
import os
import platform
from pathlib import Path

VARIABLE = "OPENBLAS_CORETYPE"
KERNELS = "Haswell"
# What the CPU must have for ``KERNELS`` (the flags of /proc/cpuinfo).
NEEDED = frozenset({"avx2", "fma"})
X86_64 = ("x86_64", "AMD64")
# The shared objects mapped into this process (Linux).
MAPS = Path("/proc/self/maps")


def cpu_flags(cpuinfo: Path = Path("/proc/cpuinfo")) -> frozenset[str]:
    """The CPU's feature flags (Linux's ``/proc/cpuinfo``); none where it cannot be read."""
    try:
        text = cpuinfo.read_text(encoding="utf-8", errors="replace")
    except OSError:
        return frozenset()
    line = next((line for line in text.splitlines() if line.startswith("flags")), "")
    return frozenset(line.partition(":")[2].split())


def pin_kernels(environ=os.environ, machine=None, flags=None, loaded=None) -> str | None:
    """Ask OpenBLAS for ``KERNELS`` where the CPU runs them, or for the kernels
    ``OPENBLAS_CORETYPE`` names already, and switch the OpenBLAS libraries this process has
    loaded to them (see the module); returns the kernels asked for, None for the CPU's own.
    ``machine`` and ``flags`` default to this process's; ``loaded``, the OpenBLAS libraries
    to switch, to those this process has mapped (only when ``environ`` is this process's)."""
    chosen = environ.get(VARIABLE)
    if chosen is None:
        machine = platform.machine() if machine is None else machine
        if machine not in X86_64:
            return None
        if not NEEDED <= (cpu_flags() if flags is None else frozenset(flags)):
            return None
        environ[VARIABLE] = chosen = KERNELS
    if loaded is None:
        loaded = loaded_openblas() if environ is os.environ else ()
    for library in loaded:
        switch(library, chosen)
    return chosen


def kernels(environ=os.environ) -> str:
    """The OpenBLAS kernels asked for: ``OPENBLAS_CORETYPE``, or "the CPU's own"."""
    return environ.get(VARIABLE) or "the CPU's own"


class OpenBLAS:
    """An OpenBLAS library built for several CPUs (``DYNAMIC_ARCH``), loaded in this process:
    the kernels it runs, which can be chosen again while no BLAS call is under way."""

    def __init__(self, path: str | Path):
        self.path = str(path)
        self.library = ctypes.CDLL(self.path)  # loaded already: the same instance
        self.library.gotoblas_corename.restype = ctypes.c_char_p

    def kernels(self) -> str:
        """The kernels it runs ("Haswell", "SkylakeX", ...)."""
        return self.library.gotoblas_corename().decode()

    def choose(self) -> None:
        """Choose its kernels again, as it did when it loaded: ``OPENBLAS_CORETYPE`` if set,
        else the CPU's own."""
        self.library.gotoblas_dynamic_quit()
        self.library.gotoblas_dynamic_init()


def switch(library: OpenBLAS, chosen: str) -> bool:
    """Make ``library`` run the kernels ``chosen`` (``OPENBLAS_CORETYPE``, set in this
    process's environment); returns whether it had to change."""
    if library.kernels().lower() == chosen.lower():
        return False
    library.choose()
    return True


def loaded_openblas(maps: Path = MAPS) -> list[OpenBLAS]:
    """The OpenBLAS libraries built for several CPUs that this process has mapped (numpy's,
    scipy's), each once; none where the maps cannot be read."""
    try:
        text = maps.read_text(encoding="utf-8", errors="replace")
    except OSError:
        return []
    paths = dict.fromkeys(
        line.split(maxsplit=5)[5]
        for line in text.splitlines()
        if len(line.split(maxsplit=5)) == 6 and "openblas" in line.rsplit("/", 1)[-1].lower()
    )
    libraries = []
    for path in paths:
        try:
            libraries.append(OpenBLAS(path))
        except (OSError, AttributeError):  # not built for several CPUs (CasADi's), or gone
            continue
    return libraries
