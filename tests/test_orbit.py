"""The walk's orbit in MuJoCo (``validate.checks.orbit``): its return map is the walk's, its
multipliers predict how perturbations decay, two step sizes agree, and the check fails the
controllers that do not walk the gait's orbit."""

import dataclasses

import numpy as np
import pytest

from tests.conftest import gait_of, optimal_gait
from validate.checks import orbit as o
from validate.studies.orbit_study import settings_at
from validate.walk.simulate import Walker, WalkSettings

_WALKERS: dict = {}
_ORBITS: dict = {}
# Steps walked by the decay test, and the grid positions its walks are averaged over (more
# than the Jacobian's). The slowest modes shrink about fourfold a step: two steps take a
# perturbation of one central-difference step along them to 0.04 of a step, above the
# standard error of the walks' mean over 24 grid positions in the mode's plane (0.02); a
# third step would be below it.
DECAY_STEPS = 2
DECAY_PHASES = 24
# A wrong controller: the servos' stiffness at which the slowest multiplier, a flip, is
# beyond -1 (kp x 0.7, 1400 N·m/rad: -1.31 ± 0.04 for the rolling knee's optimal gait at
# 0.3 m/s, -1.44 ± 0.06 for the revolute knee's; -0.84 ± 0.06 at kp x 0.65, -1.05 ± 0.13 at
# kp x 0.8), which the walk walks (20 steps, alternating in duration).
FLIP_KP = 0.7
# A gain at which the walk falls before it settles: below the robustness map's lowest kp
# scale (``biped robustness``: 0.23 for the optimal gaits at 0.3 m/s, where the swing foot
# starts scuffing; between kp x 0.15 and 0.25 the walk walks 20 steps, its orbit unstable or
# undecided, ρ 0.96-4.8).
FALL_KP = 0.1
# The servos' stiffness at which the walk without the speed loop loses speed: at the
# validation's (kp x 1, 2000 N·m/rad) the file's torques and the servos hold the gait's period
# without the loop (steps of 0.98-0.99 T, a stable orbit, ρ 0.71-0.76); at 0.75 of it the walk
# slows to steps of 1.13-1.14 T (ρ 0.81-0.89), at 0.5 (1000 N·m/rad) to 1.3 T (unstable).
SLOW_KP = 0.75


def _walker(knee: str) -> Walker:
    if knee not in _WALKERS:
        _WALKERS[knee] = Walker(gait_of(optimal_gait(knee)))
    return _WALKERS[knee]


def _orbit(knee: str, knob=None, value=None, steps=None) -> o.Orbit:
    """The orbit of the optimal gait at 0.3 m/s, computed once per session and arguments."""
    key = (knee, knob, value, steps)
    if key not in _ORBITS:
        settings = settings_at(knob, value)
        _ORBITS[key] = o.orbit(_walker(knee), settings, steps or o.Steps())
    return _ORBITS[key]


@pytest.mark.parametrize("knee", ["revolute", "rolling"])
def test_the_optimal_gaits_walk_a_stable_orbit(knee):
    """Under the validation's controller the optimal gaits at 0.3 m/s walk a stable orbit:
    ρ + 2 spreads < 1, at the gait's period, its fixed point near the file's state on the
    section, a fixed point to half a central-difference step; the section's direction, the flow, is the structural multiplier 0; the check
    passes and its JSON names every coordinate and unit."""
    result = _orbit(knee)
    m = result.multipliers
    assert result.failure is None and result.verdict == "stable", o.notes(result)
    assert result.phase == o.LANDING  # the stance foot at rest on the first section tried
    assert m.radius < 1.0 and m.upper < 1.0
    assert 0.0 < m.spread < 0.2  # the landing's noise, averaged over the grid
    # the flow is mapped to 0 within the grid's noise, which leaves 1 (a map that kept the
    # flow, test_a_map_that_keeps_the_flow_is_told_by_its_gain) far out
    assert m.flow_gain < o.MARGIN_SPREADS * m.flow_noise and o.MARGIN_SPREADS * m.flow_noise < 0.5
    assert abs(result.period_ratio - 1.0) < 0.03
    distance = np.abs(result.fixed_point - result.file_state)
    assert distance[:6].max() < 0.01 and distance[6:].max() < 0.1  # rad, rad/s
    # a fixed point of the averaged map within half a central-difference step
    assert np.linalg.norm(result.residual / result.steps.vector()) < 0.5
    figures = o.figures(result)
    assert figures["coordinates"] == list(o.COORDINATES) and len(figures["fixed_point"]) == 12
    assert len(figures["multipliers_real"]) == 11 and figures["verdict"] == "stable"


def test_the_map_restarted_on_the_section_is_the_walk():
    """The walk's own next state on the section is one of the return map's images over
    MuJoCo's grid of its state, within ``RESTART_MISS`` (``restart_miss``: 0.07 of a
    central-difference step measured, the images spreading by 0.65 of a step about their
    mean): the lift, the held stance foot and the restarted controller play the walk, its
    own position on the grid choosing among the images. A map that does not hold the walk's
    state misses by more (tests/test_two_phase_orbit: a stance foot still rocking, 1.25)."""
    walker = _walker("rolling")
    settled = o.settle(walker, WalkSettings())
    returns = o.ReturnMap(walker, WalkSettings(), settled.reference, settled.flow)
    miss = o.restart_miss(returns, settled.states, (3, 12))
    assert miss < o.RESTART_MISS, miss


def _slowest(m: o.Multipliers) -> complex:
    """The slowest multiplier, of a complex pair the one of positive imaginary part."""
    return complex(m.values[0].real, abs(m.values[0].imag))


def test_two_step_sizes_give_the_same_multipliers():
    """The slowest multiplier and ρ with steps 2/3 of the default's agree within two of
    their combined spreads (-0.05 + 0.23i, ρ 0.23 ± 0.04, against -0.05 + 0.26i, ρ 0.26 ±
    0.04); a step inside one piece of the map (1e-5 rad, one grid position) does not (ρ 1.8):
    there the map's derivative is that of a landing pinned to a physics step."""
    default = _orbit("rolling").multipliers
    two_thirds = o.Steps(angle=2.0 / 3.0 * o.STEP, rate=2.0 / 3.0 * o.RATE_STEP)
    smaller = _orbit("rolling", steps=two_thirds).multipliers
    tolerance = 2.0 * np.hypot(default.spread, smaller.spread)
    assert abs(_slowest(default) - _slowest(smaller)) < tolerance
    assert abs(default.radius - smaller.radius) < tolerance
    piece = _orbit("rolling", steps=o.Steps(angle=1e-5, rate=1e-4, phases=1))
    assert piece.multipliers is None or abs(piece.radius - default.radius) > tolerance


def test_walked_perturbations_decay_as_the_multipliers_say():
    """A perturbation of one step along the slowest mode, walked two steps both ways (24 grid
    positions): in the mode's plane (its eigenvector's real and imaginary parts; the
    validation's controller's slowest mode is a complex pair, μ = -0.05 ± 0.23i, where the
    2 ms walk's was a flip) it shrinks by |μ| a step, within two spreads of |μ|, and turns by
    arg μ a step, within 45° (an eighth of a turn, which tells a mode that keeps its sign, one
    that turns by a quarter and a flip apart); the radius of a wrong controller (``FLIP_KP``,
    a flip beyond -1) is not the factor measured. A random perturbation is left out: with
    every mode shrinking fourfold or more a step it reaches the walks' noise after one step,
    its modes still mixed."""
    result = _orbit("rolling")
    m, scale = result.multipliers, result.steps.vector()
    mode = m.vectors[:, 0] / scale
    walked = o.walked_decay(result, m.vectors[:, 0].real, DECAY_STEPS, DECAY_PHASES)
    plane = np.column_stack([mode.real, mode.imag])
    a, b = np.linalg.lstsq(plane, (walked.mean(axis=0) / scale).T, rcond=None)[0]
    z = a + 1j * b  # the mode's coordinates: z_k = conj(μ)^k z_0
    measured = float(abs(z[-1] / z[0]) ** (1.0 / DECAY_STEPS))
    assert abs(measured - abs(m.values[0])) < 2.0 * m.spread, (measured, m.values[0])
    predicted = np.conj(m.values[0]) ** np.arange(1, DECAY_STEPS + 1)
    turned = np.abs(np.angle(z[1:] / z[0] / predicted))
    assert np.all(turned < np.pi / 4), (np.degrees(np.angle(z[1:] / z[0])), m.values[0])
    wrong = _orbit("rolling", "kp", FLIP_KP)
    assert abs(measured - wrong.radius) > 2.0 * m.spread


def test_a_flip_beyond_the_unit_circle_fails_the_check():
    """``FLIP_KP`` (a gain the walk walks at, 20 steps) puts the slowest multiplier, a flip,
    beyond -1 by more than two spreads: unstable, and the check says so."""
    result = _orbit("rolling", "kp", FLIP_KP)
    assert result.multipliers.values[0].real < -1.0 and result.radius >= 1.0
    assert result.verdict == "unstable"
    assert "unstable" in o.notes(result)[-1]
    check = o.orbit_check(result)
    assert not check.passed and check.causes == ["unstable orbit"]
    assert check.line().startswith("FAIL  orbit             [unstable orbit] ")
    assert "an error may grow from step to step" in check.line()


def test_a_gain_the_robustness_map_says_falls_has_no_orbit():
    """``FALL_KP``, below the robustness map's lowest kp scale: the walk falls before it
    settles, there is no orbit, and it is reported unstable with the step it failed at."""
    result = _orbit("rolling", "kp", FALL_KP)
    assert result.multipliers is None and result.radius == np.inf
    assert result.verdict == "unstable" and "did not land step" in result.failure
    figures = o.figures(result)
    assert figures["verdict"] == "unstable" and "spectral_radius" not in figures


@pytest.mark.parametrize("knee", ["revolute", "rolling"])
def test_the_speed_loop_off_walks_another_orbit(knee):
    """Without the speed loop, with the servos at ``SLOW_KP`` of their stiffness, the gait
    loses speed: its steps grow longer than the period by more than the orbit check's
    tolerance (with the loop they do not), and the check does not take the walk for the
    gait's orbit: another orbit, steps of 1.13-1.14 T (where the search ends depends on the
    machine's floating-point kernels, the walk being slow to settle: unstable or undecided
    elsewhere, its period off if found). At the validation's stiffness the walk holds the
    gait's period without the loop."""
    walker = _walker(knee)
    slow = WalkSettings(kp_scale=SLOW_KP, speed_scale=0.0)
    walks = {"off": slow, "on": WalkSettings(kp_scale=SLOW_KP), "stiff": settings_at("speed", 0)}
    lengths = {}
    for name, settings in walks.items():
        sim = walker.walk(14, settings)
        times = np.asarray(sim.time)[np.asarray(sim.step_starts)]
        assert all(sim.landed)
        lengths[name] = float(np.mean(np.diff(times)[-4:]) / walker.period)
    assert lengths["on"] < 1.0 + o.PERIOD_TOLERANCE < lengths["off"], lengths
    assert abs(lengths["stiff"] - 1.0) < o.PERIOD_TOLERANCE, lengths
    result = o.orbit(walker, slow)
    assert result.verdict in ("another orbit", "unstable", "undecided")
    assert not result.stable
    if result.period_ratio is not None:
        assert result.period_ratio > 1.0 + o.PERIOD_TOLERANCE


def _refusal(capsys, code) -> str:
    err = capsys.readouterr().err.strip()
    assert code == 2 and len(err.splitlines()) == 1, (code, err)
    return err


def test_orbit_command_writes_the_multipliers(tmp_path, capsys):
    """`biped orbit GAIT` prints the orbit's line and writes its JSON (every number with its
    unit) and figure; `--vary kp FALL_KP` reports the fall loudly as unstable, exit 0 (a study);
    a bad knob, scale or repeated scale is one line naming it, exit 2, nothing written."""
    import json

    from biped.model.units import missing
    from biped_cli import main

    path = tmp_path / "gaits" / "rolling.json"
    path.parent.mkdir()
    gait_of(optimal_gait("rolling")).write(path)
    out = tmp_path / "orbit"
    assert main(["orbit", str(path), "--phases", "2", "--out", str(out)]) in (0, 1)
    printed = capsys.readouterr().out
    assert "the validation's controller:" in printed and "ρ" in printed
    content = json.loads((out / "gaits-rolling.json").read_text())
    assert not missing(content, content["units"]), missing(content, content["units"])
    assert (out / "gaits-rolling.png").stat().st_size > 0
    assert main(["orbit", str(path), "--vary", "kp", f"{FALL_KP:g}", "--out", str(out)]) == 0
    assert f"kp x {FALL_KP:g}: UNSTABLE: the walk did not land step" in capsys.readouterr().out
    for argv, named in [
        (["--vary", "mass", "1"], "knob 'mass'"),
        (["--vary", "kp", "-1"], "from 0 to 100"),
        (["--vary", "kp", "1,1"], "kp scale 1 given twice"),
        (["--step", "0.5"], "step = '0.5' rad"),
    ]:
        fresh = tmp_path / "fresh"
        err = _refusal(capsys, main(["orbit", str(path), *argv, "--out", str(fresh)]))
        assert named in err and "allowed" in err, err
        assert not fresh.exists()


def test_a_boundary_at_a_value_without_orbit_says_why():
    """Where the orbit search ends without an orbit, the boundary line says why, as the
    orbit's note does (a walk that missed the section did not fall)."""
    from biped_cli.orbit import boundary_lines
    from validate.checks.units import OrbitFigures
    from validate.studies.orbit_study import Boundary, OrbitStudy, StudiedOrbit, boundaries

    missed = "the walk did not reach the section in step 2: no orbit (an orbit that cannot "
    orbits = [
        StudiedOrbit(0.0, OrbitFigures("unstable"), (missed + "be found is unstable)",)),
        StudiedOrbit(0.25, OrbitFigures("stable", spectral_radius=0.69), ("slowest",)),
    ]
    study = OrbitStudy("g.json", "rolling", "sthenic", 0.3, "speed", (0.0, 0.25), tuple(orbits))
    study = dataclasses.replace(study, boundaries=tuple(boundaries(study.values, orbits)))
    assert study.boundaries == (Boundary((0.0, 0.25), ("unstable", "stable"), None),)
    assert boundary_lines(study) == [
        "  boundary: unstable at speed x 0, stable at speed x 0.25; at speed x 0 the walk did "
        "not reach the section in step 2"
    ]


def test_a_map_that_keeps_the_flow_is_told_by_its_gain():
    """The flow's gain tells a section that removes the flow (J f = 0 within the noise)
    from a map that keeps it (J f = f, gain 1), on responses with the grid's noise."""
    rng = np.random.default_rng(3)
    steps = o.Steps()
    flow = rng.standard_normal(12) * steps.vector()
    basis = o.section_basis(flow, steps)
    scale = steps.vector()[:, None]
    jacobian = 0.5 * np.eye(12)  # any contraction across the flow
    for kept in (0.0, 1.0):
        mean = jacobian @ basis * scale  # responses to the basis times the steps
        mean[:, 0] = kept * basis[:, 0] * steps.vector()
        noise = 0.1 * rng.standard_normal((o.PHASES, 12, 12)) * scale
        m = o.multipliers(mean + noise, basis, steps)
        removed = m.flow_gain < o.MARGIN_SPREADS * m.flow_noise
        assert removed == (kept == 0.0), (kept, m.flow_gain, m.flow_noise)


def test_a_complex_pair_is_written_out_not_with_plus_minus():
    """The slowest mode of a complex pair names both multipliers: "±" is a spread in every
    line beside it (ρ ± spread)."""
    pair = np.array([0.006 + 0.212j, 0.006 - 0.212j, 0.1 + 0.0j])
    multipliers = o.Multipliers(pair, np.zeros((12, 3), complex), 0.0, 0.034)
    result = o.Orbit(o.NOMINAL, o.Steps(), 0.0, period_ratio=1.0, multipliers=multipliers)
    note = o.notes(result)[0]
    assert "0.006 + 0.212i and 0.006 - 0.212i" in note and "±" not in note, note


def _knob_content(crossing: bool) -> dict:
    """A study over kp 0, 1, 2 as `biped orbit --vary kp 0:2:3` gives one: no orbit at 0,
    stable at 1 and 2; with ``crossing``, unstable at 0.5, ρ crossing 1 before 1."""
    stable = [
        {"verdict": "stable", "spectral_radius": rho, "spectral_radius_spread": spread}
        for rho, spread in ((0.760, 0.093), (0.212, 0.034))
    ]
    values, orbits = [0.0, 1.0, 2.0], [{"verdict": "unstable"}, *stable]
    boundaries = [{"between": [0.0, 1.0], "radius_crosses_1_at": None}]
    if crossing:
        values.insert(1, 0.5)
        orbits.insert(
            1, {"verdict": "unstable", "spectral_radius": 1.35, "spectral_radius_spread": 0.05}
        )
        boundaries = [{"between": [0.5, 1.0], "radius_crosses_1_at": 0.8}]
    return {"values": values, "orbits": orbits, "boundaries": boundaries, "scales": "KP"}


@pytest.mark.parametrize("crossing", [False, True])
def test_the_knob_figure_draws_what_it_measured_and_names_what_it_draws(crossing):
    """ρ against a gain: no cross on ρ's scale (a value without an orbit has no ρ: it lies
    in a strip of its own, without a scale), the legend off every panel, a band where the
    verdict changes, the dotted line named only where ρ crosses 1, every bar whole."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    from biped.pages.orbit_figures import knob_figure

    content = _knob_content(crossing)
    figure = knob_figure(content, "a study")
    renderer = FigureCanvasAgg(figure).get_renderer()
    figure.draw(renderer)
    (ax,) = [a for a in figure.axes if a.get_ylabel().startswith("spectral radius")]
    (strip,) = [a for a in figure.axes if a is not ax]

    def crosses(panel):
        return [line for line in panel.lines if line.get_marker() == "x" and len(line.get_xdata())]

    assert not crosses(ax) and len(crosses(strip)) == 1 and not len(strip.get_yticks())
    (legend,) = figure.legends
    box = legend.get_window_extent(renderer)
    assert not any(box.overlaps(panel.get_window_extent(renderer)) for panel in figure.axes)
    labels = [text.get_text() for text in legend.get_texts()]
    assert "verdict changes between these scales" in labels
    dotted = [line for line in ax.lines if line.get_linestyle() == ":"]
    assert len(dotted) == int(crossing)
    assert any("crosses 1" in label for label in labels) == crossing
    titles = [figure.get_suptitle()] + [panel.get_title() for panel in figure.axes]
    assert not any("dotted" in title for title in titles)
    found = [orbit for orbit in content["orbits"] if "spectral_radius" in orbit]
    top = max(orbit["spectral_radius"] + 2 * orbit["spectral_radius_spread"] for orbit in found)
    assert ax.get_ylim()[1] >= top  # every bar whole, none clipped to the top


def test_an_orbit_study_reads_back_what_it_writes():
    """An orbit study's JSON (``OrbitStudy.to_dict``) reads back as the same record, its keys
    in the written order; an orbit without a radius is not found, and a study whose verdict
    changes between two found orbits has ρ's crossing of 1 between them."""
    import json

    from validate.checks.units import OrbitFigures
    from validate.studies.orbit_study import OrbitStudy, StudiedOrbit, boundaries

    found = OrbitFigures("stable", spectral_radius=0.5, spectral_radius_spread=0.01, walks=27)
    fell = OrbitFigures("unstable", walks=3)
    over = OrbitFigures("unstable", spectral_radius=1.5, spectral_radius_spread=0.01)
    orbits = [StudiedOrbit(1.0, found, ("a",)), StudiedOrbit(0.5, over, ("b",))]
    study = OrbitStudy("g.json", "rolling", "sthenic", 0.3, "kp", (1.0, 0.5), tuple(orbits))
    study = dataclasses.replace(study, boundaries=tuple(boundaries(study.values, orbits)))
    assert study.boundaries[0].radius_crosses_1_at == pytest.approx(0.75)
    content = json.loads(json.dumps(study.to_dict()))
    assert OrbitStudy.from_dict(content) == study
    assert list(content) == [
        "gait",
        "knee",
        "criterion",
        "speed",
        "knob",
        "scales",
        "values",
        "orbits",
        "boundaries",
        "units",
    ]
    assert list(content["orbits"][0])[:3] == ["value", "verdict", "spectral_radius"]
    assert content["orbits"][0]["notes"] == ["a"] and "multipliers_real" not in content["orbits"][0]
    assert not StudiedOrbit(0.25, fell).found and orbits[0].found
    nominal = OrbitStudy("g.json", "rolling", "sthenic", 0.3, None, (None,), (orbits[0],))
    assert (
        nominal.to_dict()["knob"] == "none" and OrbitStudy.from_dict(nominal.to_dict()) == nominal
    )
