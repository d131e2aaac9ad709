"""Shared fixtures: both robots and seeded random motions with the stance foot fixed."""

import functools
import json
from pathlib import Path

import numpy as np
import pytest

import biped

KNEES = biped.KNEES


@pytest.fixture(params=KNEES)
def model(request):
    """The Table 1 robot with each knee kinematic."""
    return biped.Biped(biped.Robot.paper(), knee=request.param)


def random_state(model, seed, n=16, spread=0.6):
    """n seeded single-support states (q, q̇, q̈) with the stance foot flat and fixed."""
    rng = np.random.default_rng(seed)
    angles = rng.uniform(-spread, spread, (n, 6))
    return model.stance_state(angles, rng.normal(0, 2, (n, 6)), rng.normal(0, 10, (n, 6)))


def smooth_motion(model, seed, t):
    """A smooth single-support motion (sums of sines) sampled at times t [s]."""
    rng = np.random.default_rng(seed)
    amplitude = rng.uniform(0.1, 0.4, (2, 6))
    omega = rng.uniform(1.0, 6.0, (2, 6))
    phase = rng.uniform(0, 2 * np.pi, (2, 6))
    arg = omega[:, None] * np.asarray(t)[None, :, None] + phase[:, None]
    angles = (amplitude[:, None] * np.sin(arg)).sum(0)
    rates = (amplitude[:, None] * omega[:, None] * np.cos(arg)).sum(0)
    accel = -(amplitude[:, None] * omega[:, None] ** 2 * np.sin(arg)).sum(0)
    return model.stance_state(angles, rates, accel)


def complex_step_velocity(model, q, qd, names, h=1e-30):
    """Exact velocities (..., P, 2) of named points by complex-step differentiation."""
    return model.points(np.asarray(q) + 1j * h * np.asarray(qd), names).imag / h


_GAITS: dict = {}


def small_optimum(knee: str):
    """A feasible gait at 0.3 m/s from the paper's method on a small budget (Nelder-Mead,
    one run of 300 evaluations): far from optimal, its motors work (about 4 N·m RMS).
    Computed once per session."""
    from biped.optimization.optimize import optimize
    from biped.optimization.problem import GaitProblem

    if knee not in _GAITS:
        problem = GaitProblem(biped.Biped(biped.Robot.paper(), knee), 0.3)
        _GAITS[knee] = optimize(
            problem, method="nelder-mead", max_restarts=0, evaluations_per_run=300
        )
    return _GAITS[knee]


_OPTIMA: dict = {}


def optimal_gait(knee: str):
    """The optimal gait at 0.3 m/s with the optimiser's defaults (seed 0): the gait
    ``biped optimize --knee KNEE --speed 0.3`` writes, computed once per session."""
    from biped.optimization.optimize import optimize
    from biped.optimization.problem import GaitProblem

    if knee not in _OPTIMA:
        _OPTIMA[knee] = optimize(GaitProblem(biped.Biped(biped.Robot.paper(), knee), 0.3))
    return _OPTIMA[knee]


_TWO_PHASE: dict = {}


@functools.cache
def two_phase_solver(knee: str, landing: str = "impact"):
    """The two-phase solver of ``knee`` at 0.3 m/s, a tenth to a fifth of the step in double
    support, built once per session (the tests' processes share none)."""
    from biped.optimization import two_phase as tpo
    from biped.optimization.problem import GaitProblem

    problem = GaitProblem(biped.Biped(biped.Robot.paper(), knee), 0.3)
    return tpo.TwoPhaseSolver(tpo.TwoPhaseProblem(problem, (0.1, 0.2), landing=landing))


@functools.cache
def two_phase_result(knee: str, landing: str = "impact"):
    """``two_phase_solver``'s best of one start from ``optimal_gait(knee)`` (what ``biped
    optimize --double-support 0.1:0.2 --starts 1`` solves), once per session."""
    from biped.optimization import two_phase as tpo

    single = optimal_gait(knee)
    solver = two_phase_solver(knee, landing)
    return tpo.optimize_two_phase(solver, single.variables, single.value, starts=1, seed=0)


def two_phase_gait(knee: str, landing: str = "impact"):
    """The two-phase gait of ``two_phase_result`` (what ``biped optimize --double-support
    0.1:0.2 --starts 1`` writes), in memory; computed once per session."""
    from biped.records import two_phase_file

    if (knee, landing) not in _TWO_PHASE:
        result = two_phase_result(knee, landing)
        assert result.best is not None, f"the two-phase problem found no optimum: {result}"
        problem = two_phase_solver(knee, landing).problem
        _TWO_PHASE[knee, landing] = two_phase_file.gait_of(problem, result, seed=0)
    return _TWO_PHASE[knee, landing]


def gait_of(optimum, robot=None):
    """The gait of ``optimum`` (``Gait.from_optimum``), in memory."""
    from biped.records.gait_file import Gait

    return Gait.from_optimum(optimum, robot or biped.Robot.paper())


def with_torques(gait, torques):
    """``gait`` with its sample torques (N, 6) replaced by ``torques``."""
    import dataclasses

    samples = dataclasses.replace(gait.samples, torques=np.asarray(torques, dtype=float))
    return dataclasses.replace(gait, samples=samples)


def edited_gait_file(content: dict, folder, change=None, name: str = "gait.json"):
    """A gait file of a copy of ``content`` edited by ``change(copy)``, in ``folder``."""
    edited = json.loads(json.dumps(content))
    if change is not None:
        change(edited)
    path = folder / name
    path.write_text(json.dumps(edited))
    return path


def exit_status(argv) -> int:
    """The exit status of ``biped argv``, argparse's own exit included."""
    from biped_cli.main import main

    try:
        return main(argv)
    except SystemExit as stop:
        return stop.code


def refusal(read, path) -> str:
    """The BipedError of ``read(path)``: one line, naming the file."""
    with pytest.raises(biped.BipedError) as error:
        read(path)
    message = str(error.value)
    assert str(path) in message and "\n" not in message
    return message


def designed_gait():
    """A designed gait in memory (``Gait.from_design``): the comparison of the small optima,
    the rolling knee's as the design at Table 1's radii."""
    from biped.optimization.design import Comparison, Design, DesignProblem
    from biped.records.gait_file import Gait

    problem = DesignProblem(biped.Robot.paper(), 0.3)
    rolling, revolute = small_optimum("rolling"), small_optimum("revolute")
    return Gait.from_design(Comparison(problem, revolute, rolling, Design(problem, rolling)))


# The full tier's tests (``tests/slow.txt``): marked ``slow``, so that ``pytest -m "not slow"``
# runs the fast tier.
_SLOW = {
    line.strip()
    for line in (Path(__file__).parent / "slow.txt").read_text(encoding="utf-8").splitlines()
    if line.strip() and not line.startswith("#")
}


# The test files that take longest in the full tier (6 s to tens of seconds each, the
# two-phase optima's unit the longest), longest first, then the others (a few seconds
# each): a long unit of work started last would leave the other worker idle at the end of
# the run.
LONGEST_FIRST = (
    "test_two_phase_gait.py",
    "test_atlas.py",
    "test_sweep.py",
    "test_atlas_two_phase.py",
    "test_outputs.py",
    "test_actuators.py",
    "test_optimize.py",
    "test_validate.py",
    "test_converge.py",
    "test_wrong_models.py",
    "test_two_phase_sweep.py",
    "test_compiled.py",
    "test_pipeline_two_phase.py",
    "test_robustness.py",
    "test_design.py",
    "test_profile_design.py",
    "test_orbit.py",
    "test_walkable.py",
    "test_bezier.py",
    "test_runner.py",
    "test_cli_help.py",
    "test_video.py",
    "test_design_map.py",
    "test_interrupts.py",
    "test_criteria_matrix.py",
    "test_profile_graph.py",
    "test_replay.py",
    "test_profile_orbit.py",
    "test_cli.py",
    "test_paper_method.py",
    "test_page.py",
    "test_families.py",
    "test_record.py",
)


def _rank(item) -> int:
    """Where ``item``'s file runs: ``LONGEST_FIRST``'s order, the two-phase optima's files
    as their unit, then the others in their own order."""
    name = Path(str(item.fspath)).name
    name = "test_two_phase_gait.py" if name in TWO_PHASE_FILES else name
    return LONGEST_FIRST.index(name) if name in LONGEST_FIRST else len(LONGEST_FIRST)


def pytest_collection_modifyitems(config, items):
    """Mark ``slow`` each test of a function, or of a test file, listed in
    ``tests/slow.txt``; put the longest files first (``LONGEST_FIRST``)."""
    for item in items:
        if {item.nodeid.split("[")[0], item.nodeid.split("::")[0]} & _SLOW:
            item.add_marker(pytest.mark.slow)
    items.sort(key=_rank)


def assert_graph_is_the_model(problem, safety, family, seed: int) -> None:
    """The CasADi graph of ``problem``'s gait family gives the numeric model's torques,
    constraints and criteria to 1e-12 at random variables drawn with ``seed``."""
    from biped.model.criteria import evaluate_step
    from biped.model.gait import build_step
    from biped.optimization.problem import scales
    from biped.optimization.symbolic import StepGraph

    function = StepGraph(problem.model, problem.samples_per_half, safety, knots=family).function()
    rng = np.random.default_rng(seed)
    z = problem.first_guess() + 0.3 * scales(family) * rng.standard_normal(len(scales(family)))
    z[:2] = rng.uniform(0.05, 0.3, 2)
    out = function(z=z, speed=problem.speed)
    step = build_step(problem.model, problem.speed, problem.to_parameters(z), family)
    ev = evaluate_step(problem.model, step, problem.samples_per_half, safety=safety)
    checked = ~np.isnan(ev.constraints)
    for found, expected in (
        (out["torques"].full().T, ev.torques),
        (out["psi"].full().T[checked], ev.constraints[checked]),
        (float(out["sthenic"]), ev.sthenic),
        (float(out["energy"]), ev.energy),
    ):
        scale = np.max(np.abs(expected))
        np.testing.assert_allclose(found, expected, rtol=1e-12, atol=1e-12 * scale)


def _orbit_key(walker, args, kwargs) -> str:
    """What an orbit is a function of: the walker's compiled model (every number of it, the
    servos included), the gait's samples as the walk reads them, and the arguments."""
    import hashlib

    import mujoco

    model = np.empty(mujoco.mj_sizeModel(walker.model), dtype=np.uint8)
    mujoco.mj_saveModel(walker.model, None, model)
    digest = hashlib.sha256(model.tobytes())
    for name in ("t", "q", "qd", "torques", "wrench", "swing_wrench"):
        digest.update(np.ascontiguousarray(getattr(walker.samples, name)).tobytes())
    digest.update(repr((walker.samples.period, walker.samples.landing, args, kwargs)).encode())
    return digest.hexdigest()


_ORBITS: dict = {}


def pytest_runtest_setup(item):
    """Once MuJoCo's orbit module is loaded, each orbit is computed once per test process:
    MuJoCo's walks are deterministic, so the same walker and arguments give the same orbit,
    and the validations of one gait in several tests share it."""
    import sys

    module = sys.modules.get("validate.checks.orbit")
    if module is None or getattr(module.orbit, "once", False):
        return
    computed = module.orbit

    def orbit(walker, *args, **kwargs):
        key = _orbit_key(walker, args, kwargs)
        if key not in _ORBITS:
            _ORBITS[key] = computed(walker, *args, **kwargs)
        return _ORBITS[key]

    orbit.once = True
    module.orbit = orbit


# Test files whose tests share one process's two-phase optima (``two_phase_gait``,
# ``two_phase_result``; 10-45 s each to solve): run as one unit of ``--dist loadfile``, so
# that each optimum is solved once in the whole run instead of once in each worker that
# runs one of them.
TWO_PHASE_FILES = {
    "test_anchor.py",
    "test_two_phase_gait.py",
    "test_two_phase_nlp.py",
    "test_two_phase_orbit.py",
    "test_two_phase_page.py",
    "test_two_phase_record.py",
    "test_two_phase_validate.py",
    "test_two_phase_video.py",
    "test_two_phase_walk.py",
}


def pytest_xdist_make_scheduler(config, log):
    """``--dist loadfile`` with ``TWO_PHASE_FILES`` one unit of work."""
    if config.getvalue("dist") != "loadfile":
        return None
    from xdist.scheduler import LoadFileScheduling

    class SharedOptima(LoadFileScheduling):
        def _split_scope(self, nodeid: str) -> str:
            path = super()._split_scope(nodeid)
            return "two-phase optima" if Path(path).name in TWO_PHASE_FILES else path

    config.option.loadscopereorder = False  # the collection's order: ``LONGEST_FIRST``
    return SharedOptima(config, log)
