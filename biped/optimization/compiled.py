"""CasADi functions compiled to machine code, cached on disk: the same numbers, faster.

IPOPT's derivatives are built sample by sample (``biped.optimization.derivatives``): one
small SX function, the Hessian of one sample (about 12,000 operations) or its Jacobian
(about 4,000), mapped over the samples. CasADi's interpreter (its SX virtual machine) runs
them at some 7 ns an operation; compiled, the same operations run about ten times faster,
and the Hessian and the Jacobian, half of an IPOPT iteration's time, take a tenth of it
(``benchmarks/bench_optimize.py``).

The policy, whole:

- ``compiled(function)`` returns a function of the same inputs and outputs: ``function``
  compiled, else ``function`` itself (the interpreter).
- The compiled code is CasADi's own C code of the function (``CodeGenerator``), the same
  operations in the same order, compiled by the system's C compiler (``$CC``, else ``cc``)
  with ``FLAGS``: no fast-math, and no fused multiply-add contraction (``-ffp-contract=off``:
  a compiler may otherwise fuse a product and a sum into one rounding on CPUs that have the
  instruction). Each operation then rounds as the interpreter's does, and the results are
  the same bits (tests compare them over every family of the solver, and an optimum's every
  digit both ways).
- A compiled library is kept in the cache folder (``$BIPED_CACHE``, else
  ``$XDG_CACHE_HOME/biped``, else ``~/.cache/biped``), under ``compiled/``, named by a digest
  of everything that defines it: the C source, the compiler's version, the flags, CasADi's
  version and the machine's architecture. A process finds it there and loads it in
  milliseconds; the first builds it (about 2 s for a Hessian, 0.5 s for a Jacobian). It is
  written to a temporary file and renamed into place, and processes building the same one
  at once wait on a lock, so none reads half a library; one that does not load is built
  again.
- ``BIPED_COMPILE=0`` asks for the interpreter. Without a C compiler, or where a build or a
  load fails, the interpreter runs, and one warning says why: the numbers are the same, only
  slower (``biped.errors.CompileWarning``; the CLI prints it as one line).
"""

from __future__ import annotations

import contextlib
import functools
import hashlib
import os
import platform
import shutil
import subprocess
import tempfile
import warnings
from pathlib import Path

import casadi as ca

from biped.errors import CompileWarning

# The compiler's flags: optimised, position-independent, IEEE arithmetic kept (no
# -ffast-math) and no fused multiply-add (each product rounded, as the interpreter's).
FLAGS = ("-O1", "-fPIC", "-shared", "-ffp-contract=off")
SWITCH = "BIPED_COMPILE"  # "0" (or "off", "no", "false"): the interpreter always
_FAILED: set[str] = set()  # the functions whose build or load failed in this process
_SAID: set[str] = set()  # the warnings given in this process


def compiled(function: ca.Function) -> ca.Function:
    """``function`` (an SX function) compiled and loaded from the cache, building it there
    first if needed; ``function`` itself when compiling is off or impossible."""
    if not enabled():
        return function
    compiler = _compiler()
    if compiler is None:
        _warn(f"no C compiler ({os.environ.get('CC', 'cc')}) found")
        return function
    source = _source(function)
    library = cache_folder() / f"{function.name()}-{_digest(source, compiler)}.so"
    try:
        return _load(function.name(), source, compiler, library)
    except (OSError, RuntimeError, subprocess.SubprocessError) as error:
        _FAILED.add(function.name())
        _warn(f"{function.name()} could not be compiled ({str(error).splitlines()[0]})")
        return function


def _load(name: str, source: str, compiler, library: Path) -> ca.Function:
    """The function ``name`` of ``library``, built first if missing; a library that does
    not load (damaged, copied from elsewhere) is built again once."""
    if not library.exists():
        _build(source, compiler, library)
    try:
        return ca.external(name, str(library))
    except RuntimeError:
        library.unlink(missing_ok=True)
        _build(source, compiler, library)
        return ca.external(name, str(library))


def enabled() -> bool:
    """Whether compiling is asked for (``BIPED_COMPILE`` is not 0/off/no/false)."""
    return os.environ.get(SWITCH, "1").strip().lower() not in ("0", "off", "no", "false")


def mode() -> str:
    """How derivatives run in this process: ``"compiled"`` or ``"interpreted"`` (a build
    that fails also warns)."""
    if not enabled() or _compiler() is None:
        return "interpreted"
    return "interpreted in part" if _FAILED else "compiled"


def cache_folder() -> Path:
    """Where compiled libraries are kept: ``$BIPED_CACHE/compiled``, else under
    ``$XDG_CACHE_HOME/biped`` or ``~/.cache/biped``."""
    root = os.environ.get("BIPED_CACHE")
    if not root:
        xdg = os.environ.get("XDG_CACHE_HOME") or str(Path.home() / ".cache")
        root = str(Path(xdg) / "biped")
    return Path(root) / "compiled"


@functools.cache
def _compiler_identity(path: str) -> str | None:
    """The compiler's first line of ``--version`` (None if it does not run)."""
    try:
        done = subprocess.run([path, "--version"], capture_output=True, text=True, timeout=30)
    except (OSError, subprocess.SubprocessError):
        return None
    lines = done.stdout.splitlines()
    return lines[0] if done.returncode == 0 and lines else None


def _compiler() -> tuple[str, str] | None:
    """(path, identity) of the C compiler ``$CC`` or ``cc``, None without one."""
    path = shutil.which(os.environ.get("CC", "cc"))
    identity = path and _compiler_identity(path)
    return (path, identity) if identity else None


def _source(function: ca.Function) -> str:
    generator = ca.CodeGenerator(f"{function.name()}.c", {"with_header": False})
    generator.add(function)
    return generator.dump()


def _digest(source: str, compiler: tuple[str, str]) -> str:
    defining = [source, compiler[1], *FLAGS, ca.__version__, platform.machine()]
    return hashlib.sha256("\0".join(defining).encode()).hexdigest()[:32]


def _build(source: str, compiler: tuple[str, str], library: Path) -> None:
    """Compile ``source`` into ``library``, atomically, one process at a time."""
    library.parent.mkdir(parents=True, exist_ok=True)
    with _locked(library.with_suffix(".lock")):
        if library.exists():  # built by another process while this one waited
            return
        with tempfile.TemporaryDirectory(dir=library.parent, prefix=".build-") as work:
            c_file, built = Path(work) / "function.c", Path(work) / "function.so"
            c_file.write_text(source)
            done = subprocess.run(
                [compiler[0], *FLAGS, str(c_file), "-o", str(built), "-lm"],
                capture_output=True,
                text=True,
            )
            if done.returncode != 0:
                raise RuntimeError(f"{compiler[0]} exit {done.returncode}: {done.stderr.strip()}")
            os.replace(built, library)


@contextlib.contextmanager
def _locked(path: Path):
    """An exclusive lock on ``path`` where the platform has ``fcntl`` (else none)."""
    try:
        import fcntl
    except ImportError:  # pragma: no cover - Windows: two builds may race; each renames whole
        yield
        return
    with open(path, "a") as handle:
        fcntl.flock(handle, fcntl.LOCK_EX)
        try:
            yield
        finally:
            fcntl.flock(handle, fcntl.LOCK_UN)


def _warn(why: str) -> None:
    """Warn once a process for each reason."""
    if why in _SAID:
        return
    _SAID.add(why)
    warnings.warn(
        f"{why}: CasADi's interpreter evaluates the derivatives (the same numbers, slower; "
        f"{SWITCH}=0 asks for it without this warning)",
        CompileWarning,
        stacklevel=3,
    )
