"""MuJoCo beside the analytical model: inverse dynamics per sample, the forward walk's speed
(simulated seconds per wall second) on the committed models and on the previous model
settings in the same process, with MuJoCo's part of it (its rollout calls, per physics step)
and the controller's (the rest), and the time of a whole validation and of its orbit check.

    python benchmarks/bench_mujoco.py

The previous settings are the committed models as they were before the model was made
cheaper: 1 ms step, each sole a box touching the floor at four corners, the floor's default
contact parameters, knee equality at 2 ms with 1e-3 kg·m² of armature on the knee hinges,
friction 50 times harder than the normal force (impratio), constraint islands.
"""

import os

for _var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ[_var] = "1"  # one core, set before numpy loads its BLAS

import contextlib  # noqa: E402
import time  # noqa: E402
import types  # noqa: E402

import mujoco  # noqa: E402
import numpy as np  # noqa: E402
from bench_dynamics import random_states  # noqa: E402
from mujoco import rollout  # noqa: E402
from timing import median_time  # noqa: E402

import biped  # noqa: E402
from biped.optimization.optimize import optimize  # noqa: E402
from biped.optimization.problem import GaitProblem  # noqa: E402
from biped.records.gait_file import Gait  # noqa: E402
from validate.checks import orbit  # noqa: E402
from validate.checks.crosscheck import load_model, mujoco_inverse_dynamics  # noqa: E402
from validate.checks.validation import validate  # noqa: E402
from validate.scene import mjcf  # noqa: E402
from validate.scene.model import model_spec  # noqa: E402
from validate.walk import simulate  # noqa: E402
from validate.walk.simulate import Walker  # noqa: E402

SAMPLES = 1000
STEPS = 20
REPEATS = 5


def previous_settings(spec: mujoco.MjSpec, robot: biped.Robot) -> mujoco.MjSpec:
    """The committed model with the settings it had before (see the module docstring)."""
    spec = mjcf.with_box_soles(spec, robot, solref=(0.004, 1.0))
    spec.option.timestep = 0.001
    spec.option.disableflags &= ~int(mujoco.mjtDisableBit.mjDSBL_ISLAND)
    spec.option.impratio = mjcf.IMPRATIO_HARD
    floor = spec.geom("floor")
    floor.solref, floor.solimp = [0.02, 1.0], [0.9, 0.95, 0.001, 0.5, 2.0]  # MuJoCo's default
    for equality in spec.equalities:
        equality.solref = [0.002, 1.0]
    for joint in spec.joints:
        if joint.name.endswith(("_knee_upper", "_knee_lower")):
            joint.armature = 1e-3
    return spec


class _TimedRollout(rollout.Rollout):
    """MuJoCo's rollout, adding up the wall time of its calls and the physics steps they
    take (a reading period cut short by a landing still takes all its steps)."""

    seconds = 0.0
    steps = 0

    def rollout(self, *args, **kwargs):
        began = time.perf_counter()
        try:
            return super().rollout(*args, **kwargs)
        finally:
            _TimedRollout.seconds += time.perf_counter() - began
            _TimedRollout.steps += kwargs["nstep"]


@contextlib.contextmanager
def timed_rollouts():
    """The walk's calls to MuJoCo timed (``_TimedRollout.seconds``)."""
    saved = simulate.rollout
    simulate.rollout = types.SimpleNamespace(Rollout=_TimedRollout)
    try:
        yield
    finally:
        simulate.rollout = saved


def walk_times(walker: Walker):
    """Median wall times [s] of the walk and of MuJoCo's part of it (its rollout calls, in
    walks timed apart), the seconds simulated, the physics steps MuJoCo took and the steps
    walked."""
    walls, physics = [], []
    for _ in range(REPEATS):
        began = time.perf_counter()
        sim = walker.walk(STEPS)
        walls.append(time.perf_counter() - began)
        with timed_rollouts():
            _TimedRollout.seconds, _TimedRollout.steps = 0.0, 0
            walker.walk(STEPS)
            physics.append(_TimedRollout.seconds)
    simulated = sim.time[-1] - sim.time[0] + sim.model.opt.timestep
    return np.median(walls), np.median(physics), simulated, _TimedRollout.steps, sum(sim.landed)


def main():
    rng = np.random.default_rng(0)
    print(f"inverse dynamics per sample ({SAMPLES} samples), one thread")
    print(f"{'knee':10}{'analytical':>14}{'MuJoCo':>14}{'ratio':>9}")
    for knee in biped.KNEES:
        model = biped.Biped(biped.Robot.paper(), knee)
        q, qd, qdd = random_states(model, rng, SAMPLES)
        mj = load_model(model, exact=True)
        began = time.perf_counter()
        for _ in range(20):
            model.inverse_dynamics(q, qd, qdd)
        analytic = (time.perf_counter() - began) / 20 / SAMPLES
        began = time.perf_counter()
        mujoco_inverse_dynamics(mj, model, q, qd, qdd)
        reference = (time.perf_counter() - began) / SAMPLES
        print(
            f"{knee:10}{analytic * 1e6:11.2f} µs{reference * 1e6:11.2f} µs"
            f"{reference / analytic:8.0f}x"
        )
    print(
        f"\nforward walk, {STEPS} steps of the optimal gait at 0.3 m/s (median of {REPEATS} "
        "runs), one thread"
    )
    print(
        f"{'knee':10}{'model':>10}{'step':>8}{'walked':>8}{'walk':>10}{'x real':>8}"
        f"{'MuJoCo':>10}{'per step':>10}{'controller':>12}"
    )
    gaits = {}
    for knee in biped.KNEES:
        robot = biped.Robot.paper()
        optimum = optimize(GaitProblem(biped.Biped(robot, knee), 0.3))
        gait = gaits[knee] = Gait.from_optimum(optimum, robot)
        spec = model_spec(gait.biped)
        factors = {}
        for name, settings in (("committed", spec), ("previous", previous_settings(spec, robot))):
            walker = Walker(gait, settings)
            wall, physics, simulated, n, walked = walk_times(walker)
            factors[name] = simulated / wall
            print(
                f"{knee:10}{name:>10}{walker.model.opt.timestep * 1e3:6.1f}ms{walked:8d}"
                f"{wall:8.3f} s{simulated / wall:7.0f}x{physics:8.3f} s{physics / n * 1e6:8.1f} µs"
                f"{1 - physics / wall:11.0%}"
            )
        print(
            f"{knee:10}committed / previous: {factors['committed'] / factors['previous']:.2f}x "
            "the walk's speed"
        )
    print("target: 200 x real time for the committed walk on one core")
    print(
        "\nvalidation (every check: replay of both stances, walks at kp x 0.5, 1, 2, the orbit's "
        "walks), and the orbit check alone"
    )
    for knee, gait in gaits.items():
        began = time.perf_counter()
        result = validate(gait, steps=STEPS)
        wall = time.perf_counter() - began
        verdict = "PASS" if result.passed else "FAIL"
        walker = Walker(gait)
        with simulate.quiet_mujoco():
            orbit_wall, _ = median_time(orbit.orbit, walker, repeats=1)
        print(f"{knee:10}{wall:8.2f} s  {verdict}; the orbit {orbit_wall:.2f} s of it")


if __name__ == "__main__":
    main()
