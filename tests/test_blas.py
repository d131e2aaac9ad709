"""OpenBLAS's kernels: the same on every x86-64 machine with AVX2 (``biped.runtime.blas``)."""

import os
import subprocess
import sys

from biped.runtime import blas

AVX2 = {"sse2", "avx", "avx2", "fma"}


def test_kernels_are_pinned_where_the_cpu_runs_them():
    """An x86-64 CPU with AVX2 and FMA is asked for Haswell's kernels; a user's choice is
    kept; a CPU without them, another architecture or an OpenBLAS loaded already keep their
    own."""
    environ = {}
    assert blas.pin_kernels(environ, "x86_64", AVX2, loaded=()) == "Haswell"
    assert environ == {"OPENBLAS_CORETYPE": "Haswell"}
    assert blas.kernels(environ) == "Haswell"
    kept = {"OPENBLAS_CORETYPE": "Sandybridge"}
    assert blas.pin_kernels(kept, "x86_64", AVX2, loaded=()) == "Sandybridge"
    for machine, flags, loaded in (
        ("x86_64", {"sse2", "avx"}, ()),  # no AVX2: Haswell's kernels would not run
        ("aarch64", AVX2, ()),
        ("x86_64", AVX2, ("numpy",)),  # numpy's OpenBLAS chose already
    ):
        environ = {}
        assert blas.pin_kernels(environ, machine, flags, loaded) is None
        assert environ == {} and blas.kernels(environ) == "the CPU's own"


def test_importing_biped_asks_for_them_before_numpy_loads(tmp_path):
    """A process that imports biped first runs numpy and CasADi on Haswell's kernels where the
    CPU has AVX2 and FMA (the variable set before numpy loads its OpenBLAS), and records
    them in its gait files' provenance."""
    code = (
        "import os, biped, numpy; from biped.records.provenance import provenance; "
        "print(os.environ.get('OPENBLAS_CORETYPE'), provenance()['blas_kernels'], sep='|')"
    )
    environ = {k: v for k, v in os.environ.items() if k != "OPENBLAS_CORETYPE"}
    done = subprocess.run(
        [sys.executable, "-c", code], env=environ, capture_output=True, text=True, check=True
    )
    runs = blas.platform.machine() in blas.X86_64 and blas.NEEDED <= blas.cpu_flags()
    expected = "Haswell|Haswell" if runs else "None|the CPU's own"
    assert done.stdout.strip() == expected


def test_cpu_flags_of_a_cpuinfo(tmp_path):
    """The flags line of /proc/cpuinfo's first CPU; none from a file that is not there."""
    cpuinfo = tmp_path / "cpuinfo"
    cpuinfo.write_text("processor\t: 0\nflags\t\t: fpu sse2 avx2 fma\nbugs\t\t: none\n")
    assert blas.cpu_flags(cpuinfo) == {"fpu", "sse2", "avx2", "fma"}
    assert blas.cpu_flags(tmp_path / "missing") == frozenset()
