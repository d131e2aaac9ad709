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


def test_sweep_resumes_only_missing_or_corrupt_points(sweep):
    """A rerun skips saved points and redoes only deleted or corrupt ones, bit for bit."""
    folder, _ = sweep
    missing = folder / "rolling-energy-0.300.json"
    corrupt = folder / "revolute-sthenic-0.275.json"
    before = {p.name: p.read_bytes() for p in folder.glob("*.json")}
    missing.unlink()
    corrupt.write_text('{"format": "biped-gait/1"')
    log = io.StringIO()
    run_sweep(folder, biped.Robot.paper(), SPEEDS, jobs=1, stream=log, **TINY)
    assert "6 already done, 2 to run" in log.getvalue()
    after = {p.name: p.read_bytes() for p in folder.glob("*.json")}
    assert set(after) == set(before)
    for name in before:
        if name == missing.name:
            # Deterministic: the redone point equals the first run but for the timing.
            a, b = json.loads(before[name]), json.loads(after[name])
            assert a["parameters"] == b["parameters"] and a["costs"] == b["costs"]
        elif name != corrupt.name:
            assert after[name] == before[name]
    assert not list(folder.glob(".*.tmp"))


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
    with pytest.raises(biped.BipedError, match="another robot or point"):
        run_sweep(folder, other, SPEEDS, jobs=1, stream=io.StringIO(), **TINY)


def test_sweep_checks_speeds_before_any_work(tmp_path):
    """An unwalkable speed in the list fails at once, before optimising the others."""
    with pytest.raises(biped.BipedError, match="speed = 3.5"):
        run_sweep(tmp_path, biped.Robot.paper(), (0.2, 3.5), jobs=1, stream=io.StringIO(), **TINY)
    assert not list(tmp_path.glob("*.json"))
