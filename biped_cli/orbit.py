"""``biped orbit GAIT.json ... [--vary KNOB VALUES] [--out DIR]``: the orbit of each gait's walk
in MuJoCo, its Floquet multipliers (``validate.checks.orbit``), under the validation's controller or
over a range of one of its gains (``validate.studies.orbit_study``).

Per gait ``<out>/<folder>-<gait>.json`` and ``.png`` (the multipliers in the complex plane, or
with ``--vary`` ρ against the gain), written together; given gaits of both knees, also
``<out>/knees.png`` (ρ of both knees against speed) and the knees side by side.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

from biped_cli import args as types
from biped_cli import checks

DEFAULT_ORBIT = "logs/orbit"
MAX_PHASES = 256
# Bounds of the central differences' step on the angles [rad].
STEP_RANGE = (1e-4, 0.02)
# Most scales of one --vary (each an orbit: a few hundred walks).
MAX_SCALES = 100


class Vary(argparse.Action):
    """``--vary KNOB VALUES``: a knob of ``validate.studies.orbit_study.KNOBS`` and its scales
    (START:STOP:COUNT or a list, each 0 to ``MAX_SCALE``, distinct)."""

    def __call__(self, parser, namespace, values, option_string=None):
        from validate.studies.orbit_study import KNOBS, MAX_SCALE

        knob, text = (types.value_text(value) for value in values)
        if knob not in KNOBS:
            raise argparse.ArgumentError(self, f"knob {knob!r}: allowed one of {', '.join(KNOBS)}")
        try:
            scales = types.number_list(text, f"{knob} scales", MAX_SCALES, "")
        except argparse.ArgumentTypeError as error:
            raise argparse.ArgumentError(self, str(error)) from None
        if scales.size == 0 or not np.all(
            np.isfinite(scales) & (scales >= 0) & (scales <= MAX_SCALE)
        ):
            raise argparse.ArgumentError(
                self, f"{knob} scales = {text!r}: allowed scales from 0 to {MAX_SCALE:g}"
            )
        if scales.size > MAX_SCALES:
            raise argparse.ArgumentError(
                self, f"{knob} scales = {text!r}: allowed {MAX_SCALES} at most"
            )
        rounded = [round(float(v), 9) for v in scales]
        repeated = sorted({v for v in rounded if rounded.count(v) > 1})
        if repeated:
            raise argparse.ArgumentError(
                self, f"{knob} scale {repeated[0]:g} given twice: allowed each once"
            )
        setattr(namespace, self.dest, (knob, rounded))


def step(text: str) -> float:
    """The central differences' step on the angles [rad]."""
    try:
        value = float(text)
    except ValueError:
        value = float("nan")
    low, high = STEP_RANGE
    if not low <= value <= high:
        raise argparse.ArgumentTypeError(f"step = {text!r} rad: allowed {low:g} to {high:g} rad")
    return value


def add_parser(commands) -> None:
    help = "Floquet multipliers of gaits' walks in MuJoCo: is the walk a stable orbit"
    types.add_command(commands, "orbit", help, cmd_orbit)
    types.complete_later(commands, "orbit", _add_arguments)


def _add_arguments(parser) -> None:
    from validate.checks.orbit import PHASES, RATE_STEP, STEP, TWO_PHASE_PHASES
    from validate.studies.orbit_files import KNEES_FIGURE
    from validate.studies.orbit_study import KNOBS

    types.add_gaits(parser)
    knobs = "; ".join(f"{name}: {scaled}" for name, (_, scaled) in KNOBS.items())
    parser.add_argument(
        "--vary",
        nargs=2,
        action=Vary,
        default=None,
        metavar=("KNOB", "SCALES"),
        help=f"the orbit over scales of one gain ({knobs}), START:STOP:COUNT or a list "
        "S1,S2,... [1] (default: the validation's controller alone)",
    )
    rates = RATE_STEP / STEP
    types.add_options(
        parser,
        ("--phases", types.bounded(1, MAX_PHASES), None, "N", "positions of MuJoCo's "
         f"physics-step grid the return map is averaged over, 1 to {MAX_PHASES} (default "
         f"{PHASES}, {TWO_PHASE_PHASES} for a two-phase gait; 2 x 12 x N one-step walks a "
         "Jacobian)"),
        ("--step", step, STEP, "RAD", "[rad] central-difference step on the angles, the "
         f"rates' {rates:g} times it in rad/s, {STEP_RANGE[0]:g} to {STEP_RANGE[1]:g} "
         f"(default {STEP:g})"),
        ("--jobs", types.jobs, 1, "N", "processes computing orbits side by side (default 1)"),
    )  # fmt: skip
    types.add_model(parser)
    files = f": <folder>-<gait>.json and .png, and {KNEES_FIGURE} given gaits of both knees"
    checks.add_folder(
        parser, "--out", DEFAULT_ORBIT, "folder of the results", files, claims=checks.DERIVED
    )


def _value(knob: str | None, value) -> str:
    return "the validation's controller" if knob is None else f"{knob} x {value:g}"


def orbit_line(knob: str | None, orbit) -> str:
    """One printed line of an orbit (``validate.studies.orbit_study.StudiedOrbit``)."""
    where, figures = _value(knob, orbit.value), orbit.figures
    if not orbit.found:
        return f"  {where}: {figures.verdict.upper()}: {'; '.join(orbit.notes)}"
    return (
        f"  {where}: {figures.verdict.upper()}  ρ {figures.spectral_radius:.3f} ± "
        f"{figures.spectral_radius_spread:.3f}, steps {figures.period_ratio:.3f} T; "
        f"{'; '.join(orbit.notes[:1])}"
    )


def boundary_lines(study) -> list[str]:
    """Where the orbit stops being stable over the knob's values (``study``: a
    ``validate.studies.orbit_study.OrbitStudy`` with a knob)."""
    knob, out = study.knob, []
    for boundary in study.boundaries:
        (a, b), (left, right) = boundary.between, boundary.verdicts
        at = boundary.radius_crosses_1_at
        crossing = "" if at is None else f"; ρ crosses 1 at {knob} x {at:.3g}"
        for value in (a, b):
            orbit = study.orbits[study.values.index(value)]
            if not orbit.found:  # no orbit: why, as its first note says
                crossing = f"; at {knob} x {value:g} {orbit.notes[0].split(':')[0]}"
                break
        out.append(f"  boundary: {left} at {knob} x {a:g}, {right} at {knob} x {b:g}{crossing}")
    if not study.boundaries:
        verdicts = sorted({o.figures.verdict for o in study.orbits})
        out.append(f"  no boundary over the values: {', '.join(verdicts)} throughout")
    return out


def knee_lines(studies: list) -> list[str]:
    """The knees side by side at each criterion and speed both were given at, and per
    criterion the mean difference over the speeds with its spread (``studies``: each an
    ``OrbitStudy`` under the validation's controller; ``validate.studies.orbit_files``)."""
    from biped.pages.orbit_figures import SPREADS
    from validate.studies.orbit_files import knee_means, knee_pairs

    pairs = knee_pairs(studies)
    out = ["knees compared: ρ ± spread; (rolling − revolute) / revolute ± 2 spreads"]
    for pair in pairs:
        shown = f"revolute {_rho(pair.revolute)}, rolling {_rho(pair.rolling)}"
        line = f"  {pair.criterion} {pair.speed:.3f} m/s: {shown}"
        if pair.difference is not None:
            line += (
                f": {pair.difference:+.0f} ± {SPREADS * pair.spread:.0f} % "
                f"({'distinct' if pair.distinct else 'not distinguishable'})"
            )
        out.append(line)
    for mean in knee_means(pairs):
        out.append(
            f"  {mean.criterion}: mean difference over {mean.speeds} speeds {mean.mean:+.1f} ± "
            f"{SPREADS * mean.spread:.1f} %, {mean.distinct} of {mean.speeds} distinct"
        )
    return out


def _rho(orbit) -> str:
    figures = orbit.figures
    if not orbit.found:
        return f"no orbit ({figures.verdict})"
    return f"{figures.spectral_radius:.3f} ± {figures.spectral_radius_spread:.3f}"


def cmd_orbit(args) -> int:
    """Is each gait's walk in MuJoCo a stable orbit? The walk's return map from one section
    of its steps to the next (just after each landing settles, in the stance leg's
    coordinates: six free angles and their rates), its fixed point, and its Jacobian by
    central differences of one-step walks, every direction perturbed both ways (--step),
    averaged over positions of MuJoCo's physics-step grid (--phases); its eigenvalues, the
    Floquet multipliers, and the spectral radius ρ with its spread over the grid positions.
    The verdict: stable when ρ + 2 spreads < 1 at the gait's period, unstable when ρ - 2
    spreads >= 1 or a walk falls (no orbit), undecided between (validate/checks/orbit.py).

    Under the validation's controller, or with --vary over scales of one of its gains: the
    servos' stiffness (kp), their damping (kv) or the speed loop's gain (speed; 0 turns it
    off), and where the orbit stops being stable. Writes per gait <out>/<folder>-<gait>.json
    (the multipliers, the slowest mode, the fixed point beside the gait file's state, a units
    map, provenance) and .png, together; given gaits of both knees without --vary,
    <out>/knees.png, ρ against speed with the knees' difference. Exits 1 if an orbit under the
    validation's controller is not stable (without --vary), 0 otherwise.
    """
    from biped_cli.commands import read_gaits
    from biped_cli.progress import Progress
    from validate.checks.orbit import RATE_STEP, STEP, Steps
    from validate.outputs.outputs import output_name
    from validate.studies.orbit_files import run_orbits, title

    gaits = read_gaits(args.gait, args.model)
    names = [output_name(path) for path in args.gait]
    checks.claim_derived(args, "--out", names, "result")
    knob, values = args.vary if args.vary is not None else (None, [None])
    steps = Steps(angle=args.step, rate=args.step * RATE_STEP / STEP, phases=args.phases)
    with Progress(len(gaits) * len(values), "orbit") as bar:
        run = run_orbits(
            args.gait, gaits, names, args.out, knob, values, args.model, steps, args.jobs, bar
        )
    out = Path(args.out)
    for found, name in zip(run.studies, names, strict=True):
        print(title(found))
        for orbit in found.orbits:
            print(orbit_line(knob, orbit))
        if knob is not None:
            for line in boundary_lines(found):
                print(line)
        print(f"  wrote {out / (name + '.json')}, {out / (name + '.png')}", flush=True)
    print(f"{run.walks} walks in {run.wall:.1f} s on {args.jobs} process{'es' * (args.jobs > 1)}")
    if run.knees_figure is not None:
        for line in knee_lines(list(run.studies)):
            print(line)
        print(f"wrote {run.knees_figure}")
    if run.unstable:
        print(f"biped orbit: not shown stable: {', '.join(run.unstable)}", file=sys.stderr)
        return 1
    return 0
