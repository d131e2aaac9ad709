"""The multipliers of one gait's walk in MuJoCo (``validate.checks.orbit``), beside the same
number of steps walked as one continuous walk in the same process.

    python benchmarks/bench_orbit.py

For each optimal gait at 0.3 m/s (Table 1, seed 0):

- one Jacobian at one grid position: 2 x 12 one-step walks from the section (the issue's
  2 x state dimension), beside 24 steps walked as one continuous walk (the reference: what
  the steps cost without a start per walk);
- the whole orbit as ``biped validate`` computes it: the settling walk, the Jacobian at
  ``PHASES`` grid positions (2 x 12 x PHASES one-step walks), the chord steps to the fixed
  point, the multipliers and their bootstrap, beside as many steps walked as one walk.
"""

import os

for _var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ[_var] = "1"  # one core, set before numpy loads its BLAS

from timing import median_time  # noqa: E402

import biped  # noqa: E402
from biped.optimization.optimize import optimize  # noqa: E402
from biped.optimization.problem import GaitProblem  # noqa: E402
from biped.records.gait_file import Gait  # noqa: E402
from validate.checks import orbit  # noqa: E402
from validate.walk.simulate import Walker, WalkSettings, quiet_mujoco  # noqa: E402

REPEATS = 3


def one_jacobian(returns: orbit.ReturnMap, x, basis, steps: orbit.Steps):
    """2 x 12 one-step walks: the central differences at one grid position."""
    one = orbit.Steps(steps.angle, steps.rate, phases=1)
    return orbit.central_differences(returns, x, basis * one.vector()[:, None], 1)


def main() -> None:
    print(f"orbit of the optimal gaits at 0.3 m/s, one core (median of {REPEATS} runs)")
    for knee in biped.KNEES:
        gait = Gait.from_optimum(
            optimize(GaitProblem(biped.Biped(biped.Robot.paper(), knee), 0.3)),
            biped.Robot.paper(),
        )
        walker = Walker(gait)
        settings = WalkSettings()
        with quiet_mujoco():
            settled = orbit.settle(walker, settings)
            returns = orbit.ReturnMap(walker, settings, settled.reference, settled.flow)
            steps = orbit.Steps()
            basis = orbit.section_basis(settled.flow, steps)
            jacobian, _ = median_time(
                one_jacobian, returns, settled.mean, basis, steps, repeats=REPEATS, warm_up=True
            )
            continuous, _ = median_time(walker.walk, 24, repeats=REPEATS)
            whole, result = median_time(orbit.orbit, walker, settings, repeats=REPEATS)
            walked, _ = median_time(walker.walk, result.walks, repeats=1)
        m = result.multipliers
        print(
            f"{knee:9} one Jacobian (24 one-step walks) {jacobian:.3f} s, 24 steps as one walk "
            f"{continuous:.3f} s: x {jacobian / continuous:.2f}"
        )
        print(
            f"{'':9} the orbit ({result.walks} walks, {result.steps.phases} grid positions) "
            f"{whole:.2f} s, {result.walks} steps as one walk {walked:.2f} s: "
            f"x {whole / walked:.2f}; ρ {m.radius:.3f} ± {m.spread:.3f}"
        )


if __name__ == "__main__":
    main()
