"""Compiled derivatives (``biped.optimization.compiled``): the interpreter's numbers, bit for
bit, in every family of the solver; a compiler allowed to fuse products and sums gives other
bits; without a compiler the interpreter runs and says so once."""

import dataclasses
import json
import os
import re
import stat
import subprocess
import sys
import warnings
from pathlib import Path

import numpy as np
import pytest

import biped
from biped.errors import CompileWarning
from biped.model.criteria import Safety
from biped.optimization import compiled as compiled_module
from biped.optimization.compiled import compiled
from biped.optimization.problem import GaitProblem
from biped.optimization.solver import Solver
from biped.runtime.blas import cpu_flags

ROBOT = biped.Robot.paper()
UNEQUAL = dataclasses.replace(ROBOT, r1=0.03, r2=0.08)
needs_compiler = pytest.mark.skipif(
    compiled_module._compiler() is None, reason="no C compiler on this machine"
)


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
    rng = np.random.default_rng(7)
    for _ in range(3):
        x, lam_g = _inputs(machine, knee, knots, rng)
        for name in ("hessian", "jacobian"):
            arguments = (x, 0.3, 1.3, lam_g) if name == "hessian" else (x, 0.3)
            expected = getattr(interpreted, name)(*arguments)
            found = getattr(machine, name)(*arguments)
            for a, b in zip(_outputs(expected), _outputs(found), strict=True):
                np.testing.assert_array_equal(np.asarray(a), np.asarray(b))


def _outputs(result) -> list:
    return list(result) if isinstance(result, (list, tuple)) else [result]


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
    interpreted, machine = ends
    assert interpreted.converged
    np.testing.assert_array_equal(machine.variables, interpreted.variables)
    assert (machine.value, machine.iterations) == (interpreted.value, interpreted.iterations)


def _sample_function():
    from biped.optimization.symbolic import StepGraph

    return StepGraph(biped.Biped(UNEQUAL, "rolling"), 6, Safety()).sample


@needs_compiler
@pytest.mark.skipif("fma" not in cpu_flags(), reason="the CPU has no fused multiply-add")
def test_a_compiler_fusing_multiply_add_gives_other_bits(monkeypatch, tmp_path):
    """The check above can fail: the same code compiled with fused multiply-adds allowed
    (``-O2 -mfma -ffp-contract=fast``) rounds products and sums once, not twice, and gives other
    bits than the interpreter; with ``FLAGS`` the same."""
    monkeypatch.setenv("BIPED_CACHE", str(tmp_path))
    sample = _sample_function()
    inputs = np.random.default_rng(3).uniform(-1.0, 1.0, (sample.size1_in(0), 40))
    expected = np.asarray(sample.map(40)(inputs))
    same = compiled(sample)
    assert same.class_name() != sample.class_name()  # compiled, not the interpreter
    np.testing.assert_array_equal(np.asarray(same.map(40)(inputs)), expected)
    fused = ("-O2", *compiled_module.FLAGS[1:-1], "-mfma", "-ffp-contract=fast")
    monkeypatch.setattr(compiled_module, "FLAGS", fused)
    other = np.asarray(compiled(sample).map(40)(inputs))
    np.testing.assert_allclose(other, expected, rtol=1e-9, atol=1e-9)
    assert not np.array_equal(other, expected)
    assert len(list((tmp_path / "compiled").glob("*.so"))) == 2  # one library per flag set


@needs_compiler
def test_a_compiled_library_is_loaded_from_the_cache_without_the_compiler(monkeypatch, tmp_path):
    """A second process (here: a second call) finds the library by its digest and does not
    compile again; an interrupted build leaves no library behind."""
    monkeypatch.setenv("BIPED_CACHE", str(tmp_path))
    sample = _sample_function()
    compiled(sample)
    libraries = list((tmp_path / "compiled").glob("*.so"))
    assert len(libraries) == 1

    def no_build(*args, **kwargs):
        raise AssertionError("compiled again")

    monkeypatch.setattr(compiled_module, "_build", no_build)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        again = compiled(sample)
    assert again.class_name() != sample.class_name()
    assert not [p for p in (tmp_path / "compiled").iterdir() if p.name.startswith(".build-")]


@needs_compiler
def test_a_damaged_library_in_the_cache_is_built_again(monkeypatch, tmp_path):
    """A library that does not load (here: a file of other bytes under its name) is removed
    and compiled again, without a warning."""
    monkeypatch.setenv("BIPED_CACHE", str(tmp_path))
    sample = _sample_function()
    digest = compiled_module._digest(compiled_module._source(sample), compiled_module._compiler())
    library = tmp_path / "compiled" / f"{sample.name()}-{digest}.so"
    library.parent.mkdir(parents=True)
    library.write_bytes(b"\x7fELF and nothing else")
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        again = compiled(sample)
    inputs = np.random.default_rng(5).uniform(-1.0, 1.0, (sample.size1_in(0), 3))
    np.testing.assert_array_equal(np.asarray(again.map(3)(inputs)), sample.map(3)(inputs))
    assert library.stat().st_size > 1000


def _fake_compiler(tmp_path, build_exit: int) -> str:
    """A ``cc`` that prints a version and exits ``build_exit`` when asked to compile."""
    path = tmp_path / "fake-cc"
    path.write_text(
        "#!/bin/sh\n"
        'if [ "$1" = "--version" ]; then echo "fake-cc 1.0"; exit 0; fi\n'
        f'echo "fake-cc: cannot compile" >&2; exit {build_exit}\n'
    )
    path.chmod(path.stat().st_mode | stat.S_IEXEC)
    return str(path)


@pytest.mark.parametrize(
    "compiler, needle",
    [
        ("/nonexistent/cc", "no C compiler (/nonexistent/cc) found"),
        ("fake", "could not be compiled"),
    ],
)
def test_without_a_working_compiler_the_interpreter_runs_and_says_so(
    monkeypatch, tmp_path, compiler, needle
):
    """No compiler, or one that fails: the interpreted function, the same numbers, and one
    warning naming why; ``BIPED_COMPILE=0``: the interpreter without a warning."""
    monkeypatch.setenv("BIPED_CACHE", str(tmp_path))
    monkeypatch.setattr(compiled_module, "_FAILED", set())
    monkeypatch.setattr(compiled_module, "_SAID", set())
    monkeypatch.setenv("CC", _fake_compiler(tmp_path, 1) if compiler == "fake" else compiler)
    sample = _sample_function()
    with pytest.warns(CompileWarning, match=re.escape(needle)):
        found = compiled(sample)
    assert found is sample
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert compiled(sample) is sample  # said once a process
    assert not list(tmp_path.rglob("*.so"))
    expected = "interpreted in part" if compiler == "fake" else "interpreted"
    assert compiled_module.mode() == expected
    monkeypatch.setenv(compiled_module.SWITCH, "0")
    assert compiled_module.mode() == "interpreted"
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert compiled(sample) is sample


def test_the_cache_folder_follows_the_environment(monkeypatch, tmp_path):
    monkeypatch.setenv("BIPED_CACHE", str(tmp_path / "mine"))
    assert compiled_module.cache_folder() == tmp_path / "mine" / "compiled"
    monkeypatch.delenv("BIPED_CACHE")
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "xdg"))
    assert compiled_module.cache_folder() == tmp_path / "xdg" / "biped" / "compiled"
    monkeypatch.delenv("XDG_CACHE_HOME")
    assert compiled_module.cache_folder() == Path.home() / ".cache" / "biped" / "compiled"


@needs_compiler
def test_biped_optimize_without_a_compiler_says_so_once_and_writes_the_same_gait(tmp_path):
    """``biped optimize`` without a compiler: one warning line on stderr (no traceback, no
    Python warning format), "interpreted" in its time line, and the gait file's variables
    the same bits as with the compiled derivatives."""
    gaits = {}
    for name, compiler in (("compiled", "cc"), ("interpreted", "/nonexistent/cc")):
        env = {**os.environ, "CC": compiler, "BIPED_CACHE": str(tmp_path / "cache")}
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
