"""The BLAS kernels every process computes with: the same on every x86-64 machine with AVX2.

OpenBLAS, numpy's and the one CasADi's MUMPS factorizes IPOPT's systems with, picks its
kernels by the CPU it finds when it loads: Haswell's on an AMD EPYC, SkylakeX's on an Intel
Xeon with AVX-512, others elsewhere. Their sums come in other orders, so an optimum's last
digits differ, and where a solver's path is sensitive to them, so does a result. On one AMD
EPYC the atlas's richer-family solve of the revolute knee at 1 m/s and 5 cm stops at IPOPT's
acceptable level with Haswell's kernels and converges with Sandybridge's or Nehalem's
(``OPENBLAS_CORETYPE``); an Intel Xeon certified it.

``pin_kernels`` (run by ``import biped``, before numpy or CasADi loads its OpenBLAS) asks both
for Haswell's kernels (AVX2 and FMA: most x86-64 CPUs since 2013 have them), so that every
such machine computes with the same ones. A ``OPENBLAS_CORETYPE`` already set is kept; a CPU
without AVX2 and FMA, another architecture or a system without ``/proc/cpuinfo`` keeps its
own kernels, and so does a numpy loaded before ``biped`` (a program that imports numpy first
sets the variable itself). ``kernels`` says which are asked for; gait files record it
(``biped.records.provenance``).

May import: the standard library only (it runs before numpy loads).
"""

from __future__ import annotations

import os
import platform
import sys
from pathlib import Path

VARIABLE = "OPENBLAS_CORETYPE"
KERNELS = "Haswell"
# What the CPU must have for ``KERNELS`` (the flags of /proc/cpuinfo).
NEEDED = frozenset({"avx2", "fma"})
X86_64 = ("x86_64", "AMD64")


def cpu_flags(cpuinfo: Path = Path("/proc/cpuinfo")) -> frozenset[str]:
    """The CPU's feature flags (Linux's ``/proc/cpuinfo``); none where it cannot be read."""
    try:
        text = cpuinfo.read_text(encoding="utf-8", errors="replace")
    except OSError:
        return frozenset()
    line = next((line for line in text.splitlines() if line.startswith("flags")), "")
    return frozenset(line.partition(":")[2].split())


def pin_kernels(environ=os.environ, machine=None, flags=None, loaded=None) -> str | None:
    """Ask OpenBLAS for ``KERNELS`` where the CPU runs them (see the module); returns the
    kernels asked for, None for the CPU's own. ``machine``, ``flags`` and ``loaded`` (the
    modules imported) default to this process's."""
    if VARIABLE in environ:
        return environ[VARIABLE]
    loaded = set(sys.modules) if loaded is None else set(loaded)
    if {"numpy", "casadi"} & loaded:  # an OpenBLAS loaded already: left to itself
        return None
    machine = platform.machine() if machine is None else machine
    if machine not in X86_64:
        return None
    if not NEEDED <= (cpu_flags() if flags is None else frozenset(flags)):
        return None
    environ[VARIABLE] = KERNELS
    return KERNELS


def kernels(environ=os.environ) -> str:
    """The OpenBLAS kernels asked for: ``OPENBLAS_CORETYPE``, or "the CPU's own"."""
    return environ.get(VARIABLE) or "the CPU's own"
