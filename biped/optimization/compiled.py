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
- The compiled code is CasADi's own C code of the function (``CodeGenerator``): the
  interpreter's operations, in its order. It is compiled by the system's C compiler
  (``$CC``, else ``cc``) with ``FLAGS``: IEEE arithmetic (no fast-math), no fused
  multiply-add (``-ffp-contract=off``: a product and a sum each rounded, as the
  interpreter's, which a compiler may otherwise fuse at ``-O2`` or on CPUs where the
  instruction is standard), no library call rewritten (``-fno-builtin``: ``sin`` and ``cos``
  of one angle stay two calls of the C library's, not its ``sincos``) and, on Linux, no
  symbol left unresolved (``-Wl,-z,defs``: a function the C library lacks fails the build,
  not the first call).
- Each library is checked when loaded: its outputs at a few fixed inputs must be the
  interpreter's, bit for bit, or the interpreter runs (a compiler wrapper adding its own
  flags, another C library). Tests compare both over every family of the solver, and an
  optimum's every digit both ways.
- A library is kept in the cache folder (``$BIPED_CACHE``, else ``$XDG_CACHE_HOME/biped``,
  else ``~/.cache/biped``), under ``compiled/``, named by a digest of everything that
  defines it: the function (CasADi's serialization of it, from which its C source follows),
  the compiler's command and whole ``--version``, the flags, CasADi's version, the platform
  (architecture, pointer size, C library). A process finds it there and loads it in
  milliseconds, once for all its solvers; the first builds it (about 2 s for a Hessian,
  0.5 s for a Jacobian). It is written through a temporary file and renamed into place
  (``biped.runtime.files.atomic_path``) under a lock (waited on for ``LOCK_WAIT`` at most; a
  file system without locks builds without), so that processes building the same one at
  once build it once and none reads half a library; one that does not load is built again,
  once.
- ``BIPED_COMPILE=0`` asks for the interpreter. Without a C compiler, where a build fails
  or outlasts ``BUILD_TIMEOUT``, or where a library does not load or check, the interpreter
  runs, and one warning a process says why: the numbers are the same, only slower
  (``biped.errors.CompileWarning``; the CLI prints it as one line). A library whose build
  failed is not tried again in the process, nor the compiler once it has hung.
"""

from __future__ import annotations

import contextlib
import functools
import hashlib
import os
import platform
import shlex
import shutil
import struct
import subprocess
import sys
import time
import warnings
from pathlib import Path

import casadi as ca
import numpy as np

from biped.errors import BipedError, CompileWarning
from biped.runtime.files import atomic_path

# The compiler's flags (the module's docstring says why each).
FLAGS = (
    "-O1",
    "-fPIC",
    "-shared",
    "-ffp-contract=off",
    "-fno-builtin",
    *(("-Wl,-z,defs",) if sys.platform.startswith("linux") else ()),
)
SWITCH = "BIPED_COMPILE"  # one of OFF: the interpreter always
ON, OFF = ("1", "on", "yes", "true"), ("0", "off", "no", "false")
BUILD_TIMEOUT = 300.0  # [s] a compilation still running then is abandoned
LOCK_WAIT = 600.0  # [s] the longest wait for another process's build of the same library
CHECK_COLUMNS = 3  # the fixed inputs a loaded library is checked at

_said: set[str] = set()  # the warnings given in this process
_outcomes: dict[str, bool] = {}  # the functions compiled (True) or not (False), by name
_broken_compiler: list[str] = []  # why the compiler hung, once it has
_failed_builds: dict[str, str] = {}  # why a library could not be built, by its path
_loaded: dict[str, ca.Function] = {}  # the libraries loaded and checked, by their path


class NotCompiled(Exception):
    """Why a function runs in the interpreter (said in a ``CompileWarning``)."""


def compiled(function: ca.Function) -> ca.Function:
    """``function`` (an SX function) compiled and loaded from the cache, building it there
    first if needed; ``function`` itself when compiling is off or impossible."""
    if not enabled():
        return function
    try:
        if _broken_compiler:
            raise NotCompiled(_broken_compiler[0])
        compiler = _compiler()
        if compiler is None:
            raise NotCompiled(f"no C compiler ({os.environ.get('CC', 'cc')}) found")
        machine = _load(function, compiler)
    except NotCompiled as why:
        _outcomes[function.name()] = False
        _warn(str(why))
        return function
    except Exception as error:  # anything else: the interpreter, and why
        _outcomes[function.name()] = False
        _warn(f"{function.name()} could not be compiled ({_first_line(error)})")
        return function
    _outcomes[function.name()] = True
    return machine


def enabled() -> bool:
    """Whether compiling is asked for: ``BIPED_COMPILE`` unset or one of ``ON``, not one of
    ``OFF``; another value is refused, naming it."""
    value = os.environ.get(SWITCH, "1")
    if value.strip().lower() not in ON + OFF:
        raise BipedError(
            f"{SWITCH} = {value!r}: allowed {', '.join(ON)} (compile) or {', '.join(OFF)}"
        )
    return value.strip().lower() in ON


def mode() -> str:
    """How derivatives run in this process: ``"compiled"``, ``"interpreted"`` or
    ``"interpreted in part"`` (some functions; each such case also warns)."""
    if not enabled() or not any(_outcomes.values()):
        return "interpreted"
    return "compiled" if all(_outcomes.values()) else "interpreted in part"


def cache_folder() -> Path:
    """Where compiled libraries are kept: ``$BIPED_CACHE/compiled``, else
    ``$XDG_CACHE_HOME/biped/compiled`` or ``~/.cache/biped/compiled``."""
    root = os.environ.get("BIPED_CACHE")
    if not root:
        xdg = os.environ.get("XDG_CACHE_HOME") or str(Path.home() / ".cache")
        root = str(Path(xdg) / "biped")
    return Path(root) / "compiled"


def _load(function: ca.Function, compiler: tuple) -> ca.Function:
    """The compiled ``function`` from this process's libraries or the cache, built first if
    missing, built again once if it does not load; checked against the interpreter."""
    library = cache_folder() / f"{function.name()}-{_digest(function, compiler)}.so"
    if str(library) in _loaded:  # the same function of another solver (grid, barrier)
        return _loaded[str(library)]
    if str(library) in _failed_builds:
        raise NotCompiled(_failed_builds[str(library)])
    if not library.exists():
        _build(function, compiler, library)
    try:
        machine = ca.external(function.name(), str(library))
    except RuntimeError:  # damaged, or made elsewhere: replaced whole
        _build(function, compiler, library, again=True)
        machine = ca.external(function.name(), str(library))
    if not _same_bits(function, machine):
        raise NotCompiled(
            f"{function.name()} compiled does not give the interpreter's bits ({library})"
        )
    _loaded[str(library)] = machine
    return machine


def _same_bits(function: ca.Function, machine: ca.Function) -> bool:
    """Whether ``machine`` gives ``function``'s outputs, bit for bit, at fixed inputs: the
    same numbers, NaN where the interpreter gives NaN (whose sign and payload C does not fix:
    a profiled knee's square root of a negative number at inputs outside its family)."""
    rng = np.random.default_rng(0)
    inputs = [
        rng.uniform(-1.0, 1.0, (function.size1_in(k), function.size2_in(k) * CHECK_COLUMNS))
        for k in range(function.n_in())
    ]
    mapped = [function.map(CHECK_COLUMNS), machine.map(CHECK_COLUMNS)]
    expected, found = (f.call(inputs) for f in mapped)
    return all(_same_numbers(a, b) for a, b in zip(expected, found, strict=True))


def _same_numbers(a, b) -> bool:
    """Every number the same bits, NaN at the same places."""
    a, b = np.asarray(a), np.asarray(b)
    nan = np.isnan(a)
    same_nan = a.shape == b.shape and np.array_equal(nan, np.isnan(b))
    return same_nan and a[~nan].tobytes() == b[~nan].tobytes()


def _compiler() -> tuple[tuple[str, ...], str] | None:
    """(command, identity) of the C compiler ``$CC`` (a command with its arguments) or
    ``cc``; None without one that runs."""
    words = shlex.split(os.environ.get("CC", "cc"))
    path = shutil.which(words[0]) if words else None
    if path is None:
        return None
    command = (path, *words[1:])
    identity = _identity(command)
    return (command, identity) if identity else None


@functools.cache
def _identity(command: tuple[str, ...]) -> str | None:
    """The compiler's whole ``--version`` and its target (None if it does not run)."""
    said = []
    for question in ("--version", "-dumpmachine"):
        try:
            done = subprocess.run(
                [*command, question], capture_output=True, timeout=30, stdin=subprocess.DEVNULL
            )
        except (OSError, subprocess.SubprocessError):
            return None
        if question == "--version" and done.returncode != 0:
            return None
        said.append(done.stdout.decode(errors="replace").strip())
    return "\n".join(said) or None


def _source(function: ca.Function) -> str:
    generator = ca.CodeGenerator(f"{function.name()}.c", {"with_header": False})
    generator.add(function)
    return generator.dump()


def _digest(function: ca.Function, compiler: tuple) -> str:
    """What names a library: the function (CasADi's serialization of it, which the C source
    follows and is three times slower to make), the compiler, the flags, CasADi, the
    platform."""
    command, identity = compiler
    platform_ = [sys.platform, platform.machine(), str(struct.calcsize("P")), *platform.libc_ver()]
    defining = [function.serialize(), *command, identity, *FLAGS, ca.__version__, *platform_]
    return hashlib.sha256("\0".join(defining).encode()).hexdigest()[:32]


def _build(function: ca.Function, compiler: tuple, library: Path, again: bool = False) -> None:
    """Compile ``function``'s C code into ``library``, atomically (``atomic_path``), one
    process at a time; ``again``: replace the library there unless another process did
    since this one failed to load it."""
    library.parent.mkdir(parents=True, exist_ok=True)
    before = _stamp(library)
    with _locked(library.with_suffix(".lock")):
        if library.exists() and (not again or _stamp(library) != before):
            return  # built by another process while this one waited
        with atomic_path(library) as built:
            command = [*compiler[0], *FLAGS, "-x", "c", "-", "-o", str(built), "-lm"]
            try:
                done = subprocess.run(
                    command,
                    input=_source(function).encode(),
                    capture_output=True,
                    timeout=BUILD_TIMEOUT,
                )
            except subprocess.TimeoutExpired:
                _broken_compiler.append(f"{command[0]} ran over {BUILD_TIMEOUT:g} s")
                raise NotCompiled(_broken_compiler[0]) from None
            if done.returncode != 0:
                said = _error_line(done.stderr.decode(errors="replace"))
                why = f"{command[0]} failed (exit {done.returncode}: {said})"
                _failed_builds[str(library)] = why
                raise NotCompiled(why)


def _stamp(path: Path):
    try:
        stat = path.stat()
    except OSError:
        return None
    return (stat.st_ino, stat.st_mtime_ns, stat.st_size)


@contextlib.contextmanager
def _locked(path: Path):
    """An exclusive lock on ``path``, waited on for ``LOCK_WAIT`` at most; none where the
    platform or the file system has none (the rename alone keeps a library whole)."""
    try:
        import fcntl
    except ImportError:  # Windows: two builds may race; each renames its library whole
        yield
        return
    with open(path, "a") as handle:
        held = _acquire(handle, fcntl)
        try:
            yield
        finally:
            if held:
                fcntl.flock(handle, fcntl.LOCK_UN)


def _acquire(handle, fcntl) -> bool:
    deadline = time.monotonic() + LOCK_WAIT
    while True:
        try:
            fcntl.flock(handle, fcntl.LOCK_EX | fcntl.LOCK_NB)
            return True
        except BlockingIOError:
            if time.monotonic() > deadline:
                return False  # another build hangs: build without it
            time.sleep(0.05)
        except OSError:  # a file system without locks
            return False


def _error_line(text: str) -> str:
    """The compiler's first line that names an error (not the linker driver's summary),
    else its last line."""
    lines = [line.strip() for line in text.splitlines() if line.strip()]
    errors = [
        line
        for line in lines
        if ("error" in line.lower() or "undefined" in line) and not line.startswith("collect2")
    ]
    return errors[0] if errors else (lines or ["no message"])[-1]


def _first_line(error: BaseException) -> str:
    lines = str(error).strip().splitlines()
    return lines[0] if lines else type(error).__name__


def _warn(why: str) -> None:
    """Warn once a process for each reason."""
    if why in _said:
        return
    _said.add(why)
    warnings.warn(
        f"{why}: CasADi's interpreter evaluates the derivatives (the same numbers, slower; "
        f"{SWITCH}=0 asks for it without this warning)",
        CompileWarning,
        stacklevel=3,
    )
