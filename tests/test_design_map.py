"""Design maps: hinges on the axes, the joint optimum below every grid point, resume and
settings like a sweep, figures and summary from the files."""

import json

import numpy as np
import pytest

import biped
from biped.pages.design_map_figures import draw
from biped.studies.design_map import (
    MANIFEST,
    MapPoint,
    load,
    run_design_map,
    speed_summaries,
)
from tests.background import PROMPTLY, numbers, stopped_twice_then_resumed

ROBOT = biped.Robot.paper()
SPEED = 0.3
GRID = {"r1": [0.0, 0.12], "r2": [0.15]}


@pytest.fixture(scope="module")
def small_map(tmp_path_factory):
    """A 2 x 1 map at 0.3 m/s, one start per optimization, in this process."""
    folder = tmp_path_factory.mktemp("map") / "map"
    log = folder.parent / "log.txt"
    with open(log, "w") as stream:
        run_design_map(folder, ROBOT, [SPEED], **GRID, starts=1, jobs=1, stream=stream)
    return folder


def test_map_axes_are_hinges_and_the_joint_optimum_is_lowest(small_map):
    """Every optimization is certified; the grid point r1 = 0 (a rolling circle on a point)
    has the revolute knee's optimum; the joint optimum is at or below every grid point, the
    Table 1 radii and the revolute knee (it starts from them)."""
    settings, results = load(small_map)
    assert len(results) == 5 and all(c["certified"] for c in results.values())
    revolute = results[MapPoint("revolute", SPEED)]["value"]
    hinge = results[MapPoint("grid", SPEED, (0.0, 0.15))]["value"]
    rolling = results[MapPoint("grid", SPEED, (0.12, 0.15))]["value"]
    assert hinge == pytest.approx(revolute, rel=1e-6)
    assert abs(rolling / revolute - 1) > 1e-3  # the radii matter away from the axes
    design = results[MapPoint("design", SPEED)]
    others = [c["value"] for p, c in results.items() if p.kind != "design"]
    assert design["value"] <= min(others) * (1 + 1e-9)
    (summary,) = speed_summaries(settings, results)
    assert summary.radii == tuple(design["radii"])
    assert summary.gain(summary.design) == pytest.approx(100 * (design["value"] / revolute - 1))


def test_map_resumes_and_refuses_other_settings(small_map):
    """Run again, nothing is recomputed and no file changes; another seed is refused naming
    it; a point file removed is the only one run again, to the same numbers."""
    before = {p.name: p.read_bytes() for p in small_map.glob("*.json")}
    log = small_map.parent / "again.txt"
    with open(log, "w") as stream:
        run_design_map(small_map, ROBOT, [SPEED], **GRID, starts=1, jobs=1, stream=stream)
    assert "0 to run" in log.read_text()
    assert {p.name: p.read_bytes() for p in small_map.glob("*.json")} == before
    with pytest.raises(biped.BipedError, match="seed = 0, this run has 1"):
        run_design_map(small_map, ROBOT, [SPEED], **GRID, seed=1, starts=1, jobs=1)
    removed = small_map / MapPoint("table1", SPEED).filename()
    removed.unlink()
    with open(log, "w") as stream:
        run_design_map(small_map, ROBOT, [SPEED], **GRID, starts=1, jobs=1, stream=stream)
    assert "1 to run" in log.read_text()

    def numbers(data: bytes) -> dict:  # all but the wall time
        return {k: v for k, v in json.loads(data).items() if k != "seconds"}

    assert numbers(removed.read_bytes()) == numbers(before[removed.name])


def test_map_figures_and_summary(small_map):
    """The map's figure and summary.csv are written; the summary's gain is the design's
    criterion against the revolute knee's, both read from the point files."""
    written = draw(small_map)
    names = {path.name for path in written}
    assert names == {"map-0.300.png", "summary.csv"}
    assert all(path.stat().st_size > 0 for path in written)
    row = (small_map / "summary.csv").read_text().splitlines()[1].split(",")
    design = json.loads((small_map / MapPoint("design", SPEED).filename()).read_text())
    revolute = json.loads((small_map / MapPoint("revolute", SPEED).filename()).read_text())
    assert float(row[7]) == pytest.approx(100 * (design["value"] / revolute["value"] - 1), abs=1e-3)
    assert json.loads((small_map / MANIFEST).read_text())["r1"] == GRID["r1"]


def test_map_legend_lies_outside_the_plot(small_map):
    """The map's legend covers no part of its plot area (the grid's corners, the Table 1
    radii near r = 0 among them): it lies below the axes."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    from biped.pages.design_map_figures import map_figure

    settings, results = load(small_map)
    figure = map_figure(settings, speed_summaries(settings, results)[0], results)
    renderer = FigureCanvasAgg(figure).get_renderer()
    figure.draw(renderer)
    (ax,) = [ax for ax in figure.axes if ax.get_xlabel().startswith("r1")]
    legends = figure.legends + [ax.get_legend()] * (ax.get_legend() is not None)
    assert len(legends) == 1
    box, plot = legends[0].get_window_extent(renderer), ax.get_window_extent(renderer)
    assert not box.overlaps(plot) and box.y1 <= plot.y0
    labels = {text.get_text() for text in legends[0].get_texts()}
    assert {"Table 1 radii", "joint optimum"} <= labels


def test_every_optimization_line_gives_its_criterion_with_its_unit(small_map):
    """Each optimization's line in the map's log gives its criterion value with its unit
    (the sthenic criterion's, N²·m·s)."""
    lines = [
        line for line in (small_map.parent / "log.txt").read_text().splitlines() if "C = " in line
    ]
    assert lines and all("N²·m·s" in line.split("C = ")[1] for line in lines), lines


def test_a_map_stopped_by_signals_while_its_workers_run_resumes_to_the_same(small_map, tmp_path):
    """`biped design-map --jobs 2` as a script's background job, stopped while its workers
    solve by Ctrl-C to its process group and then by SIGTERM, exits 130 then 143 within
    seconds with one line, its workers ended; run again, it ends with the numbers of an
    uninterrupted map."""
    argv = ["design-map", "--speeds", str(SPEED), "--jobs", "2", "--starts", "1"]
    argv += ["--r1", ",".join(map(str, GRID["r1"])), "--r2", ",".join(map(str, GRID["r2"]))]
    stops = stopped_twice_then_resumed(argv, tmp_path / "map")
    assert [stop.status for stop in stops] == [130, 143]
    for stop, name in zip(stops, ("Ctrl-C", "SIGTERM"), strict=True):
        assert stop.stderr.splitlines()[-1] == f"biped design-map: interrupted ({name})"
        assert stop.seconds < PROMPTLY
    assert numbers(tmp_path / "map") == numbers(small_map)


def _made_up_map(r1, r2, grid_value, table1: float, revolute: float = 30.0):
    """Settings and results of a map at 0.3 m/s whose every optimization is certified:
    ``grid_value(r1, r2)`` on the grid, ``table1`` at the Table 1 radii, no joint optimum."""
    from biped.model.criteria import PAPER_SAFETY
    from biped.optimization.design import radius_limits
    from biped.studies.design_map import MapSettings

    upper = tuple(radius_limits(ROBOT))
    settings = MapSettings(ROBOT, "sthenic", PAPER_SAFETY, (SPEED,), r1, r2, upper, 0, 1)
    results = {
        MapPoint("grid", SPEED, (a, b)): {"certified": True, "value": grid_value(a, b)}
        for a in r1
        for b in r2
    }
    results[MapPoint("table1", SPEED)] = {"certified": True, "value": table1}
    results[MapPoint("revolute", SPEED)] = {"certified": True, "value": revolute}
    return settings, results


def test_a_coarse_map_puts_the_table_1_radii_on_their_measured_side():
    """On a 2 x 2 grid whose far corner costs more than the revolute knee, the Table 1 radii
    measured below it: the map's colour at the Table 1 radii holds their measured value (the
    map is linear between every measured point), so they lie on the side of the revolute
    knee's contour that the summary gives them."""
    from matplotlib.contour import ContourSet
    from matplotlib.path import Path

    from biped.pages.design_map_figures import map_figure

    def grid_value(a, b):  # the hinges on the axes cost what the revolute knee does
        return 30.0 + (0.5 if a > 0 and b > 0 else 0.0)

    settings, results = _made_up_map((0.0, 0.08), (0.0, 0.08), grid_value, table1=29.8)
    (summary,) = speed_summaries(settings, results)
    assert summary.gain(summary.table1) < 0
    figure = map_figure(settings, summary, results)
    (ax,) = [ax for ax in figure.axes if ax.get_xlabel().startswith("r1")]
    (filled,) = [c for c in ax.collections if isinstance(c, ContourSet) and c.filled]
    near = 100 * np.array(settings.problem(SPEED).reference_radii) + 0.01  # [cm] off its vertex
    bands = [
        (low, high)
        for path, low, high in zip(
            filled.get_paths(), filled.levels[:-1], filled.levels[1:], strict=True
        )
        if sum(Path(ring).contains_point(near) for ring in path.to_polygons()) % 2
    ]
    assert len(bands) == 1 and bands[0][1] <= summary.revolute, bands


def test_a_map_of_one_radius_each_says_why_it_is_empty():
    """A 1 x 1 grid has no map to draw: the figure says so and why, and gives each certified
    point's value and its change against the revolute knee."""
    from biped.pages.design_map_figures import map_figure

    settings, results = _made_up_map((0.08,), (0.08,), lambda a, b: 29.0, table1=29.8)
    (summary,) = speed_summaries(settings, results)
    figure = map_figure(settings, summary, results)
    (ax,) = [ax for ax in figure.axes if ax.get_xlabel().startswith("r1")]
    assert "no map" in ax.get_title() and "2 or more of each" in ax.get_title()
    labels = [text.get_text() for text in ax.texts]
    assert any(label.startswith("29 N²·m·s (-3.33 % vs revolute)") for label in labels), labels
    assert any(label.startswith("29.8 N²·m·s (-0.67 % vs revolute)") for label in labels)
