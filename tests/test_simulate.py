"""Forward simulation of a gait file in MuJoCo with contact: the optimal gaits walk at any
gain from half to twice the default, and a walk that scuffs, rolls its foot, slides or
shuffles is told apart from one that walks."""

import mujoco
import numpy as np
import pytest

from biped.model.kinematics import ZH
from tests.conftest import gait_of, optimal_gait, small_optimum, with_torques
from validate.checks.checks import (
    MAX_FOOT_TILT,
    MAX_SLIP,
    scuff_notes,
    walk_causes,
    walk_figures,
    walks,
)
from validate.scene.model import model_spec
from validate.walk import contact
from validate.walk.simulate import FALLEN, RESYNC, Push, Walker, WalkSettings

STEPS = 20


@pytest.fixture(scope="module", params=["revolute", "rolling"])
def walk(request):
    """Both robots' optimal gaits at 0.3 m/s walked for 20 steps, with their figures."""
    optimum = optimal_gait(request.param)
    walker = Walker(gait_of(optimum))
    sim = walker.walk(STEPS)
    figures = walk_figures(
        walker.biped, walker.samples, sim, optimum.costs()["energy"], contact.ground_reaction(sim)
    )
    return walker, optimum, sim, figures


def test_optimal_gait_walks_twenty_steps_without_slip_or_fall(walk):
    """Every step lands in its window and advances the hip by a step length, the stance foot
    neither slides (< 1 mm on the ground while it carries the robot) nor tilts, the swing
    foot never touches the floor before its landing, no MuJoCo warning."""
    _, optimum, sim, figures = walk
    assert figures["steps"] == STEPS and all(sim.landed) and len(sim.landed) == STEPS
    assert walks(figures, STEPS) and not figures["fell"]
    assert figures["max_slip"] < MAX_SLIP
    assert figures["max_foot_tilt"] < MAX_FOOT_TILT
    assert figures["scuff_steps"] == 0 and figures["warnings"] == 0
    # The robot covers the gait's distance: 20 steps of S = V T, each about S.
    assert figures["distance"] == pytest.approx(STEPS * optimum.step.step_length, rel=0.05)
    assert 0.9 < figures["step_advance_range"][0] <= figures["step_advance_range"][1] < 1.1


def test_walk_follows_the_gait(walk):
    """Away from the landings the centre of pressure lies on the gait's ZMP within 2 mm RMS
    (the ankle's speed feedback moves it by 3 mm per cm/s), the ground force is the gait's
    within 1 % of the weight, and the joints follow their references to 5 mrad."""
    _, _, sim, figures = walk
    assert figures["zmp_rms_error"] < 2e-3
    assert figures["ground_force_rms_error"] < 0.01
    layout = sim.layout
    rows = sim.step_slices()[0]
    errors = sim.ctrl[rows][:, layout.positions] - layout.joint_angles(sim.qpos[rows])
    assert np.abs(errors).max() < 0.005


def test_rolling_knee_equality_holds_in_the_walk(walk):
    """The joint equality of the rolling knee holds to a milliradian over the whole walk,
    landings included."""
    walker, _, _, figures = walk
    if walker.biped.knee == "rolling":
        assert figures["max_knee_equality_violation"] < 1e-3
    else:
        assert "max_knee_equality_violation" not in figures


@pytest.mark.parametrize("scale", [0.5, 2.0])
def test_walk_holds_over_the_gains(walk, scale):
    """At half and twice the servos' stiffness the optimal gait still walks 20 steps: the
    verdict does not hang on the gains."""
    walker, optimum, _, _ = walk
    sim = walker.walk(STEPS, WalkSettings(kp_scale=scale))
    figures = walk_figures(walker.biped, walker.samples, sim, optimum.costs()["energy"])
    assert walks(figures, STEPS), figures


def test_fall_ends_the_simulation():
    """Without torques and feedback the robot collapses: the simulation stops once the hip
    has dropped by a quarter, within two steps, and the report says fell."""
    gait = gait_of(small_optimum("revolute"))
    gait = with_torques(gait, np.zeros_like(gait.samples.torques))
    walker = Walker(gait)
    sim = walker.walk(3, WalkSettings(kp_scale=0.0, kv_scale=0.0))
    assert len(sim.landed) <= 2 and not sim.landed[-1]
    assert sim.hip_height()[-1] == pytest.approx(FALLEN * walker.samples.q[0, ZH], abs=0.01)
    figures = walk_figures(walker.biped, walker.samples, sim, 1.0)
    assert figures["fell"] and figures["steps"] == 0 and not figures["stalled"]
    assert walk_causes(figures, 3)[0] == "fell"


def test_flipped_torques_roll_the_stance_foot():
    """With every torque of the file's sign flipped and tripled, the stance foot rolls onto
    its heel within the first step, the hip still up (its toe lifts by 12 cm): the foot check
    fails before any fall. A servo's tracking error is the torque it lacks over its stiffness:
    Γ x -3 lacks 4 Γ, which servos of 2000 N·m/rad track as closely as those of 1000 tracked
    Γ x -1 (2 Γ), which rolled the foot then (0.27 rad); with 2000 N·m/rad, Γ x -1 walks two
    steps (the replay fails it: tests/test_replay.py), Γ x -2 scuffs, Γ x -3 rolls 0.48 rad."""
    gait = gait_of(optimal_gait("revolute"))
    gait = with_torques(gait, -3.0 * gait.samples.torques)
    walker = Walker(gait)
    sim = walker.walk(2)
    first = contact.foot_tilt(sim, walker.period)
    assert first.tilt[0] > MAX_FOOT_TILT and first.toe_lift[0] > 0.01
    assert sim.hip_height()[sim.step_slices()[0]].min() > 0.85  # [m] not fallen
    figures = walk_figures(walker.biped, walker.samples, sim, 1.0)
    assert figures["max_foot_tilt"] > MAX_FOOT_TILT and not walks(figures, 2)
    assert "tilted" in walk_causes(figures, 2) and "fell" not in walk_causes(figures, 2)


def test_a_scuff_fails_the_walk_with_its_duration_and_depth():
    """A plank 4 mm high on the floor in the left foot's path (the gait clears the floor by
    1 mm): the swing foot touches it before its landing window, and the walk fails with the
    time it spent on it and how deep it went."""
    gait = gait_of(optimal_gait("revolute"))
    biped = gait.biped
    spec = model_spec(biped)
    spec.worldbody.add_geom(
        name="plank",
        type=mujoco.mjtGeom.mjGEOM_BOX,
        size=[0.005, 0.03, 0.002],
        pos=[0.21, 0.09, 0.002],  # between the left sole's first two places, on its side
        contype=0,
        conaffinity=1,
    )
    walker = Walker(gait, spec)
    sim = walker.walk(4)
    figures = walk_figures(walker.biped, walker.samples, sim, 1.0)
    assert figures["scuff_steps"] >= 1 and 1 in contact.scuffs(sim, walker.period).steps
    assert figures["scuff_duration"] > 0.0 and figures["scuff_depth"] >= 0.0
    assert not walks(figures, 4) and "scuffed" in walk_causes(figures, 4)
    assert "scuffed" in scuff_notes(sim, walker.period, figures, 4)[0]
    clean = Walker(gait).walk(4)
    assert walks(walk_figures(walker.biped, walker.samples, clean, 1.0), 4)


def test_low_friction_slips():
    """On a floor of friction coefficient 0.05 (the gait needs |Fx| / Fz up to about 0.1)
    the stance foot slides by centimetres: no step counts."""
    walker = Walker(gait_of(optimal_gait("revolute")))
    sim = walker.walk(6, WalkSettings(friction=0.05))
    figures = walk_figures(walker.biped, walker.samples, sim, 1.0)
    assert figures["max_slip"] > 10 * MAX_SLIP and figures["steps"] == 0
    assert "slipped" in walk_causes(figures, 6)
    assert figures["max_slip_share"] == pytest.approx(
        figures["max_slip"] / walker.samples.step_length
    )


def test_push_gives_its_impulse():
    """A push gives the trunk the impulse asked for, over one reading period, and moves the
    robot's centre of mass the way it pushes."""
    walker = Walker(gait_of(small_optimum("rolling")))
    free = walker.walk(3)
    after = int(np.searchsorted(free.time, 0.3 + 2 * RESYNC))
    for impulse in (-5.0, 5.0):
        sim = walker.walk(3, WalkSettings(push=Push(impulse, 0.3)))
        assert sim.pushed == pytest.approx(impulse, rel=1e-9)
        change = sim.hip_speed()[after] - free.hip_speed()[after]
        assert np.sign(change) == np.sign(impulse) and abs(change) > 0.01  # [m/s]


def test_shuffling_does_not_advance():
    """Landings that do not carry the hip forward by half a step length are not steps: a walk
    whose hip is held in place from its second step (a robot shuffling) walked one step, did
    not advance and did not fall (the hip stays up)."""
    from validate.checks.checks import walk_causes

    walker = Walker(gait_of(small_optimum("revolute")))
    sim = walker.walk(4)
    held = sim.step_slices()[1].start
    qpos = sim.qpos.copy()
    column = sim.layout.state_index("hip_x") - 1  # the state vector starts with the time
    qpos[held:, column] = qpos[held, column]
    sim.qpos = qpos
    figures = walk_figures(walker.biped, walker.samples, sim, 1.0)
    assert figures["steps"] == 1 and figures["stalled"] and not figures["fell"]
    assert walk_causes(figures, 4) == ["did not advance"]


def test_phase_follows_the_hip():
    """The controller's phase is the gait's time at the hip's advance over the stance ankle:
    0 at the start of the walk, through the whole step by its touchdown, and moving back
    only by what a reading of the state every 20 ms corrects."""
    walker = Walker(gait_of(small_optimum("rolling")))
    sim = walker.walk(1)
    assert sim.landed == [True]
    assert sim.phase[0] == pytest.approx(0.0, abs=1e-9)
    assert sim.phase[-1] > 0.9 * walker.period
    assert np.diff(sim.phase).min() > -RESYNC


@pytest.mark.parametrize("knee", ["revolute", "rolling"])
def test_walk_spends_the_gait_energy(knee):
    """For a gait whose motors work (a small-budget optimum, about 4 N·m RMS), the energy
    MuJoCo's actuators spend per step, feedback and landings included, is the gait's
    energy criterion to a few per cent."""
    optimum = small_optimum(knee)
    walker = Walker(gait_of(optimum))
    sim = walker.walk(4)
    figures = walk_figures(walker.biped, walker.samples, sim, optimum.costs()["energy"])
    assert figures["steps"] == 4
    assert figures["feedforward_rms"] > 3.0
    assert figures["energy_per_step"] == pytest.approx(optimum.costs()["energy"], rel=0.05)


def test_simulation_is_deterministic():
    """The same gait simulated twice gives the same states, bit for bit."""
    walker = Walker(gait_of(small_optimum("rolling")))
    first, second = (walker.walk(2) for _ in range(2))
    assert np.array_equal(first.qpos, second.qpos) and np.array_equal(first.ctrl, second.ctrl)


def test_an_unstable_walk_counts_its_warnings_and_writes_no_log(tmp_path, monkeypatch, capfd):
    """A walk MuJoCo finds unstable (servos 10⁴ times too stiff for its step) counts its
    warnings and fails, prints nothing and leaves no MUJOCO_LOG.TXT in the working directory;
    MuJoCo's warning handler is the caller's again after it."""
    monkeypatch.chdir(tmp_path)
    before = mujoco.get_mju_user_warning()
    walker = Walker(gait_of(small_optimum("revolute")))
    sim = walker.walk(1, WalkSettings(kp_scale=1e4))
    assert sim.warnings > 0
    figures = walk_figures(walker.biped, walker.samples, sim, 1.0)
    assert not walks(figures, 1) and "MuJoCo warning" in walk_causes(figures, 1)
    assert list(tmp_path.iterdir()) == []
    assert capfd.readouterr() == ("", "")
    assert mujoco.get_mju_user_warning() is before


def test_a_failed_forward_check_says_why_in_words():
    """Zero torques, the servos alone holding the joints: the forward check fails, its causes
    first on its line and its first note saying why in words (the steps walked, then each
    cause on its physical scale), so a line that gives only the notes (the atlas's) names the
    reason: in the first step the stance foot slides (46 mm, a share of the step) and rolls
    onto its edge (0.24 rad, mm off the floor), the swing foot drags (ms, mm deep), the hip
    stays up; the servos of 2000 N·m/rad alone land the steps (advancing the hip 0.80-1.09
    of the step; those of 1000 N·m/rad did not: "did not advance"). The optimal gait's check
    passes with no such note and no cause."""
    from validate.checks.checks import check_forward

    gait = gait_of(small_optimum("revolute"))
    limp = Walker(with_torques(gait, np.zeros_like(gait.samples.torques)))
    check, _, _ = check_forward(limp, 3, energy=1.0)
    causes = ["scuffed", "slipped", "tilted"]
    assert not check.passed and check.causes == causes
    assert check.line().startswith(f"FAIL  forward           [{', '.join(causes)}] ")
    first = check.notes[0]
    assert first.startswith("not a walk of 3 steps: 0 of 3 steps within the limits, "), first
    assert "mm off the floor (allowed < 0.01 rad: 2.6 mm at the far end of the 25.8 cm" in first
    assert "swing foot scuffed the floor" in first and "mm deep" in first
    assert "% of the 0.183 m step (allowed < 1 mm, 0.55 %)" in first
    check, _, _ = check_forward(Walker(gait), 2, energy=1.0)
    assert check.passed and check.causes == []
    assert not any(n.startswith("not a walk") for n in check.notes)
