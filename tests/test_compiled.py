"""Compiled derivatives (``biped.optimization.compiled``): the interpreter's numbers, bit for
bit, in every family of the solver; a compiler allowed to fuse products and sums gives other
bits, and is refused when its library is loaded; without a working compiler the interpreter
runs and says so once."""

import dataclasses
import json
import os
import platform
import re
import stat
import subprocess
import sys

import casadi as ca
import numpy as np
import pytest

import biped
from biped.errors import BipedError, CompileWarning
from biped.model.criteria import Safety
from biped.optimization import compiled as compiled_module
from biped.optimization.compiled import compiled
from biped.optimization.problem import GaitProblem
from biped.optimization.solver import Solver
from biped.runtime.blas import cpu_flags
from biped.runtime.files import is_temporary

# A fallback to the interpreter is a failure here unless a test expects it (pytest.warns).
pytestmark = pytest.mark.filterwarnings("error::biped.errors.CompileWarning")

ROBOT = biped.Robot.paper()
UNEQUAL = dataclasses.replace(ROBOT, r1=0.03, r2=0.08)
needs_compiler = pytest.mark.skipif(
    compiled_module._compiler() is None, reason="no C compiler on this machine"
)


@pytest.fixture(scope="module")
def cache(tmp_path_factory):
    """A compile cache of this file's own (not the user's)."""
    return tmp_path_factory.mktemp("cache")


@pytest.fixture(autouse=True)
def fresh_state(monkeypatch, cache):
    """Each test with the module's state of a new process, and this file's cache."""
    monkeypatch.setenv("BIPED_CACHE", str(cache))
    monkeypatch.delenv(compiled_module.SWITCH, raising=False)
    for name, empty in (
        ("_said", set),
        ("_outcomes", dict),
        ("_failed_builds", dict),
        ("_loaded", dict),
    ):
        monkeypatch.setattr(compiled_module, name, empty())
    monkeypatch.setattr(compiled_module, "_broken_compiler", [])


def _solver(monkeypatch, switch: str, knee, criterion, safety, radii, knots) -> Solver:
    monkeypatch.setenv(compiled_module.SWITCH, switch)
    bounds = ((0.001, 0.001), (0.15, 0.2)) if radii else None
    return Solver(biped.Biped(UNEQUAL, knee), criterion, safety, 6, bounds, knots)


def _inputs(solver: Solver, knee: str, knots: int, rng) -> tuple:
    problem = GaitProblem(biped.Biped(UNEQUAL, knee), 0.3, knots=knots)
    z = problem.first_guess() + 0.2 * rng.standard_normal(solver.size)
    extra = rng.uniform(0.5, 2.0, solver.nlp.size1_in(0) - solver.size - solver.slacks)
    x = np.concatenate([z / solver.scales, extra, rng.random(solver.slacks)])
    return x, rng.standard_normal(solver.n_constraints)


def _outputs(result) -> list:
    return list(result) if isinstance(result, (list, tuple)) else [result]


@needs_compiler
@pytest.mark.parametrize(
    "knee, criterion, safety, radii, knots",
    [
        ("revolute", "sthenic", Safety(), None, 1),
        ("rolling", "energy", Safety(clearance=0.02), None, 1),
        ("rolling", "energy-per-metre", Safety(knee_bend=0.1), None, 1),
        ("rolling", "electrical", Safety(), None, 1),
        ("rolling", "sthenic", Safety(), "design", 1),
        ("revolute", "energy", Safety(), None, 3),
    ],
)
def test_compiled_derivatives_are_the_interpreters_bits(
    monkeypatch, knee, criterion, safety, radii, knots
):
    """IPOPT's Hessian of the Lagrangian and constraint Jacobian, with the per-sample
    functions compiled and interpreted: the same bits at random variables and multipliers
    (a design's radii, the slacks, the richer family, the motors' criterion)."""
    interpreted = _solver(monkeypatch, "0", knee, criterion, safety, radii, knots)
    machine = _solver(monkeypatch, "1", knee, criterion, safety, radii, knots)
    assert compiled_module.mode() == "compiled"  # the other is not the interpreter again
    rng = np.random.default_rng(7)
    for _ in range(3):
        x, lam_g = _inputs(machine, knee, knots, rng)
        for name in ("hessian", "jacobian"):
            arguments = (x, 0.3, 1.3, lam_g) if name == "hessian" else (x, 0.3)
            expected = getattr(interpreted, name)(*arguments)
            found = getattr(machine, name)(*arguments)
            for a, b in zip(_outputs(expected), _outputs(found), strict=True):
                np.testing.assert_array_equal(np.asarray(a), np.asarray(b))


@needs_compiler
def test_an_energy_solve_is_the_same_bits_compiled_and_interpreted(monkeypatch):
    """One energy start solved both ways: every variable, the value and the iteration count
    the same (IPOPT's path is sensitive to the last bit: it would tell a difference)."""
    problem = GaitProblem(biped.Biped(ROBOT, "rolling"), 0.3, "energy")
    start = problem.first_guess(0.1 / 0.3)
    ends = []
    for switch in ("0", "1"):
        monkeypatch.setenv(compiled_module.SWITCH, switch)
        solver = Solver(problem.model, "energy", problem.safety, problem.samples_per_half)
        ends.append(solver.solve(problem, start, barrier="monotone"))
    assert compiled_module.mode() == "compiled"
    interpreted, machine = ends
    assert interpreted.converged
    np.testing.assert_array_equal(machine.variables, interpreted.variables)
    assert (machine.value, machine.iterations) == (interpreted.value, interpreted.iterations)


def _sample_function():
    from biped.optimization.symbolic import StepGraph

    return StepGraph(biped.Biped(UNEQUAL, "rolling"), 6, Safety()).sample


def _fusing_flags() -> tuple:
    """Flags under which the compiler fuses a product and a sum (``-O2``, and on x86-64 the
    FMA instructions), or skip where the CPU has none."""
    if platform.machine() in ("x86_64", "AMD64"):
        if "fma" not in cpu_flags():
            pytest.skip("the CPU has no fused multiply-add")
        return ("-O2", "-mfma")
    if platform.machine() in ("aarch64", "arm64"):
        return ("-O2",)
    pytest.skip(f"no fused multiply-add flags known for {platform.machine()}")


@needs_compiler
def test_without_ffp_contract_off_a_fusing_compiler_gives_other_bits(monkeypatch):
    """Why ``-ffp-contract=off``: at ``-O2`` with the FMA instructions, the same code keeps
    the interpreter's bits with it, and gives other bits without it (products and sums
    rounded once, not twice), which the check of a loaded library refuses: the interpreter
    runs, with a warning."""
    sample = _sample_function()
    inputs = np.random.default_rng(3).uniform(-1.0, 1.0, (sample.size1_in(0), 40))
    expected = np.asarray(sample.map(40)(inputs))
    kept = (*compiled_module.FLAGS, *_fusing_flags())
    monkeypatch.setattr(compiled_module, "FLAGS", kept)
    same = compiled(sample)
    assert same.class_name() != sample.class_name()  # compiled, not the interpreter
    np.testing.assert_array_equal(np.asarray(same.map(40)(inputs)), expected)
    fused = tuple(f for f in kept if f != "-ffp-contract=off") + ("-ffp-contract=fast",)
    monkeypatch.setattr(compiled_module, "FLAGS", fused)
    compiler = compiled_module._compiler()
    digest = compiled_module._digest(sample, compiler)
    library = compiled_module.cache_folder() / f"fused-{digest}.so"
    compiled_module._build(sample, compiler, library)
    other = np.asarray(ca.external(sample.name(), str(library)).map(40)(inputs))
    np.testing.assert_allclose(other, expected, rtol=1e-9, atol=1e-9)
    assert not np.array_equal(other, expected)
    with pytest.warns(CompileWarning, match="does not give the interpreter's bits"):
        assert compiled(sample) is sample


@needs_compiler
def test_a_compiled_library_is_loaded_from_the_cache_without_the_compiler(monkeypatch, tmp_path):
    """Another solver of the process (another grid: the same per-sample function) gets the
    library already loaded; another process (here: the process's libraries forgotten) finds
    it by its digest and does not compile again; no temporary file is left behind."""
    monkeypatch.setenv("BIPED_CACHE", str(tmp_path))
    sample = _sample_function()
    first = compiled(sample)
    folder = compiled_module.cache_folder()
    libraries = list(folder.glob(f"{sample.name()}-*.so"))
    assert len(libraries) == 1

    def no_build(*args, **kwargs):
        raise AssertionError("compiled again")

    monkeypatch.setattr(compiled_module, "_build", no_build)
    from biped.optimization.symbolic import StepGraph

    other_grid = StepGraph(biped.Biped(UNEQUAL, "rolling"), 13, Safety()).sample
    assert compiled(other_grid) is first
    monkeypatch.setattr(compiled_module, "_loaded", {})
    again = compiled(sample)
    assert again is not first and again.class_name() != sample.class_name()
    assert not [p for p in folder.iterdir() if is_temporary(p)]


@needs_compiler
def test_a_damaged_library_in_the_cache_is_built_again(monkeypatch, tmp_path):
    """A library that does not load (here: a file of other bytes under its name) is replaced
    and compiled again, without a warning."""
    monkeypatch.setenv("BIPED_CACHE", str(tmp_path))
    sample = _sample_function()
    digest = compiled_module._digest(sample, compiled_module._compiler())
    library = tmp_path / "compiled" / f"{sample.name()}-{digest}.so"
    library.parent.mkdir(parents=True)
    library.write_bytes(b"\x7fELF and nothing else")
    again = compiled(sample)
    inputs = np.random.default_rng(5).uniform(-1.0, 1.0, (sample.size1_in(0), 3))
    np.testing.assert_array_equal(np.asarray(again.map(3)(inputs)), sample.map(3)(inputs))
    assert library.stat().st_size > 1000


@needs_compiler
@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="-z defs is GNU ld's")
def test_a_function_the_c_library_lacks_fails_the_build_not_the_call():
    """``erfinv`` is CasADi's, not the C library's: the build fails (``-Wl,-z,defs``) and
    the interpreter runs, instead of a library that would end the process at its first
    call."""
    x = ca.SX.sym("x")
    inverse = ca.Function("inverse_erf", [x], [ca.erfinv(x)])
    with pytest.warns(CompileWarning, match="erfinv"):
        assert compiled(inverse) is inverse
    assert float(inverse(0.5)) == pytest.approx(0.4769362762044699)
    assert compiled_module.mode() == "interpreted"


def _fake_compiler(tmp_path, build_exit: int) -> str:
    """A ``cc`` that prints a version and exits ``build_exit`` when asked to compile."""
    path = tmp_path / "fake-cc"
    path.write_text(
        "#!/bin/sh\n"
        'if [ "$1" = "--version" ]; then echo "fake-cc 1.0"; exit 0; fi\n'
        'if [ "$1" = "-dumpmachine" ]; then echo "fake"; exit 0; fi\n'
        f'echo "fake-cc: error: cannot compile" >&2; exit {build_exit}\n'
    )
    path.chmod(path.stat().st_mode | stat.S_IEXEC)
    return str(path)


@pytest.mark.parametrize(
    "compiler, needle",
    [
        ("/nonexistent/cc", "no C compiler (/nonexistent/cc) found"),
        ("fake", "failed (exit 1: fake-cc: error: cannot compile)"),
    ],
)
def test_without_a_working_compiler_the_interpreter_runs_and_says_so(
    monkeypatch, tmp_path, compiler, needle
):
    """No compiler, or one that fails: the interpreted function, the same numbers, and one
    warning naming why, once; ``BIPED_COMPILE=0``: the interpreter without a warning."""
    monkeypatch.setenv("BIPED_CACHE", str(tmp_path))
    monkeypatch.setenv("CC", _fake_compiler(tmp_path, 1) if compiler == "fake" else compiler)
    sample = _sample_function()
    with pytest.warns(CompileWarning, match=re.escape(needle)):
        found = compiled(sample)
    assert found is sample
    assert compiled(sample) is sample  # said once a process (a second warning would fail)
    assert not list(tmp_path.rglob("*.so"))
    assert compiled_module.mode() == "interpreted"
    monkeypatch.setenv(compiled_module.SWITCH, "0")
    assert compiled(sample) is sample


def test_a_compiler_command_with_arguments_is_one_compiler(monkeypatch):
    """``CC="cc -m64"``: the command and its arguments, not "no C compiler"."""
    if compiled_module._compiler() is None:
        pytest.skip("no C compiler on this machine")
    monkeypatch.setenv("CC", "cc -m64" if platform.machine() == "x86_64" else "cc -O1")
    command, identity = compiled_module._compiler()
    assert len(command) == 2 and identity


def test_the_cache_folder_follows_the_environment(monkeypatch, tmp_path):
    monkeypatch.setenv("BIPED_CACHE", str(tmp_path / "mine"))
    assert compiled_module.cache_folder() == tmp_path / "mine" / "compiled"
    monkeypatch.delenv("BIPED_CACHE")
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "xdg"))
    assert compiled_module.cache_folder() == tmp_path / "xdg" / "biped" / "compiled"


def test_a_home_that_cannot_be_found_leaves_the_interpreter(monkeypatch):
    """No cache folder to be had (no ``HOME``, no user entry): the interpreter, a warning,
    no error."""
    monkeypatch.delenv("BIPED_CACHE")
    monkeypatch.delenv("XDG_CACHE_HOME", raising=False)

    def nowhere():
        raise RuntimeError("Could not determine home directory.")

    monkeypatch.setattr(compiled_module.Path, "home", staticmethod(nowhere))
    if compiled_module._compiler() is None:
        pytest.skip("no C compiler on this machine")
    sample = _sample_function()
    with pytest.warns(CompileWarning, match="Could not determine home directory"):
        assert compiled(sample) is sample


@needs_compiler
def test_biped_optimize_without_a_compiler_says_so_once_and_writes_the_same_gait(tmp_path, cache):
    """``biped optimize`` without a compiler: one warning line on stderr (no traceback, no
    Python warning format), "interpreted" in its time line, and the gait file's variables
    the same bits as with the compiled derivatives."""
    gaits = {}
    for name, compiler in (("compiled", "cc"), ("interpreted", "/nonexistent/cc")):
        env = {**os.environ, "CC": compiler, "BIPED_CACHE": str(cache)}
        out = tmp_path / f"{name}.json"
        argv = [sys.executable, "-m", "biped", "optimize", "--knee", "revolute"]
        done = subprocess.run(
            argv + ["--speed", "0.3", "--out", str(out)], env=env, capture_output=True, text=True
        )
        assert done.returncode == 0, done.stderr
        assert f"exact derivatives built, {name})" in done.stdout
        warned = [line for line in done.stderr.splitlines() if "warning: no C compiler" in line]
        assert len(warned) == (name == "interpreted")
        assert "Traceback" not in done.stderr and "CompileWarning" not in done.stderr
        gaits[name] = json.loads(out.read_text())["optimizer"]["variables"]
    assert gaits["compiled"] == gaits["interpreted"]


def test_a_bad_switch_is_refused_naming_it(monkeypatch, tmp_path):
    """``BIPED_COMPILE=maybe``: an error naming the value and what is allowed, not a silent
    choice; ``biped optimize`` says it on one line and exits 2."""
    monkeypatch.setenv(compiled_module.SWITCH, "maybe")
    with pytest.raises(BipedError, match=r"BIPED_COMPILE = 'maybe': allowed 1, on, yes, true"):
        compiled(_sample_function())
    argv = [sys.executable, "-m", "biped", "optimize", "--knee", "revolute", "--speed", "0.3"]
    argv += ["--out", str(tmp_path / "gait.json")]
    done = subprocess.run(argv, env=dict(os.environ), capture_output=True, text=True)
    assert done.returncode == 2 and not (tmp_path / "gait.json").exists()
    lines = [line for line in done.stderr.splitlines() if not line.startswith("optimizing")]
    assert lines == [
        "biped optimize: error: BIPED_COMPILE = 'maybe': allowed 1, on, yes, "
        "true (compile) or 0, off, no, false"
    ]
