"""Command-line entry point ``biped``: one program, one subcommand per job.

Errors in the input print one line on stderr and exit with status 2.
"""

from __future__ import annotations

import argparse
import os
import signal
import sys

import numpy as np

from biped.criteria import CRITERIA, MAX_CLEARANCE, MAX_ZMP_MARGIN, Safety
from biped.dynamics import JOINTS, Biped
from biped.errors import BipedError
from biped.kinematics import KNEES
from biped.robot import Robot
from biped.sweep import DEFAULT_SPEEDS

EXIT_BAD_INPUT = 2
DEFAULT_SWEEP = "logs/sweep"
DEFAULT_FIGURES = "logs/figures"
DEFAULT_RECORDINGS = "logs/recordings"
DEFAULT_PIPELINE = "logs/pipeline"
DEFAULT_SPEED = 0.3  # [m/s] the walking speed of the pipeline
ROBOT_HELP = "robot parameters, .json or .toml; fields left out keep Table 1 (default: Table 1)"


def _robot(path: str | None) -> Robot:
    return Robot.paper() if path is None else Robot.from_file(path)


def demo_posture(model: Biped, hip_ahead: float = 0.05, hip_height: float = 0.86):
    """A single-support posture held still: stance leg from the inverse geometric model.

    Args:
        hip_ahead: [m] hip ahead of the stance ankle.
        hip_height: [m] hip above the ground.
    """
    hip_from_ankle = [hip_ahead, hip_height - model.robot.ankle_height]
    shank, thigh = model.leg_angles(hip_from_ankle)
    # Swing leg behind, knee bent, foot level; trunk upright.
    angles = np.array([0.0, shank, thigh, -0.15, -0.55, 0.0])
    return model.stance_state(angles)


def cmd_demo(args) -> int:
    """Print the torques, ground wrench and ZMP that hold a one-leg posture still."""
    robot = _robot(args.robot)
    knees = KNEES if args.knee is None else (args.knee,)
    names = [f"Γ {j} [N·m]" for j in JOINTS] + ["Fx [N]", "Fz [N]", "Cy [N·m]", "x_ZMP [m]"]
    columns = []
    for knee in knees:
        model = Biped(robot, knee)
        q, qd, qdd = demo_posture(model, args.hip_ahead, args.hip_height)
        torques, wrench = model.inverse_dynamics(q, qd, qdd)
        columns.append([*torques, *wrench, model.zmp(q, qd, qdd)])
    print(
        f"Robot: {robot.total_mass:.2f} kg, {robot.height:.3f} m, "
        f"knee radii r1 = {robot.r1} m, r2 = {robot.r2} m"
    )
    print(
        f"Posture held still: hip {args.hip_ahead:+.3f} m ahead of the stance ankle, "
        f"{args.hip_height:.3f} m high; swing leg behind, trunk upright.\n"
    )
    print(f"{'':22}" + "".join(f"{knee:>12}" for knee in knees))
    for i, name in enumerate(names):
        print(f"{name:22}" + "".join(f"{column[i] + 0.0:12.4f}" for column in columns))
    return 0


def _speed(text: str) -> float:
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"speed = {text!r} is not a number") from None
    if not (np.isfinite(value) and value > 0):
        raise argparse.ArgumentTypeError(f"speed = {text!r} m/s: allowed > 0")
    return value


def _speeds(text: str) -> np.ndarray:
    """'0.15:0.45:13' (start:stop:count) or '0.2,0.3' (a list)."""
    try:
        if ":" in text:
            start, stop, count = text.split(":")
            values = np.linspace(float(start), float(stop), int(count))
        else:
            values = np.array([float(v) for v in text.split(",")])
    except ValueError:
        raise argparse.ArgumentTypeError(
            f"speeds = {text!r}: allowed START:STOP:COUNT or a comma-separated list"
        ) from None
    if values.size == 0 or not np.all(np.isfinite(values) & (values > 0)):
        raise argparse.ArgumentTypeError(f"speeds = {text!r}: allowed speeds > 0 m/s")
    return np.round(values, 6)


def _check_output(path: str, option: str = "--out") -> None:
    """Fail before any work if ``path`` cannot become a file."""
    from pathlib import Path

    target = Path(path)
    if target.is_dir():
        raise BipedError(f"{option} {path!r} is a folder: allowed a file path")
    _check_folder(str(target.parent), option, of=path)


def _check_folder(path: str, option: str, of: str | None = None) -> None:
    """Fail before any work if ``path`` cannot be (or become) a writable folder."""
    from pathlib import Path

    folder = Path(path)
    named = of if of is not None else path
    existing = folder
    while not existing.exists():
        existing = existing.parent
    if not existing.is_dir():
        raise BipedError(f"{option} {named!r}: {str(existing)!r} is a file, allowed a folder")
    if not os.access(existing, os.W_OK):
        raise BipedError(f"{option} {named!r}: folder {str(existing)!r} is not writable")


def cmd_optimize(args) -> int:
    """Find the optimal gait of one robot at one walking speed and write it as JSON.

    Exits 0 with the gait file written when the optimum is feasible on the fine check grid;
    otherwise names the violated constraints, writes nothing and exits 1.
    """
    from biped import gait_file
    from biped.optimize import check_speed, optimize

    robot = _robot(args.robot)
    model = Biped(robot, args.knee)
    check_speed(model, args.speed)
    _check_output(args.out)
    print(
        f"optimizing {args.knee} knee, {args.criterion} criterion, {args.speed} m/s "
        f"(seed {args.seed})...",
        file=sys.stderr,
    )
    optimum = optimize(model, args.speed, args.criterion, seed=args.seed, **_budget(args))
    ev = optimum.evaluation
    print(
        f"{args.knee} {args.criterion} {args.speed} m/s: criterion {optimum.value:.6g}, "
        f"sthenic {ev.sthenic:.6g} N²·m·s, energy {ev.energy:.6g} J, "
        f"period {optimum.step.period:.4f} s, step {optimum.step.step_length:.4f} m, "
        f"{optimum.evaluations} evaluations in {optimum.seconds:.1f} s"
    )
    if not optimum.feasible:
        worst = ", ".join(f"{k} = {v:.3g}" for k, v in ev.violations().items())
        print(
            f"biped optimize: infeasible optimum, violated constraints (Ψ < 0): {worst}; "
            f"no file written",
            file=sys.stderr,
        )
        return 1
    path = gait_file.write_json(args.out, gait_file.to_dict(optimum, robot, args.seed))
    print(f"wrote {path}")
    return 0


def cmd_sweep(args) -> int:
    """Optimal gaits over a range of speeds, both knees and both criteria, on all cores.

    Each point is saved as it completes; run the same command again to resume.
    """
    from biped.sweep import run_sweep

    # A terminated sweep stops its worker processes too (the pool closes on SystemExit).
    signal.signal(signal.SIGTERM, lambda *_: sys.exit(128 + signal.SIGTERM))
    robot = _robot(args.robot)
    run_sweep(
        args.out,
        robot,
        args.speeds,
        args.knees,
        args.criteria,
        seed=args.seed,
        jobs=args.jobs,
        **_budget(args),
    )
    print(f"sweep results in {args.out}")
    return 0


def cmd_figures(args) -> int:
    """PNG figures reproducing the paper's Figs. 4-8 and a comparison table (markdown)."""
    from biped.figures import make_figures

    for path in make_figures(args.sweep, args.out):
        print(f"wrote {path}")
    return 0


def _budget(args) -> dict:
    return {
        "max_restarts": args.restarts,
        "evaluations_per_run": args.evaluations,
        "polish_iterations": args.polish,
        "safety": Safety(clearance=args.clearance, zmp_margin=args.zmp_margin),
    }


def _add_budget(parser):
    from biped.optimize import EVALUATIONS_PER_RUN, MAX_RESTARTS, POLISH_ITERATIONS

    parser.add_argument("--seed", type=int, default=0, help="orients the restarts (default 0)")
    parser.add_argument(
        "--restarts",
        type=_non_negative,
        default=MAX_RESTARTS,
        help=f"Nelder-Mead restarts from the best point at most (default {MAX_RESTARTS})",
    )
    parser.add_argument(
        "--evaluations",
        type=_positive,
        default=EVALUATIONS_PER_RUN,
        metavar="N",
        help=f"criterion evaluations per Nelder-Mead run (default {EVALUATIONS_PER_RUN})",
    )
    parser.add_argument(
        "--clearance",
        type=_clearance,
        default=0.0,
        metavar="M",
        help="[m] height the swing foot must keep off the ground away from the ends of the "
        "step (default 0, the paper's z >= 0)",
    )
    parser.add_argument(
        "--zmp-margin",
        type=_zmp_margin,
        default=0.0,
        metavar="M",
        help="[m] distance the ZMP must keep inside the sole's heel and toe (default 0)",
    )
    parser.add_argument(
        "--polish",
        type=_non_negative,
        default=POLISH_ITERATIONS,
        metavar="N",
        help=f"SLSQP polish iterations at most, 0 for none (default {POLISH_ITERATIONS})",
    )


def _margin(name: str, high: float):
    def parse(text: str) -> float:
        try:
            value = float(text)
        except ValueError:
            value = float("nan")
        if not (0.0 <= value <= high):
            raise argparse.ArgumentTypeError(f"{name} = {text!r} m: allowed 0 to {high}")
        return value

    return parse


_clearance = _margin("clearance", MAX_CLEARANCE)
_zmp_margin = _margin("zmp margin", MAX_ZMP_MARGIN)


def _non_negative(text: str) -> int:
    try:
        value = int(text)
    except ValueError:
        value = -1
    if value < 0:
        raise argparse.ArgumentTypeError(f"{text!r}: allowed an integer >= 0")
    return value


def _positive(text: str) -> int:
    try:
        value = int(text)
    except ValueError:
        value = 0
    if value < 1:
        raise argparse.ArgumentTypeError(f"{text!r}: allowed an integer >= 1")
    return value


def _validate_and_record(gait: dict, steps: int, rrd):
    """Every check of a gait read by ``gait_file.read`` and its recording at ``rrd``.

    Returns the validation and its report (the checks as JSON, and the recording's path).
    """
    from validate.record import record
    from validate.report import as_json, validate

    result = validate(gait, steps=steps)
    written = record(rrd, result.biped, result.step, result.simulation, result.contact)
    return result, {**as_json(result.checks), "recording": str(written)}


def cmd_validate(args) -> int:
    """Cross-check gait files in MuJoCo and record each for rerun.

    Checks: analytical inverse dynamics and impact against MuJoCo's dynamics of the MJCF, and
    a forward walk with contact over --steps steps (every step lands, no fall, no slip, centre
    of pressure in the foot and on the gait's ZMP). Prints a table per gait (or JSON with
    --json) and writes a rerun recording per gait; exits 0 only when every check of every
    gait passes, 1 otherwise.
    """
    import json
    from pathlib import Path

    from biped import gait_file

    if args.rrd and len(args.gait) > 1:
        raise BipedError(f"--rrd names one recording: allowed with one gait (got {len(args.gait)})")
    gaits = [gait_file.read(path) for path in args.gait]  # all readable before any work
    recordings = [
        Path(args.rrd) if args.rrd else Path(DEFAULT_RECORDINGS) / (Path(path).stem + ".rrd")
        for path in args.gait
    ]
    duplicated = {str(p) for p in recordings if recordings.count(p) > 1}
    if duplicated:
        raise BipedError(
            f"gaits of the same file name would share the recording {sorted(duplicated)[0]!r}: "
            "allowed gait files with distinct names"
        )
    for rrd in recordings:
        _check_output(str(rrd), "--rrd")
    reports, passed = {}, 0
    for path, gait, rrd in zip(args.gait, gaits, recordings, strict=True):
        result, reports[path] = _validate_and_record(gait, args.steps, rrd)
        written = reports[path]["recording"]
        passed += result.passed
        if not args.json:
            print(f"{path}: {gait['knee']} knee, {gait['criterion']}, {gait['speed']} m/s")
            for check in result.checks:
                print("  " + check.line())
            print(f"recording: {written}  (open with: rerun {written})", flush=True)
    if args.json:
        print(json.dumps(reports[args.gait[0]] if len(args.gait) == 1 else reports, indent=1))
    elif len(args.gait) > 1:
        print(f"{passed} of {len(args.gait)} gaits pass every check")
    return 0 if passed == len(args.gait) else 1


def cmd_pipeline(args) -> int:
    """The whole pipeline at one walking speed, for each knee: optimal gait (as
    ``biped optimize``), validation in MuJoCo (as ``biped validate``: inverse dynamics,
    impact, forward walk with contact) and its rerun recording; then the two knees compared.

    Writes, per knee, the gait file and the validation report (JSON) in --out and the
    recording in --recordings; prints where they are. Exits 0 only when every gait is
    feasible and passes every check, 1 otherwise.
    """
    from pathlib import Path

    from biped import gait_file
    from biped.optimize import check_speed, optimize

    robot = _robot(args.robot)
    out, recordings = Path(args.out), Path(args.recordings)
    for knee in args.knees:
        check_speed(Biped(robot, knee), args.speed)
    _check_folder(args.out, "--out")
    _check_folder(args.recordings, "--recordings")
    passed, costs, written = True, {}, []
    for knee in args.knees:
        name = f"{knee}-{args.criterion}-{args.speed:.3f}"
        print(f"[{knee}] optimizing at {args.speed} m/s ({args.criterion})...", flush=True)
        optimum = optimize(
            Biped(robot, knee), args.speed, args.criterion, seed=args.seed, **_budget(args)
        )
        ev = optimum.evaluation
        print(
            f"[{knee}] sthenic {ev.sthenic:.4g} N²·m·s, energy {ev.energy:.4g} J, period "
            f"{optimum.step.period:.4f} s, step {optimum.step.step_length:.4f} m "
            f"({optimum.seconds:.1f} s)"
        )
        if not optimum.feasible:
            worst = ", ".join(f"{k} = {v:.3g}" for k, v in ev.violations().items())
            print(f"[{knee}] FAIL  optimum infeasible: {worst}")
            passed = False
            continue
        costs[knee] = optimum.costs()
        gait = gait_file.to_dict(optimum, robot, seed=args.seed)
        gait_path = gait_file.write_json(out / f"{name}.json", gait)
        print(f"[{knee}] validating {args.steps} steps in MuJoCo...", flush=True)
        result, report = _validate_and_record(
            gait_file.read(gait_path), args.steps, recordings / f"{name}.rrd"
        )
        for check in result.checks:
            print(f"[{knee}]   " + check.line())
        rrd = report["recording"]
        report_path = gait_file.write_json(
            out / f"{name}.report.json", {**report, "gait": str(gait_path)}
        )
        written.append((knee, gait_path, report_path, rrd))
        passed = passed and result.passed
    if len(costs) == 2:
        revolute, rolling = costs["revolute"], costs["rolling"]
        changes = ", ".join(
            f"{criterion} {100.0 * (rolling[criterion] / revolute[criterion] - 1.0):+.1f} %"
            for criterion in CRITERIA
        )
        print(f"rolling vs revolute knee, {args.criterion}-optimal gaits: {changes}")
    for knee, gait_path, report_path, rrd in written:
        print(f"{knee:9} gait {gait_path}, report {report_path}")
        print(f"{knee:9} recording {rrd}  (open with: rerun {rrd})")
    print("all checks passed" if passed else "some checks FAILED")
    return 0 if passed else 1


class _Parser(argparse.ArgumentParser):
    """argparse with one-line errors: 'biped optimize: error: ...' and exit status 2."""

    def error(self, message):
        self.exit(EXIT_BAD_INPUT, f"{self.prog}: error: {message}\n")


def build_parser() -> argparse.ArgumentParser:
    parser = _Parser(
        prog="biped",
        description="Quasi-optimal gaits of planar bipeds with revolute or rolling knees.",
    )
    commands = parser.add_subparsers(
        dest="command", required=True, metavar="COMMAND", parser_class=_Parser
    )
    demo = commands.add_parser(
        "demo",
        help="torques, ground wrench and ZMP of a one-leg posture",
        description=cmd_demo.__doc__,
    )
    demo.add_argument("--knee", choices=KNEES, help="one knee kinematic (default: both)")
    demo.add_argument("--robot", metavar="FILE", help=ROBOT_HELP)
    demo.add_argument(
        "--hip-ahead",
        type=float,
        default=0.05,
        metavar="M",
        help="[m] hip ahead of the stance ankle (default 0.05)",
    )
    demo.add_argument(
        "--hip-height",
        type=float,
        default=0.86,
        metavar="M",
        help="[m] hip above the ground (default 0.86)",
    )
    demo.set_defaults(run=cmd_demo)

    opt = commands.add_parser(
        "optimize", help="optimal gait at one speed", description=cmd_optimize.__doc__
    )
    opt.add_argument("--knee", choices=KNEES, required=True)
    opt.add_argument("--criterion", choices=CRITERIA, default="sthenic")
    opt.add_argument("--speed", type=_speed, required=True, metavar="V", help="[m/s] > 0")
    opt.add_argument("--out", required=True, metavar="FILE", help="gait file to write (JSON)")
    _add_budget(opt)
    opt.add_argument("--robot", metavar="FILE", help=ROBOT_HELP)
    opt.set_defaults(run=cmd_optimize)

    sweep = commands.add_parser(
        "sweep", help="optimal gaits over speeds, knees, criteria", description=cmd_sweep.__doc__
    )
    sweep.add_argument(
        "--speeds",
        type=_speeds,
        default=DEFAULT_SPEEDS,
        metavar="S",
        help="START:STOP:COUNT or a list V1,V2,... [m/s] (default 0.15:0.45:13)",
    )
    sweep.add_argument("--knees", nargs="+", choices=KNEES, default=list(KNEES))
    sweep.add_argument("--criteria", nargs="+", choices=CRITERIA, default=list(CRITERIA))
    sweep.add_argument(
        "--out", default=DEFAULT_SWEEP, metavar="DIR", help=f"(default {DEFAULT_SWEEP})"
    )
    sweep.add_argument(
        "--jobs", type=_positive, default=None, help="processes (default: all cores)"
    )
    _add_budget(sweep)
    sweep.add_argument("--robot", metavar="FILE", help=ROBOT_HELP)
    sweep.set_defaults(run=cmd_sweep)

    val = commands.add_parser(
        "validate",
        help="cross-check a gait in MuJoCo and record it",
        description=cmd_validate.__doc__,
    )
    val.add_argument(
        "gait", metavar="GAIT.json", nargs="+", help="gait files from optimize, sweep, pipeline"
    )
    val.add_argument("--steps", type=_positive, default=20, help="steps to walk (default 20)")
    val.add_argument(
        "--rrd",
        metavar="PATH",
        help=f"recording of a single gait (default {DEFAULT_RECORDINGS}/<gait>.rrd)",
    )
    val.add_argument(
        "--json",
        action="store_true",
        help="print the report as JSON (several gaits: an object keyed by file)",
    )
    val.set_defaults(run=cmd_validate)

    pipe = commands.add_parser(
        "pipeline",
        help="optimize, validate and record both knees at one speed",
        description=cmd_pipeline.__doc__,
    )
    pipe.add_argument(
        "--speed", type=_speed, default=DEFAULT_SPEED, metavar="V", help="[m/s] (default 0.3)"
    )
    pipe.add_argument("--knees", nargs="+", choices=KNEES, default=list(KNEES))
    pipe.add_argument("--criterion", choices=CRITERIA, default="sthenic")
    pipe.add_argument("--steps", type=_positive, default=20, help="steps to walk (default 20)")
    pipe.add_argument(
        "--out",
        default=DEFAULT_PIPELINE,
        metavar="DIR",
        help=f"gait files and reports (default {DEFAULT_PIPELINE})",
    )
    pipe.add_argument(
        "--recordings",
        default=DEFAULT_RECORDINGS,
        metavar="DIR",
        help=f"rerun recordings (default {DEFAULT_RECORDINGS})",
    )
    _add_budget(pipe)
    pipe.add_argument("--robot", metavar="FILE", help=ROBOT_HELP)
    pipe.set_defaults(run=cmd_pipeline)

    fig = commands.add_parser(
        "figures", help="figures and table of the comparison", description=cmd_figures.__doc__
    )
    fig.add_argument("--sweep", default=DEFAULT_SWEEP, metavar="DIR", help="sweep results")
    fig.add_argument("--out", default=DEFAULT_FIGURES, metavar="DIR", help="(default logs/figures)")
    fig.set_defaults(run=cmd_figures)
    return parser


def main(argv: list[str] | None = None) -> int:
    """Run the ``biped`` command; returns the exit status."""
    args = build_parser().parse_args(argv)
    try:
        return args.run(args)
    except (BipedError, OSError) as error:
        print(f"biped {args.command}: error: {error}", file=sys.stderr)
        return EXIT_BAD_INPUT


if __name__ == "__main__":
    sys.exit(main())
