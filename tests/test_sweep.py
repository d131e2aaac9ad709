"""Sweeps of certified optima: every point certified, resumed to the same files after an
interrupt at any point, folders of other settings refused; figures and the comparison table
come from them."""

import io
import json

import pytest

import biped
from biped import gait_file
from biped import sweep as sweep_module
from biped.figures import make_figures
from biped.sweep import INDEPENDENT, MANIFEST, run_sweep

SPEEDS = (0.275, 0.3)
FAST = dict(starts=1, jobs=1)


@pytest.fixture(scope="module")
def sweep(tmp_path_factory):
    """A small sweep, both knees and both criteria, two speeds, one process."""
    folder = tmp_path_factory.mktemp("sweep")
    log = io.StringIO()
    run_sweep(folder, biped.Robot.paper(), SPEEDS, stream=log, **FAST)
    return folder, log.getvalue()


def test_sweep_saves_every_point_certified(sweep):
    """Each (knee, criterion, speed) has a gait file with its own speed, converged and
    feasible; the folder records the settings."""
    folder, log = sweep
    files = sorted(folder.glob("*-*.json"))
    assert len(files) == 2 * 2 * len(SPEEDS)
    for path in files:
        gait = gait_file.read(path)
        assert path.name == f"{gait['knee']}-{gait['criterion']}-{gait['speed']:.3f}.json"
        assert gait["optimizer"]["status"] == "converged" and gait["feasible"]
        # its own start, its one neighbouring speed's and the other knee's
        assert gait["optimizer"]["starts"] == 3
    assert "8 to run" in log and "8 of 8 points certified" in log
    manifest = json.loads((folder / MANIFEST).read_text())
    assert manifest["seed"] == 0 and manifest["starts"] == 1 and manifest["speeds"] == list(SPEEDS)


def _content(folder):
    """Gait files without what differs from run to run (timing, the command line)."""
    result = {}
    for path in sorted(folder.glob("*-*.json")):
        gait = json.loads(path.read_bytes())
        gait["optimizer"].pop("seconds")
        gait.pop("provenance", None)
        result[path.name] = gait
    return result


class Interrupt(Exception):
    pass


@pytest.mark.parametrize("after", [1, 3, 6])
def test_interrupted_sweep_resumes_to_the_same_files(sweep, tmp_path, monkeypatch, after):
    """A sweep stopped after any number of written points (during either stage), with a
    stale temporary file left behind, and run again ends with the files of an uninterrupted
    sweep and no temporary file."""
    folder, _ = sweep
    write = gait_file.write_json
    count = [0]

    def stop_after(path, content):
        if count[0] == after:
            raise Interrupt
        count[0] += 1
        return write(path, content)

    robot = biped.Robot.paper()
    monkeypatch.setattr(gait_file, "write_json", stop_after)
    with pytest.raises(Interrupt):
        run_sweep(tmp_path, robot, SPEEDS, criteria=("sthenic",), stream=io.StringIO(), **FAST)
    monkeypatch.setattr(gait_file, "write_json", write)
    (tmp_path / INDEPENDENT / ".rolling-sthenic-0.300.json.abc123.tmp").write_text('{"cut')
    run_sweep(tmp_path, robot, SPEEDS, criteria=("sthenic",), stream=io.StringIO(), **FAST)
    expected = {k: v for k, v in _content(folder).items() if "-sthenic-" in k}
    assert _content(tmp_path) == expected
    assert not list(tmp_path.rglob("*.tmp"))


def test_sweep_refuses_other_settings(sweep):
    """Resuming into a folder made with another robot, seed or start count is refused."""
    folder, _ = sweep
    with pytest.raises(biped.BipedError, match="robot"):
        run_sweep(folder, biped.Robot.from_mapping({"r1": 0.08}), SPEEDS, **FAST)
    with pytest.raises(biped.BipedError, match="seed = 0"):
        run_sweep(folder, biped.Robot.paper(), SPEEDS, seed=1, **FAST)
    with pytest.raises(biped.BipedError, match="starts = 1"):
        run_sweep(folder, biped.Robot.paper(), SPEEDS, starts=2, jobs=1)


def test_sweep_checks_its_input_before_any_work(tmp_path):
    """An unwalkable speed or a knee named twice fails at once, writing nothing."""
    with pytest.raises(biped.BipedError, match="speed = 3.5"):
        run_sweep(tmp_path, biped.Robot.paper(), (0.2, 3.5), **FAST)
    with pytest.raises(biped.BipedError, match="each once"):
        run_sweep(tmp_path, biped.Robot.paper(), SPEEDS, knees=("rolling", "rolling"), **FAST)
    assert not list(tmp_path.rglob("*.json"))


def test_figures_and_table(sweep, tmp_path):
    """figures writes Figs. 4-8 and a table with the paper's numbers beside ours."""
    folder, _ = sweep
    paths = make_figures(folder, tmp_path)
    names = sorted(p.name for p in paths)
    assert names == ["comparison.md", "fig4.png", "fig5.png", "fig6.png", "fig7.png", "fig8.png"]
    for path in paths:
        assert path.stat().st_size > 1000
    table = (tmp_path / "comparison.md").read_text()
    best = {}
    for knee in biped.KNEES:
        gaits = [gait_file.read(p) for p in folder.glob(f"{knee}-sthenic-*.json")]
        best[knee] = min(gaits, key=lambda g: g["costs"]["sthenic"])
    reduction = 1 - best["rolling"]["costs"]["sthenic"] / best["revolute"]["costs"]["sthenic"]
    assert f"| ~17% | {reduction:.1%} |" in table
    assert f"| 0.27 | {best['revolute']['speed']:.3f} |" in table
    gaits = [gait_file.read(p) for p in folder.glob("*-*.json")]
    confirmed = sum(g["optimizer"]["starts_at_best"] >= 2 for g in gaits)
    assert f"{confirmed} of 8 optima were reached by at least two starts" in table


def test_figures_leave_out_uncertified_optima(sweep, tmp_path):
    """A gait whose solver did not converge is not plotted nor tabled as an optimum."""
    folder, _ = sweep
    copy = tmp_path / "sweep"
    copy.mkdir()
    for path in folder.glob("*-*.json"):
        (copy / path.name).write_bytes(path.read_bytes())
    name = "rolling-sthenic-0.300.json"
    gait = json.loads((copy / name).read_text())
    gait["optimizer"]["status"] = "Maximum_Iterations_Exceeded"
    (copy / name).write_text(json.dumps(gait))
    table = (make_figures(copy, tmp_path / "figures")[-1]).read_text()
    assert " of 7 optima were reached" in table


def test_module_names_no_temporary_leftovers():
    """The stage folder is hidden and not a gait file of the sweep."""
    assert INDEPENDENT.startswith(".") and sweep_module.MANIFEST.endswith(".json")
