"""Sweeps of certified optima: every point certified, resumed to the same files after an
interrupt at any point, folders of other settings refused; figures and the comparison table
come from them."""

import dataclasses
import io
import json
from types import SimpleNamespace

import numpy as np
import pytest

import biped
from biped.optimization.optimize import CONFIRM, MONOTONE, apart_from_table, optimize
from biped.optimization.problem import GaitProblem
from biped.optimization.table import OTHER_KNEE_START
from biped.pages.figures import make_figures
from biped.pages.style import KNEE_LABELS
from biped.records import gait_file
from biped.records.gait_file import Costs
from biped.studies import campaign
from biped.studies import sweep as sweep_module
from biped.studies.sweep import INDEPENDENT, MANIFEST, run_sweep, sweep_settings

SPEEDS = (0.275, 0.3)
FAST = dict(jobs=1)
# Two processes: the module's sweep, and what an interrupted sweep resumes on (the files are
# the same on any number of processes).
TWO = dict(jobs=2)


def _settings(robot=None, speeds=SPEEDS, seed=0, starts=1):
    """A small sweep's settings (one start a point)."""
    return sweep_settings(robot or biped.Robot.paper(), speeds, seed=seed, starts=starts)


@pytest.fixture(scope="module")
def sweep(tmp_path_factory):
    """A small sweep, both knees and both criteria, two speeds, two processes."""
    folder = tmp_path_factory.mktemp("sweep")
    log = io.StringIO()
    run_sweep(folder, _settings(), stream=log, **TWO)
    return folder, log.getvalue()


def test_sweep_saves_every_point_certified(sweep):
    """Each (knee, criterion, speed) has a gait file with its own speed, converged and
    feasible; the folder records the settings."""
    folder, log = sweep
    files = sorted(folder.glob("*-*.json"))
    assert len(files) == 2 * 2 * len(SPEEDS)
    for path in files:
        gait = gait_file.read(path)
        assert path.name == f"{gait.knee}-{gait.criterion}-{gait.speed:.3f}.json"
        assert gait.optimizer.status == "converged" and gait.feasible
        # the sthenic criterion: its own start, the table's (the neighbouring speeds', the
        # other knee's), its one neighbouring speed's and the other knee's optima; the
        # energy criterion: the table's starts in place of its own (the table covers these
        # speeds), the neighbours' under two barriers, the other knee's under three, the
        # sthenic optimum of its own problem under two, and the given ones; an energy point
        # reached by a single start is confirmed by more (``confirm``); a neighbour's optimum
        # that is one of the table's starts is that start, not solved again
        kinds = [start.kind for start in gait.optimizer.report().history]
        more = [k for k in kinds if k.endswith(CONFIRM)]
        point = sweep_module.Point(gait.knee, gait.criterion, gait.speed)
        neighbours = sweep_module.neighbours(point, SPEEDS, biped.KNEES)
        given = [
            campaign.variables(
                gait_file.read(folder / INDEPENDENT / n.filename()).optimizer.variables
            )
            for n in neighbours
        ]
        problem = GaitProblem(
            biped.Biped(biped.Robot.paper(), gait.knee), gait.speed, gait.criterion
        )
        new = len(apart_from_table(problem, given))
        assert kinds.count("given") == new <= len(given)
        own = 7 if gait.criterion == "energy" else 3
        assert gait.optimizer.starts == own + new + len(more)
        assert not more or gait.criterion == "energy"
        assert (OTHER_KNEE_START + MONOTONE in kinds) == (gait.criterion == "energy")
    assert "16 optimizations for 8 points" in log
    assert "0 already done (0 of stage 1, 0 of stage 2), 16 to run" in log
    assert "8 of 8 points certified" in log
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


@pytest.mark.parametrize(
    "after, criteria",
    [(1, ("sthenic",)), (3, ("sthenic",)), (6, ("sthenic",)), (6, ("sthenic", "energy"))],
)
def test_interrupted_sweep_resumes_to_the_same_files(sweep, tmp_path, monkeypatch, after, criteria):
    """A sweep stopped after any number of written files (in any stage: with both criteria,
    after 6 the energy optima started from the sthenic ones are being written), with a
    stale temporary file left behind, and run again ends with the files of an uninterrupted
    sweep and no temporary file. It is stopped on one process (the files written
    there are the ones counted), resumed on two."""
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
        run_sweep(tmp_path, _settings(robot), criteria=criteria, stream=io.StringIO(), **FAST)
    assert count[0] == after
    monkeypatch.setattr(gait_file, "write_json", write)
    (tmp_path / INDEPENDENT / ".rolling-sthenic-0.300.json.abc123.tmp").write_text('{"cut')
    run_sweep(tmp_path, _settings(robot), criteria=criteria, stream=io.StringIO(), **TWO)
    expected = {k: v for k, v in _content(folder).items() if k.split("-")[1] in criteria}
    assert _content(tmp_path) == expected
    assert not list(tmp_path.rglob("*.tmp"))


class CountingBar:
    """A progress bar that records its total and the units advanced."""

    def __init__(self, total):
        self.total, self.done = total, 0

    def advance(self, units=1, note=None):
        self.done += units

    def clear(self):
        pass


def test_a_resumed_sweep_counts_optimizations_as_its_bar_does(tmp_path, monkeypatch):
    """A sweep interrupted once its independent optima are saved says, when resumed, how many
    optimizations it has, how many of each kind are done, and as many to run as its bar
    counts and runs."""
    write = gait_file.write_json
    tiny = dict(knees=("revolute",), criteria=("sthenic",), **FAST)

    def stop_after_independent(path, content):
        if INDEPENDENT not in str(path):
            raise Interrupt
        return write(path, content)

    robot = biped.Robot.paper()
    monkeypatch.setattr(gait_file, "write_json", stop_after_independent)
    with pytest.raises(Interrupt):
        run_sweep(tmp_path, _settings(robot), stream=io.StringIO(), **tiny)
    monkeypatch.setattr(gait_file, "write_json", write)
    log, bars = io.StringIO(), []

    def counting_bar(total):
        bars.append(CountingBar(total))
        return bars[-1]

    run_sweep(tmp_path, _settings(robot), stream=log, progress=counting_bar, **tiny)
    plan = log.getvalue().splitlines()[0]
    assert "4 optimizations for 2 points" in plan and "in 2 stages (own starts, final)" in plan
    assert plan.endswith("2 already done (2 of stage 1, 0 of stage 2), 2 to run")
    assert [(bar.total, bar.done) for bar in bars] == [(2, 2)]


def test_sweep_refuses_other_settings(sweep):
    """Resuming into a folder made with another robot, seed or start count is refused."""
    folder, _ = sweep
    with pytest.raises(biped.BipedError, match="robot"):
        run_sweep(folder, _settings(biped.Robot.from_mapping({"r1": 0.08})), **FAST)
    with pytest.raises(biped.BipedError, match="seed = 0"):
        run_sweep(folder, _settings(seed=1), **FAST)
    with pytest.raises(biped.BipedError, match="starts = 1"):
        run_sweep(folder, _settings(starts=2), jobs=1)


def test_a_sweep_of_the_earlier_format_is_refused_not_resumed(sweep, tmp_path):
    """A sweep folder of format biped-sweep/2 (its robot without actuators had the earlier
    default set, whose electrical figures are not the catalog's) is neither resumed nor
    tabled: both say its format, naming the folder's record."""
    folder, _ = sweep
    old = _copy(folder, tmp_path / "old", "*.json")
    record = json.loads((old / MANIFEST).read_text())
    (old / MANIFEST).write_text(json.dumps({**record, "format": "biped-sweep/2"}))
    with pytest.raises(biped.BipedError, match="made with format = 'biped-sweep/2'"):
        run_sweep(old, _settings(), **FAST)
    with pytest.raises(biped.BipedError, match="'biped-sweep/2', another version's"):
        sweep_module.optima_table(old)
    assert sweep_module.optima_table(folder)["series"]


def test_sweep_checks_its_input_before_any_work(tmp_path):
    """An unwalkable speed or a knee named twice fails at once, writing nothing."""
    with pytest.raises(biped.BipedError, match="speed = 3.5"):
        run_sweep(tmp_path, _settings(speeds=(0.2, 3.5)), **FAST)
    with pytest.raises(biped.BipedError, match="each once"):
        run_sweep(tmp_path, _settings(), knees=("rolling", "rolling"), **FAST)
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
        best[knee] = min(gaits, key=lambda g: g.costs.sthenic)
    difference = 100 * (best["rolling"].costs.sthenic / best["revolute"].costs.sthenic - 1)
    assert f"| -17.0 % | {difference:+.1f} % |" in table
    speed = best["revolute"].speed  # at an end of the sweep's grid: said so
    end = {SPEEDS[0]: " (the slowest of the sweep)", SPEEDS[-1]: " (the fastest of the sweep)"}
    assert f"| 0.27 | {speed:.3f}{end.get(speed, '')} |" in table
    gaits = [gait_file.read(p) for p in folder.glob("*-*.json")]
    confirmed = sum(g.optimizer.starts_at_best >= 2 for g in gaits)
    assert f"{confirmed} of 8 optima were reached by at least two starts" in table
    # the motors' energy per metre of the optima, from the gait files
    least = [best[knee].costs.electrical for knee in ("revolute", "rolling")]
    shown = f"{least[0]:.4g} / {least[1]:.4g} ({100 * (least[1] / least[0] - 1):+.1f} %)"
    assert (
        f"of the least sthenic optimum, revolute / rolling (rolling vs revolute) [J/m] | | {shown} |"
    ) in table
    electrical = {
        (g.knee, round(g.speed, 6)): g.costs.electrical for g in gaits if g.criterion == "sthenic"
    }
    speeds = sorted(
        {v for k, v in electrical if k == "rolling"} & {v for k, v in electrical if k == "revolute"}
    )
    mean = np.mean(
        [100 * (electrical["rolling", v] / electrical["revolute", v] - 1) for v in speeds]
    )
    assert (
        f"of the sthenic optima, rolling vs revolute, mean over the {len(speeds)} speeds both "
        f"knees have | | {mean:+.1f} % |"
    ) in table
    # gait files written before the actuators have no electrical figures: no such rows
    older = _copy(folder, tmp_path / "older", "*-*.json")
    for path in older.glob("*-*.json"):
        content = json.loads(path.read_text())
        del content["costs"]["electrical"]
        path.write_text(json.dumps(content))
    older_table = make_figures(older, tmp_path / "older-figures")[-1].read_text()
    assert "electrical" not in older_table and "| -17.0 % |" in older_table


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


def _pixels(figure) -> np.ndarray:
    """The figure drawn (H, W, 3), as PNG would show it."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    canvas = FigureCanvasAgg(figure)
    canvas.draw()
    return np.asarray(canvas.buffer_rgba())[..., :3]


def _texts(figure) -> set:
    from matplotlib.text import Text

    return {t.get_text() for t in figure.findobj(Text) if t.get_text()}


def _panel(figure, title):
    return next(ax for ax in figure.axes if ax.get_title() == title)


def test_each_figure_is_drawn_with_its_labels(sweep):
    """Every figure has ink (an empty figure has none) and its labels: torques and angles
    named by joint, angles in degrees (the curve under 'stance shank q1' is q1 in degrees),
    the model's friction coefficient and the largest |Fx| / Fz of each knee in Fig. 7."""
    from matplotlib.figure import Figure

    from biped.model.dynamics import JOINTS
    from biped.pages.figures import FOOT_FRICTION, read_sweep, sweep_figures

    folder, _ = sweep
    series, flagged = read_sweep(folder)
    figures = sweep_figures(series, flagged)
    assert sorted(figures) == ["fig4.png", "fig5.png", "fig6.png", "fig7.png", "fig8.png"]
    assert _pixels(Figure()).std() == 0.0
    for name, figure in figures.items():
        pixels = _pixels(figure)
        colours = np.unique(pixels.astype(np.int32) @ np.array([1 << 16, 1 << 8, 1]))
        assert pixels.std() > 20 and len(colours) > 50, name
    for name in ("fig4.png", "fig8.png"):
        assert {
            "walking speed [m/s]",
            r"sthenic criterion $C_\Gamma$ per metre walked [N²·m·s]",
        } <= _texts(figures[name])
    torques = _texts(figures["fig5.png"])
    assert {f"Γ{i + 1} {j.replace('_', ' ')}" for i, j in enumerate(JOINTS)} <= torques
    assert {"Γ2 stance knee", "Γ5 swing knee", "torque [N·m]"} <= torques
    angles = figures["fig6.png"]
    names = ["swing foot qp2", "stance shank q1", "stance thigh q2", "swing thigh q3"]
    assert {*names, "swing shank q4", "trunk q5", "angle from the vertical [°]"} <= _texts(angles)
    gait = next(g for g in series[("rolling", "sthenic")] if g.speed == 0.3)
    for title, k in (("stance shank q1", 2), ("swing thigh q3", 4), ("trunk q5", 6)):
        drawn = [line.get_ydata() for line in _panel(angles, title).get_lines()]
        assert any(np.allclose(y, np.degrees(gait.samples.q[:, k])) for y in drawn), title
    ground = figures["fig7.png"]
    texts = _texts(ground)
    assert f"μ = {FOOT_FRICTION:g}, the model's friction" in texts
    friction = _panel(ground, "|Fx| / Fz: friction needed")
    assert any(np.allclose(line.get_ydata(), FOOT_FRICTION) for line in friction.get_lines())
    for knee in biped.KNEES:
        gait = next(g for g in series[(knee, "sthenic")] if g.speed == 0.3)
        wrench = gait.samples.wrench
        largest = np.max(np.abs(wrench[:, 0]) / wrench[:, 1])
        assert f"largest |Fx|/Fz {largest:.3f}" in texts
        assert friction.get_ylim()[1] > max(largest, FOOT_FRICTION)


def _synthetic_series(outlier=None):
    """Both knees' optima at 13 speeds, smooth criteria; ``outlier``: (knee, index, factor)
    multiplies one gait's energy."""
    speeds = np.linspace(0.15, 0.45, 13)
    series = {}
    for knee in biped.KNEES:
        for criterion in ("sthenic", "energy"):
            series[(knee, criterion)] = [
                SimpleNamespace(  # the fields of a ``Gait`` the figures read
                    knee=knee,
                    criterion=criterion,
                    speed=float(v),
                    feasible=True,
                    optimizer=SimpleNamespace(status="converged"),
                    costs=Costs(
                        sthenic=30.0 + 40.0 * (v - 0.3) ** 2 + (knee == "rolling"),
                        energy=10.0 + 5.0 * v + 0.2 * (knee == "rolling"),
                        energy_per_metre=None,
                    ),
                )
                for v in speeds
            ]
    if outlier is not None:
        knee, index, factor = outlier
        gait = series[(knee, "sthenic")][index]
        gait.costs = dataclasses.replace(gait.costs, energy=gait.costs.energy * factor)
    return series


def test_a_far_out_value_within_the_panel_s_reach_is_drawn_on_the_axis():
    """Fig. 8's differences of the default sweep: +1.0 % at 0.15 m/s is far out of the
    others' quartiles (-1.7 to 0 %) but spanning it leaves them most of the axis: it is drawn
    on the curve, not at the edge; a value ten times the bulk's span away is at the edge."""
    from biped.pages.figures import bulk_limits, off_bulk

    percent = [1.0, 0.0, -0.6, -0.8, -0.4, -0.5, -0.5, -0.6, -0.8, -0.8, -0.9, -1.1, -1.7, 0.0]
    assert off_bulk(percent)[0]  # Tukey's far out
    low, high = bulk_limits(percent)
    assert low < -1.7 and high > 1.0
    low, high = bulk_limits([-17.0, *percent[1:]])
    assert low > -17.0 and low < -1.7 and high > 0.0


def test_a_point_off_the_bulk_is_marked_and_does_not_set_the_axis():
    """An energy 30 times the others' (one gait) is drawn at the panel's edge with its value
    written, and the axis spans the other gaits, so the knees' curves stay apart; without
    it, every point is on the axis and nothing is marked."""
    from biped.pages.figures import criterion_figure

    series = _synthetic_series(("rolling", 12, 30.0))
    value = series[("rolling", "sthenic")][12].costs.energy
    figure = criterion_figure(series, "sthenic", "energy", "Fig. 4")
    energy = _panel(figure, "energy criterion of the same gaits")
    others = [g.costs.energy for k in biped.KNEES for g in series[(k, "sthenic")]][:-1]
    low, high = energy.get_ylim()
    assert high < value and low <= min(others) and max(others) <= high
    assert max(others) - min(others) > 0.5 * (high - low)  # the bulk fills the axis
    assert f"rolling 0.450 m/s:\n{value:.4g} J, off scale" in _texts(figure)
    plain = criterion_figure(_synthetic_series(), "sthenic", "energy", "Fig. 4")
    assert not [t for t in _texts(plain) if "off scale" in t]
    low, high = _panel(plain, "energy criterion of the same gaits").get_ylim()
    everything = [g.costs.energy for k in biped.KNEES for g in series[(k, "sthenic")]]
    assert low <= min(everything) and sorted(everything)[-2] <= high


def test_a_gait_not_certified_is_marked_apart_from_the_curves():
    """A gait whose solver did not converge is a labelled cross, not a point of a curve."""
    from biped.pages.figures import criterion_figure

    series = _synthetic_series()
    gait = series[("revolute", "sthenic")].pop(4)
    gait.optimizer = SimpleNamespace(status="Maximum_Iterations_Exceeded")
    figure = criterion_figure(series, "sthenic", "energy", "Fig. 4", flagged=[gait])
    texts = _texts(figure)
    assert "revolute: not certified\n(solver: Maximum_Iterations_Exceeded)" in texts
    assert "not certified" in texts  # the legend
    panel = _panel(figure, "optimal sthenic criterion")
    curve = next(line for line in panel.get_lines() if line.get_label() == KNEE_LABELS["revolute"])
    assert gait.speed not in list(curve.get_xdata())


def test_figures_are_written_all_or_none(sweep, tmp_path, monkeypatch):
    """A sweep lacking a knee is refused before anything is written, and a failure while
    writing the set leaves none of it: an earlier complete set in the folder stays as it was,
    with no staging folder left behind."""
    from matplotlib.figure import Figure

    folder, _ = sweep
    out = tmp_path / "figures"
    make_figures(folder, out)
    before = {p.name: (p.read_bytes(), p.stat().st_mtime_ns) for p in out.iterdir()}
    assert len(before) == 6
    rolling = tmp_path / "rolling-only"
    rolling.mkdir()
    for path in folder.glob("rolling-*.json"):
        (rolling / path.name).write_bytes(path.read_bytes())
    with pytest.raises(biped.BipedError, match="revolute knee"):
        make_figures(rolling, out)
    saved = Figure.savefig
    calls = [0]

    def fail_on_the_third(self, *args, **kwargs):
        calls[0] += 1
        if calls[0] == 3:
            raise OSError("disk full")
        return saved(self, *args, **kwargs)

    monkeypatch.setattr(Figure, "savefig", fail_on_the_third)
    with pytest.raises(OSError, match="disk full"):
        make_figures(folder, out)
    after = {p.name: (p.read_bytes(), p.stat().st_mtime_ns) for p in out.iterdir()}
    assert after == before


def test_knees_certified_at_different_speeds_give_no_mean(sweep, tmp_path):
    """Where the knees have no speed in common, each mean difference (the criterion's and
    the motors' energy) says so; no row reads 'nan'."""
    folder, _ = sweep
    low, high = (f"{v:.3f}" for v in SPEEDS)
    disjoint = _copy(folder, tmp_path / "disjoint", "*-*.json")
    for path in [
        *disjoint.glob(f"rolling-*-{low}.json"),
        *disjoint.glob(f"revolute-*-{high}.json"),
    ]:
        path.unlink()
    table = make_figures(disjoint, tmp_path / "figures", stream=io.StringIO())[-1].read_text()
    assert "nan" not in table.lower()
    none = "speeds both knees have | | none: no speed where both knees are certified |"
    assert table.count(none) == 4  # per criterion: its own and the motors' energy


def _copy(folder, destination, pattern):
    destination.mkdir()
    for path in folder.glob(pattern):
        (destination / path.name).write_bytes(path.read_bytes())
    return destination


def test_a_sweep_lacking_a_criterion_gives_the_other_and_says_what_it_leaves_out(sweep, tmp_path):
    """A sweep of one criterion gives that criterion's figures and rows only, says in
    comparison.md and on the console what it leaves out, removes the left-out figure of an
    earlier set, and writes no 'nan'; one with nothing to compare is refused."""
    from biped.pages.figures import compared_criteria, read_sweep

    folder, _ = sweep
    out = tmp_path / "figures"
    make_figures(folder, out, stream=io.StringIO())  # an earlier, complete set
    sthenic = _copy(folder, tmp_path / "sthenic", "*-sthenic-*.json")
    log = io.StringIO()
    paths = make_figures(sthenic, out, stream=log)
    assert sorted(p.name for p in paths) == [
        "comparison.md",
        "fig4.png",
        "fig5.png",
        "fig6.png",
        "fig7.png",
    ]
    assert not (out / "fig8.png").exists()
    table = (out / "comparison.md").read_text()
    assert "nan" not in table.lower() and "energy criterion, rolling vs revolute" not in table
    assert "Left out: fig8.png and the energy rows: the sweep has no energy optima" in table
    assert "left out fig8.png and the energy rows" in log.getvalue()
    energy = _copy(folder, tmp_path / "energy", "*-energy-*.json")
    paths = make_figures(energy, tmp_path / "energy-figures", stream=io.StringIO())
    assert sorted(p.name for p in paths) == ["comparison.md", "fig8.png"]
    table = paths[-1].read_text()
    assert "nan" not in table.lower() and "Left out: fig4.png, fig5.png" in table
    # a criterion whose optima of one knee are not certified is left out, naming the knee
    name = "rolling-energy-0.300.json"
    gait = json.loads((energy / name).read_text())
    gait["optimizer"]["status"] = "Maximum_Iterations_Exceeded"
    (energy / name).write_text(json.dumps(gait))
    (energy / "rolling-energy-0.275.json").unlink()
    series, flagged = read_sweep(energy)
    assert compared_criteria(series, flagged) == (
        (),
        [
            "the sweep has no sthenic optima (`biped sweep --criteria sthenic energy` makes both)",
            "the sweep has no certified energy optimum of the rolling knee",
        ],
    )
    with pytest.raises(biped.BipedError, match="nothing to compare.*rolling knee"):
        make_figures(energy, tmp_path / "refused")
    assert not (tmp_path / "refused").exists()


def test_every_difference_between_the_knees_has_one_sign(sweep, tmp_path):
    """(rolling − revolute) / revolute in %, negative where the rolling knee needs less:
    in comparison.md (the paper's numbers too) and in the figures' difference panels."""
    from biped.optimization.comparison import DIFFERENCE, relative_change
    from biped.pages.figures import PAPER, read_sweep, sweep_figures

    assert relative_change(0.9, 1.0) == pytest.approx(-10.0)
    assert PAPER["sthenic_difference"] < 0 and PAPER["energy_difference"] < 0  # less: rolling
    folder, _ = sweep
    table = make_figures(folder, tmp_path, stream=io.StringIO())[-1].read_text()
    assert DIFFERENCE in table
    series, flagged = read_sweep(folder)
    figures = sweep_figures(series, flagged)
    for criterion, name in (("sthenic", "fig4.png"), ("energy", "fig8.png")):
        best = {
            knee: min(g.costs.criterion(criterion) for g in series[(knee, criterion)])
            for knee in biped.KNEES
        }
        change = relative_change(best["rolling"], best["revolute"])
        assert f"| {change:+.1f} % |" in table
        panel = _panel(figures[name], f"rolling vs revolute knee, optimal {criterion} criterion")
        curve = next(line for line in panel.get_lines() if line.get_marker() == "D")
        expected = [
            relative_change(
                *(
                    next(g for g in series[(k, criterion)] if g.speed == v).costs.criterion(
                        criterion
                    )
                    for k in ("rolling", "revolute")
                )
            )
            for v in SPEEDS
        ]
        assert np.allclose(curve.get_ydata(), expected)


def test_criterion_figures_say_their_units_and_sign_and_why_fig8_middle_scatters():
    """Figs. 4 and 8: each axis of a criterion says per metre or per step with its symbol
    set as mathtext (no literal underscore), the knees are named in words, a third panel
    holds the difference in %, and Fig. 8 says why the sthenic criterion of the energy
    optima is not a smooth curve."""
    from biped.optimization.comparison import DIFFERENCE
    from biped.pages.figures import OTHER_NOTES, criterion_figure

    series = _synthetic_series()
    for criterion, other in (("sthenic", "energy"), ("energy", "sthenic")):
        figure = criterion_figure(series, criterion, other, "Fig.")
        texts = _texts(figure)
        assert r"energy criterion $C_E$ per step [J]" in texts
        assert r"sthenic criterion $C_\Gamma$ per metre walked [N²·m·s]" in texts
        assert not [t for t in texts if "C_" in t and "$" not in t]
        assert not [t for t in texts if "(ck)" in t or "(rk)" in t]
        assert {"revolute knee", "rolling knee"} <= texts
        assert "(rolling − revolute) / revolute [%]" in texts
        caption = figure.get_supxlabel().replace("\n", " ")
        assert DIFFERENCE in caption
        assert (
            OTHER_NOTES["energy"] in caption if criterion == "energy" else "Middle" not in caption
        )
        panel = _panel(figure, f"rolling vs revolute knee, optimal {criterion} criterion")
        assert any(np.allclose(line.get_ydata(), 0.0) for line in panel.get_lines())
        _pixels(figure)  # the mathtext renders


def test_a_resume_with_other_speeds_is_refused_naming_the_speeds(tmp_path, capsys):
    """A sweep folder resumed with other speeds is refused naming the speeds, the option the
    user changed, before the paper's method's settings (which follow from them) are checked;
    nothing is written."""
    from biped.model.criteria import PAPER_SAFETY
    from biped.studies import paper_method, sweep
    from biped_cli import main

    robot = biped.Robot.paper()
    sweep.SWEEP.claim(tmp_path, sweep.Settings(robot, PAPER_SAFETY, (0.25, 0.3), 0, 3))
    runs = paper_method.PaperMethod(robot, PAPER_SAFETY, 0.3, 5)
    paper_method.PAPER.claim(tmp_path / paper_method.FOLDER, runs)
    before = sorted(tmp_path.rglob("*"))
    assert main(["sweep", "--speeds", "0.25,0.35", "--out", str(tmp_path)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "speeds = [0.25, 0.3]" in err[0] and "[0.25, 0.35]" in err[0], err
    assert sorted(tmp_path.rglob("*")) == before


def _series(speeds, swapped=False):
    """Sthenic optima of both knees at ``speeds``, in memory, as read_sweep gives them;
    ``swapped``: each gait labelled with the other speed's (a criterion that rises as the
    speed falls)."""
    from tests.conftest import gait_of

    gaits = {}
    for knee in biped.KNEES:
        found = []
        for speed in speeds:
            problem = GaitProblem(biped.Biped(biped.Robot.paper(), knee), speed)
            found.append(gait_of(optimize(problem, starts=1)))
        if swapped:
            found = [
                dataclasses.replace(g, speed=v) for g, v in zip(found, speeds[::-1], strict=True)
            ]
        gaits[(knee, "sthenic")] = sorted(found, key=lambda g: g.speed)
    return gaits


def test_comparison_of_one_speed_claims_no_trend_and_shows_the_difference():
    """From one speed: no mean over '1 speeds', no trend over speed, no located minimum; a
    least value of each knee to four digits with their difference; the stance-knee flexion
    says which knee is which."""
    from biped.pages.figures import comparison_table

    series = _series((0.3,))
    table = comparison_table(series)
    assert "1 speeds" not in table and "the one speed both knees have" in table
    assert "falls" not in table and "keeps falling" not in table
    assert "no minimum located" in table
    values = {k: series[(k, "sthenic")][0].costs.sthenic for k in biped.KNEES}
    difference = 100 * (values["rolling"] / values["revolute"] - 1)
    pair = f"{values['revolute']:.4g} / {values['rolling']:.4g} ({difference:+.1f} %)"
    assert f"(rolling vs revolute) [N²·m·s per metre walked] | | {pair} |" in table
    assert "q2 - q1, sthenic optimum near 0.3 m/s, revolute / rolling [rad]" in table


def test_comparison_claims_a_fall_to_the_slowest_speed_only_where_the_data_falls():
    """Over two speeds, 'falls at every step' only where each knee's sthenic criterion
    rises with the speed; where it does not, no word of the slowest speed."""
    from biped.pages.figures import comparison_table

    series = _series((0.25, 0.3))
    rising = all(np.all(np.diff([g.costs.sthenic for g in gaits]) > 0) for gaits in series.values())
    assert rising  # the sthenic optima per metre fall with the speed here
    assert "falls at every step of the sweep" in comparison_table(series)
    assert "slowest speed" not in comparison_table(_series((0.25, 0.3), swapped=True))


def test_a_bezier_sweep_writes_bezier_gaits_and_a_resume_in_another_family_is_refused(
    tmp_path, capsys
):
    """`biped sweep --family bezier --degree 5`: its gait files are Bézier gaits whose every
    figure is their parameters' (read back consistent), its record names the family, and
    the folder resumed in the paper's spline or another degree is refused naming the
    family, nothing written."""
    from biped.model.bezier import Bezier
    from biped_cli import main

    out = tmp_path / "sweep"
    common = ["sweep", "--speeds", "0.3", "--knees", "rolling", "--criteria", "sthenic"]
    common += ["--starts", "1", "--paper-seeds", "0", "--jobs", "1", "--out", str(out)]
    assert main([*common, "--family", "bezier", "--degree", "5"]) == 0
    gait = gait_file.Gait.read(out / "rolling-sthenic-0.300.json", consistent=True)
    assert gait.knots == Bezier(5) and gait.feasible
    assert len(gait.parameters) == 9 + 6 * (5 - 3)
    assert json.loads((out / MANIFEST).read_text())["knots"] == {"bezier": 5}
    capsys.readouterr()
    before = {p: p.stat().st_mtime_ns for p in out.rglob("*")}
    for other in ([], ["--family", "bezier", "--degree", "6"]):
        assert main([*common, *other]) == 2
        err = capsys.readouterr().err.strip().splitlines()
        assert len(err) == 1 and "knots = {'bezier': 5}" in err[0], err
    assert {p: p.stat().st_mtime_ns for p in out.rglob("*")} == before
