"""Knee profiles designed with the gait (``biped.optimization.profile_design``, ``biped design
--profile``): certified, within the surfaces' bounds, never worse than the circles they
start from; their gait file reads back and walks on its own MJCF."""

import contextlib
import io

import numpy as np
import pytest

import biped
from biped.model.profile import MARGINS
from biped.optimization.design import DesignProblem, optimize_design
from biped.optimization.profile_design import NEVER_WORSE, ProfileProblem, optimize_profile

ROBOT = biped.Robot.paper()


@pytest.fixture(scope="module")
def circles():
    return optimize_design(DesignProblem(ROBOT, 0.3), starts=1)


@pytest.fixture(scope="module")
def designed(tmp_path_factory):
    """``biped design --speed 0.3 --profile linear`` (one start each): status, output, file."""
    from biped_cli import main

    path = tmp_path_factory.mktemp("profile") / "profile.json"
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        argv = ["design", "--speed", "0.3", "--profile", "linear", "--starts", "1"]
        code = main(argv + ["--out", str(path)])
    return code, out.getvalue(), err.getvalue(), path


def test_the_profile_is_certified_within_its_bounds_and_never_worse_than_the_circles(circles):
    problem = ProfileProblem(DesignProblem(ROBOT, 0.3))
    design = optimize_profile(problem, circles)
    assert design.certified and design.search.converged and not design.kept_circles
    assert design.value <= circles.value * (1 + NEVER_WORSE)
    assert design.value < circles.value * (1 - 1e-4)  # at 0.3 m/s it does better
    margins = problem.margins(design.parameters)
    assert set(margins) == set(MARGINS) and min(margins.values()) > -1e-9
    low, high = np.array(problem.lower), np.array(problem.upper)
    assert np.all(low - 1e-9 <= design.parameters) and np.all(design.parameters <= high + 1e-9)
    assert type(design.optimum.problem.model).__name__ == "ProfileBiped"


def test_a_profile_no_better_than_the_circles_keeps_the_circles(circles, monkeypatch):
    """Unless a profile ends below the circles by NEVER_WORSE, the circles are the design,
    their optimum as it was: never a worse knee."""
    from biped.optimization import profile_design

    monkeypatch.setattr(profile_design, "NEVER_WORSE", 0.5)
    design = optimize_profile(ProfileProblem(DesignProblem(ROBOT, 0.3)), circles)
    assert design.kept_circles and design.optimum is circles.optimum
    assert design.parameters == (*circles.radii, 0.0, 0.0) and design.gain == 0.0


def test_profile_command_writes_the_profile_and_compares_four_knees(designed):
    from biped.records import gait_file

    code, out, err, path = designed
    assert code == 0, err
    gait = gait_file.read(path)
    profile = gait.design["profile"]
    assert (gait.robot.k1, gait.robot.k2) == (profile["rates"]["k1"], profile["rates"]["k2"])
    assert gait.robot.profiled and profile["family"] == "linear" and not profile["kept_circles"]
    labels = [row["knee"] for row in gait.design["compared"]]
    assert labels[-1] == "rolling, linear profile" and len(labels) == 4
    gain = gait.design["gains_percent"]["profile_vs_circles"]
    assert gain < 0 and f"{gain:+.3f} % vs the designed circles" in out
    content = gait.to_dict()
    units = gait_file.Gait.units("sthenic", profile=True, profile_design=True)
    assert content["units"] == units


def test_the_profile_walks_on_its_own_mjcf_and_its_knee_is_the_models(designed):
    """The designed profile's gait on the MJCF of its robot: the model, inverse-dynamics,
    knee-load, impact, replay, walk and gains checks pass (the orbit's is reported,
    README: within the landing's noise)."""
    from biped.records import gait_file
    from validate.checks.validation import validate

    result = validate(gait_file.read(designed[3]), steps=20)
    failed = [check.line() for check in result.checks if not check.passed]
    assert all(line.split()[1] == "orbit" for line in failed), failed
    model = next(check for check in result.checks if check.name == "model")
    assert model.figures["knee_position_error"] < 1e-6
    assert model.figures["knee_angle_error"] < 1e-6


@pytest.mark.parametrize(
    "argv, needle",
    [
        (["--profile", "cubic"], "argument --profile: invalid choice: 'cubic'"),
        (["--profile", "linear", "--robot", "ROBOT"], "has a profiled knee (k1 = 0.01"),
    ],
)
def test_bad_profile_options_are_one_line_and_exit_2(tmp_path, capsys, argv, needle):
    from biped_cli import main

    robot = tmp_path / "robot.toml"
    robot.write_text("r1 = 0.1\nr2 = 0.1\nk1 = 0.01\n")
    argv = [str(robot) if a == "ROBOT" else a for a in argv]
    out = str(tmp_path / "d.json")
    assert main(["design", "--speed", "0.3", *argv, "--out", out]) == 2
    lines = capsys.readouterr().err.strip().splitlines()
    assert len(lines) == 1 and needle in lines[0], lines


def test_a_profile_design_that_does_not_converge_exits_1(tmp_path, monkeypatch, capsys):
    from biped.optimization import design as design_module
    from biped.optimization import profile_design, solver
    from biped_cli import main

    monkeypatch.setitem(solver.IPOPT_OPTIONS, "max_iter", 3)
    caches = (design_module._solver, solver._solver, profile_design._solver)
    for cache in caches:
        cache.cache_clear()
    try:
        path = tmp_path / "profile.json"
        argv = ["design", "--speed", "0.3", "--profile", "linear", "--starts", "1"]
        assert main([*argv, "--out", str(path)]) == 1
        assert "the profile's solver did not converge" in capsys.readouterr().err
        assert not path.exists()
    finally:
        for cache in caches:
            cache.cache_clear()


def test_the_profiles_page_draws_it_beside_the_circles(designed, tmp_path):
    """'biped report' on the profile's file: a section with its rates, the surfaces'
    margins and gains, and the figure of the surfaces, the contact and the torques, the
    circles' gait (written beside the profile's) drawn with it."""
    from biped.pages.profile_figures import profile_figure
    from biped.records import gait_file
    from biped_cli import main

    path = designed[3]
    circles_path = path.with_name(path.stem + "-circles.json")
    circles = gait_file.read(circles_path)
    assert not circles.robot.profiled and circles.design["radii"]["r1"] > 0.18
    assert main(["report", str(path), "--out", str(tmp_path / "pages")]) == 0
    (page,) = (tmp_path / "pages").glob("*.md")
    text = page.read_text()
    assert "## Knee profile" in text and "profile vs designed circles" in text
    assert (page.with_suffix("") / "profile.png").is_file()
    figure = profile_figure(gait_file.read(path), circles)
    lines = [line for ax in figure.axes[3:] for line in ax.get_lines()]
    assert sum("circles" in line.get_label() for line in lines) == 6  # beside the circles'


def test_a_machined_profile_over_the_speeds_beside_circles_designed_at_each(designed):
    """At its own speed the profile is its design (never worse than the circles designed
    there, nor than those circles machined); a knee not certified leaves its changes
    unknown (None), never zero."""
    from biped.records import gait_file
    from biped.studies.profile_speeds import SpeedRow, row_at, table

    gait = gait_file.read(designed[3])
    circles = next(r for r in gait.design["compared"] if r["knee"] == "rolling, optimal radii")
    machined = (circles["radii"]["r1"], circles["radii"]["r2"])
    row = row_at(gait.robot, machined, 0.3, "sthenic", gait.safety, starts=1)
    assert row.all_certified and row.radii == pytest.approx(machined, abs=1e-6)
    assert row.values["profile"] == pytest.approx(gait.costs.sthenic, rel=1e-6)
    assert row.change("profile", "circles") < 0 and row.change("profile", "machined") < 0
    assert row.values["machined"] == pytest.approx(row.values["circles"], rel=1e-6)
    unknown = SpeedRow(0.5, row.values, {**row.certified, "profile": False}, row.radii)
    assert unknown.change("profile", "circles") is None
    assert unknown.to_dict()["profile_vs_revolute"] is None
    assert "n/a" in table([unknown], "N²·m·s") and "NOT CERTIFIED: profile" in table([unknown], "")


def test_profile_speeds_refuses_a_gait_of_circles(designed, capsys):
    from biped_cli import main

    circles = designed[3].with_name(designed[3].stem + "-circles.json")
    assert main(["profile-speeds", str(circles), "--out", str(circles.with_name("s.json"))]) == 2
    lines = capsys.readouterr().err.strip().splitlines()
    assert len(lines) == 1 and "of circles: allowed the gait file of a knee profile" in lines[0]
