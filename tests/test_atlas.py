"""The atlas: the energy per metre is the energy per step over the step length; a
difference no larger than its uncertainty is not distinguishable; a small atlas answers the
walkable constraints unless asked the paper's, writes its CSV, figures and sentences from its
numbers, resumes to the same files and refuses other settings."""

import csv
import dataclasses
import io
import json

import numpy as np
import pytest

import biped
from biped.model.criteria import PAPER_SAFETY, WALKABLE, Safety, safety_dict
from biped.model.kinematics import KNEES
from biped.optimization.optimize import Report, checked, optimize
from biped.optimization.problem import GaitProblem
from biped.optimization.solver import Solver
from biped.pages import atlas as pages
from biped.pages.atlas_line import AtlasLine
from biped.records.atlas_optimum import AtlasOptimum
from biped.records.gait_file import Gait
from biped.studies import atlas
from biped.studies.atlas import Cell, Difference
from tests.background import PROMPTLY, numbers, stopped_twice_then_resumed

ROBOT = biped.Robot.paper()


def test_energy_per_metre_is_the_energy_per_step_over_the_step_length():
    """The solver's objective of the energy per metre equals the energy criterion's divided
    by the step length S = V T at any point (slacks at |Γ θ̇|), and a gait file holds it."""
    model = biped.Biped(ROBOT, "rolling")
    rng = np.random.default_rng(3)
    values = {}
    z = GaitProblem(model, 0.3).first_guess(0.5) + 0.01 * rng.standard_normal(21)
    for criterion in ("energy", "energy-per-metre"):
        solver = Solver(model, criterion, PAPER_SAFETY, 6)
        oracle = solver.nlp.oracle()  # (x, p) -> (f, g)
        power = np.asarray(solver.evaluate(z, 0.3)[2]).T.ravel()
        x = np.concatenate([z / solver.scales, np.abs(power)])
        values[criterion] = float(oracle(x, 0.3)[0])
    length = 0.3 * z[-1]
    assert values["energy-per-metre"] == pytest.approx(values["energy"] / length, rel=1e-12)
    optimum = optimize(GaitProblem(model, 0.3, "energy-per-metre"), starts=1)
    gait = Gait.from_optimum(optimum, ROBOT)
    assert gait.costs.energy_per_metre == pytest.approx(
        gait.costs.energy / gait.step_length, rel=1e-12
    )
    assert optimum.value == pytest.approx(gait.costs.energy_per_metre, rel=1e-12)
    weight = 70.0 * 9.81  # Table 1's mass [kg] times g [m/s²]
    assert ROBOT.weight == pytest.approx(weight, rel=1e-12)
    assert gait.costs.cost_of_transport == pytest.approx(
        gait.costs.energy / (weight * gait.step_length), rel=1e-12
    )


def test_a_difference_no_larger_than_its_uncertainty_is_not_distinguishable():
    near = Difference(-0.5, discretization=0.3, tolerance=1e-8, starts=0.25, richer=None, why="")
    assert near.uncertainty == pytest.approx(0.55)
    assert not near.distinguishable
    far = Difference(-0.6, discretization=-0.3, tolerance=0.0, starts=0.25, richer=None, why="")
    assert far.distinguishable
    empty = Difference(None, 0.0, 0.0, 0.0, None, "rolling INFEASIBLE")
    assert not empty.distinguishable
    row = pages.Row("sthenic", Cell(0.3, 0.0, 0.0), near, None, None)
    line = pages.csv_text([row], ROBOT.weight).splitlines()[1].split(",")
    assert line[pages.COLUMNS.index("distinguishable")] == "no"


def test_the_csv_names_the_atlas_gait_family():
    """The knots column is the family the atlas solved (--knots, --family bezier --degree),
    not always the paper's, and reads back as that family."""
    from biped.model.bezier import Bezier

    diff = Difference(-1.0, discretization=0.1, tolerance=0.0, starts=0.1, richer=None, why="")
    row = pages.Row("sthenic", Cell(0.3, 0.0, 0.0), diff, None, None)
    column = pages.COLUMNS.index("knots")
    for knots, written in ((1, "1"), (7, "7"), (Bezier(11), "bezier 11")):
        line = pages.csv_text([row], ROBOT.weight, knots).splitlines()[1]
        assert line.split(",")[column] == written
        assert AtlasLine.from_csv(line).knots == knots


def test_the_csv_gives_the_cost_of_transport_of_the_energies_per_metre_only():
    """The cost of transport of a per-metre energy is its value over m g; the sthenic
    criterion has none."""
    diff = Difference(-1.0, discretization=0.1, tolerance=0.0, starts=0.1, richer=None, why="")
    for criterion, expected in (("energy-per-metre", 300.0 / ROBOT.weight), ("sthenic", None)):
        finals = [_final(criterion, value, 2) for value in (300.0, 297.0)]
        row = pages.Row(criterion, Cell(0.3, 0.0, 0.0), diff, *finals)
        line = pages.csv_text([row], ROBOT.weight).splitlines()[1].split(",")
        value = line[pages.COLUMNS.index("cost of transport revolute")]
        if expected is None:
            assert value == ""
        else:
            assert float(value) == pytest.approx(expected, rel=1e-5)


def test_a_csv_line_is_its_record_and_reads_back_to_the_same_line():
    """A line of atlas.csv is ``AtlasLine.to_csv``'s, each field in its column with its unit
    (a knee's cost in its criterion's); read back (``from_csv``) it writes the same line. A
    cell without a difference leaves the costs, the verdict and the uncertainty empty, never
    0, and says why; a line of another width is refused."""
    from biped.model.units import declared_units
    from biped.pages.atlas_line import COLUMNS, AtlasLine

    diff = Difference(-1.25, 0.1, -2e-8, 0.0, -0.5, why="")
    finals = [_final("electrical", v, 3) for v in (310.0, 306.125)]
    rows = [
        pages.Row("electrical", Cell(0.4, 0.01, 0.1), diff, *finals),
        pages.Row(
            "sthenic", Cell(0.3, 0.0, 0.0), Difference(None, *[None] * 4, 'a "X"'), None, None
        ),
    ]
    for row in rows:
        text = pages.line(row, ROBOT.weight).to_csv()
        assert text == pages.csv_text([row], ROBOT.weight).splitlines()[1]
        record = AtlasLine.from_csv(text)
        assert record.to_csv() == text  # the figures to the digits the line gives
    full, empty = (AtlasLine.from_csv(pages.line(row, ROBOT.weight).to_csv()) for row in rows)
    assert full.cost_of_transport_rolling == pytest.approx(306.125 / ROBOT.weight, rel=1e-5)
    assert full.distinguishable is True and full.starts_at_best_rolling == 3
    assert empty.revolute is None and empty.distinguishable is None and empty.uncertainty is None
    assert empty.why_empty == 'a "X"' and empty.walks_rolling == "not walked"
    units = declared_units(AtlasLine, criterion="electrical")
    assert units["revolute"] == "J/m" and units["speed"] == "m/s" and units["difference"] == "%"
    assert len(COLUMNS) == len(units) + 6  # criterion, unit, verdict and three sentences
    with pytest.raises(ValueError, match="cells in a line"):
        AtlasLine.from_csv("0.300,0.000")


@pytest.fixture(scope="module")
def small(tmp_path_factory):
    folder = tmp_path_factory.mktemp("atlas")
    settings = atlas.Settings(ROBOT, (0.3,), (0.0, 0.02), (0.0,), ("sthenic",), 1, 0, 1)
    log = io.StringIO()
    atlas.run_atlas(folder, settings, jobs=1, stream=log)
    return folder, settings, log.getvalue()


def test_a_small_atlas_writes_its_table_figures_and_sentences(small):
    folder, settings, log = small
    assert "atlas: done" in log and "4 of 4 points certified" in log
    written = pages.write(folder)
    assert [p.name for p in written] == ["atlas.csv", "atlas-sthenic.png", "atlas.md"]
    lines = (folder / "atlas.csv").read_text().splitlines()
    assert lines[0].split(",")[: len(pages.COLUMNS)] == list(pages.COLUMNS)
    assert len(lines) == 1 + 2
    table = pages.rows(folder, settings)
    for row in table:  # the difference is the knees' costs on the check grid
        costs = [r.costs["sthenic"] for r in (row.rolling, row.revolute)]
        assert row.difference.value == pytest.approx(100 * (costs[0] / costs[1] - 1), rel=1e-9)
        assert row.difference.richer is not None  # both cells are corners
    text = (folder / "atlas.md").read_text()
    best = min(table, key=lambda r: r.difference.value)
    if best.difference.distinguishable:
        assert f"by {-best.difference.value:.2f}" in text
    else:  # named among the cells not told apart, or whose uncertainty is not measured
        assert pages._where(best) in text


def test_the_default_atlas_answers_the_walkable_constraints(small):
    """An atlas's margins are the walkable constraints unless told otherwise: its record holds
    them, its plan line says so, and each final optimum obeys them with its cell's clearance
    (its variables checked again under a problem made here), as its gait file records."""
    folder, settings, log = small
    assert settings.safety == WALKABLE
    record = json.loads((folder / atlas.MANIFEST).read_text())
    assert record["safety"] == safety_dict(WALKABLE, kept=("knee_bend",))
    assert atlas.load(folder).safety == WALKABLE
    assert log.startswith(
        f"atlas under the walkable constraints: ZMP {WALKABLE.zmp_margin:g} m inside the sole, "
        f"landing at {WALKABLE.landing_share:g} V at most, friction {WALKABLE.friction:g}, "
        f"joints {WALKABLE.joint_margin:g} rad from their stops, hip at "
        f"{WALKABLE.hip_progress:g} V at least: "
    )
    for cell in settings.cells():
        safety = dataclasses.replace(WALKABLE, clearance=cell.clearance)
        for knee in KNEES:
            point = atlas.Point("final", knee, "sthenic", cell)
            record = atlas.read(folder, point)
            problem = GaitProblem(biped.Biped(ROBOT, knee), cell.speed, "sthenic", safety)
            optimum = checked(problem, np.array(record.variables), record.report)
            assert optimum.feasible and record.certified
            assert set(optimum.evaluation.walkable) == set(WALKABLE.walkable)
            assert min(m.min() for m in optimum.evaluation.walkable.values()) >= 0.0
            assert Gait.read(folder / point.gait_filename()).safety == safety


def test_the_paper_constraints_give_the_atlas_of_before(tmp_path, capsys):
    """With the paper's margins an atlas's record is the one made before the margins existed
    (no such field); a record without it reads as the paper's and resumes, and a run with
    other margins is refused in one line naming both, by the command line with exit 2."""
    from biped_cli import main

    paper = atlas.Settings(
        ROBOT, (0.3,), (0.0,), (0.0,), ("sthenic",), 1, 0, 1, safety=PAPER_SAFETY
    )
    content = paper.to_dict()
    before = ["format", "robot", "speeds", "clearances", "knee_bends", "criteria", "knots"]
    before += ["seed", "starts", "method", "version", "casadi", "optima_table"]
    assert list(content) == before
    assert atlas.Settings.from_dict(content).safety == PAPER_SAFETY
    assert paper.constraints_words() == "the paper's constraints"
    point = atlas.Point("final", "rolling", "sthenic", Cell(0.3, 0.02, 0.1))
    assert paper.problem(point).safety == Safety(clearance=0.02, knee_bend=0.1)
    (tmp_path / atlas.MANIFEST).write_text(json.dumps(content))
    assert atlas.check_folder(tmp_path, paper)
    walkable = dataclasses.replace(paper, safety=WALKABLE)
    with pytest.raises(
        biped.BipedError, match="this folder's atlas answers the paper's constraints"
    ):
        atlas.check_folder(tmp_path, walkable)
    argv = ["atlas", "--speeds", "0.3", "--clearances", "0", "--criteria", "sthenic"]
    assert main([*argv, "--starts", "1", "--out", str(tmp_path)]) == 2
    (line,) = capsys.readouterr().err.strip().splitlines()
    assert "answers the paper's constraints, this run asks the walkable constraints: ZMP" in line
    assert "run with --paper-constraints or choose another --out folder" in line


def test_a_resumed_atlas_runs_nothing_and_other_settings_are_refused(small):
    folder, settings, _ = small
    log = io.StringIO()
    atlas.run_atlas(folder, settings, jobs=1, stream=log)
    assert "20 already done, 0 to run" in log.getvalue()
    other = atlas.Settings(ROBOT, (0.3,), (0.0, 0.03), (0.0,), ("sthenic",), 1, 0, 1)
    with pytest.raises(biped.BipedError, match="atlas was made with clearances"):
        atlas.run_atlas(folder, other, jobs=1, stream=io.StringIO())


def test_an_atlas_stopped_by_signals_while_its_workers_run_resumes_to_the_same(small, tmp_path):
    """`biped atlas --jobs 2` as a script's background job, stopped while its workers solve by
    Ctrl-C to its process group and then by SIGTERM, exits 130 then 143 within seconds with
    one line, its workers ended; run again, it ends with the optima of an uninterrupted
    atlas."""
    folder, settings, _ = small
    argv = ["atlas", "--speeds", "0.3", "--clearances", "0,0.02", "--criteria", "sthenic"]
    argv += ["--starts", "1", "--no-walks", "--jobs", "2"]
    stops = stopped_twice_then_resumed(argv, tmp_path / "atlas")
    assert [stop.status for stop in stops] == [130, 143]
    for stop, name in zip(stops, ("Ctrl-C", "SIGTERM"), strict=True):
        assert stop.stderr.splitlines()[-1] == f"biped atlas: interrupted ({name})"
        assert stop.seconds < PROMPTLY
    optima = numbers(tmp_path / "atlas")
    assert optima and optima == numbers(folder)


def stage_record(value: float, status: str = "converged") -> AtlasOptimum:
    """A stage's record of an optimum of ``value`` (sthenic), as ``AtlasOptimum`` keeps it."""
    converged = status == "converged"
    at_best = 1 if converged else 0
    report = Report("ipopt", status, 1, at_best, 10, 0.0, 0.0, 1.0, 0, value)
    return AtlasOptimum(
        status=status,
        feasible=True,
        certified=converged,
        value=value,
        costs={"sthenic": value},
        starts=1,
        starts_at_best=at_best,
        single_start=None,
        next_optimum=0.0,
        violations="",
        period=1.0,
        step_length=0.3,
        seconds=1.0,
        report=report,
        variables=(0.0,) * 21,
    )


def _final(criterion: str, value: float, starts_at_best: int) -> AtlasOptimum:
    """A knee's final record of ``value`` of ``criterion``, reached by ``starts_at_best``."""
    record = stage_record(value)
    return dataclasses.replace(record, costs={criterion: value}, starts_at_best=starts_at_best)


def _write_cell(folder, cell, values: dict) -> None:
    """Records of ``cell``: {(stage, knee): (value, status)}."""

    for (stage, knee), (value, status) in values.items():
        path = folder / atlas.Point(stage, knee, "sthenic", cell).filename()
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text(stage_record(value, status).to_json())


def test_a_re_solve_that_did_not_converge_measures_nothing(tmp_path):
    """A tighter tolerance's re-solve that ends at the acceptable level leaves its term and
    the uncertainty unknown (empty in the CSV, never 0), the cell not distinguishable, and
    the CSV, atlas.md and the run's summary say which re-solve and why."""
    settings = atlas.Settings(ROBOT, (0.3,), (0.0,), (0.0,), ("sthenic",), 1, 0, 1)
    acceptable = "Solved_To_Acceptable_Level"
    values = {
        ("final", "revolute"): (100.0, "converged"),
        ("final", "rolling"): (90.0, "converged"),
        ("fine", "revolute"): (100.1, "converged"),
        ("fine", "rolling"): (90.0, "converged"),
        ("tight", "revolute"): (100.0, acceptable),
        ("tight", "rolling"): (90.0, "converged"),
        ("richer", "revolute"): (99.0, "converged"),
        ("richer", "rolling"): (88.0, "converged"),
    }
    _write_cell(tmp_path, settings.cells()[0], values)
    (row,) = pages.rows(tmp_path, settings)
    diff = row.difference
    assert diff.value == pytest.approx(-10.0)
    assert diff.tolerance is None and diff.uncertainty is None and not diff.distinguishable
    assert diff.discretization == pytest.approx(100 * (90.0 / 100.1 - 1) + 10.0)
    line = pages.csv_text([row], ROBOT.weight).splitlines()[1]
    fields = next(csv.reader([line]))
    assert fields[pages.COLUMNS.index("tolerance [%]")] == ""
    assert fields[pages.COLUMNS.index("uncertainty [%]")] == ""
    assert fields[pages.COLUMNS.index("distinguishable")] == "no"
    why = fields[pages.COLUMNS.index("why empty")]
    assert "tighter tolerance" in why and f"revolute NOT CONVERGED: {acceptable}" in why
    text = pages.sentences(settings, [row])
    assert "not measured" in text and acceptable in text
    assert "less in 1 of 1" not in text
    summary = atlas.summarize(tmp_path, settings)
    assert "NOT MEASURED" in summary and "tighter tolerance" in summary and acceptable in summary


def _walk(passed: bool, cause: str = "") -> atlas.Walk:
    """A made-up walk of the forward walk alone."""
    return atlas.Walk(False, {"forward": atlas.WalkCheck(passed, cause)}, {})


def _drawn_figure(speeds, clearances, criterion):
    """The atlas figure of a table of made-up differences, walked (the first cell's rolling
    knee's gait does not walk), drawn, and its renderer."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    settings = atlas.Settings(ROBOT, speeds, clearances, (0.0,), (criterion,), 1, 0, 1)
    table = [
        pages.Row(
            criterion,
            cell,
            Difference(-1.0 - k, 0.1, 0.0, 0.1, None, ""),
            None,
            None,
            {"revolute": _walk(True), "rolling": _walk(k > 0, "" if k else "fell")},
        )
        for k, cell in enumerate(settings.cells())
    ]
    figure = pages.figure(settings, table, criterion, walked=True)
    renderer = FigureCanvasAgg(figure).get_renderer()
    figure.draw(renderer)
    return figure, renderer


@pytest.mark.parametrize(
    "speeds, clearances", [((0.2,), (0.0, 0.03)), (atlas.DEFAULT_SPEEDS, atlas.DEFAULT_CLEARANCES)]
)
def test_the_atlas_figure_is_readable(speeds, clearances):
    """Whatever the criterion and grid: no literal underscore outside mathtext, the title
    within the figure, the speed ticks of the curves apart, every cell's label 8 pt or larger
    on a box of its own (over the hatching), the legends off the curves and the map."""
    import re

    from matplotlib.text import Text

    for criterion in pages.CRITERION_NAMES:
        figure, renderer = _drawn_figure(speeds, clearances, criterion)
        for text in figure.findobj(Text):
            assert "_" not in re.sub(r"\$[^$]*\$", "", text.get_text()), text.get_text()
        title = figure._suptitle.get_window_extent(renderer)
        assert 0 <= title.x0 and title.x1 <= figure.bbox.width, figure._suptitle.get_text()
    (curves,) = [ax for ax in figure.axes if "bars" in ax.get_title()]
    (grid,) = [ax for ax in figure.axes if "cells" in ax.get_title()]
    low, high = curves.get_xlim()
    ticks = [t for t in curves.get_xticklabels() if t.get_text()]
    ticks = [t for t in ticks if low <= t.get_position()[0] <= high]
    boxes = sorted((t.get_window_extent(renderer) for t in ticks), key=lambda b: b.x0)
    apart = [a.x1 < b.x0 for a, b in zip(boxes[:-1], boxes[1:], strict=True)]
    assert boxes and all(apart), [t.get_text() for t in ticks]
    assert grid.texts and min(t.get_fontsize() for t in grid.texts) >= 8.0
    assert all(t.get_bbox_patch() is not None for t in grid.texts)  # over any hatching
    legend = curves.get_legend().get_window_extent(renderer)
    assert not legend.overlaps(curves.get_window_extent(renderer))
    legend = grid.get_legend().get_window_extent(renderer)
    assert not legend.overlaps(grid.get_window_extent(renderer)) and legend.y0 >= 0


def test_atlas_md_says_what_each_number_compares_for_one_speed(tmp_path):
    """One speed, two clearances, the richer gait measured at one corner and not at the
    other: atlas.md counts in the singular where there is one (no range of one value), says
    what the richer gait's move compares, why the other corner has none (as the CSV's 'why
    empty' does), and that the optima were not walked."""
    settings = atlas.Settings(ROBOT, (0.2,), (0.0, 0.03), (0.0,), ("sthenic",), 1, 0, 1)
    acceptable = "Solved_To_Acceptable_Level"
    for cell, richer in zip(settings.cells(), ("converged", acceptable), strict=True):
        values = {
            (stage, knee): (value, "converged")
            for stage in ("final", "fine", "tight")
            for knee, value in (("revolute", 100.0), ("rolling", 80.0))
        }
        values |= {("richer", "revolute"): (50.0, richer), ("richer", "rolling"): (38.0, richer)}
        _write_cell(tmp_path, cell, values)
    table = pages.rows(tmp_path, settings)
    text = pages.sentences(settings, table)
    assert "over 1 speed (0.2 m/s), 2 swing-foot clearances (0 and 3 cm)" in text
    assert "a least stance-knee bend of 0 rad" in text
    assert "1 speeds" not in text and "0.2-0.2" not in text and "1 corner cells" not in text
    assert "at 1 corner cell (0.2 m/s, clearance 0 cm) the difference moves by -4.00 " in text
    assert "percentage points (its value with 3 knots less the paper's spline's)" in text
    missing = f"0.2 m/s, clearance 3 cm (revolute NOT CONVERGED: {acceptable}; rolling"
    assert missing in text
    assert "Not walked" in text and "--no-walks" in text
    lines = list(csv.reader(pages.csv_text(table, ROBOT.weight).splitlines()))
    why = lines[2][pages.COLUMNS.index("why empty")]
    assert lines[2][pages.COLUMNS.index("difference with 3 knots [%]")] == ""
    assert why.startswith("3 knots not measured") and acceptable in why


@pytest.fixture(scope="module")
def walked(small, tmp_path_factory):
    """The small atlas's optima walked in MuJoCo (a copy of its folder), and the run's log."""
    import shutil

    from validate.studies import atlas_walks

    folder = tmp_path_factory.mktemp("walked") / "atlas"
    shutil.copytree(small[0], folder)
    log = io.StringIO()
    atlas_walks.run_walks(folder, small[1], jobs=1, stream=log)
    return folder, log.getvalue()


# The checks of `biped validate`, each run at the corners and the best pay-off.
EVERY_CHECK = ["model", "inverse_dynamics", "knee_loads", "impact"]
EVERY_CHECK += ["feedforward", "forward", "gains", "orbit"]


def test_every_certified_optimum_gets_a_walk_record(small, walked):
    """Each certified final optimum has the record of its walk: every check at the corners
    (each cell of this atlas is one), its verdict, why a check failed, the key figures with
    their units; a gait walks when every check passes, a stable orbit among them. A second
    run walks nothing again."""
    from validate.studies import atlas_walks

    _, settings, _ = small
    folder, log = walked
    assert log.startswith("atlas walks: 4 certified optima walked in MuJoCo (20-step forward")
    assert "0 already walked, 4 to walk" in log
    records = sorted(p.name for p in (folder / atlas.WALKS).glob("*.json"))
    assert len(records) == 4
    for cell in settings.cells():
        for knee in KNEES:
            point = atlas.Point("final", knee, "sthenic", cell)
            content = json.loads((folder / point.at(atlas.WALKS).filename()).read_text())
            walk = atlas.read_walk(folder, point)
            assert walk.every_check and list(walk.checks) == EVERY_CHECK
            assert walk.walks == all(c.passed for c in walk.checks.values())
            assert content["walks"] == walk.walks and content["gait"] == point.gait_filename()
            assert walk.checks["orbit"].passed == (walk.figures["orbit_verdict"] == "stable")
            assert all(bool(c.cause) != c.passed for c in walk.checks.values())
            assert {n: c.to_dict() for n, c in walk.checks.items()} == content["checks"]
            assert 0 <= walk.figures["steps"] <= 20 and walk.figures["spectral_radius"] > 0
            for name in ("max_slip", "feedback_share", "replay_feedback_share"):
                assert content["units"][f"figures.{name}"] and walk.figures[name] >= 0
            modelled = walk.figures["model_energy_per_step"]
            assert modelled == pytest.approx(Gait.read(folder / point.gait_filename()).costs.energy)
    counted = sum(bool(atlas.read_walk(folder, p)) for p in atlas_walks.certified(folder, settings))
    assert counted == 4
    again = io.StringIO()
    atlas_walks.run_walks(folder, settings, jobs=1, stream=again)
    assert "4 already walked, 0 to walk" in again.getvalue()


def test_away_from_the_corners_a_gait_is_walked_and_replayed(small, tmp_path):
    """A walk of the light kind runs the forward walk and the replay alone: no orbit."""
    from biped.studies.campaign import Task
    from validate.studies import atlas_walks

    folder, settings, _ = small
    point = atlas.Point("final", "rolling", "sthenic", settings.cells()[0])
    (tmp_path / point.gait_filename()).write_bytes((folder / point.gait_filename()).read_bytes())
    (tmp_path / atlas.WALKS).mkdir()
    walk = atlas_walks.WalkPoint(point, every_check=False)
    line = atlas_walks._walk(Task(atlas_walks._walk, settings, walk, str(tmp_path)))
    found = atlas.read_walk(tmp_path, point)
    assert list(found.checks) == ["feedforward", "forward"] and not found.every_check
    assert "spectral_radius" not in found.figures and "(walk, replay)" in line


def _stage_records(folder, speeds_values: dict) -> atlas.Settings:
    """An atlas of one clearance whose final, finer-grid and tighter records are made up:
    {speed: (revolute, rolling)} sthenic values, None for a knee not certified."""
    speeds = tuple(speeds_values)
    settings = atlas.Settings(ROBOT, speeds, (0.0,), (0.0,), ("sthenic",), 1, 0, 1)
    for cell in settings.cells():
        values = {}
        for knee, value in zip(KNEES, speeds_values[cell.speed], strict=True):
            status = "converged" if value is not None else "Infeasible_Problem_Detected"
            for stage in ("final", "fine", "tight", "richer"):
                values[(stage, knee)] = (value or 1.0, status)
        _write_cell(folder, cell, values)
    return settings


def test_the_walks_are_the_certified_optima_every_check_at_corners_and_best_payoff(tmp_path):
    """Every certified final optimum is walked, none other; every check at the corners and
    at the best pay-off, the forward walk and the replay elsewhere. A walk that raised is
    recorded, measures nothing and is walked again."""
    from validate.studies import atlas_walks

    values = {0.2: (100.0, 99.0), 0.3: (100.0, 80.0), 0.4: (100.0, None), 0.5: (100.0, 98.0)}
    settings = _stage_records(tmp_path, values)
    assert atlas.best_payoff(tmp_path, settings, "sthenic") == Cell(0.3, 0.0, 0.0)
    walks = atlas_walks.walks(tmp_path, settings)
    chosen = {(w.point.cell.speed, w.point.knee): w.every_check for w in walks}
    expected = {(s, k): s != 0.4 for s in values for k in KNEES if (s, k) != (0.4, "rolling")}
    assert chosen == expected
    walk = walks[0]
    record = atlas_walks.content(walk, None, "BipedError: no gait file")
    path = tmp_path / walk.filename()
    path.parent.mkdir(exist_ok=True)
    path.write_text(json.dumps(record))
    found = atlas.read_walk(tmp_path, walk.point)
    assert found.walks is None and found.causes() == "not measured: BipedError: no gait file"
    assert not atlas_walks._done(tmp_path, walk)
    assert atlas_walks.unmeasured(tmp_path, settings)[0].endswith("(BipedError: no gait file)")


def _write_walk(folder, cell, knee: str, checks: list, every_check: bool = False) -> None:
    """The record of a made-up walk of ``knee``'s sthenic optimum in ``cell``, as
    ``validate.studies.atlas_walks`` writes it, of ``checks``: (name, passed, notes)."""
    from validate.checks.checks import Check
    from validate.studies import atlas_walks

    point = atlas.Point("final", knee, "sthenic", cell)
    walk = atlas_walks.WalkPoint(point, every_check)
    made = [Check(name, passed, {}, notes) for name, passed, notes in checks]
    path = folder / walk.filename()
    path.parent.mkdir(exist_ok=True)
    path.write_text(json.dumps(atlas_walks.content(walk, made)))


UNDECIDED = ["slowest multiplier 0.952", "not shown stable: within the landing's noise of 1"]
WALKS = [("feedforward", True, []), ("forward", True, [])]


def _made_up_walked_atlas(folder) -> atlas.Settings:
    """Three cells whose rolling knee needs 20, 10 and 5 % less; at the best pay-off (0.2
    m/s) the rolling knee's gait does not walk (its orbit only undecided), elsewhere both
    knees' gaits walk."""
    values = {0.2: (100.0, 80.0), 0.3: (100.0, 90.0), 0.4: (100.0, 95.0)}
    settings = _stage_records(folder, values)
    for cell in settings.cells():
        for knee in KNEES:
            every = cell.speed != 0.3
            checks = WALKS + [("orbit", True, ["stable"])] if every else WALKS
            if (cell.speed, knee) == (0.2, "rolling"):
                checks = WALKS + [("orbit", False, UNDECIDED)]
            _write_walk(folder, cell, knee, checks, every)
    return settings


def test_a_gait_that_does_not_walk_is_marked_in_the_csv_figure_and_page(tmp_path):
    """A cell whose gait does not walk (an orbit only undecided) is 'no' with its cause in the
    CSV, framed in red in the figure with a legend entry, and named with its cause in
    atlas.md, which counts the optima that walk; not walked (--no-walks), nothing is."""
    settings = _made_up_walked_atlas(tmp_path)
    table = pages.rows(tmp_path, settings)
    lines = list(csv.reader(pages.csv_text(table, ROBOT.weight).splitlines()))
    walks = [(line[0], line[-2], line[-1]) for line in lines[1:]]
    cause = "orbit: not shown stable: within the landing's noise of 1"
    assert lines[0][-2:] == ["walks revolute", "walks rolling"]
    assert walks == [
        ("0.200", "yes", f"no: {cause}"),
        ("0.300", "yes", "yes"),
        ("0.400", "yes", "yes"),
    ]
    figure = pages.figure(settings, table, "sthenic", walked=True)
    (grid,) = [ax for ax in figure.axes if "cells" in ax.get_title()]
    (frame,) = [p for p in grid.patches if p.get_gid() == "not walking"]
    assert frame.get_x() < 0 < frame.get_x() + frame.get_width()  # the first speed's cell
    assert [t.get_text() for t in grid.get_legend().get_texts()] == [pages.NOT_WALKING_LABEL]
    assert "a red frame where a knee's gait does not walk" in figure._suptitle.get_text()
    text = pages.sentences(settings, table, walked=True)
    assert "Of the 6 certified optima walked in MuJoCo, 5 walk" in text
    assert f"0.2 m/s, clearance 0 cm: revolute walks; rolling does not walk: {cause}" in text
    assert "4 of them, at the corners" in text
    unwalked = pages.rows(tmp_path, settings, walked=False)
    assert "not walked" in pages.csv_text(unwalked, ROBOT.weight).splitlines()[1]
    figure = pages.figure(settings, unwalked, "sthenic")
    assert not [p for p in figure.axes[0].patches if p.get_gid() == "not walking"]
    assert "not walked in MuJoCo (--no-walks)" in figure._suptitle.get_text()


def test_the_walking_payoff_is_among_walking_cells_only(tmp_path):
    """atlas.md's pay-off among walking gaits is the best difference where both knees' gaits
    walk (10 % at 0.3 m/s), beside the best over all certified cells (20 % at 0.2 m/s, whose
    rolling knee's gait does not walk)."""
    settings = _made_up_walked_atlas(tmp_path)
    text = pages.sentences(settings, pages.rows(tmp_path, settings), walked=True)
    assert "needs less in 3 of 3 cells, by 20.00 ± 0.00 % at most (0.2 m/s" in text
    assert (
        "- Among walking gaits (both knees' gaits walk in MuJoCo in 2 of the 3 certified "
        "cells), the rolling knee needs less in 2, by 10.00 ± 0.00 % at most (0.3 m/s, "
        "clearance 0 cm)." in text
    )


def test_an_atlas_stopped_by_signals_while_it_walks_resumes_to_the_same(small, walked, tmp_path):
    """`biped atlas --jobs 2` whose optimizations are done, stopped while its workers walk the
    optima in MuJoCo by Ctrl-C to its process group and then by SIGTERM, exits 130 then 143
    within seconds with one line; run again, it ends with the walks of an uninterrupted
    run, and its pages say which gaits walk."""
    import shutil

    folder, _, _ = small
    out = tmp_path / "atlas"
    shutil.copytree(folder, out)
    argv = ["atlas", "--speeds", "0.3", "--clearances", "0,0.02", "--criteria", "sthenic"]
    stops = stopped_twice_then_resumed([*argv, "--starts", "1", "--jobs", "2"], out)
    assert [stop.status for stop in stops] == [130, 143]
    for stop, name in zip(stops, ("Ctrl-C", "SIGTERM"), strict=True):
        assert stop.stderr.splitlines()[-1] == f"biped atlas: interrupted ({name})"
        assert "atlas walks: 4 certified optima walked" in stop.stderr
        assert stop.seconds < PROMPTLY
    assert numbers(out / atlas.WALKS) == numbers(walked[0] / atlas.WALKS)
    assert "walks revolute" in (out / "atlas.csv").read_text()


def test_a_bezier_atlas_is_certified_in_its_family_and_kept_apart(tmp_path):
    """An atlas of Bézier gaits (--family bezier): its optima and gait files are of that
    family, it has no 3-knot re-solve (that family does not hold it), its CSV and atlas.md
    name the family, and the folder resumed in the paper's spline is refused."""
    from biped.model.bezier import Bezier

    family = Bezier(5)
    settings = atlas.Settings(ROBOT, (0.3,), (0.0,), (0.0,), ("sthenic",), family, 0, 1)
    log = io.StringIO()
    atlas.run_atlas(tmp_path, settings, jobs=1, stream=log)
    assert "2 of 2 points certified" in log.getvalue() and "3 knots" not in log.getvalue()
    assert settings.corners() == [] and not list((tmp_path / "richer").glob("*.json"))
    for knee in KNEES:
        point = atlas.Point("final", knee, "sthenic", settings.cells()[0])
        gait = Gait.read(tmp_path / point.gait_filename(), consistent=True)
        assert gait.knots == family
    (row,) = pages.rows(tmp_path, settings, walked=False)
    assert row.difference.uncertainty is not None  # finer grid and tighter tolerance measured
    pages.write(tmp_path, walked=False)
    (line,) = (tmp_path / "atlas.csv").read_text().splitlines()[1:]
    assert AtlasLine.from_csv(line).knots == family
    assert "Bézier curves of degree 5 (21 parameters)" in (tmp_path / "atlas.md").read_text()
    paper = dataclasses.replace(settings, knots=1)
    with pytest.raises(biped.BipedError, match="atlas was made with knots"):
        atlas.run_atlas(tmp_path, paper, jobs=1, stream=io.StringIO())
