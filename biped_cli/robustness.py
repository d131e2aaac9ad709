"""``biped robustness GAIT.json ... [--out DIR]``: the robustness map of gait files in MuJoCo
(``validate.studies.robustness``), written per gait as JSON and as a figure.

The files are named from the gait file's path as its recording is (``validate.outputs.outputs``):
``logs/robustness/<folder>-<gait>.json`` and ``.png``, written together, all or none.
"""

from __future__ import annotations

import sys
from pathlib import Path

from biped.errors import BipedError
from biped_cli import args as types
from biped_cli import checks

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
    # --out checked before the gait files' checks, which take time; its maps named from them
    checks.add_folder(
        parser, "--out", DEFAULT_ROBUSTNESS, "folder of the maps", files, claims=checks.DERIVED
    )
    checks.declare_rule(parser, ("--steps", "--push-step"), _settings)


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


def heading(mapped) -> str:
    """The line naming a gait file's map (``validate.studies.robustness.GaitMap``): the file,
    its knee, criterion and speed, the model its walks were played on."""
    return (
        f"{mapped.gait}: {mapped.knee} knee, {mapped.criterion}, {mapped.speed} m/s, "
        f"on {mapped.model}"
    )


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
    from validate.studies.robustness import LIMITS
    from validate.studies.robustness_files import map_gaits

    settings = _settings(args)
    gaits = read_gaits(args.gait, args.model)
    names = [output_name(path) for path in args.gait]
    checks.claim_derived(args, "--out", names, "map")
    out, failed, mapped = Path(args.out), [], {}
    with Progress(len(gaits) * (1 + len(LIMITS)), "robustness") as bar:
        maps = map_gaits(args.gait, gaits, names, args.out, args.model, settings, progress=bar)
        for found, name in zip(maps, names, strict=True):
            bar.clear()
            path, result = found.mapped.gait, found.mapped.map
            print(heading(found.mapped))
            if not found.written:
                print(f"  FAIL  the nominal walk: {', '.join(result.nominal_failures)}; no map")
                failed.append(path)
                continue
            mapped[path] = result
            for line in lines(result):
                print(line)
            print(
                f"  wrote {out / (name + '.json')}, {out / (name + '.png')} ({result.walks} walks, "
                f"{found.wall:.1f} s, {settings.jobs} process{'es' if settings.jobs > 1 else ''})",
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
