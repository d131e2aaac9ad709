"""Inverse dynamics per sample, batch of 1,000, one core.

Compares the closed-form inverse dynamics (``Biped.inverse_dynamics``) with a reference
computed in the same process: assembling D, H, Q as matrices and solving eq. (19) with a
generic 9 x 9 linear solve per sample.

    python benchmarks/bench_dynamics.py
"""

import os

for _var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ[_var] = "1"  # one core, set before numpy loads its BLAS

import numpy as np  # noqa: E402
from timing import median_time  # noqa: E402

import biped  # noqa: E402
from biped.model.dynamics import JOINT_MATRIX  # noqa: E402

BATCH = 1000
REPEATS = 200


def reference(model, q, qd, qdd):
    """D q̈ + H + Q from the matrices, then a generic solve of B Γ + A_cᵀ F_e = τ."""
    tau = (model.mass_matrix(q) @ qdd[..., None])[..., 0] + model.bias_forces(q, qd)
    tau = tau + model.gravity_forces(q)
    ac_t = np.swapaxes(model.contact_jacobian(q), -1, -2)
    system = np.concatenate([np.broadcast_to(JOINT_MATRIX.T, ac_t.shape[:-2] + (9, 6)), ac_t], -1)
    return np.linalg.solve(system, tau[..., None])[..., 0]


def random_states(model, rng, n: int):
    """n random single-support states (q, q̇, q̈) with the stance foot flat: the benchmarks'
    samples."""
    angles = rng.uniform(-0.6, 0.6, (n, 6))
    return model.stance_state(angles, rng.normal(size=(n, 6)), rng.normal(size=(n, 6)))


def main():
    rng = np.random.default_rng(0)
    print(f"inverse dynamics, batch of {BATCH} samples, median of {REPEATS} runs, one thread")
    print(f"{'knee':10}{'closed form':>16}{'reference':>16}{'speed-up':>10}")
    for knee in biped.KNEES:
        model = biped.Biped(biped.Robot.paper(), knee)
        q, qd, qdd = random_states(model, rng, BATCH)
        torques, wrench = model.inverse_dynamics(q, qd, qdd)
        assert np.allclose(np.concatenate([torques, wrench], -1), reference(model, q, qd, qdd))
        fast, _ = median_time(model.inverse_dynamics, q, qd, qdd, repeats=REPEATS, warm_up=True)
        slow, _ = median_time(reference, model, q, qd, qdd, repeats=20, warm_up=True)
        fast, slow = fast / BATCH, slow / BATCH
        print(f"{knee:10}{fast * 1e6:13.3f} µs{slow * 1e6:13.3f} µs{slow / fast:9.1f}x")
    print("target: under 5 µs per sample")


if __name__ == "__main__":
    main()
