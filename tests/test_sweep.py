"""Sweeps resume where they stopped; figures and the comparison table come from them."""

import io
import json

import pytest

import biped
from biped import gait_file
from biped.figures import make_figures
from biped.sweep import run_sweep

TINY = dict(max_restarts=0, evaluations_per_run=200, polish_iterations=25)
SPEEDS = (0.275, 0.3)


@pytest.fixture(scope="module")
def sweep(tmp_path_factory):
    """A tiny sweep, both knees and both criteria, two speeds, one process."""
    folder = tmp_path_factory.mktemp("sweep")
    log = io.StringIO()
    run_sweep(folder, biped.Robot.paper(), SPEEDS, jobs=1, stream=log, **TINY)
    return folder, log.getvalue()


def test_sweep_saves_every_point(sweep):
    """Each (knee, criterion, speed) has a readable gait file with its own speed."""
    folder, log = sweep
    files = sorted(folder.glob("*.json"))
    assert len(files) == 2 * 2 * len(SPEEDS)
    for path in files:
        gait = gait_file.read(path)
        assert path.name == f"{gait['knee']}-{gait['criterion']}-{gait['speed']:.3f}.json"
    assert "8 to run" in log


def _content(folder):
    """Gait files without their timing, which differs from run to run."""
    result = {}
    for path in folder.glob("*.json"):
        gait = json.loads(path.read_bytes())
        del gait["optimizer"]["seconds"]
        result[path.name] = gait
    return result


def test_interrupted_sweep_resumes_to_the_same_numbers(sweep, tmp_path):
    """A sweep stopped after its first speed and run again equals an uninterrupted sweep."""
    folder, _ = sweep
    run_sweep(tmp_path, biped.Robot.paper(), SPEEDS[:1], jobs=1, stream=io.StringIO(), **TINY)
    log = io.StringIO()
    run_sweep(tmp_path, biped.Robot.paper(), SPEEDS, jobs=1, stream=log, **TINY)
    assert "4 already done, 4 to run" in log.getvalue()
    assert _content(tmp_path) == _content(folder)
    assert not list(tmp_path.glob(".*.tmp"))


def test_sweep_redoes_corrupt_points_only(sweep, tmp_path):
    """A corrupt gait file counts as missing; the other files are left as they are."""
    folder, _ = sweep
    for path in folder.glob("*.json"):
        (tmp_path / path.name).write_bytes(path.read_bytes())
    corrupt = tmp_path / "revolute-sthenic-0.300.json"
    corrupt.write_text('{"format": "biped-gait/1"')
    before = {p.name: p.read_bytes() for p in tmp_path.glob("*.json") if p != corrupt}
    log = io.StringIO()
    run_sweep(tmp_path, biped.Robot.paper(), SPEEDS, jobs=1, stream=log, **TINY)
    assert "7 already done, 1 to run" in log.getvalue()
    assert gait_file.read(corrupt)["speed"] == 0.3
    for name, content in before.items():
        if not name.startswith("revolute-sthenic"):
            assert (tmp_path / name).read_bytes() == content


def test_figures_and_table(sweep, tmp_path):
    """figures writes Figs. 4-8 and a table with the paper's numbers beside ours."""
    folder, _ = sweep
    paths = make_figures(folder, tmp_path)
    names = sorted(p.name for p in paths)
    assert names == ["comparison.md", "fig4.png", "fig5.png", "fig6.png", "fig7.png", "fig8.png"]
    for path in paths:
        assert path.stat().st_size > 1000
    table = (tmp_path / "comparison.md").read_text()
    # Our numbers in the table are those of the gait files.
    best = {}
    for knee in biped.KNEES:
        gaits = [gait_file.read(p) for p in folder.glob(f"{knee}-sthenic-*.json")]
        gaits = [g for g in gaits if g["feasible"]]
        best[knee] = min(gaits, key=lambda g: g["costs"]["sthenic"])
    reduction = 1 - best["rolling"]["costs"]["sthenic"] / best["revolute"]["costs"]["sthenic"]
    assert f"| ~17% | {reduction:.1%} |" in table
    assert f"| 0.27 | {best['revolute']['speed']:.3f} |" in table


def test_sweep_refuses_another_robots_folder(sweep):
    """Resuming into a folder of another robot's gaits is an error, not a silent mix."""
    folder, _ = sweep
    other = biped.Robot.from_mapping({"r1": 0.08})
    with pytest.raises(biped.BipedError, match="another robot, safety or point"):
        run_sweep(folder, other, SPEEDS, jobs=1, stream=io.StringIO(), **TINY)


def test_sweep_checks_speeds_before_any_work(tmp_path):
    """An unwalkable speed in the list fails at once, before optimising the others."""
    with pytest.raises(biped.BipedError, match="speed = 3.5"):
        run_sweep(tmp_path, biped.Robot.paper(), (0.2, 3.5), jobs=1, stream=io.StringIO(), **TINY)
    assert not list(tmp_path.glob("*.json"))
