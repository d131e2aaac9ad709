"""MuJoCo beside the analytical model: inverse dynamics per sample, and the forward
validation's speed (simulated seconds per wall second).

    python benchmarks/bench_mujoco.py
"""

import os

for _var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ[_var] = "1"  # one core, set before numpy loads its BLAS

import time  # noqa: E402

import mujoco  # noqa: E402
import numpy as np  # noqa: E402
from bench_dynamics import random_states  # noqa: E402
from mujoco import rollout  # noqa: E402

import biped  # noqa: E402
from biped.optimize import optimize  # noqa: E402
from biped.problem import GaitProblem  # noqa: E402
from validate.crosscheck import load_model, mujoco_inverse_dynamics  # noqa: E402
from validate.simulate import simulate  # noqa: E402

SAMPLES = 1000


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
    print("\nforward validation, 20 steps of the optimal gait at 0.3 m/s (median of 3 runs)")
    print(
        f"{'knee':10}{'simulated':>11}{'simulate':>11}{'x real':>8}{'physics':>10}{'x real':>8}"
        f"{'per step':>11}"
    )
    for knee in biped.KNEES:
        model = biped.Biped(biped.Robot.paper(), knee)
        optimum = optimize(GaitProblem(model, 0.3))
        walls = []
        for _ in range(3):
            began = time.perf_counter()
            sim = simulate(model, optimum.step, steps=20)
            walls.append(time.perf_counter() - began)
        simulated = sim.time[-1] - sim.time[0] + sim.model.opt.timestep
        # The floor: MuJoCo stepping the same model through the same controls in one call
        # (timing only: the gains do not alternate with the legs here).
        data = mujoco.MjData(sim.model)
        state = np.concatenate([sim.time[:1], sim.qpos[0], sim.qvel[0]])
        physics = []
        for _ in range(3):
            began = time.perf_counter()
            rollout.rollout(sim.model, data, state, sim.ctrl)
            physics.append(time.perf_counter() - began)
        wall, floor = np.median(walls), np.median(physics)
        print(
            f"{knee:10}{simulated:9.2f} s{wall:9.3f} s{simulated / wall:7.0f}x"
            f"{floor:8.3f} s{simulated / floor:7.0f}x{floor / len(sim.ctrl) * 1e6:8.1f} µs"
        )
    print(
        "target: 200 x real time; 'physics' is MuJoCo's own stepping at the model's 1 ms "
        "step, the most any controller can reach on this machine"
    )


if __name__ == "__main__":
    main()
