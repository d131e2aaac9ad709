"""OpenBLAS's kernels: the same on every x86-64 machine with AVX2 (``biped.runtime.blas``)."""

import os
import subprocess
import sys
from pathlib import Path

import pytest

import biped
from biped.runtime import blas

AVX2 = {"sse2", "avx", "avx2", "fma"}
# Whether this machine pins the kernels (an x86-64 CPU with AVX2 and FMA).
PINNED = blas.platform.machine() in blas.X86_64 and blas.NEEDED <= blas.cpu_flags()


def test_kernels_are_pinned_where_the_cpu_runs_them():
    """An x86-64 CPU with AVX2 and FMA is asked for Haswell's kernels, numpy loaded or not; a
    user's choice is kept; a CPU without them or another architecture keep their own."""
    environ = {}
    assert blas.pin_kernels(environ, "x86_64", AVX2, loaded=()) == "Haswell"
    assert environ == {"OPENBLAS_CORETYPE": "Haswell"}
    assert blas.kernels(environ) == "Haswell"
    kept = {"OPENBLAS_CORETYPE": "Sandybridge"}
    assert blas.pin_kernels(kept, "x86_64", AVX2, loaded=()) == "Sandybridge"
    assert blas.pin_kernels({}, "x86_64", AVX2, loaded=()) == "Haswell"  # numpy here loaded
    for machine, flags, loaded in (
        ("x86_64", {"sse2", "avx"}, ()),  # no AVX2: Haswell's kernels would not run
        ("aarch64", AVX2, ()),
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
    expected = "Haswell|Haswell" if PINNED else "None|the CPU's own"
    assert done.stdout.strip() == expected


def test_cpu_flags_of_a_cpuinfo(tmp_path):
    """The flags line of /proc/cpuinfo's first CPU; none from a file that is not there."""
    cpuinfo = tmp_path / "cpuinfo"
    cpuinfo.write_text("processor\t: 0\nflags\t\t: fpu sse2 avx2 fma\nbugs\t\t: none\n")
    assert blas.cpu_flags(cpuinfo) == {"fpu", "sse2", "avx2", "fma"}
    assert blas.cpu_flags(tmp_path / "missing") == frozenset()


# A parent process whose numpy loaded with other kernels than its workers' (``KERNELS``), then
# the figures of one motion computed by the parent and by a spawned worker, compared bit for bit.
# ``FIRST`` is what the parent imports before biped; ``AFTER`` what it does to the variable
# once numpy has loaded, before biped (its workers inherit the variable as it then stands).
_PARENT_AND_WORKER = """
import os, sys
os.environ["OPENBLAS_CORETYPE"] = "Sandybridge"  # no FMA: sums rounded otherwise than Haswell's
import numpy
{after}
import biped
from concurrent.futures import ProcessPoolExecutor
from multiprocessing import get_context

from tests.test_blas import figures_of_a_motion

with ProcessPoolExecutor(1, mp_context=get_context("spawn")) as pool:
    worker = pool.submit(figures_of_a_motion).result()
print(figures_of_a_motion() == worker)
"""


def figures_of_a_motion() -> bytes:
    """The rolling knee's torques and ground wrench on seeded motions, as bytes."""
    import numpy as np

    from tests.conftest import random_state

    model = biped.Biped(biped.Robot.paper(), "rolling")
    torques, wrench = model.inverse_dynamics(*random_state(model, 0))
    return np.concatenate([torques.ravel(), wrench.ravel()]).tobytes()


def _same_in_parent_and_worker(after: str) -> bool:
    code = _PARENT_AND_WORKER.format(after=after)
    environ = {k: v for k, v in os.environ.items() if k != "OPENBLAS_CORETYPE"}
    environ["PYTHONPATH"] = str(Path(__file__).parents[1])
    done = subprocess.run(
        [sys.executable, "-c", code], env=environ, capture_output=True, text=True, timeout=120
    )
    assert done.returncode == 0, done.stderr
    return {"True": True, "False": False}[done.stdout.strip()]


@pytest.mark.skipif(not PINNED, reason="keeps the CPU's own kernels (no AVX2 and FMA)")
def test_a_process_that_loaded_numpy_first_computes_as_its_workers():
    """A figure is the same bits whichever process computed it and whatever it imported first:
    a parent whose numpy loaded with other kernels (an AVX-512 CPU's own, here Sandybridge's)
    is switched by ``import biped`` to the kernels its spawned workers load with. Kept on
    other kernels than its workers (its own choice of the variable), it computes otherwise."""
    assert _same_in_parent_and_worker(after='del os.environ["OPENBLAS_CORETYPE"]')
    apart = 'import biped; os.environ["OPENBLAS_CORETYPE"] = "Haswell"  # the workers only'
    assert not _same_in_parent_and_worker(after=apart)


@pytest.mark.skipif(not PINNED, reason="keeps the CPU's own kernels (no AVX2 and FMA)")
def test_loaded_openblas_is_switched_to_the_kernels_asked_for():
    """This process's numpy runs the kernels ``OPENBLAS_CORETYPE`` asks for (the test process
    imported numpy before biped)."""
    libraries = blas.loaded_openblas()
    assert libraries, "numpy's OpenBLAS is not among this process's libraries"
    assert {library.kernels() for library in libraries} == {os.environ["OPENBLAS_CORETYPE"]}
