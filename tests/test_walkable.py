"""The walkable constraints (``biped.model.walkable``): the solver's graph and the check compute
one formula; each binds where it should (the paper's optimum breaks it, the constrained
optimum keeps it on the check grid, active, at a higher cost); a landing at speed 0 has no
impact; the clearance envelope is kept at every sample of the check grid."""

import dataclasses
import functools

import numpy as np
import pytest

import biped
from biped.model import walkable
from biped.model.criteria import (
    CLEARANCE_FLOOR,
    CLEARANCE_FULL,
    PAPER_SAFETY,
    Safety,
    clearance_envelope,
    evaluate_step,
)
from biped.model.gait import build_step
from biped.model.robot import JOINT_STOPS
from biped.optimization.optimize import optimize
from biped.optimization.problem import GaitProblem
from biped.optimization.symbolic import StepGraph

ROBOT = biped.Robot.paper()
SPEED = 0.3


@functools.cache
def optimum(knee: str = "rolling", safety: Safety = PAPER_SAFETY):
    """The certified optimum of the sthenic criterion at 0.3 m/s under ``safety``."""
    problem = GaitProblem(biped.Biped(ROBOT, knee), SPEED, safety=safety)
    found = optimize(problem, starts=3)
    assert found.certified, found.report.status
    return problem, found


def _step(problem, found):
    return build_step(problem.model, problem.speed, problem.to_parameters(found.variables))


def test_the_solver_and_the_check_compute_one_formula():
    """At seeded random gaits, the solver's rows of every walkable constraint (its graph,
    scaled, with its margins) equal the numeric check's (``step_margins(solver=True)``) on
    the solver's samples to 1e-9 of their scale; with another friction coefficient they
    differ."""
    safety = Safety(landing_speed=0.3, friction=0.6, joint_margin=0.05, hip_progress=0.2)
    model = biped.Biped(ROBOT, "rolling")
    problem = GaitProblem(model, SPEED, safety=safety)
    graph = StepGraph(model, problem.samples_per_half, safety)
    constraints = graph.function()
    names = np.array(graph.constraint_names)
    rng = np.random.default_rng(11)
    for _ in range(3):
        z = problem.first_guess(rng.uniform(0.4, 0.8)) + 0.02 * rng.standard_normal(21)
        rows = np.asarray(constraints(z, SPEED)[8]).ravel()
        step = build_step(model, SPEED, problem.to_parameters(z))
        numeric = evaluate_step(
            model, step, problem.samples_per_half, margins=True, safety=safety
        ).walkable
        assert set(numeric) == set(safety.walkable)
        for name, margins in numeric.items():
            expected = margins.ravel() / walkable.SCALES[name]  # sample-major
            np.testing.assert_allclose(rows[names == name], expected, rtol=0, atol=1e-9)
    other = dataclasses.replace(safety, friction=0.5)
    numeric = evaluate_step(model, step, problem.samples_per_half, True, other).walkable
    expected = numeric["friction"].ravel() / walkable.SCALES["friction"]
    assert np.abs(rows[names == "friction"] - expected).max() > 1e-3


# A setting of each constraint that the paper's optimum at 0.3 m/s (rolling knee) breaks: its
# sole lands at 0.90 m/s, its impulse has |Ix| / Iz = 0.30, its hips come within 0.36 rad of
# their stops, its hip slows to 0.60 V.
BINDING = {
    "landing": Safety(landing_speed=0.3),
    "impact_friction": Safety(friction=0.25),
    "joint_stops": Safety(joint_margin=0.4),
    "progress": Safety(hip_progress=0.7),
}


@pytest.mark.parametrize("name", sorted(BINDING))
def test_each_walkable_constraint_binds_where_it_should(name):
    """The paper's optimum breaks the setting (infeasible under it, naming the constraint);
    the optimum under it is certified, keeps it at every sample of the check grid, holds it
    active (its tightest margin within 1 % of the constraint's scale) and costs more."""
    safety = BINDING[name]
    paper_problem, paper = optimum()
    model = paper_problem.model
    evaluation = evaluate_step(model, _step(paper_problem, paper), 100, safety=safety)
    assert name in evaluation.violations()
    problem, found = optimum(safety=safety)
    margins = found.evaluation.walkable[name]
    assert found.feasible and margins.min() >= 0.0
    assert margins.min() < 0.01 * walkable.SCALES[name]
    assert found.value > paper.value * 1.01


def _impact_loss(problem, found) -> float:
    """[J] The kinetic energy the landing destroys, ½ (q̇⁻ − q̇⁺)ᵀ D (q̇⁻ − q̇⁺) (Carnot: the
    kinetic energy before less after)."""
    q, before = _step(problem, found).end
    after, _ = problem.model.impact(q, before)
    mass = problem.model.mass_matrix(q)
    lost = 0.5 * (before - after) @ mass @ (before - after)
    assert lost == pytest.approx(0.5 * (before @ mass @ before - after @ mass @ after), rel=1e-9)
    return lost


def test_a_landing_bound_is_the_soles_largest_speed():
    """Under a landing speed of 0.3 m/s the sole touches down at 0.3 m/s at most (at 0.90
    m/s without), and the landing destroys less kinetic energy (0.77 J, 1.24 J without,
    though its impulse is larger: the sole comes down more vertically, against the whole
    robot's weight)."""
    paper_problem, paper = optimum()
    problem, found = optimum(safety=BINDING["landing"])
    velocities = [
        walkable.touchdown_velocity(p.model, *_step(p, f).end)
        for p, f in ((paper_problem, paper), (problem, found))
    ]
    speeds = np.linalg.norm(velocities, axis=1)
    assert speeds[0] > 0.85 and speeds[1] <= 0.3 + walkable.LANDING_TOLERANCE
    assert _impact_loss(problem, found) < 0.7 * _impact_loss(paper_problem, paper)


def test_a_landing_at_speed_zero_has_no_impact():
    """An impactless landing (landing speed 0): the sole touches down at rest (1 μm/s), the
    impulse vanishes and the impact map leaves the velocities as they are."""
    problem, found = optimum(safety=Safety(landing_speed=0.0))
    step = _step(problem, found)
    velocity = walkable.touchdown_velocity(problem.model, *step.end)
    assert np.linalg.norm(velocity) <= walkable.LANDING_TOLERANCE
    assert np.abs(step.impulse).max() < 1e-4
    qd_plus, _ = problem.model.impact(*step.end)
    assert np.abs(qd_plus - step.end[1]).max() < 1e-4


def test_friction_holds_the_stance_foot_and_the_impulse_in_the_cone():
    """Under μ = 0.25 the impact's |Ix| <= μ Iz (0.30 Iz without) and |Fx| <= μ Fz at every
    sample of the check grid."""
    problem, found = optimum(safety=BINDING["impact_friction"])
    step = _step(problem, found)
    assert abs(step.impulse[0]) <= 0.25 * step.impulse[1] + 1e-12
    wrench = found.evaluation.wrench
    assert np.all(np.abs(wrench[:, 0]) <= 0.25 * wrench[:, 1])


def test_joint_stops_are_in_the_mjcfs_convention():
    """The constrained joints' margins are their distances to the MJCF's stops, each joint's
    angle its child's less its parent's: minus the paper's θ (a standing robot's joints at
    0 are each |stop| from the stops)."""
    theta = np.zeros((6, 1))
    margins = np.array(walkable.joint_stop_margins(theta, 0.0)).ravel()
    kinds = [kind for kind in walkable.STOPPED.values() for _ in range(2)]
    expected = [abs(JOINT_STOPS[kind][i % 2]) for i, kind in enumerate(kinds)]
    np.testing.assert_allclose(margins, expected)
    theta[5] = -0.7  # the swing ankle's child − parent is +0.7, past its 0.6 stop
    margins = np.array(walkable.joint_stop_margins(theta, 0.0)).ravel()
    assert margins[7] == pytest.approx(-0.1)


def test_the_clearance_envelope():
    """Nothing within the windows; a third of the clearance at the window's edge, rising to
    all of it at 30 % of the step from each end; all of it outside windows of 30 % or more."""
    t = np.array([0.0, 0.05, 0.1, 0.2, 0.3, 0.5, 0.7, 0.8, 0.95, 1.0])
    found = clearance_envelope(t, 0.03, 0.1)
    mid = CLEARANCE_FLOOR + (1 - CLEARANCE_FLOOR) * (0.2 - 0.1) / (CLEARANCE_FULL - 0.1)
    expected = 0.03 * np.array([0, 0, CLEARANCE_FLOOR, mid, 1, 1, 1, mid, 0, 0])
    np.testing.assert_allclose(found, expected, atol=1e-15)
    np.testing.assert_allclose(clearance_envelope(t, 0.03, 0.35)[4:6], [0.0, 0.03])


def test_the_clearance_is_kept_at_every_check_sample():
    """With 3 cm at 0.3 m/s the swing sole keeps the envelope at each of the check grid's
    samples (the solver constrains those between its own), and none of the optimum's
    samples inside the windows is required to."""
    problem, found = optimum(safety=Safety(clearance=0.03))
    psi = found.evaluation.constraints[:, 5:]
    assert np.nanmin(psi) >= 0.0
    paper_problem, paper = optimum()
    kept = evaluate_step(
        paper_problem.model, _step(paper_problem, paper), 100, safety=Safety(clearance=0.03)
    )
    assert "swing_heel" in kept.violations() or "swing_toe" in kept.violations()


def test_a_landing_bound_as_a_share_of_the_walking_speed():
    """``landing_share`` s bounds the sole's landing speed at s V: at 0.3 m/s a share of 1 is
    the bound 0.3 m/s (the same optimum to 1e-9); at 0.6 m/s it is 0.6 m/s. Both at once
    are refused."""
    _, by_speed = optimum(safety=BINDING["landing"])
    _, by_share = optimum(safety=Safety(landing_share=1.0))
    assert by_share.value == pytest.approx(by_speed.value, rel=1e-9)
    problem = GaitProblem(biped.Biped(ROBOT, "rolling"), 0.6, safety=Safety(landing_share=1.0))
    found = optimize(problem, starts=1)
    velocity = walkable.touchdown_velocity(problem.model, *_step(problem, found).end)
    assert 0.55 < np.linalg.norm(velocity) <= 0.6 + walkable.LANDING_TOLERANCE
    with pytest.raises(biped.BipedError, match="allowed one of the two"):
        Safety(landing_speed=0.3, landing_share=1.0)


def test_a_gait_file_gives_the_landing_and_the_tightest_margins(tmp_path):
    """A gait file gives the sole's touchdown velocity and speed, the landing's friction
    ratio and, for the walkable constraints its margins ask, their tightest margins with
    units; an edited one is refused by name; a file written before them reads. A landing at
    rest is a consistent impact (no impulse to push)."""
    import json

    from biped.records import gait_file
    from biped.records.gait_file import Gait

    safety = Safety(landing_speed=0.3, friction=0.6, joint_margin=0.05, hip_progress=0.2)
    problem, found = optimum(safety=safety)
    path = Gait.from_optimum(found, ROBOT).write(tmp_path / "walkable.json")
    content = json.loads(path.read_text())
    impact, walk = content["impact"], content["walkability"]
    assert impact["touchdown_speed"] == pytest.approx(np.hypot(*impact["touchdown_velocity"]))
    assert impact["touchdown_speed"] <= 0.3 + walkable.LANDING_TOLERANCE
    assert set(walk) == {"friction_needed", "joint_stop_distance", "least_hip_speed"} | set(
        safety.walkable
    )
    assert content["units"]["walkability.landing"] == "m/s"
    assert content["units"]["walkability.friction"] == "N"
    assert walk["landing"] >= 0.0 and walk["landing"] < 0.01
    gait_file.read_consistent(path)
    edited = {**content, "impact": {**impact, "touchdown_speed": 0.1}}
    with pytest.raises(biped.BipedError, match="impact.touchdown_speed"):
        gait_file.read_consistent(gait_file.write_json(tmp_path / "edited.json", edited))
    old = {k: v for k, v in content.items() if k != "walkability"}
    old["impact"] = {
        k: v for k, v in impact.items() if k not in ("touchdown_velocity", "touchdown_speed")
    }
    old["impact"].pop("friction_needed")
    gait = gait_file.read_consistent(gait_file.write_json(tmp_path / "old.json", old))
    assert gait.walkability is None and gait.impact.touchdown_speed is None
    _, at_rest = optimum(safety=Safety(landing_speed=0.0))
    impact = Gait.from_optimum(at_rest, ROBOT).impact
    assert impact.consistent and impact.touchdown_speed <= walkable.LANDING_TOLERANCE


def test_the_command_lines_walkable_preset_and_its_options():
    """``--walkable`` gives the preset (``WALKABLE``); an option given replaces its value (a
    landing speed the preset's landing share); without it, the paper's problem; a value out
    of range is one line naming it, exit 2."""
    from biped.model.criteria import WALKABLE
    from biped_cli import build_parser, main
    from biped_cli.args import safety

    def parsed(*options):
        argv = ["optimize", "--knee", "rolling", "--speed", "0.3", "--out", "g.json", *options]
        return safety(build_parser().parse_args(argv))

    assert parsed() == PAPER_SAFETY
    assert parsed("--walkable") == WALKABLE
    assert parsed("--walkable", "--friction", "0.8") == dataclasses.replace(WALKABLE, friction=0.8)
    assert parsed("--walkable", "--landing-speed", "0.3") == dataclasses.replace(
        WALKABLE, landing_speed=0.3, landing_share=None
    )
    assert parsed("--landing-share", "1", "--clearance-window", "0.2") == Safety(
        landing_share=1.0, clearance_window=0.2
    )
    for option, value in (("--friction", "5"), ("--landing-share", "-1"), ("--hip-progress", "x")):
        assert main(["optimize", "--knee", "rolling", "--speed", "0.3", option, value]) == 2


def test_a_fast_gaits_sole_keeps_above_the_floor_near_its_landing():
    """At 0.7 m/s with 2 cm of clearance (energy per metre), the revolute knee's toe went
    0.025 mm into the floor between the solver's samples near landing, where the clearance's
    window asks only that the sole be above the floor: the optimum is now certified, its sole
    above the floor at every sample of the check grid."""
    problem = GaitProblem(
        biped.Biped(ROBOT, "revolute"), 0.7, "energy-per-metre", Safety(clearance=0.02)
    )
    found = optimize(problem, starts=3)
    assert found.certified, found.evaluation.violations_line()
    assert np.nanmin(found.evaluation.constraints[:, 5:]) >= 0.0
