"""The feedforward check: one step of the gait file replayed with its torques. The exact
torques pass; for the optimal gaits at 0.3 m/s, any one joint's torques 20 % off, the torques
played 10 % of a period late, or every torque but the stance ankle's zeroed, fail."""

import numpy as np
import pytest

from biped.model.dynamics import JOINTS
from biped.records.gait_file import Gait
from tests.conftest import gait_of, optimal_gait, with_torques
from validate.checks import FEEDFORWARD_SHARE, check_feedforward
from validate.model import model_spec
from validate.replay import replay_model, replay_step
from validate.samples import GaitSamples

KNEES = ("revolute", "rolling")


@pytest.fixture(scope="module", params=KNEES)
def optimum(request):
    """The optimal gait of a knee, its robot and its replay model."""
    gait = gait_of(optimal_gait(request.param))
    biped = gait.biped
    spec = model_spec(biped)
    return gait, biped, spec, replay_model(spec, biped.knee)


def shares(gait, biped, model) -> np.ndarray:
    """Share of each joint's torque (Γ1..Γ6) its servo added, left leg in stance."""
    return replay_step(model, GaitSamples.from_gait(gait), biped, "left").shares()


def mutated(gait: Gait, change) -> Gait:
    """A copy of ``gait`` whose sample torques (N, 6) are ``change(torques, samples)``."""
    torques = np.array(gait.samples.torques, dtype=float)
    return with_torques(gait, change(torques, GaitSamples.from_gait(gait)))


def test_exact_torques_pass(optimum):
    """The file's own torques leave the servos under 5 % of every joint's torque, both legs
    in stance."""
    gait, biped, spec, _ = optimum
    check = check_feedforward(spec, biped, GaitSamples.from_gait(gait))
    assert check.passed, check.line()
    assert check.figures["max_feedback_share"] < FEEDFORWARD_SHARE
    for joint in JOINTS:
        assert check.figures[f"torque_rms_{joint}"] > 0.0


@pytest.mark.parametrize("factor", [0.8, 1.2])
@pytest.mark.parametrize("joint", range(6), ids=JOINTS)
def test_one_joint_off_by_a_fifth_fails(optimum, joint, factor):
    """One joint's torques times 0.8 or 1.2: that joint's servo supplies the difference,
    beyond the bound."""
    gait, biped, _, model = optimum

    def scale(torques, _samples):
        torques[:, joint] *= factor
        return torques

    seen = shares(mutated(gait, scale), biped, model)
    assert seen[joint] >= FEEDFORWARD_SHARE, (JOINTS[joint], seen)


def test_late_torques_fail(optimum):
    """The torques played 10 % of the period late (each sample takes the torque of 0.1 T
    before): the check fails, the mutation being seen at every joint."""
    gait, biped, spec, model = optimum

    def late(_torques, samples):
        return samples.at("torques", samples.t - 0.1 * samples.period)

    wrong = mutated(gait, late)
    assert np.all(shares(wrong, biped, model) >= FEEDFORWARD_SHARE)
    assert not check_feedforward(spec, biped, GaitSamples.from_gait(wrong)).passed


def test_stance_ankle_alone_fails(optimum):
    """Every torque but the stance ankle's zeroed: the five other servos carry their joints
    alone (share 1)."""
    gait, biped, spec, model = optimum

    def ankle_only(torques, _samples):
        torques[:, 1:] = 0.0
        return torques

    wrong = mutated(gait, ankle_only)
    seen = shares(wrong, biped, model)
    np.testing.assert_allclose(seen[1:], 1.0, atol=1e-9)
    assert not check_feedforward(spec, biped, GaitSamples.from_gait(wrong)).passed
