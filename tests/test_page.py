"""biped report: one page per gait with its figures, parameters, criteria, the constraints'
tightest margins, the validation verdict beside it and links to its own recording only."""

import json

import numpy as np
import pytest

from biped import Robot
from biped.model.criteria import CONSTRAINTS
from biped.model.dynamics import JOINTS
from biped.model.gait import PARAMETERS
from biped.records import gait_file
from biped.records.gait_file import Gait
from biped_cli import main
from tests.conftest import small_optimum
from validate.outputs.outputs import claim

NAME = "rolling-sthenic-0.300"


@pytest.fixture(scope="module")
def written(tmp_path_factory):
    """A gait file in logs/pipeline with a validation report, an owned recording and a
    video beside; its page written by 'biped report' into logs/reports."""
    root = tmp_path_factory.mktemp("page")
    gait_path = root / "logs/pipeline" / f"{NAME}.json"
    Gait.from_optimum(small_optimum("rolling"), Robot.paper()).write(gait_path)
    recording = root / "logs/recordings" / f"{NAME}.rrd"
    recording.parent.mkdir(parents=True)
    recording.write_bytes(b"recording")
    claim(recording, gait_path)
    video = recording.with_suffix(".mp4")
    video.write_bytes(b"video")
    report = {
        "forward": {
            "steps": 20,
            "max_slip": 0.0004,
            "fell": False,
            "step_duration_range": [0.99, 1.02],
            "passed": False,
            "notes": ["the swing foot scuffed the floor", "kp × 2: decided by scuffing"],
        },
        "orbit": {
            "verdict": "stable",
            "spectral_radius": 0.7,
            "spectral_radius_spread": 0.1,
            "multipliers_real": [-0.7, 0.2, 0.1],
            "multipliers_imag": [0.0, 0.1, -0.1],
            "flow_multiplier": 0.05,
            "passed": True,
            "notes": ["slowest multiplier -0.700 (a flip: errors alternate from step to step)"],
        },
        "passed": False,
        "units": {"forward.steps": "1", "forward.max_slip": "m"},
        "recording": str(recording),
        "video": [str(video)],
    }
    (root / "logs/pipeline" / f"{NAME}.report.json").write_text(json.dumps(report))
    out = root / "logs/reports"
    assert main(["report", str(gait_path), "--out", str(out)]) == 0
    return gait_path, out, (out / f"pipeline-{NAME}.md").read_text()


def test_page_states_the_gait_by_name_with_units(written):
    """Every parameter by name with its unit, the criteria with theirs, and the tightest
    margin of each constraint: the file's worst value, at the sample where Ψ is smallest."""
    from biped.pages.page import constraint_profile

    gait_path, _, text = written
    gait = gait_file.read(gait_path)
    for name in PARAMETERS:
        unit = "s" if name == "period" else "m" if name.endswith("_hip") else "rad"
        assert f"| {name} | {gait.parameters[name]:.6g} | {unit}" in text
    assert f"| {gait.costs.sthenic:.5g} | N²·m·s |" in text
    assert f"| {gait.costs.energy:.5g} | J |" in text
    t_n, psi, _ = constraint_profile(gait)
    for i, name in enumerate(CONSTRAINTS):
        worst = getattr(gait.constraints, name)
        assert np.nanmin(psi[:, i]) == pytest.approx(worst, rel=1e-9, abs=1e-12)
        at = t_n[int(np.nanargmin(psi[:, i]))]
        assert f"| {worst:.4g} |" in text and f"| {at:.3f} |" in text


def test_page_shows_the_validation_and_links_its_own_outputs(written):
    """The verdict and figures (with units) of the report beside the gait, and relative links
    to the recording and video that report names, the recording owned by this gait."""
    _, out, text = written
    assert "Validation in MuJoCo: **FAIL**" in text
    assert "| max_slip | 0.0004 | m |" in text and "| fell | no |" in text
    assert "| step_duration_range | 0.99 to 1.02 |" in text  # a range
    # notes are sentences, each on its own line, not a range
    assert "- the swing foot scuffed the floor\n- kp × 2: decided by scuffing\n" in text
    assert "| notes |" not in text and "floor to kp" not in text
    assert f"](../recordings/{NAME}.rrd)" in text and f"](../recordings/{NAME}.mp4)" in text
    assert f"](../pipeline/{NAME}.json)" in text


def test_page_figures_are_drawn_and_labelled(written):
    """Each figure the page shows exists, has ink and its labels."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.text import Text
    from PIL import Image

    from biped.pages.page import CONSTRAINT_MEANING, FIGURE_NAMES, gait_figures

    gait_path, out, text = written
    for name in FIGURE_NAMES:
        assert f"(pipeline-{NAME}/{name})" in text
        pixels = np.asarray(Image.open(out / f"pipeline-{NAME}" / name).convert("RGB"))
        assert pixels.std() > 20, name
    figure = gait_figures(gait_file.read(gait_path))["constraints.png"]
    FigureCanvasAgg(figure).draw()
    texts = {t.get_text() for t in figure.findobj(Text)}
    assert set(CONSTRAINT_MEANING.values()) <= texts
    assert sum(t.startswith("smallest ") for t in texts) == len(CONSTRAINTS)


def test_page_draws_the_orbit_checks_multipliers(written):
    """A report with an orbit check: its multipliers listed and drawn in the complex plane
    (the page's orbit.png, with ink)."""
    from PIL import Image

    _, out, text = written
    assert "### orbit: PASS" in text and "| multipliers_real | -0.7, 0.2, 0.1 |" in text
    assert f"(pipeline-{NAME}/orbit.png)" in text
    pixels = np.asarray(Image.open(out / f"pipeline-{NAME}" / "orbit.png").convert("RGB"))
    assert pixels.std() > 20


def test_page_links_no_recording_of_another_gait(written, tmp_path):
    """A recording whose owner is another gait file is not linked; without a report beside
    the gait, the page says it is not validated."""
    from biped.pages.page import Page, markdown
    from biped_cli.report import links, read_validation

    gait_path, _, _ = written
    copy = tmp_path / "sweep" / f"{NAME}.json"
    copy.parent.mkdir()
    copy.write_bytes(gait_path.read_bytes())
    report = read_validation(gait_path.with_name(f"{NAME}.report.json"))
    assert links(copy, report) == []  # the recording and video are the pipeline gait's
    assert [link.label for link in links(gait_path, report)] == ["recording", "video (mp4)"]
    page = Page(f"sweep-{NAME}", copy, gait_file.read(copy))
    text = markdown(page, tmp_path)
    assert "Not validated in MuJoCo" in text and "- recording:" not in text


def test_report_is_all_or_none(written, tmp_path, capsys):
    """A bad gait file among good ones is refused (exit 2, one line naming it) before
    anything is written: the earlier pages stay as they were."""
    gait_path, out, _ = written
    before = {p: p.read_bytes() for p in out.rglob("*") if p.is_file()}
    bad = tmp_path / "bad.json"
    bad.write_text("{")
    assert main(["report", str(gait_path), str(bad), "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert "bad.json" in err and len(err.strip().splitlines()) == 1
    assert {p: p.read_bytes() for p in out.rglob("*") if p.is_file()} == before
    assert not [p for p in out.iterdir() if p.name.startswith(".")]
    assert main(["report", str(gait_path), str(gait_path), "--out", str(out)]) == 2
    assert "share the page" in capsys.readouterr().err


def test_a_report_whose_verdict_is_not_its_checks_is_refused(written, tmp_path, capsys):
    """A validation report that says it passed while a check failed is not read onto the
    page: exit 2, one line naming the report and the failed check."""
    gait_path, _, _ = written
    copy = tmp_path / f"{NAME}.json"
    copy.write_bytes(gait_path.read_bytes())
    content = json.loads(gait_path.with_name(f"{NAME}.report.json").read_text())
    copy.with_name(f"{NAME}.report.json").write_text(json.dumps({**content, "passed": True}))
    assert main(["report", str(copy), "--out", str(tmp_path / "pages")]) == 2
    err = capsys.readouterr().err
    assert f"{NAME}.report.json" in err and "failed are: forward" in err
    assert len(err.strip().splitlines()) == 1 and not (tmp_path / "pages").exists()


@pytest.fixture(scope="module")
def optimal_page(tmp_path_factory):
    """The optimal rolling-knee gait at 0.3 m/s (IPOPT) as read from its file, its page's
    Markdown and its figures."""
    from biped.pages.page import Page, gait_figures, markdown
    from tests.conftest import optimal_gait

    path = tmp_path_factory.mktemp("optimal") / f"{NAME}.json"
    Gait.from_optimum(optimal_gait("rolling"), Robot.paper()).write(path)
    gait = gait_file.read(path)
    return gait, markdown(Page(NAME, path, gait), path.parent), gait_figures(gait)


def test_page_says_why_the_torques_jump_at_the_knot(optimal_page):
    """The page states the largest torque jump at t/T = 0.5 from the samples' two limits
    there and why (the spline is C¹), and every torque panel marks the knot and its jump."""
    from matplotlib.lines import Line2D

    gait, text, figures = optimal_page
    t, torques = gait.samples.t, gait.samples.torques
    k = int(np.flatnonzero(np.diff(t) == 0.0)[0])
    assert t[k] == pytest.approx(gait.period / 2)
    jumps = torques[k + 1] - torques[k]
    largest = jumps[int(np.argmax(np.abs(jumps)))]
    assert abs(largest) > 0.1  # the paper's C¹ spline: a jump worth saying
    assert "jump at t/T = 0.5" in text and f"{largest:+.3g} N·m" in text and "C¹" in text
    panels = [ax for ax in figures["torques.png"].axes if ax.get_title()]
    assert len(panels) == 6
    for ax, jump in zip(panels, jumps, strict=True):
        knots = [ln for ln in ax.findobj(Line2D) if list(ln.get_xdata()) == [0.5, 0.5]]
        assert knots, ax.get_title()
        assert any(t.get_text().startswith(f"jump {jump:+.3g}") for t in ax.texts), ax.get_title()


def test_a_bezier_gaits_page_marks_no_knot_and_no_jump(tmp_path):
    """A Bézier gait (one curve over the step, its accelerations continuous) has no knot: its
    page draws no knot line and says no jump, where a spline's marks its knots."""
    from matplotlib.lines import Line2D

    from biped.model.bezier import Bezier
    from biped.model.dynamics import Biped
    from biped.optimization.optimize import optimize
    from biped.optimization.problem import GaitProblem
    from biped.pages.page import Page, gait_figures, markdown

    problem = GaitProblem(Biped(Robot.paper(), "rolling"), 0.3, knots=Bezier(5))
    path = tmp_path / f"{NAME}.json"
    Gait.from_optimum(optimize(problem, starts=1), Robot.paper()).write(path)
    gait = gait_file.read(path)
    assert gait.knots == Bezier(5)
    text, figures = markdown(Page(NAME, path, gait), tmp_path), gait_figures(gait)
    assert "jump at" not in text
    assert "no knot, no jump" in figures["torques.png"].texts[0].get_text()
    for ax in figures["torques.png"].axes:
        assert not [ln for ln in ax.findobj(Line2D) if list(ln.get_xdata()) == [0.5, 0.5]]


def test_page_says_where_constraints_dip_below_the_solver_margin(optimal_page):
    """Each constraint below its margin δ on the check grid (only between the solver's
    samples, which hold δ) is named on the page with its smallest value, and its panel
    zooms on it in an inset; no other panel has one."""
    from biped.model.criteria import evaluate_step, margin_profile
    from biped.model.dynamics import Biped
    from biped.model.gait import build_step
    from biped.optimization.problem import CHECK_SAMPLES_PER_HALF, SOLVER_SAMPLES_PER_HALF
    from biped.pages.page import CONSTRAINT_MEANING

    gait, text, figures = optimal_page
    model = Biped(gait.robot, gait.knee)
    step = build_step(model, gait.speed, gait.parameter_vector)

    def below(n):
        psi = evaluate_step(model, step, n, safety=gait.safety).constraints
        delta = margin_profile(n)
        with np.errstate(invalid="ignore"):
            return psi, (delta > 0) & (psi < delta * (1 - 1e-6))

    psi, dips = below(CHECK_SAMPLES_PER_HALF)
    assert not below(SOLVER_SAMPLES_PER_HALF)[1].any()  # the solver holds δ at its samples
    assert dips[:, CONSTRAINTS.index("swing_knee")].any()  # the dip of the issue, Ψ5
    assert "between the solver's samples" in text and "the gait is feasible" in text
    panels = {ax.get_title(): ax for ax in figures["constraints.png"].axes if ax.get_title()}
    delta = margin_profile(CHECK_SAMPLES_PER_HALF)
    for i, name in enumerate(CONSTRAINTS):
        insets = panels[CONSTRAINT_MEANING[name]].child_axes
        if dips[:, i].any():
            k = int(np.argmin(np.where(dips[:, i], psi[:, i] - delta[:, i], np.inf)))
            unit = "mrad" if name.endswith("knee") else "mm"  # δ: 1 mrad, 1 mm
            assert f"Ψ{i + 1} to {psi[k, i] * 1e3:.3g} {unit}" in text, name
            assert len(insets) == 1, name
        else:
            assert not insets, name


def test_the_table_gives_each_constraint_where_it_binds(optimal_page):
    """Each constraint's row is its smallest Ψ / δ where the solver keeps a margin: the swing
    foot's heel and toe, whose smallest Ψ lies at the step's ends where δ ramps to 0 and
    binds nothing, are given mid-step, where they bind the optimum (Ψ / δ about 1)."""
    from biped.pages.page import constraint_profile, tightest_margins

    gait, _, _ = optimal_page
    t_n, psi, delta = constraint_profile(gait)
    rows = {row.name: row for row in tightest_margins(gait)}
    for i, name in enumerate(CONSTRAINTS):
        held = delta[:, i] > 0
        assert rows[name].ratio == pytest.approx(np.nanmin(psi[held, i] / delta[held, i]))
    for name in ("swing_heel", "swing_toe"):
        assert 0.1 < rows[name].at < 0.9 and rows[name].ratio == pytest.approx(1.0, abs=0.02)


def test_page_gives_the_ligament_load_each_knee_needs(optimal_page):
    """The rolling knee's page says the gait needs ligaments and how much, in N, for each knee
    (stance, swing): the file's largest tensions; the swing knee pulls about 40 N."""
    gait, text, _ = optimal_page
    stance, swing = gait.knee_loads.max_tension
    assert gait.knee_loads.needs_ligaments and 35.0 < swing < 50.0
    assert "## Knee loads: the ligaments each knee needs" in text
    assert f"This gait needs ligaments: {stance:.4g} N in the stance knee (in stance), " in text
    assert f"{swing:.4g} N in the swing knee (in swing)" in text
    assert "| knee | ligament load needed [N] | largest tension [N] |" in text
    assert f"| swing knee, in swing | {swing:.4g} | {swing:.4g} | 0 | never compressed |" in text


def test_a_revolute_knee_needs_no_ligament_and_an_old_file_no_section():
    """The revolute knee's pin carries the tension: its page says no ligament is needed; a
    file written before the knee loads has no such section."""
    import dataclasses

    from biped.pages.page import knee_lines

    gait = Gait.from_optimum(small_optimum("revolute"), Robot.paper())
    text = "\n".join(knee_lines(gait))
    assert "the pin carries tension, so no ligament is needed" in text
    assert f"| swing knee, in swing | none (a pin) | {gait.knee_loads.max_tension[1]:.4g} |" in text
    assert knee_lines(dataclasses.replace(gait, knee_loads=None)) == []


def test_a_designed_knees_page_states_its_radii_and_what_it_was_compared_with(tmp_path):
    """The page of a designed knee's gait states r1 and r2 with their bounds, the knees it
    was compared with and the changes; every rolling knee's page states its radii."""
    from biped.pages.page import Page, markdown
    from tests.conftest import designed_gait

    gait = designed_gait()
    text = markdown(Page("design", tmp_path / "design.json", gait), tmp_path)
    assert "| knee radii r1 / r2 | 0.05 / 0.05 | m |" in text
    assert "## Knee design" in text
    assert (
        "| r1 | 0.05 | 0.001 | 0.1811 | m |" in text
        and "| r2 | 0.05 | 0.001 | 0.2362 | m |" in text
    )
    for knee in ("| revolute | - | - |", "| rolling, Table 1 radii | 0.05 | 0.05 |"):
        assert knee in text
    gains = gait.design["gains_percent"]
    assert f"- optimal radii vs revolute: {gains['design_vs_revolute']:+.2f} %" in text
    assert f"- Table 1 radii vs revolute: {gains['table1_vs_revolute']:+.2f} %" in text


@pytest.fixture(scope="module")
def walked_page(tmp_path_factory):
    """The validation report of the optimal rolling gait at 0.3 m/s (its replay and its
    forward walk, as ``biped validate`` writes them) and its page's Markdown and figures."""
    from biped.pages.page import Page, markdown, page_figures
    from tests.conftest import gait_of, optimal_gait
    from validate.checks import checks
    from validate.checks.validation import validation_report
    from validate.scene.model import model_spec
    from validate.walk.samples import GaitSamples
    from validate.walk.simulate import Walker

    gait = gait_of(optimal_gait("rolling"))
    spec = model_spec(gait.biped)
    replay = checks.check_feedforward(spec, gait.biped, GaitSamples.from_gait(gait))
    forward, _, _ = checks.check_forward(Walker(gait, spec), 10, gait.costs.energy)
    report = validation_report([replay, forward])
    path = tmp_path_factory.mktemp("walked") / f"{NAME}.json"
    page = Page(NAME, path, gait, report)
    return report, markdown(page, path.parent), page_figures(page)


def test_page_shows_mujocos_walk_beside_the_models(walked_page):
    """The page's table gives per joint the model's RMS torque, MuJoCo's, its rotors' and
    servos' parts and the replay's servo against the torque scale, then the energy per step
    of both and their ratio, the ground force's error over the weight; the figures in it are
    the report's. MuJoCo's walk follows the model: the hips' torques over the step correlate
    with the model's (above 0.75) and not with the other leg's (below 0.5). The servos add
    their stiffness times the walk's tracking error, which does not halve when the stiffness
    doubles: with servos of 2000 N·m/rad the stance hip's servo peaks at 1.6 N·m (0.57 N·m
    with 1000 N·m/rad, both at 1 ms), the servos' share of the walk's torque is 0.53 (0.37),
    and the hips correlate with the model's at 0.80 (stance) and 0.91 (swing) (0.97 and
    0.997), with the other leg's at -0.37 and 0.08."""
    from biped.pages.figures import joint_label

    report, text, _ = walked_page
    forward, replay = report.check("forward").figures, report.check("feedforward").figures
    assert "### MuJoCo's walk beside the model's" in text
    for j, joint in enumerate(JOINTS):
        cells = [f"{forward[name][j]:.3g}" for name in ("gait_torque_rms", "mujoco_torque_rms")]
        assert f"| {joint_label(j, joint)} | {' | '.join(cells)} |" in text, joint
        assert f"| {replay[f'feedback_ratio_{joint}']:.2g} |\n" in text
    ratio = forward["energy_per_step"] / forward["analytic_energy_per_step"]
    assert forward["energy_ratio"] == pytest.approx(ratio)
    assert (
        f"| {forward['analytic_energy_per_step']:.3g} | {forward['energy_per_step']:.3g} | "
        f"{ratio:.3g} | J |" in text
    )
    assert f"| {forward['ground_force_rms_error']:.3g} | | weight |" in text
    phase = np.array(forward["profile_phase"])
    after = phase >= forward["landing_window"]
    model = np.array(forward["gait_torque_profile"])[after]
    mujoco = np.array(forward["mujoco_torque_profile"])[after]
    for hip, other in ((2, 3), (3, 2)):  # stance hip, swing hip
        assert np.corrcoef(model[:, hip], mujoco[:, hip])[0, 1] > 0.75
        assert np.corrcoef(model[:, hip], mujoco[:, other])[0, 1] < 0.5


def test_page_draws_mujocos_torques_beside_the_models(walked_page, tmp_path):
    """walk_torques.png: one panel per joint, titled Γ1..Γ6 with torque in N·m over t/T,
    the model's curve and MuJoCo's, its rotors' and servos' parts (with ink when written)."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from PIL import Image

    from biped.pages.walk_figures import TORQUES_FIGURE

    report, text, figures = walked_page
    assert f"({NAME}/{TORQUES_FIGURE})" in text
    figure = figures[TORQUES_FIGURE]
    panels = [ax for ax in figure.axes if ax.get_title()]
    assert [ax.get_title() for ax in panels] == [
        f"Γ{j + 1} {joint.replace('_', ' ')}" for j, joint in enumerate(JOINTS)
    ]
    for ax in panels:
        assert ax.get_ylabel() == "torque [N·m]" and ax.get_xlabel() == "normalised time t/T"
        assert len(ax.get_lines()) >= 5  # zero, model, MuJoCo, rotors, servos
    FigureCanvasAgg(figure).draw()
    figure.savefig(tmp_path / TORQUES_FIGURE, dpi=60)
    assert np.asarray(Image.open(tmp_path / TORQUES_FIGURE).convert("RGB")).std() > 20


def test_a_walk_not_measured_is_unknown_on_the_page():
    """A per-joint figure the walk could not measure (null in the report) is n/a on the page,
    never 0; a report without the walk's per-joint figures has no such section."""
    from biped.pages.walk_figures import walk_lines
    from biped.records.validation_report import CheckResult, ValidationReport

    forward = {
        "steps": 0,
        "gait_torque_rms": [None] * 6,
        "mujoco_torque_rms": [None] * 6,
        "rotor_torque_rms": [None] * 6,
        "servo_torque_rms": [None] * 6,
        "energy_per_step": None,
        "analytic_energy_per_step": 1.5,
        "energy_ratio": None,
    }
    text = "\n".join(walk_lines(ValidationReport((CheckResult("forward", False, forward),))))
    assert "| Γ1 stance ankle | n/a | n/a | n/a | n/a | n/a | n/a | n/a |" in text
    assert "| 1.5 | n/a | n/a | J |" in text and "| 0 |" not in text
    assert walk_lines(ValidationReport((CheckResult("forward", False, {"steps": 3}),))) == []
