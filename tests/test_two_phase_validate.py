"""A two-phase gait in MuJoCo: its samples cover both phases, MuJoCo's dynamics and a replay
of both phases agree with it (both feet's ground forces in double support), and the checks
not built for it say so."""

import dataclasses

import numpy as np
import pytest

from biped import Biped
from biped.model.kinematics import swap_legs
from tests.conftest import two_phase_gait
from validate.checks import checks as c
from validate.checks import orbit as o
from validate.checks.validation import two_phase_checks
from validate.scene.model import compile_spec, model_spec
from validate.walk.samples import GaitSamples


@pytest.fixture(scope="module")
def gait():
    """The rolling knee's zero-speed landing: its replay follows the file (the impact
    landing's optimum, inside the floor's friction cone, touches down at 3 m/s and does not:
    docs/gaits.md)."""
    return two_phase_gait("rolling", "zero-speed")


@pytest.fixture(scope="module")
def impact_gait():
    return two_phase_gait("rolling")


@pytest.fixture(scope="module")
def samples(gait):
    return GaitSamples.from_gait(gait)


def test_samples_cover_both_phases_continuously(impact_gait):
    """The samples run from lift-off through the landing (positions continuous, the
    velocities jumping by the impact: the file's double support starts after it) to the
    next lift-off, which is the first sample's state with the legs swapped; the front foot
    carries no load in single support and the file's wrench in double support."""
    gait, samples = impact_gait, GaitSamples.from_gait(impact_gait)
    t_land, eps = samples.landing, 1e-9
    assert samples.period == pytest.approx(gait.period + gait.double_support.duration)
    before, after = samples.at("q", [t_land - eps]), samples.at("q", [t_land + eps])
    np.testing.assert_allclose(before, after, atol=1e-7)
    np.testing.assert_allclose(samples.at("qd", [t_land - eps])[0], gait.samples.qd[-1], atol=1e-6)
    np.testing.assert_allclose(
        samples.at("qd", [t_land + eps])[0], gait.double_support.samples.qd[0], atol=1e-6
    )
    q_lift, qd_lift = swap_legs(gait.biped, samples.q[-1], samples.qd[-1])
    np.testing.assert_allclose(q_lift, samples.q[0], atol=1e-12)
    np.testing.assert_allclose(qd_lift, samples.qd[0], atol=1e-12)
    single = samples.t < t_land
    assert not np.any(samples.swing_wrench[single])
    np.testing.assert_allclose(
        samples.double_support().swing_wrench, gait.double_support.samples.front_wrench
    )
    assert samples.single_support().period == gait.period


def test_validation_of_a_two_phase_gait(gait, impact_gait):
    """On its own model: the model, MuJoCo's inverse dynamics along both phases (the front
    foot's wrench given), the knee loads, the landing against MuJoCo's impact map holding
    both feet (the impact landing's impulses) and the replay of both phases (the zero-speed
    landing's), with both feet's ground forces within ``FOOT_FORCE_SHARE`` of the weight,
    pass; MuJoCo's walk of both phases, its gains and its orbit pass too (the zero-speed
    landing's walk: docs/gaits.md), the joints' work per step within 10 % of the file's over
    both phases; the orbit is measured on a section of its single support where the stance
    foot is at rest."""
    impact_checks, *_ = two_phase_checks(impact_gait, model_spec(impact_gait.biped))
    impact = {c.name: c for c in impact_checks}
    for name in ("model", "inverse_dynamics", "knee_loads", "impact"):
        assert impact[name].passed, impact[name].line()
    found, sim, *_ = two_phase_checks(gait, model_spec(gait.biped))
    checks = {check.name: check for check in found}
    for check in found:
        assert check.passed, check.line()
    figures = checks["feedforward"].figures
    for foot in ("rear", "front"):
        assert figures[f"{foot}_force_rms_error"] < c.FOOT_FORCE_SHARE * gait.robot.weight
    assert sim.double_support and all(sim.landed) and not checks["forward"].figures["fell"]
    # MuJoCo's joints work per step within 10 % of the file's over both phases; against the
    # single support's work alone (what the file's costs hold) they would not
    walked = checks["forward"].figures["energy_per_step"]
    assert walked == pytest.approx(gait.double_support.energy, rel=0.1)
    assert walked > 1.1 * gait.costs.energy
    assert not any("energy_ratio not measured" in n for n in checks["forward"].notes)
    assert checks["orbit"].figures["section_phase"] > o.LANDING  # where the foot is at rest


def test_wrong_knee_model_fails_the_replay(gait, samples, impact_gait):
    """The rolling knee's two-phase gait replayed on the revolute knee's model: the servos
    and both feet's forces are far off, and so is its landing against MuJoCo's impact map."""
    wrong = Biped(gait.robot, "revolute")
    check = c.check_two_phase_feedforward(model_spec(wrong), wrong, samples)
    assert not check.passed and set(check.causes) == {"servo share", "foot forces"}
    model = compile_spec(model_spec(wrong))
    landing = GaitSamples.from_gait(impact_gait)
    impact = c.check_two_phase_impact(model, wrong, landing, impact_gait)
    assert not impact.passed and impact.causes == ["model mismatch"]


def test_double_support_stretched_fails_the_replay(gait, samples):
    """The double support's duration 10 % longer in the samples (the same torques, a slower
    motion): the feet's forces and the servos are off."""
    t = samples.t.copy()
    later = t > samples.landing
    t[later] = samples.landing + 1.1 * (t[later] - samples.landing)
    stretched = dataclasses.replace(samples, t=t, period=float(t[-1]))
    check = c.check_two_phase_feedforward(model_spec(gait.biped), gait.biped, stretched)
    assert not check.passed and "foot forces" in check.causes


def test_another_split_fails_the_feet_forces(gait, samples):
    """The same motion and torques with 100 N moved from the rear foot's Fz to the front
    foot's in the file: MuJoCo's feet, pushed by the same torques, do not carry that split."""
    rear, front = samples.wrench.copy(), samples.swing_wrench.copy()
    double = samples.t >= samples.landing
    rear[double, 1] -= 100.0
    front[double, 1] += 100.0
    moved = dataclasses.replace(samples, wrench=rear, swing_wrench=front)
    check = c.check_two_phase_feedforward(model_spec(gait.biped), gait.biped, moved)
    assert not check.passed and check.causes == ["foot forces"]


def test_biped_validate_of_a_two_phase_gait(gait, tmp_path, capsys):
    """``biped validate`` on a two-phase gait file runs its checks (the orbit's too), writes
    the report and the recording and exits 0 (every check passed); at the servos' stiffness
    halved the orbit, a flip, is not shown stable and the command exits 1."""
    import json

    from biped_cli import main

    path = gait.write(tmp_path / "two.json")
    rrd = tmp_path / "rec" / "two.rrd"
    assert main(["validate", str(path), "--rrd", str(rrd)]) == 0
    printed = capsys.readouterr().out
    assert "PASS  feedforward" in printed and "PASS  impact" in printed
    assert "PASS  forward" in printed and "PASS  orbit" in printed
    assert "FAIL" not in printed and "not run" not in printed
    report = json.loads((tmp_path / "rec" / "two.report.json").read_text())
    assert report["passed"] is True and report["feedforward"]["passed"] is True
    assert report["units"]["feedforward.rear_force_rms_error"] == "N"
    assert rrd.exists() and report["recording"] == str(rrd)


def test_the_walk_slips_at_twice_the_committed_step(gait):
    """At twice the committed 1 ms step (the models' step before; ``at_timestep``: contacts,
    stops and the knee's coupling at two steps' time constant) the two-phase walk's stance
    foot creeps under the servos' damping (MuJoCo solves the contacts without the damping it
    then integrates implicitly) beyond the forward check's millimetre; at the committed step
    it walks the same steps without slipping, the model's spec untouched."""
    from validate.scene.model import at_timestep
    from validate.walk import contact
    from validate.walk.simulate import Walker

    committed = model_spec(gait.biped)
    coarse = at_timestep(committed, 0.002)
    assert committed.option.timestep == 0.001 and coarse.option.timestep == 0.002
    assert all(g.solref[0] == 0.004 for g in coarse.geoms if g.contype or g.conaffinity)
    slips = []
    for spec in (coarse, committed):
        walker = Walker(gait, spec)
        sim = walker.walk(8)
        assert all(sim.landed)
        settle = int(contact.SETTLE * walker.period / sim.model.opt.timestep)
        slips.append(float(sim.stance_foot_slip(settle).max()))
    assert slips[0] > 0.6e-3 and slips[1] < 0.3e-3, slips  # [m]


def test_the_validations_controller_walks_a_stable_orbit_and_without_its_speed_loop_not(gait):
    """With the validation's controller (servos of 2000 N·m/rad, the stance ankle's speed
    loop) the two-phase walk's orbit is stable; without the speed loop the walk stops landing
    within ten steps, no orbit is found, and the check fails."""
    from validate.checks.orbit import check_orbit
    from validate.walk.simulate import Walker, WalkSettings

    walker = Walker(gait, model_spec(gait.biped))
    (stable, _), (loose, found) = (
        check_orbit(walker, s) for s in (c.WALK, WalkSettings(speed_scale=0.0))
    )
    assert stable.passed, stable.line()
    assert not loose.passed and found.multipliers is None, loose.line()
    assert "did not land step" in found.failure
