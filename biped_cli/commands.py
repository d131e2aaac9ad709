"""The subcommands of ``biped``: one function per job, each returning the exit status, and
beside each the function that registers its parser (``add_<command>``). The commands check
their input and print; what they run end to end lives in ``validate.workflows``.

Errors in the input raise ``BipedError`` (one line on stderr, exit status 2).
"""

from __future__ import annotations

import sys

import numpy as np

from biped.errors import BipedError, UnreachableError
from biped.model.dynamics import JOINTS, Biped
from biped.model.kinematics import KNEES
from biped.model.robot import Robot
from biped_cli import args as types
from biped_cli import checks
from biped_cli.args import budget, robot_of, safety

DEFAULT_SWEEP = "logs/sweep"
DEFAULT_FIGURES = "logs/figures"
DEFAULT_RECORDINGS = "logs/recordings"
DEFAULT_PIPELINE = "logs/pipeline"
DEFAULT_SPEED = 0.3  # [m/s] the walking speed of the pipeline


def check_simulable(robot: Robot, knee: str, source: str) -> None:
    """Fail before any work if MuJoCo cannot model the robot's knee (``validate.scene.mjcf``: the
    rolling knee is a link between the centres of its two rolling circles, so r1, r2 > 0)."""
    if knee == "rolling" and (robot.r1 <= 0.0 or robot.r2 <= 0.0):
        raise BipedError(
            f"{source}: a rolling knee with r1 = {robot.r1} m, r2 = {robot.r2} m cannot be "
            "simulated in MuJoCo: allowed r1, r2 > 0 (r1 = r2 = 0 is the revolute knee)"
        )


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
    robot = robot_of(args)
    knees = KNEES if args.knee is None else (args.knee,)
    names = [f"Γ {j} [N·m]" for j in JOINTS] + ["Fx [N]", "Fz [N]", "Cy [N·m]", "x_ZMP [m]"]
    columns = []
    for knee in knees:
        model = Biped(robot, knee)
        try:
            q, qd, qdd = demo_posture(model, args.hip_ahead, args.hip_height)
        except UnreachableError as error:
            raise BipedError(
                f"--hip-ahead {args.hip_ahead:g} m, --hip-height {args.hip_height:g} m: {error}"
            ) from None
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


def add_demo(commands) -> None:
    help = "torques, ground wrench and ZMP of a one-leg posture"
    demo = types.add_command(commands, "demo", help, cmd_demo)
    demo.add_argument(
        "--knee", choices=KNEES, help=f"one knee kinematic; {types.KNEE_HELP} (default: both)"
    )
    types.add_robot(demo)
    for option, default, where in (
        ("--hip-ahead", 0.05, "ahead of the stance ankle"),
        ("--hip-height", 0.86, "above the ground"),
    ):
        help = f"[m] hip {where} (default {default})"
        demo.add_argument(option, type=types.metres, default=default, metavar="M", help=help)


def optimum_line(knee: str, criterion: str, speed: float, optimum) -> str:
    """An optimum in three lines: its step; both criteria on the check grid (``costs`` in
    its gait file, what the comparisons use); its criterion on the solver's samples
    (``optimizer.value``, what ranked the starts; left out for a result without it)."""
    from biped.model.criteria import CRITERION_UNITS
    from biped.model.gait import pieces as family_pieces
    from biped.optimization.comparison import NELDER_MEAD_SAMPLES_PER_STEP
    from biped.optimization.problem import CHECK_SAMPLES

    problem = optimum.problem
    pieces = family_pieces(problem.knots)  # each piece closed: its ends counted on both sides
    check_per_step = pieces * (CHECK_SAMPLES[problem.knots] + 1)
    solver_per_step = pieces * (problem.samples_per_half + 1)
    ev = optimum.evaluation
    lines = [
        f"{knee} knee, {criterion}-optimal gait at {speed} m/s: period "
        f"{optimum.step.period:.4f} s, step {optimum.step.step_length:.4f} m",
        f"  costs, on the check grid ({check_per_step} samples per step; the "
        f"comparisons use them): sthenic {ev.sthenic:.6g} N²·m·s, energy {ev.energy:.6g} J, "
        f"electrical {ev.electrical / optimum.step.step_length:.6g} J/m (no regeneration)",
    ]
    samples = (
        f"{solver_per_step} per step; it ranks the starts"
        if optimum.report.method == "ipopt"
        else f"{NELDER_MEAD_SAMPLES_PER_STEP} per step, penalties included"
    )
    if np.isfinite(optimum.report.value):
        lines.append(
            f"  optimizer.value, on the solver's samples ({samples}): {criterion} "
            f"{optimum.report.value:.6g} {CRITERION_UNITS[criterion]}"
        )
    return "\n".join(lines)


def cmd_optimize(args) -> int:
    """Find the optimal gait of one robot at one walking speed and write it as JSON.

    IPOPT with exact derivatives from several starts (``--starts``); the best converged
    start wins. Exits 0 with the gait file written when the optimum is converged and
    feasible on the fine check grid. Exits 1 when no start converged (naming the solver's
    status) or the optimum is infeasible (naming the violated constraints); the file is
    written only when feasible, with the solver's status in it.
    """
    from biped.optimization.compiled import mode as derivatives_mode
    from biped.optimization.optimize import confirm, optimize, prepare
    from biped.optimization.problem import GaitProblem
    from biped.records import gait_file
    from biped.runtime.runner import free_cores

    robot = robot_of(args)
    model = Biped(robot, args.knee)
    family = types.gait_family(args)
    problem = GaitProblem(model, args.speed, args.criterion, safety(args), knots=family)
    given = budget(args)
    if args.double_support is not None:  # what the two-phase problem does not build
        from biped.optimization.two_phase import TwoPhaseProblem

        TwoPhaseProblem(problem, args.double_support)
    print(f"optimizing {problem.describe()} ({args.method}, seed {args.seed})...", file=sys.stderr)
    setup = prepare(problem) if args.method == "ipopt" else 0.0
    optimum = confirm(problem, optimize(problem, **given))
    ev = optimum.evaluation
    print(optimum_line(args.knee, args.criterion, args.speed, optimum))
    report = optimum.report
    print(report.summary())
    if args.method == "ipopt":
        print(
            f"time: setup {setup:.2f} s (IPOPT and its exact derivatives built, "
            f"{derivatives_mode()}), solve "
            f"{report.seconds:.2f} s ({report.starts} starts on {min(free_cores(), report.starts)} "
            "processes)"
        )
    if report.converged and report.method == "ipopt" and not report.confirmed:
        print(
            "warning: the best value was reached by a single start; more --starts may "
            "find a better optimum",
            file=sys.stderr,
        )
    if not report.converged:
        message = f"biped optimize: the solver did not converge ({report.method}: {report.status})"
        if optimum.feasible:
            path = gait_file.Gait.from_optimum(optimum, robot).write(args.out)
            message += f"; {path} is written but is not a certified optimum"
        else:
            worst = ev.violations_line()
            message += f"; the result is infeasible (Ψ < 0: {worst}), no file written"
        print(message, file=sys.stderr)
        return 1
    if not optimum.feasible:
        print(
            "biped optimize: infeasible optimum, violated constraints (Ψ < 0): "
            f"{ev.violations_line()}; no file written",
            file=sys.stderr,
        )
        return 1
    if args.double_support is not None:
        return cmd_double_support(args, problem, optimum)
    path = gait_file.Gait.from_optimum(optimum, robot).write(args.out)
    print(f"wrote {path}")
    return 0


def add_optimize(commands) -> None:
    opt = types.add_command(commands, "optimize", "optimal gait at one speed", cmd_optimize)
    types.add_knee(opt, required=True)
    types.add_criterion(opt)
    types.add_speed(opt)
    checks.add_gait_out(opt)
    types.add_budget(opt)
    types.add_knots(opt)
    types.add_bezier(opt)
    types.add_robot(opt)
    types.add_double_support(
        opt,
        "also optimize the gait of two phases, single then double support (both feet flat), "
        "started from the single-support optimum, its double support a share of the step "
        "from LOW to HIGH (0 <= LOW <= HIGH < 0.5; one number: that share): sthenic "
        "criterion, IPOPT with --method ipopt only; --out then receives the two-phase "
        "gait file (both phases, see docs/gaits.md); default: single support only",
    )
    types.add_landing(opt)
    checks.declare_rule(opt, ("--double-support", "--method"), _check_double_support)


def _check_double_support(args) -> None:
    """The two-phase optimum is IPOPT's."""
    if args.double_support is not None and args.method != "ipopt":
        raise BipedError(f"--double-support with --method {args.method}: allowed ipopt")


def cmd_double_support(args, problem, optimum) -> int:
    """The two-phase optimum from the single-support ``optimum`` of ``problem`` (as many
    starts as ``--starts``, seeded by ``--seed``), printed beside it and written to
    ``args.out``; 1 when no start converged to an optimum feasible on the numeric model."""
    from biped.optimization.two_phase import TwoPhaseProblem
    from biped.records import two_phase_file

    two = TwoPhaseProblem(problem, args.double_support, landing=args.landing)
    solved = two_phase_file.solve(two, optimum.variables, optimum.value, args.starts, args.seed)
    print(
        f"time: two phases' setup {solved.setup_seconds:.2f} s, solves "
        f"{solved.result.seconds:.2f} s"
    )
    if solved.gait is None:
        print(f"biped optimize: {solved.failure()}; no file written", file=sys.stderr)
        return 1
    print(solved.line(optimum.value))
    if solved.result.at_best < 2:
        print(
            "warning: the best two-phase value was reached by a single start; more --starts "
            "may find a better optimum",
            file=sys.stderr,
        )
    print(f"wrote {solved.gait.write(args.out)}")
    return 0


def cmd_sweep(args) -> int:
    """Optimal gaits over a range of speeds, both knees and both criteria, on all cores
    (or on a Dask cluster with --dask tcp://HOST:PORT).

    Each optimization is saved as it completes; run the same command again to resume.
    Progress on stderr, with the time elapsed and an estimate of the time left: a bar on a
    terminal, else a line at most every 10 s. Exits 0 when every point is certified, 1
    otherwise (the summary names those that are not).
    """
    from biped.runtime.runner import check_dask
    from biped.studies import paper_method
    from biped.studies.sweep import (
        INDEPENDENT,
        MANIFEST,
        check_sweep,
        run_sweep,
        sweep_settings,
        uncertified,
    )

    robot = robot_of(args)
    family = types.gait_family(args)
    # at the sweep's speed nearest the paper's optima
    paper_speed = float(min(args.speeds, key=lambda v: abs(v - paper_method.SPEED)))
    # the sweep's own settings first: the paper's method's follow from them
    sweep = sweep_settings(robot, args.speeds, args.seed, args.starts, safety(args), family)
    check_sweep(args.out, sweep)
    if args.paper_seeds:  # refused before the sweep runs, not after
        paper = paper_method.paper_settings(robot, paper_speed, args.paper_seeds, safety(args))
        paper_method.check_paper_method(args.out, paper)
    if args.dask is not None:
        check_dask(args.dask)
    two = None
    if args.double_support is not None:  # refused before the sweep runs, not after
        from biped.studies import two_phase_sweep

        two = two_phase_sweep.two_phase_settings(sweep, args.double_support, args.landing)
        two_phase_sweep.check_two_phase(args.out, two)
        args.criteria = [two_phase_sweep.CRITERION]  # the two-phase problem's only one
    which = (args.knees, args.criteria)
    points = run_sweep(args.out, sweep, *which, **types.campaign(args, "sweep"))
    runs = []
    if args.paper_seeds:
        where = types.campaign(args, "paper's method")
        runs = paper_method.run_paper_method(args.out, paper, *which, **where)

    def files(n: int) -> str:
        return f"{n} gait file{'' if n == 1 else 's'}"

    folder = f", {paper_method.FOLDER}/ ({paper_method.SETTINGS} and {files(len(runs))})"
    print(  # the folder's files, once: a file per optimization is too many to name
        f"sweep results in {args.out}: {MANIFEST}, {files(len(points))} "
        f"<knee>-<criterion>-<speed>.json, {INDEPENDENT}/ (each point's first solve)"
        f"{folder if runs else ''}"
    )
    status = 1 if uncertified(args.out, points, sweep) else 0
    if two is not None:  # from the sweep's single-support optima, those certified
        status = max(status, cmd_sweep_double_support(args, two))
    return status


def cmd_sweep_double_support(args, settings) -> int:
    """The sweep's two-phase optima (``biped.studies.two_phase_sweep``), their summary and
    figure printed and written; 1 when a point has no two-phase optimum."""
    from pathlib import Path

    from biped.pages.two_phase_sweep_figures import two_phase_sweep_figure
    from biped.studies import two_phase_sweep as study

    summary = study.run_two_phase(
        args.out, settings, args.knees, **types.campaign(args, "double support")
    )
    folder = Path(args.out) / study.FOLDER
    figure = two_phase_sweep_figure(summary, folder / study.FIGURE)
    print(summary.table())
    print(
        f"double support results in {folder}: {study.RECORD}, {study.SUMMARY}, {figure.name}, "
        f"a two-phase gait file (or its failure record) <knee>-sthenic-<speed>.json per point"
    )
    return 1 if any(p.double is None for p in summary.points) else 0


def add_sweep(commands) -> None:
    from biped.studies.sweep import DEFAULT_SPEEDS

    help = "optimal gaits over speeds, knees, criteria"
    sweep = types.add_command(commands, "sweep", help, cmd_sweep)
    types.add_speeds(sweep, DEFAULT_SPEEDS, "0.15:0.45:13")
    types.add_knee(sweep, several=True)
    types.add_criterion(sweep, several=True)
    checks.add_folder(sweep, "--out", DEFAULT_SWEEP, "folder of the sweep")
    types.add_jobs(sweep)
    types.add_budget(sweep, sweep=True)
    types.add_knots(sweep)
    types.add_bezier(sweep)
    types.add_robot(sweep)
    types.add_dask(sweep)
    types.add_options(
        sweep,
        ("--paper-seeds", types.bounded(0, 100), 5, "N", "also run the paper's Nelder-Mead "
         "from N seeds at the speed nearest 0.3 m/s, for every knee and criterion, for "
         "comparison.md (default 5; 0: none)"),
    )  # fmt: skip
    types.add_double_support(
        sweep,
        "also optimize at each speed and knee the gait of two phases, single then double "
        "support, its double support a share of the step from LOW to HIGH (0 <= LOW <= HIGH "
        "< 0.5; one number: that share), started from the sweep's single-support optimum of "
        "the same point: sthenic criterion only (--criteria sthenic, the default with this "
        "option), written with a summary and a figure in OUT/double-support/ "
        "(docs/gaits.md); default: single support only",
    )
    types.add_landing(sweep)
    checks.declare_rule(sweep, ("--double-support", "--criteria"), _check_sweep_double_support)


def _check_sweep_double_support(args) -> None:
    """The two-phase problem has the sthenic criterion only."""
    if args.double_support is None or not types.given(args, "criteria"):
        return
    others = [c for c in args.criteria if c != "sthenic"]
    if others:
        raise BipedError(
            f"--criteria {' '.join(args.criteria)} with --double-support: allowed sthenic "
            "(the two-phase problem's only criterion)"
        )


def cmd_figures(args) -> int:
    """PNG figures reproducing the paper's Figs. 4-8 and a comparison table (markdown)."""
    from pathlib import Path

    from biped.pages.figures import make_figures
    from biped.records import gait_file

    takes = "--sweep a folder of the gait files that biped sweep writes"
    for gait in sorted(Path(args.sweep).glob("*-*.json")):  # each its parameters' gait
        gait_file.read_consistent(gait, takes)
    for path in make_figures(args.sweep, args.out):
        print(f"wrote {path}")
    return 0


def add_figures(commands) -> None:
    fig = types.add_command(commands, "figures", "figures and table of the comparison", cmd_figures)
    fig.add_argument(
        "--sweep",
        default=DEFAULT_SWEEP,
        metavar="DIR",
        help="folder of a sweep's results, as biped sweep --out writes it (default %(default)s)",
    )
    checks.add_folder(fig, "--out", DEFAULT_FIGURES, "folder of the figures and comparison.md")


def cmd_table(args) -> int:
    """A table of optima over speed, as the one that starts every optimization (one more
    start: the optima at the neighbouring speeds, interpolated), from a sweep's certified
    final optima, as JSON. No command takes it as an option: every optimization reads the
    installed package's table, biped/optimization/optima.json of the package (this command
    prints where it is: of the source tree only with 'pip install -e .'); a table written
    elsewhere starts optimizations once it is copied there."""
    from biped.optimization.table import SHIPPED
    from biped.records.gait_file import write_json
    from biped.studies.sweep import optima_table

    content = optima_table(args.sweep)
    counts = ", ".join(
        f"{len(s['speeds'])} {s['knee']} {s['criterion']}" for s in content["series"]
    )
    path = write_json(args.out, content)
    print(f"wrote {path} ({counts} optima)")
    if path.resolve() == SHIPPED.resolve():
        print(f"optimizations start from it from now on: it is the package's table, {SHIPPED}")
    else:
        print(
            f"optimizations read the package's table, {SHIPPED}, not this file: copy it "
            "there to start them from it"
        )
    return 0


def add_table(commands) -> None:
    table = types.add_command(
        commands, "table", "a table of optima like the one that starts optimizations", cmd_table
    )
    table.add_argument(
        "--sweep",
        default=DEFAULT_SWEEP,
        metavar="DIR",
        help="folder of a sweep's results, as biped sweep --out writes it, whose certified "
        f"optima the table holds (default %(default)s); {types.CERTIFIED_HELP}",
    )
    checks.add_out(
        table,
        "--out",
        checks.FILE,
        f"the table written (JSON), {types.FOLDERS_CREATED} (default %(default)s); "
        "optimizations read the package's table alone (printed), so this file starts them "
        "once copied there",
        default="logs/optima.json",
    )


def read_gaits(paths: list, model: str | None = None, two_phase: bool = False) -> list:
    """The gait files at ``paths`` (``biped validate``, ``biped robustness``), checked before
    any work: each readable, its samples, costs and constraints its parameters', its knee
    one MuJoCo can model, and ``model`` (an MJCF path, if given) one it can be played on; a
    two-phase gait refused unless ``two_phase`` (``Gait.read``).

    Raises BipedError naming the file (and ``--model``). Returns the ``Gait`` records.
    """
    from biped.records.gait_file import Gait

    gaits = [Gait.read(path, consistent=True, two_phase=two_phase) for path in paths]
    for path, gait in zip(paths, gaits, strict=True):
        check_simulable(gait.robot, gait.knee, f"gait file {path!r}")
    if model is not None:
        from validate.scene.model import model_spec

        for path, gait in zip(paths, gaits, strict=True):
            with types.naming(f"--model, gait file {path!r}"):
                model_spec(gait.biped, model)
    return gaits


def cmd_validate(args) -> int:
    """Cross-check gait files in MuJoCo and record each for rerun.

    Checks, on the MJCF of --model (default: the committed model of the gait's knee for the
    Table 1 robot, the one generated from the gait's robot otherwise): the model is the
    gait's robot; the file's torques, ground wrench, ZMP and impact against MuJoCo's
    dynamics; each step replayed with the file's torques (the share of every joint's torque
    its servo had to add); a forward walk with contact over --steps steps (every step lands
    and advances, no fall, no slip, the stance foot flat, no scuff of the swing foot); the
    same walk at half and twice the servo stiffness; the walk's orbit stable (the spectral
    radius of its return map from step to step, plus two of its spreads, below 1: biped
    orbit, validate/checks/orbit.py). Prints a table per gait (or JSON with
    --json) and writes a rerun recording per gait (--spawn, --connect: also to a viewer), the
    report as JSON beside it (<recording>.report.json, which biped report reads) and,
    with --video, the video of the walk; exits 0 only when every check of every gait passes,
    1 otherwise. A gait file whose samples, costs, constraints or feasibility are not those
    of its parameters is refused before any work (exit 2, naming the field).
    """
    import json

    from biped.records.gait_file import write_json
    from biped_cli.progress import Progress
    from validate.outputs.outputs import report_path
    from validate.workflows import validate_and_record

    gif = _gif(args)
    gaits = read_gaits(args.gait, args.model, two_phase=True)
    recordings = _recordings(args)
    models = [_walked_model(gait, args) for gait in gaits]
    if args.timestep is not None and not args.json:
        print(
            f"MuJoCo's physics step {args.timestep:g} s (--timestep): contacts, stops and the "
            "knee coupling at two steps' time constant",
            flush=True,
        )
    if args.kp_scale != 1.0 and not args.json:
        print(f"the walks' servo stiffness × {args.kp_scale:g} (--kp-scale)", flush=True)
    reports, passed = {}, 0
    with Progress(len(args.gait), "validate") as bar:
        for path, gait, rrd, model in zip(args.gait, gaits, recordings, models, strict=True):
            bar.update(note=path)
            with types.naming(f"gait file {path!r}"):
                result, reports[path] = validate_and_record(
                    gait,
                    rrd,
                    steps=args.steps,
                    video=args.video,
                    gif=gif,
                    spawn=args.spawn,
                    connect=args.connect,
                    source=path,
                    model=model,
                    settings=_walk_settings(args),
                )
            written = write_json(report_path(rrd), reports[path].with_files(gait=path).to_dict())
            passed += result.passed
            bar.clear()
            if not args.json:
                _print_validation(path, gait, result, reports[path])
                print(f"report {written} (biped report {path} reads it)", flush=True)
            bar.advance()
    if args.json:
        content = {path: report.to_dict() for path, report in reports.items()}
        print(json.dumps(content[args.gait[0]] if len(args.gait) == 1 else content, indent=1))
    elif len(args.gait) > 1:
        print(f"{passed} of {len(args.gait)} gaits pass every check")
    return 0 if passed == len(args.gait) else 1


def _walk_settings(args):
    """The walks' gains: the validation's, the servos' stiffness × --kp-scale (None: the
    validation's own)."""
    if args.kp_scale == 1.0:
        return None
    from validate.walk.simulate import WalkSettings

    return WalkSettings(kp_scale=args.kp_scale)


def _walked_model(gait, args):
    """The model a gait is validated on: --model (a path; None: the default), at --timestep
    when given (``validate.scene.model.at_timestep``)."""
    if args.timestep is None:
        return args.model
    from validate.scene.model import at_timestep, model_spec

    return at_timestep(model_spec(gait.biped, args.model), args.timestep)


def _check_one_gait(args) -> None:
    """--rrd and --video name the output of a single gait."""
    if args.rrd and len(args.gait) > 1:
        raise BipedError(f"--rrd names one recording: allowed with one gait (got {len(args.gait)})")
    if args.video and len(args.gait) > 1:
        raise BipedError(f"--video names one video: allowed with one gait (got {len(args.gait)})")


def _check_video(args) -> None:
    """--gif writes beside the --video, an MP4."""
    if args.gif and not args.video:
        raise BipedError("--gif writes beside the --video: allowed with --video FILE.mp4")
    if args.video:
        from validate.outputs.video import check_suffix

        check_suffix(args.video, "--video", ".mp4", " (--gif writes a GIF beside it)")


def _gif(args) -> str | None:
    """The GIF's path beside the video, if asked."""
    from pathlib import Path

    return str(Path(args.video).with_suffix(".gif")) if args.gif else None


def _given_recording(args) -> list:
    """The recording --rrd names and its report beside it (none: named from the gaits)."""
    from validate.outputs.outputs import report_path

    return [args.rrd, str(report_path(args.rrd))] if args.rrd else []


def _recordings(args) -> list:
    """The recording of each gait file (--rrd, or named from the file) and its report, each
    checked free and claimed, the recording that gait file's own, before any work."""
    from pathlib import Path

    from validate.outputs.outputs import check_owner, output_name, report_path

    recordings = [
        Path(args.rrd) if args.rrd else Path(DEFAULT_RECORDINGS) / f"{output_name(path)}.rrd"
        for path in args.gait
    ]
    checks.claim_derived(args, "--rrd", recordings, "recording")
    for rrd, path in zip(recordings, args.gait, strict=True):
        check_owner(rrd, path)  # never another gait's recording
    checks.claim_derived(args, "--rrd", [report_path(rrd) for rrd in recordings], "recording")
    return recordings


def _gifs(args) -> list:
    """The GIF written beside the video, if asked (the check of --gif's output)."""
    gif = _gif(args) if args.video else None
    return [] if gif is None else [gif]


def _print_validation(path: str, gait, result, report) -> None:
    """The table of a gait's checks and the files written for it."""
    from validate.workflows import files_lines

    print(f"{path}: {gait.knee} knee, {gait.criterion}, {gait.speed} m/s")
    for check in result.checks:
        print("  " + check.line())
    for line in files_lines(report):
        print(line, flush=True)


def add_validate(commands) -> None:
    help = "cross-check a gait in MuJoCo and record it"
    val = types.add_command(commands, "validate", help, cmd_validate)
    types.add_gaits(val)
    types.add_steps(val)
    types.add_timestep(val)
    types.add_kp_scale(val)
    checks.declare_rule(val, ("--rrd", "--video"), _check_one_gait)
    checks.add_out(
        val,
        "--rrd",
        checks.FILE,
        f"recording of a single gait (default {DEFAULT_RECORDINGS}/<folder>-<gait>.rrd, "
        "named from the gait file's folder and name; another gait's recording is refused; "
        f"{types.FOLDERS_CREATED})",
        claims=checks.DERIVED,
        paths=_given_recording,
        metavar="PATH",
    )
    val.add_argument(
        "--json",
        action="store_true",
        help="print the report as JSON (several gaits: an object keyed by file)",
    )
    checks.add_out(
        val,
        "--video",
        checks.FILE,
        "also render MuJoCo's walk of a single gait to an H.264 MP4 video, a path "
        f"ending in .mp4 ({types.FOLDERS_CREATED}; MUJOCO_GL=egl without a display; default: "
        "no video)",
        metavar="FILE.mp4",
    )
    val.add_argument(
        "--gif", action="store_true", help="with --video, also an animated GIF beside it"
    )
    checks.declare_rule(val, ("--gif", "--video"), _check_video)
    checks.declare_output(val, checks.Output("--gif", checks.FILE, checks.WHOLE, paths=_gifs))
    viewer = val.add_mutually_exclusive_group()
    viewer.add_argument(
        "--spawn",
        action="store_true",
        help="also stream the recording to a rerun viewer started for it (the one on PATH, else "
        "the one installed beside this Python); a viewer that does not take it is a warning, "
        "the file and the checks stand",
    )
    viewer.add_argument(
        "--connect",
        metavar="URL",
        nargs="?",
        const="",
        default=None,
        type=types.viewer_url,
        help="also stream the recording to the rerun viewer running at URL (URL left out: its "
        "local address, rerun+http://127.0.0.1:9876/proxy; default: no stream); a viewer that "
        "does not take it is a warning, the file and the checks stand",
    )
    types.add_model(val)


def cmd_pipeline(args) -> int:
    """The whole pipeline at one walking speed, for each knee: optimal gait (as
    ``biped optimize``), validation in MuJoCo (as ``biped validate``: inverse dynamics,
    impact, forward walk with contact), its rerun recording and the video of its walk; then
    the two knees compared.

    With --double-support, also each knee's two-phase optimum (single then double support,
    as ``biped optimize --double-support``) started from its single-support optimum, written
    (<knee>-sthenic-<speed>-double-support.json), validated and recorded the same way, and
    both optima printed side by side with the knees' difference (as ``biped sweep
    --double-support``).

    Writes, per knee, the gait file and the validation report (JSON) in --out and the
    recording and the video (MP4, unless --no-video) in --recordings; prints where they are.
    Exits 0 only when every gait is certified (converged, feasible) and passes every check,
    1 otherwise, its last line naming each gait that is not and the checks that failed.
    """
    from functools import partial
    from pathlib import Path

    from biped.optimization.optimize import check_speed
    from biped_cli.design import design_problem
    from validate.outputs.outputs import check_owner
    from validate.workflows import Pipeline, run_pipeline

    robot = robot_of(args)
    family = types.gait_family(args)
    for knee in args.knees:
        check_speed(Biped(robot, knee), args.speed)
    for knee in args.knees:
        check_simulable(robot, knee, f"--robot {args.robot!r}" if args.robot else "robot")
    if args.double_support is not None:  # what the two-phase problem does not build
        from biped.optimization.problem import GaitProblem
        from biped.optimization.two_phase import TwoPhaseProblem

        for knee in args.knees:
            problem = GaitProblem(Biped(robot, knee), args.speed, args.criterion, safety(args))
            TwoPhaseProblem(problem, args.double_support, landing=args.landing)
    pipeline = Pipeline(
        robot,
        args.speed,
        tuple(args.knees),
        args.criterion,
        safety(args),
        args.steps,
        Path(args.out),
        Path(args.recordings),
        budget(args),
        video=not args.no_video,
        design=design_problem(args, robot, args.speed) if args.design else None,
        family=family,
        double_support=args.double_support,
        landing=args.landing,
    )
    for name in pipeline.names():  # never another gait's recording
        check_owner(
            pipeline.recordings / f"{name}.rrd", pipeline.out / f"{name}.json", "--recordings"
        )
    return 0 if run_pipeline(pipeline, say=partial(print, flush=True)) else 1


def _check_design_family(args) -> None:
    """--design with the paper's spline only: the knee design's family."""
    from biped.model.gait import family_label

    family = types.gait_family(args)
    if args.design and family != 1:
        raise BipedError(
            f"--design with the family {family_label(family)}: allowed with the paper's spline "
            "(--knots 1, --family spline), the knee design's"
        )


def _check_pipeline_double_support(args) -> None:
    """The two-phase problem's gait: IPOPT's, sthenic, the paper's spline, no knee design."""
    if args.double_support is None:
        return
    _check_double_support(args)
    if args.criterion != "sthenic":
        raise BipedError(
            f"--criterion {args.criterion} with --double-support: allowed sthenic (the "
            "two-phase problem's only criterion)"
        )
    if args.family != "spline" or args.knots != 1:
        given = f"--family {args.family}" if args.family != "spline" else f"--knots {args.knots}"
        raise BipedError(
            f"{given} with --double-support: allowed the paper's spline (--family spline, "
            "--knots 1), the two-phase problem's"
        )
    if args.design:
        raise BipedError(
            "--design with --double-support: allowed one of them (the two-phase problem has "
            "no knee design)"
        )


def add_pipeline(commands) -> None:
    help = "optimize, validate and record both knees at one speed"
    pipe = types.add_command(commands, "pipeline", help, cmd_pipeline)
    types.add_speed(pipe, DEFAULT_SPEED)
    types.add_knee(pipe, several=True)
    types.add_criterion(pipe)
    types.add_steps(pipe)
    checks.add_folder(pipe, "--out", DEFAULT_PIPELINE, "folder of the gait files and reports")
    what = "folder of the rerun recordings and videos"
    # its recordings are named from --out, claimed: its gait files, pages and recordings
    checks.add_folder(pipe, "--recordings", DEFAULT_RECORDINGS, what, claims=checks.WITH_ANOTHER)
    pipe.add_argument(
        "--no-video",
        action="store_true",
        help="skip the videos of the walks (<recordings>/<gait>.mp4; an earlier run's is removed)",
    )
    types.add_budget(pipe)
    types.add_knots(pipe)
    types.add_bezier(pipe)
    checks.declare_rule(pipe, ("--design", "--family", "--knots"), _check_design_family)
    types.add_robot(pipe)
    types.add_double_support(
        pipe,
        "also optimize each knee's gait of two phases, single then double support (both feet "
        "flat), started from its single-support optimum, its double support a share of the "
        "step from LOW to HIGH (0 <= LOW <= HIGH < 0.5; one number: that share), and write, "
        "validate and record it as <knee>-sthenic-<speed>-double-support: sthenic criterion, "
        "IPOPT, the paper's spline (--knots 1), no --design (docs/gaits.md); default: single "
        "support only",
    )
    types.add_landing(pipe)
    checks.declare_rule(
        pipe,
        ("--double-support", "--method", "--criterion", "--knots", "--family", "--design"),
        _check_pipeline_double_support,
    )
    pipe.add_argument(
        "--design",
        action="store_true",
        help="also optimise the rolling knee's radii with the gait, validate the designed "
        "gait and compare revolute, Table 1 radii and optimal radii in one table",
    )
