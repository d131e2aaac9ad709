"""``biped size GAIT.json ... [--catalog FILE] [--margin M]``: the actuators a gait needs.

Per kind of joint (ankle, knee, hip: a leg's joint drives it standing and swinging) the
gait's peak torque, RMS torque, peak speed and peak power, and the lightest combination of
the catalog (``biped.model.sizing``) that meets them with the margin; the total actuator
mass of each gait (two of each kind), side by side for several gaits.
"""

from __future__ import annotations

import argparse
import sys

from biped_cli.args import add_command, add_gaits

HEADER = (
    f"  {'joint':<6} {'peak torque':>12} {'RMS torque':>11} {'peak speed':>11} "
    f"{'peak power':>11}  combination (mass, peak voltage)"
)
UNITS = f"  {'':<6} {'[N·m]':>12} {'[N·m]':>11} {'[rad/s]':>11} {'[W]':>11}"


def margin(text: str) -> float:
    """A margin: a share from 0 to 10 (0.2 is 20 %)."""
    try:
        value = float(text)
    except ValueError:
        value = float("nan")
    if not 0.0 <= value <= 10.0:
        raise argparse.ArgumentTypeError(
            f"margin = {text!r}: allowed a share from 0 to 10 (0.2 is 20 %)"
        )
    return value


def sizing_of(gait, catalog, share: float) -> list:
    """The choices (``biped.model.sizing.size``) for a gait file's samples."""
    import numpy as np

    from biped.model.criteria import simpson_weights
    from biped.model.sizing import size
    from biped.optimization.problem import CHECK_SAMPLES

    samples, model = gait.samples, gait.biped
    weights = gait.period * simpson_weights(CHECK_SAMPLES[gait.knots], gait.knots)
    rates, accels = model.joint_angles(samples.qd), model.joint_angles(samples.qdd)
    return size(np.asarray(samples.torques), rates, accels, weights, gait.period, catalog, share)


def _line(choice) -> str:
    r = choice.requirement
    figures = (
        f"  {r.kind:<6} {r.peak_torque:>12.4g} {r.rms_torque:>11.4g} {r.peak_speed:>11.4g} "
        f"{r.peak_power:>11.4g}  "
    )
    if choice.candidate is None:
        return figures + f"NONE: {choice.reason}"
    c = choice.candidate
    voltage = r.figures(c.actuator)["peak voltage"][0]
    return figures + f"{c.name} ({c.mass:g} kg, {voltage:.3g} V)"


def cmd_size(args) -> int:
    """Size the actuators of each gait: per kind of joint (ankle, knee, hip; a leg's joint
    drives it standing and swinging) the peak torque, the RMS torque over two steps, the
    peak speed and the peak power, and the lightest actuator of the catalog (--catalog,
    default the package's: integrated actuators, each cited) whose peak torque, continuous
    torque, top speed and supply voltage exceed them by the margin (--margin); the total
    actuator mass of each gait, side by side. Exits 1 when a joint of a gait has no
    combination, naming the limit no combination meets.
    """
    from biped.model.sizing import load_catalog
    from biped.records import gait_file

    catalog = load_catalog(args.catalog)
    gaits = [(path, gait_file.read_consistent(path)) for path in args.gait]  # all read first
    for path, gait in gaits:
        why = uncertified(gait)
        if why is not None:  # as biped optimize warns: its actuators may be another optimum's
            more = "more --starts may find a better one, which other actuators may drive"
            print(f"warning: {path}: its optimum is {why}; {more}", file=sys.stderr)
    totals, status = [], 0
    for path, gait in gaits:
        print(
            f"{path}: {gait.knee} knee, {gait.criterion} criterion, {gait.speed:.3f} m/s "
            f"(margin {100 * args.margin:g} %)"
        )
        print(HEADER)
        print(UNITS)
        choices = sizing_of(gait, catalog, args.margin)
        for choice in choices:
            print(_line(choice))
        missing = [c.requirement.kind for c in choices if c.candidate is None]
        if missing:
            status = 1
            totals.append((path, gait, None))
            for c in choices:
                if c.candidate is None:
                    print(f"{path}: no combination drives the {c.requirement.kind}: {c.reason}")
            continue
        total = 2 * sum(c.candidate.mass for c in choices)
        totals.append((path, gait, total))
        print(f"  total actuator mass: {total:.3f} kg (two ankles, two knees, two hips)")
    if len(totals) > 1:
        print(
            "side by side: total actuator mass, and the electrical energy per metre with the "
            "gait's own actuators (costs.electrical, no regeneration):"
        )
        for path, gait, total in totals:
            shown = "no combination" if total is None else f"{total:.3f} kg"
            print(
                f"  {gait.knee:<9} {gait.criterion:<17} {gait.speed:.3f} m/s  {shown}  "
                f"{_electrical(gait)}  ({path})"
            )
        for line in _knee_differences(totals):
            print(line)
    if status:
        print("biped size: a joint has no combination of the catalog", file=sys.stderr)
    return status


def uncertified(gait) -> str | None:
    """Why a gait file's optimum is not certified, or reached by a single start only
    (``biped.optimization.comparison``); None if it is certified and confirmed."""
    from biped.optimization.comparison import SINGLE_START

    report = gait.optimizer
    if not report.converged:
        return f"not certified: the solver did not converge ({report.status})"
    if not gait.feasible:
        return "not certified: infeasible on the check grid"
    if report.method == "ipopt" and not report.confirmed:
        return f"{SINGLE_START} ({report.starts_at_best} of {report.starts} starts)"
    return None


def _electrical(gait) -> str:
    value = gait.costs.electrical
    return "electrical not recorded" if value is None else f"{value:.4f} J/m"


def _knee_differences(totals) -> list[str]:
    """For each speed and criterion with one gait of each knee: (rolling − revolute) /
    revolute of the electrical energy per metre and of the total actuator mass."""
    from biped.optimization.comparison import DIFFERENCE, relative_change

    lines = []
    groups: dict = {}
    for _, gait, total in totals:
        groups.setdefault((gait.criterion, gait.speed), {}).setdefault(gait.knee, []).append(
            (gait, total)
        )
    for (criterion, speed), knees in groups.items():
        pairs = [knees.get(k, []) for k in ("revolute", "rolling")]
        if any(len(pair) != 1 for pair in pairs):
            continue
        (revolute, mass_v), (rolling, mass_r) = pairs[0][0], pairs[1][0]
        energy = relative_change(
            rolling.costs.electrical or float("nan"), revolute.costs.electrical or float("nan")
        )
        mass = relative_change(mass_r or float("nan"), mass_v or float("nan"))
        flagged = [f"{g.knee}: {uncertified(g)}" for g in (rolling, revolute) if uncertified(g)]
        lines.append(
            f"  rolling vs revolute, {criterion} optima at {speed:.3f} m/s: electrical energy "
            f"{energy:+.2f} %, actuator mass {mass:+.2f} % ({DIFFERENCE})"
            + (f"; not a certified comparison ({'; '.join(flagged)})" if flagged else "")
        )
    return lines


def add_parser(commands) -> None:
    from biped.model.sizing import DEFAULT_MARGIN

    parser = add_command(commands, "size", "the actuators a gait needs, from a catalog", cmd_size)
    add_gaits(parser)
    parser.add_argument(
        "--catalog",
        metavar="FILE",
        help="catalog of actuators, JSON (default: the package's, biped/model/"
        "catalog.json: seven CubeMars / T-Motor actuators of 6:1 to 64:1, from their datasheets)",
    )
    parser.add_argument(
        "--margin",
        type=margin,
        default=DEFAULT_MARGIN,
        metavar="M",
        help=f"margin on every requirement, a share (default {DEFAULT_MARGIN}: 20 %%)",
    )
