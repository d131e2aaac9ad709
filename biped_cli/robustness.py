"""``biped robustness GAIT.json ... [--out DIR]``: the robustness map of gait files in MuJoCo
(``validate.studies.robustness``), written per gait as JSON and as a figure.

The files are named from the gait file's path as its recording is (``validate.outputs.outputs``):
``logs/robustness/<folder>-<gait>.json`` and ``.png``, written together, all or none.
"""

from __future__ import annotations

import json
import sys
import time
from pathlib import Path

from biped.errors import BipedError
from biped_cli import args as types

DEFAULT_ROBUSTNESS = "logs/robustness"
# Most bisections of one limit (each halves its uncertainty).
MAX_ITERATIONS = 30
# What the printed lines call each limit, and how they show its values: factor, unit, sign.
SHOWN = {
    "push_forward": ("push forward", 1.0, "N·s", "+"),
    "push_backward": ("push backward", 1.0, "N·s", "+"),
    "friction": ("friction μ", 1.0, "", ""),
    "trunk_mass_heavier": ("trunk mass heavier", 100.0, "%", "+"),
    "trunk_mass_lighter": ("trunk mass lighter", 100.0, "%", "+"),
    "kp_scale_low": ("kp scale low", 1.0, "x", ""),
    "kp_scale_high": ("kp scale high", 1.0, "x", ""),
}


def add_parser(commands) -> None:
    help = "robustness map of gaits in MuJoCo: pushes, friction, trunk mass, gains"
    types.add_command(commands, "robustness", help, cmd_robustness)
    types.complete_later(commands, "robustness", _add_arguments)


def _add_arguments(parser) -> None:
    from validate.studies.robustness import RobustnessSettings

    default = RobustnessSettings()
    types.add_gaits(parser)
    types.add_options(
        parser,
        ("--steps", types.steps, default.steps, "N",
         f"steps of every walk, 2 to {types.MAX_STEPS} (default {default.steps})"),
        ("--push-step", types.positive, default.push_step, "N", "the pushes act at mid-step "
         f"of step N, before the last (default {default.push_step})"),
        ("--iterations", types.bounded(1, MAX_ITERATIONS), default.iterations, "N",
         f"bisections of each limit, 1 to {MAX_ITERATIONS} (default {default.iterations})"),
        ("--jobs", types.jobs, default.jobs, "N",
         f"processes walking the limits side by side (default {default.jobs})"),
    )  # fmt: skip
    types.add_model(parser)
    files = ": <folder>-<gait>.json and .png"
    types.add_folder(parser, "--out", DEFAULT_ROBUSTNESS, "folder of the maps", files)


def _settings(args):
    from validate.studies.robustness import RobustnessSettings

    if args.steps < 2:
        raise BipedError(
            f"--steps {args.steps}: allowed 2 to {types.MAX_STEPS} (a push, then a step)"
        )
    if args.push_step >= args.steps:
        raise BipedError(
            f"--push-step {args.push_step}: allowed 1 to {args.steps - 1}, a step before the "
            f"last of --steps {args.steps} (the walk goes on after the push)"
        )
    return RobustnessSettings(args.steps, args.push_step, args.iterations, args.jobs)


def model_source(gait, model: str | None) -> str:
    """What the map's walks were played on: ``model`` as given, the committed model, or the
    one generated from the gait's robot."""
    from validate.scene.model import committed_model

    if model is not None:
        return model
    committed = committed_model(gait.biped)
    if committed is None:
        return "generated from the gait's robot (validate.scene.mjcf)"
    return f"mjcf/{committed.name}"  # the committed model, wherever this copy keeps it


def _value(name: str, value: float | None) -> str:
    _, factor, unit, sign = SHOWN[name]
    if value is None:
        return "n/a"
    return f"{factor * value:{sign if value else ''}.3g} {unit}".rstrip()


def lines(result) -> list[str]:
    """The printed lines of a map (``validate.studies.robustness.RobustnessMap``: its limits,
    their brackets and why the first failing walk failed)."""
    settings = result.settings
    out = [
        f"  walks of {settings.steps} steps; pushes at mid-step {settings.push_step} "
        f"({result.push_time:.3f} s); {settings.iterations} bisections per limit"
    ]
    for name, limit in result.limits.items():
        label = SHOWN[name][0]
        near, far = limit.bracket
        bracket = f"bracket {_value(name, near)} to {_value(name, far)}"
        if limit.bracketed:
            low, high = limit.reproducible
            machines = f"on any machine {_value(name, low)} to {_value(name, high)}"
            detail = f"fails at {_value(name, limit.fails_at)}; {machines}; {bracket}"
            why = ": " + ", ".join(limit.failures)
        else:
            detail = f"{bracket}: its end walks too, the limit lies beyond"
            why = ""
        out.append(f"  {label:19} {_value(name, limit.limit):>11}  ({detail}){why}")
    return out


def _range(name: str, limit) -> str:
    from validate.studies.robustness import reproducible_range

    low, high = reproducible_range(limit)
    if high == float("inf"):
        return f"beyond {_value(name, low)}"
    if low == float("-inf"):
        return f"beyond {_value(name, high)}"
    return f"{_value(name, low)} to {_value(name, high)}"


def comparison_lines(maps: dict) -> list[str]:
    """Each limit of the first map (path -> ``RobustnessMap``) beside every other map's, said
    distinguishable only where the ranges they keep across machines do not overlap
    (``validate.studies.robustness.distinguishable``)."""
    from validate.studies.robustness import MACHINE_STEPS, distinguishable

    (first, reference), *others = maps.items()
    out = [
        f"compared (each limit as it lies on any machine: {MACHINE_STEPS} bisection step "
        "either way of its bracket)"
    ]
    for name, limit in reference.limits.items():
        for path, result in others:
            other = result.limits[name]
            verdict = "distinct" if distinguishable(limit, other) else "not distinguishable"
            out.append(
                f"  {SHOWN[name][0]:19} {first} {_range(name, limit)}, "
                f"{path} {_range(name, other)}: {verdict}"
            )
    return out


def _write_map(out: Path, name: str, mapped) -> None:
    """Write a gait's robustness map (``validate.studies.robustness.GaitMap``) as
    <out>/<name>.json and .png, both or neither."""
    from biped.pages.style import save
    from biped.records.provenance import provenance
    from biped.runtime.files import atomic_set
    from validate.studies.robustness_figure import robustness_figure

    content = {**mapped.to_dict(), "provenance": provenance()}
    title = f"{mapped.gait}: {mapped.knee} knee, {mapped.speed} m/s"
    figure = robustness_figure(mapped.map, title)
    with atomic_set(out, f"robustness-{name}") as staging:  # both or neither
        text = json.dumps(content, indent=1, allow_nan=False)
        (staging / f"{name}.json").write_text(text, encoding="utf-8")
        save(figure, staging / f"{name}.png")


def cmd_robustness(args) -> int:
    """Map how far each gait still walks in MuJoCo from its nominal conditions: the largest
    forward and backward push on the trunk [N·s] at mid-step of --push-step, the lowest
    friction coefficient, the trunk-mass error of the model (heavier, lighter), and the range
    of the servos' stiffness; each by bisection (--iterations) between the nominal walk and
    a stated bracket end, every walk --steps steps long and judged as the forward check of
    'biped validate' judges it (steps land and advance, no fall, slip, foot tilt, scuff or
    MuJoCo warning).

    Writes per gait <out>/<folder>-<gait>.json (limits, brackets, tolerances, why the first
    failing walk failed, a units map, provenance) and .png, together; progress on stderr,
    with the time elapsed and left (a bar on a terminal, else a line at most every 10 s).
    Exits 1 if a gait's nominal walk fails (no map is written for it), 0 otherwise.
    """
    from biped_cli.commands import read_gaits
    from biped_cli.progress import Progress
    from validate.outputs.outputs import output_name
    from validate.studies import robustness

    settings = _settings(args)
    types.check_folder(args.out, "--out")  # before the gait files' checks, which take time
    gaits = read_gaits(args.gait, args.model)
    names = [output_name(path) for path in args.gait]
    types.distinct_outputs(names, "map")
    types.claim_outputs(args.out, names)
    out, failed, mapped = Path(args.out), [], {}
    with Progress(len(gaits) * (1 + len(robustness.LIMITS)), "robustness") as bar:
        for path, gait, name in zip(args.gait, gaits, names, strict=True):
            bar.update(note=path)
            began = time.perf_counter()
            with types.naming(f"gait file {path!r}"):
                result = robustness.robustness_map(gait, args.model, settings, progress=bar)
            wall = time.perf_counter() - began
            source = model_source(gait, args.model)
            bar.clear()
            print(f"{path}: {gait.knee} knee, {gait.criterion}, {gait.speed} m/s, on {source}")
            if not result.passed:
                print(f"  FAIL  the nominal walk: {', '.join(result.nominal_failures)}; no map")
                failed.append(path)
                continue
            found = robustness.GaitMap(
                str(path), gait.knee, gait.criterion, gait.speed, source, result
            )
            _write_map(out, name, found)
            mapped[path] = result
            for line in lines(result):
                print(line)
            print(
                f"  wrote {out / (name + '.json')}, {out / (name + '.png')} ({result.walks} walks, "
                f"{wall:.1f} s, {settings.jobs} process{'es' if settings.jobs > 1 else ''})",
                flush=True,
            )
    if len(mapped) > 1:
        print("\n".join(comparison_lines(mapped)))
    if failed:
        print(
            f"biped robustness: the nominal walk fails for {', '.join(failed)}: no robustness "
            "map for it",
            file=sys.stderr,
        )
        return 1
    return 0
