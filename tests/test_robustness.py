"""The robustness map of a gait: each limit bounds the walks (short of it the gait walks, past
it the gait fails), the friction limit is no lower than what the gait's own ground force
needs, wrong torques show in a narrower map and a shifted trunk-mass window, the map is the
same on one process or two and on a rerun, and bad input is one line."""

import dataclasses
import json
import os
import subprocess
import sys

import mujoco
import numpy as np
import pytest

from biped import Robot
from biped.errors import BipedError
from biped.model.robot import FOOT_FRICTION
from biped.records.gait_file import Gait
from biped_cli import main
from tests.conftest import gait_of, optimal_gait, with_torques
from validate.checks.checks import walk_verdict
from validate.scene.mjcf import FOLDER
from validate.scene.model import compile_spec
from validate.studies import robustness
from validate.studies.robustness import (
    LIMITS,
    Limit,
    RobustnessSettings,
    distinguishable,
    map_limit,
    robustness_map,
    trunk_mass_spec,
)
from validate.walk.simulate import Push, Walker, WalkSettings

# Five bisections: at four, a push's step is 1.25 N·s, and the rolling gait's forward push
# without its torques (fails from 1.33 N·s) and with them (walks to 2.42 N·s; 8 bisections)
# both lie between 1.25 and 2.5 N·s.
SETTINGS = RobustnessSettings(steps=5, push_step=2, iterations=5)
OPTIONS = ["--steps", "5", "--push-step", "2", "--iterations", "5"]
# The maps compared with and without AVX-512 kernels: the command's 8 bisections, on walks of 5
# steps (its 10 steps at the 1 ms physics step took twice the 2 ms step's time; the limits of
# walks of 5 and 10 steps are the same but the lowest kp scale's).
MACHINE_OPTIONS = ["--steps", "5", "--push-step", "2"]


@pytest.fixture(scope="module")
def gait():
    """The optimal rolling-knee gait at 0.3 m/s, in memory."""
    return gait_of(optimal_gait("rolling"))


@pytest.fixture(scope="module")
def mapped(gait):
    """Its map on the committed Table 1 model, with small counts."""
    return robustness_map(gait, settings=SETTINGS)


@pytest.fixture(scope="module")
def walker(gait):
    return Walker(gait)


def _fails(walker, settings: WalkSettings) -> list[str]:
    return walk_verdict(walker, walker.walk(SETTINGS.steps, settings), SETTINGS.steps)


def _with_torques(gait: Gait, scale: float) -> Gait:
    return with_torques(gait, scale * gait.samples.torques)


def test_every_limit_is_a_closed_bisection(mapped):
    """The nominal walk walks, every limit is bracketed by a failing walk, lies between the
    nominal value and the far end, and is within bracket / 2^iterations (arithmetic) or its
    ratio's root (geometric) of the first failing value."""
    assert mapped.passed and tuple(mapped.limits) == LIMITS
    for limit in mapped.limits.values():
        near, far = limit.bracket
        assert limit.bracketed and limit.failures, limit
        assert min(near, far) <= limit.limit <= max(near, far)
        assert abs(limit.fails_at - near) > abs(limit.limit - near)  # beyond it, from nominal
        if limit.geometric:
            expected = abs(np.log(far / near)) / 2**SETTINGS.iterations
            assert abs(np.log(limit.fails_at / limit.limit)) == pytest.approx(expected)
        else:
            assert limit.tolerance == pytest.approx(abs(far - near) / 2**SETTINGS.iterations)
    assert mapped.walks == SETTINGS.planned_walks()


@pytest.mark.parametrize("name", ["push_forward", "push_backward"])
def test_a_walk_takes_half_the_push_limit_and_falls_past_it(mapped, walker, name):
    """Re-walked outside the bisection: the gait walks through a push of half its limit and
    fails at one and a half times the first failing push (the push's direction matters: a
    push given the other way would map the other limit)."""
    limit = mapped.limits[name]
    assert abs(limit.limit) > 0.0  # the optimal gait takes some push
    at = mapped.push_time
    assert not _fails(walker, WalkSettings(push=Push(0.5 * limit.limit, at)))
    assert _fails(walker, WalkSettings(push=Push(1.5 * limit.fails_at, at)))


def test_friction_limit_lies_between_the_gait_s_need_and_the_model_s(mapped, gait, walker):
    """The lowest friction coefficient that walks is below the model's (biped.model.robot's
    FOOT_FRICTION) and no lower than the largest |Fx| / Fz of the gait's own ground force;
    on half of it the stance foot slips."""
    limit = mapped.limits["friction"]
    wrench = gait.samples.wrench
    needed = float(np.max(np.abs(wrench[:, 0]) / wrench[:, 1]))
    assert mapped.friction == FOOT_FRICTION
    assert needed <= limit.limit < FOOT_FRICTION
    failures = _fails(walker, WalkSettings(friction=0.5 * limit.limit))
    assert any("slipped" in failure for failure in failures), failures


def test_zero_torques_give_a_narrower_map(gait, mapped):
    """Without the file's torques the servos alone still walk the gait, but it fails at a
    forward push, a heavier trunk and a lower stiffness that the exact gait walks at."""
    limp = _with_torques(gait, 0.0)
    assert not _fails(Walker(limp), WalkSettings())  # the nominal walk: the map exists
    zero = {
        name: map_limit(limp, name, settings=SETTINGS)
        for name in ("push_forward", "trunk_mass_heavier", "kp_scale_low")
    }
    exact = mapped.limits
    assert zero["push_forward"].fails_at <= exact["push_forward"].limit
    assert zero["trunk_mass_heavier"].fails_at <= exact["trunk_mass_heavier"].limit
    assert zero["kp_scale_low"].fails_at >= exact["kp_scale_low"].limit


def test_trunk_mass_window_follows_the_torques(gait, mapped):
    """The heavier-trunk limit measures the mass the file's torques carry: with every torque
    x 0.5 the gait fails on a trunk the exact gait walks with, with x 1.2 it walks with a
    trunk the exact gait fails on."""
    exact = mapped.limits["trunk_mass_heavier"]
    weak = map_limit(_with_torques(gait, 0.5), "trunk_mass_heavier", settings=SETTINGS)
    strong = map_limit(_with_torques(gait, 1.2), "trunk_mass_heavier", settings=SETTINGS)
    assert weak.fails_at <= exact.limit
    assert exact.fails_at <= strong.limit


def test_a_far_end_that_walks_is_the_limit_unbracketed(gait, monkeypatch):
    """A bracket too narrow to hold a failure says so: its far end is the limit, with no
    failing value and no tolerance, after one walk."""
    monkeypatch.setattr(robustness, "MAX_GAIN_SCALE", 2.0)
    limit = map_limit(gait, "kp_scale_high", settings=SETTINGS)
    assert not limit.bracketed and limit.limit == 2.0 and limit.fails_at is None
    assert limit.tolerance is None and limit.walks == 1


def test_a_limit_lies_on_any_machine_within_a_step_of_its_bracket(mapped):
    """Each limit's reproducible range holds its bracket (the limit and the first failing
    value) widened by one bisection step on either side: arithmetic steps of ``tolerance``,
    geometric ones of the ratio fails_at / limit."""
    for limit in mapped.limits.values():
        low, high = limit.reproducible
        near, far = sorted((limit.limit, limit.fails_at))
        if limit.geometric:
            ratio = far / near
            assert (low, high) == pytest.approx((near / ratio, far * ratio))
        else:
            assert (low, high) == pytest.approx((near - limit.tolerance, far + limit.tolerance))


def _shifted(limit: Limit, steps: float) -> Limit:
    """``limit`` moved ``steps`` bisection steps away from its nominal value."""
    move = steps * (limit.fails_at - limit.limit)
    return dataclasses.replace(limit, limit=limit.limit + move, fails_at=limit.fails_at + move)


def test_limits_a_step_apart_are_not_distinguishable_and_far_ones_are(mapped):
    """Two maps whose limit differs by one or two bisection steps cannot be told apart across
    machines; by four steps they can; a limit beyond its bracket's end is distinct from one
    well inside it and not from another beyond it."""
    push = mapped.limits["push_forward"]
    same = Limit.from_dict("push_forward", json.loads(json.dumps(push.to_dict())))
    assert same == push  # as a map written earlier reads back
    assert not distinguishable(same, _shifted(push, 1.0))
    assert not distinguishable(same, _shifted(push, 2.0))
    assert distinguishable(same, _shifted(push, 4.0))
    assert distinguishable(_shifted(push, 4.0), same)  # symmetric
    beyond = Limit("push_forward", "N·s", (0.0, 2.0), 2.0, None, (), False, 1)
    assert distinguishable(same, beyond) == (push.reproducible[1] < 2.0)
    assert not distinguishable(beyond, dataclasses.replace(beyond))


def test_the_map_keeps_its_limits_without_avx512_kernels(tmp_path):
    """The revolute knee's optimal gait at 0.3 m/s optimized and mapped without numpy's
    AVX-512 kernels, as on a machine without them, and with them: every limit of each map
    lies within the other's reproducible range (at the 2 ms step, 3 of 14 limits moved by one
    step; at 1 ms with servos of 2000 N·m/rad the revolute map's 7 limits are the same both
    ways, on walks of 5 steps as of 10, which give the same limits but the lowest kp scale:
    0.210 and 0.237)."""
    maps = {}
    for name, env in (("avx", {}), ("baseline", {"NPY_DISABLE_CPU_FEATURES": "AVX512_ICL X86_V4"})):
        gait, out = tmp_path / f"{name}.json", tmp_path / name
        run = {**os.environ, **env}
        for command in (
            ["optimize", "--knee", "revolute", "--speed", "0.3", "--out", str(gait)],
            ["robustness", str(gait), *MACHINE_OPTIONS, "--out", str(out)],
        ):
            subprocess.run(
                [sys.executable, "-m", "biped", *command], env=run, check=True, capture_output=True
            )
        maps[name] = json.loads((out / f"{tmp_path.name}-{name}.json").read_text())["limits"]
    for name in LIMITS:
        avx, baseline = maps["avx"][name], maps["baseline"][name]
        low, high = avx["reproducible"]
        assert low <= baseline["limit"] <= high, (name, avx, baseline)
        low, high = baseline["reproducible"]
        assert low <= avx["limit"] <= high, (name, avx, baseline)


def test_trunk_mass_models_come_from_the_robot(gait):
    """The model of a trunk 10 % heavier is generated from the robot's parameters with
    trunk_mass x 1.1; scaling the trunk of the committed model gives the same masses and
    inertias, and no error gives the committed model itself."""
    biped = gait.biped
    committed = FOLDER / "scene_rolling.xml"
    paper = compile_spec(mujoco.MjSpec.from_file(str(committed)))
    generated = compile_spec(trunk_mass_spec(biped, 0.1))
    scaled = compile_spec(trunk_mass_spec(biped, 0.1, committed))
    nominal = compile_spec(trunk_mass_spec(biped, 0.0))
    trunk = paper.body("trunk").id
    assert generated.body_mass[trunk] == pytest.approx(1.1 * Robot.paper().trunk_mass)
    np.testing.assert_allclose(generated.body_mass, scaled.body_mass, rtol=1e-12)
    np.testing.assert_allclose(generated.body_inertia, scaled.body_inertia, rtol=1e-12)
    others = np.arange(paper.nbody) != trunk
    np.testing.assert_array_equal(generated.body_mass[others], paper.body_mass[others])
    np.testing.assert_array_equal(nominal.body_mass, paper.body_mass)


def test_the_map_is_the_same_on_two_processes(gait, mapped):
    """The limits walked on two worker processes give the map walked in this process."""
    two = robustness_map(gait, settings=dataclasses.replace(SETTINGS, jobs=2))
    assert two.to_dict() == mapped.to_dict()


# ------------------------------------------------------------------------ the command


@pytest.fixture(scope="module")
def gait_path(gait, tmp_path_factory):
    return gait.write(tmp_path_factory.mktemp("gaits") / "rolling.json")


@pytest.fixture(scope="module")
def written(gait_path, tmp_path_factory):
    """``biped robustness`` with small counts: its exit status, output folder and JSON."""
    out = tmp_path_factory.mktemp("maps")
    code = main(["robustness", str(gait_path), *OPTIONS, "--out", str(out)])
    path = out / f"{gait_path.parent.name}-rolling.json"
    return code, out, path, path.read_bytes()


def _numbers(content, path=""):
    """Paths of the numbers of a JSON content (a list of numbers is one path)."""
    if isinstance(content, dict):
        for key, value in content.items():
            yield from _numbers(value, f"{path}.{key}" if path else key)
    elif isinstance(content, list):
        if any(isinstance(v, (int, float)) and not isinstance(v, bool) for v in content):
            yield path
        for value in content:
            if isinstance(value, (dict, list)):
                yield from _numbers(value, path)
    elif isinstance(content, (int, float)) and not isinstance(content, bool):
        yield path


def test_the_command_writes_the_map_with_a_unit_for_every_number(written, mapped):
    """Exit 0; the JSON beside its figure holds the API's map, a unit for each of its
    numbers (provenance aside) and the versions that made it."""
    code, out, path, text = written
    content = json.loads(text)
    assert code == 0 and path.with_suffix(".png").exists()
    assert content["limits"] == mapped.to_dict()["limits"]
    numbers = set(_numbers({k: v for k, v in content.items() if k != "provenance"}))
    missing = sorted(numbers - set(content["units"]))
    assert not missing and "limits.push_forward.limit" in numbers
    assert content["units"]["limits.push_forward.limit"] == "N·s"
    assert content["provenance"]["mujoco"] == mujoco.__version__
    assert content["model"] == "mjcf/scene_rolling.xml"


def test_a_rerun_writes_the_same_json(written, gait_path):
    """The same command again gives the same bytes (no time or host in the file)."""
    code, out, path, text = written
    assert main(["robustness", str(gait_path), *OPTIONS, "--out", str(out)]) == 0
    assert path.read_bytes() == text


def test_a_nominal_walk_that_fails_exits_1_without_a_map(gait_path, tmp_path, capsys):
    """On a model whose soles and floor have friction 0.05 the nominal walk slips: FAIL on
    stdout, one line on stderr, exit 1, no file."""
    for name in ("scene_rolling.xml", "biped_rolling.xml"):
        text = (FOLDER / name).read_text().replace('friction="1.0 ', 'friction="0.05 ')
        (tmp_path / name).write_text(text)
    out = tmp_path / "maps"
    argv = ["robustness", str(gait_path), *OPTIONS, "--model", str(tmp_path / "scene_rolling.xml")]
    code = main([*argv, "--out", str(out)])
    captured = capsys.readouterr()
    assert code == 1 and "FAIL  the nominal walk" in captured.out and "slipped" in captured.out
    assert len(captured.err.strip().splitlines()) == 1
    assert not out.exists() or not any(out.iterdir())


@pytest.mark.parametrize(
    "case, named",
    [
        ("push step", "--push-step"),
        ("corrupt gait", "is not valid JSON"),
        ("other knee", "revolute knee"),
        ("out is a file", "--out"),
    ],
)
def test_bad_input_is_one_line(gait_path, tmp_path, capsys, case, named):
    """Each bad input: exit 2, one line on stderr naming it, nothing written, before any
    walk."""
    argv = ["robustness", str(gait_path), *OPTIONS, "--out", str(tmp_path / "maps")]
    if case == "push step":
        argv += ["--push-step", "6"]
    elif case == "corrupt gait":
        bad = tmp_path / "bad.json"
        bad.write_text('{"format": ')
        argv[1] = str(bad)
    elif case == "other knee":
        argv += ["--model", str(FOLDER / "scene_revolute.xml")]
    else:
        (tmp_path / "file").write_text("")
        argv[-1] = str(tmp_path / "file" / "maps")
    assert main(argv) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("biped robustness") and named in err[0], err
    assert not (tmp_path / "maps").exists()


def test_settings_refuse_a_push_after_the_last_step():
    """The walk goes on after the push: a push at the last step is refused."""
    with pytest.raises(BipedError, match="push step"):
        RobustnessSettings(steps=4, push_step=4)


def test_a_map_reads_back_what_it_writes():
    """A gait's map as written (``GaitMap.to_dict``, through JSON) reads back as the same
    records, its settings but the processes, which the content does not keep; the gait's
    fields come first and the speed has its unit."""
    from validate.studies.robustness import GaitMap, RobustnessMap

    limits = {
        name: Limit(name, robustness.LIMIT_UNITS[name], (0.0, 2.0), 0.5, 0.75, ("fell",), False, 5)
        for name in LIMITS
    }
    high = Limit("kp_scale_high", limits["friction"].unit, (1.0, 16.0), 16.0, None, (), True, 1)
    limits["kp_scale_high"] = high
    result = RobustnessMap(SETTINGS, 0.59, 1.5, 1.0, 10.0, (), limits)
    mapped = GaitMap("g.json", "rolling", "sthenic", 0.3, "mjcf/scene_rolling.xml", result)
    content = json.loads(json.dumps(mapped.to_dict()))
    assert list(content)[:6] == ["gait", "knee", "criterion", "speed", "model", "passed"]
    assert content["units"]["speed"] == "m/s" and content["ranges"]["kp_scale"] == [0.5, 16.0]
    read = GaitMap.from_dict(content)
    assert read.map.settings == dataclasses.replace(SETTINGS, jobs=1)
    assert read == mapped and read.to_dict() == content
    failed = dataclasses.replace(result, nominal_failures=("fell",), limits={})
    assert RobustnessMap.from_dict(failed.to_dict()) == failed
