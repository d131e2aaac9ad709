"""The gait file of two phases: it reads back to the same motion, is checked against its
parameters, leaves single-support files as they were, and reads without CasADi or MuJoCo."""

import dataclasses
import functools
import json
import subprocess
import sys

import numpy as np
import pytest

from biped.model import double_support as ds
from biped.model.kinematics import swap_legs
from biped.records import gait_file
from tests.conftest import edited_gait_file, refusal, small_optimum, two_phase_gait


@pytest.fixture(scope="module")
def written(tmp_path_factory):
    """The rolling knee's two-phase gait written, and its path."""
    gait = two_phase_gait("rolling")
    return gait, gait.write(tmp_path_factory.mktemp("two") / "two.json")


def test_two_phase_gait_reads_back_to_the_same_motion(written):
    """Read back (checked against its parameters), the file gives the same step: the same
    parameters, the same double support's cubics, duration, front foot's wrench and
    samples, the same single support samples; rewritten, the same bytes."""
    gait, path = written
    read = gait_file.read_consistent(path, two_phase=True)
    assert read.two_phase and read.parameters == gait.parameters
    ours, theirs = gait.double_support, read.double_support
    assert theirs.duration == ours.duration and theirs.landing == "impact"
    np.testing.assert_array_equal(theirs.front_wrench_array, ours.front_wrench_array)
    for f in dataclasses.fields(ours.samples):
        np.testing.assert_array_equal(
            getattr(theirs.samples, f.name), getattr(ours.samples, f.name)
        )
    np.testing.assert_array_equal(read.samples.q, gait.samples.q)
    step = read.two_phase_step()
    np.testing.assert_allclose(step.double.coefficients, list(theirs.coefficients.values()))
    again = read.write(path.with_name("again.json"))
    assert again.read_bytes() == path.read_bytes()


def test_two_phase_gait_is_the_numeric_model(written):
    """The file's double support holds both feet (on the closed chain), its torques and rear
    wrench solve eq. (19') with its front wrench, its motion is continuous with the single
    support at the landing (positions; the velocities after the impact) and at lift-off
    (legs swapped), and S = V (T + T_ds)."""
    gait, _ = written
    phase, model = gait.double_support.samples, gait.biped
    assert ds.held_feet_residual(model, gait.step_length, phase.q, phase.qd) < 1e-9
    torques, rear = ds.split_with_swing_wrench(
        model, phase.q, phase.qd, phase.qdd, phase.front_wrench
    )
    np.testing.assert_allclose(torques, phase.torques, atol=1e-9)
    np.testing.assert_allclose(rear, phase.rear_wrench, atol=1e-9)
    np.testing.assert_allclose(phase.q[0], gait.samples.q[-1], atol=1e-12)
    lift = swap_legs(model, phase.q[-1], phase.qd[-1])
    np.testing.assert_allclose(lift[0], gait.samples.q[0], atol=1e-12)
    np.testing.assert_allclose(lift[1], gait.samples.qd[0], atol=1e-12)
    duration = gait.double_support.duration
    assert gait.step_length == pytest.approx(gait.speed * (gait.period + duration), rel=1e-12)


def _edit_duration(content):
    content["double_support"]["duration"] *= 1.1


def _edit_parameter(content):
    content["parameters"]["double_support"] *= 1.1
    content["step_length"] = content["speed"] * (
        content["period"] + content["parameters"]["double_support"]
    )
    content["double_support"]["duration"] = content["parameters"]["double_support"]


def _edit_front_wrench(content):
    content["double_support"]["front_wrench"][3][1] += 50.0


@pytest.mark.parametrize(
    "change, named",
    [
        (_edit_duration, "step_length"),
        (_edit_parameter, "double_support"),
        (_edit_front_wrench, "double_support"),
        (lambda c: c["double_support"].update(landing="soft"), "double_support.landing"),
        (lambda c: c["double_support"].pop("samples"), "double_support.samples"),
        (lambda c: c["double_support"].update(energy=1.0), "double_support.energy"),
    ],
)
def test_an_edited_two_phase_gait_is_refused(written, tmp_path, change, named):
    """A duration, a parameter or a front foot's wrench changed, an unknown landing, missing
    samples: refused, naming the field (the phase's duration changed: the step no longer
    S = V (T + T_ds); the front wrench changed: the samples' torques are not its)."""
    _, path = written
    content = json.loads(path.read_text())
    read = functools.partial(gait_file.read_consistent, two_phase=True)
    message = refusal(read, edited_gait_file(content, tmp_path, change))
    assert named in message


def test_the_work_over_both_phases_adds_the_double_supports(written, tmp_path):
    """The file's C_E over both phases is the single support's and the double support's
    joint work; over the double support the joints' signed work is the robot's change of
    mechanical energy (the feet are held: the ground does none), which their work ∫ Σ |Γ θ̇|
    bounds; torques 10 % off break that balance. A file written before these figures reads,
    without them."""
    gait, path = written
    double, model, phase = gait.double_support, gait.biped, gait.double_support.samples
    work = double.energy - gait.costs.energy
    assert double.energy_per_metre == pytest.approx(double.energy / gait.step_length)

    def mechanical(k):
        return model.kinetic_energy(phase.q[k], phase.qd[k]) + model.potential_energy(phase.q[k])

    def signed(torques):
        return np.trapezoid((model.joint_angles(phase.qd) * torques).sum(-1), phase.t)

    change = mechanical(-1) - mechanical(0)
    assert signed(phase.torques) == pytest.approx(change, abs=1e-3 * work)
    assert work >= abs(change) and work > 0.0
    assert abs(signed(1.1 * phase.torques) - change) > 1e-2 * work
    content = json.loads(path.read_text())
    for name in ("energy", "energy_per_metre"):
        content["double_support"].pop(name)
    older = tmp_path / "older.json"
    older.write_text(json.dumps(content))
    read = gait_file.read_consistent(older, two_phase=True)
    assert read.double_support.energy is None and read.double_support.energy_per_metre is None


def test_single_support_gait_files_are_unchanged(tmp_path):
    """A gait of single support has no double support: its file holds no such block or
    units, and reading and rewriting it gives the same bytes."""
    gait = gait_file.Gait.from_optimum(small_optimum("rolling"), gait_file.Robot.paper())
    path = gait.write(tmp_path / "one.json")
    content = json.loads(path.read_text())
    assert "double_support" not in content
    assert not [key for key in content["units"] if key.startswith("double_support")]
    again = gait_file.read_consistent(path, two_phase=True).write(tmp_path / "again.json")
    assert again.read_bytes() == path.read_bytes()


_READ = """
import sys
sys.modules["casadi"] = None
sys.modules["mujoco"] = None
from biped.records import gait_file
gait = gait_file.read_consistent(sys.argv[1], two_phase=True)
print(gait.double_support.sthenic)
"""


def test_two_phase_gait_reads_without_casadi_or_mujoco(written):
    """A two-phase gait file reads and is checked against its parameters with CasADi and
    MuJoCo blocked."""
    gait, path = written
    done = subprocess.run(
        [sys.executable, "-c", _READ, str(path)], capture_output=True, text=True, timeout=120
    )
    assert done.returncode == 0, done.stderr
    assert float(done.stdout) == pytest.approx(gait.double_support.sthenic, rel=1e-12)


def test_commands_not_built_for_two_phases_refuse_it(written, tmp_path, capsys):
    """A two-phase gait file given where only single support is built (a reader's default,
    ``biped robustness``) is refused by name, before any work (exit 2, one line), never read
    as the single support phase alone."""
    from biped_cli import main

    _, path = written
    assert "is of two phases" in refusal(gait_file.read_consistent, path)
    assert main(["robustness", str(path), "--out", str(tmp_path / "map")]) == 2
    error = capsys.readouterr().err
    assert error.count("\n") == 1 and "is of two phases" in error
    assert not (tmp_path / "map").exists()
