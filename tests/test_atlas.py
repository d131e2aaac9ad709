"""The atlas: the energy per metre is the energy per step over the step length; a
difference no larger than its uncertainty is not distinguishable; a small atlas writes its
CSV, figures and sentences from its numbers, resumes to the same files and refuses other
settings."""

import io

import numpy as np
import pytest

import biped
from biped.model.criteria import PAPER_SAFETY
from biped.optimization.optimize import optimize
from biped.optimization.problem import GaitProblem
from biped.optimization.solver import Solver
from biped.pages import atlas as pages
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


def test_the_csv_gives_the_cost_of_transport_of_the_energies_per_metre_only():
    """The cost of transport of a per-metre energy is its value over m g; the sthenic
    criterion has none."""
    diff = Difference(-1.0, discretization=0.1, tolerance=0.0, starts=0.1, richer=None, why="")
    for criterion, expected in (("energy-per-metre", 300.0 / ROBOT.weight), ("sthenic", None)):
        finals = [{"costs": {criterion: value}, "starts_at_best": 2} for value in (300.0, 297.0)]
        row = pages.Row(criterion, Cell(0.3, 0.0, 0.0), diff, *finals)
        line = pages.csv_text([row], ROBOT.weight).splitlines()[1].split(",")
        value = line[pages.COLUMNS.index("cost of transport revolute")]
        if expected is None:
            assert value == ""
        else:
            assert float(value) == pytest.approx(expected, rel=1e-5)


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
        costs = [r["costs"]["sthenic"] for r in (row.rolling, row.revolute)]
        assert row.difference.value == pytest.approx(100 * (costs[0] / costs[1] - 1), rel=1e-9)
        assert row.difference.richer is not None  # both cells are corners
    text = (folder / "atlas.md").read_text()
    best = min(table, key=lambda r: r.difference.value)
    assert f"by {-best.difference.value:.2f}" in text


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
