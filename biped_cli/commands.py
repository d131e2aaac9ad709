"""The subcommands of ``biped``: one function per job, each returning the exit status.

Errors in the input raise ``BipedError`` (one line on stderr, exit status 2).
"""

from __future__ import annotations

import sys

import numpy as np

from biped.errors import BipedError, UnreachableError
from biped.model.criteria import CRITERIA
from biped.model.dynamics import JOINTS, Biped
from biped.model.kinematics import KNEES
from biped.model.robot import Robot
from biped.records.provenance import provenance
from biped_cli.args import budget, check_folder, check_output, safety

DEFAULT_SWEEP = "logs/sweep"
DEFAULT_FIGURES = "logs/figures"
DEFAULT_RECORDINGS = "logs/recordings"
DEFAULT_PIPELINE = "logs/pipeline"
DEFAULT_SPEED = 0.3  # [m/s] the walking speed of the pipeline


def _robot(path: str | None) -> Robot:
    return Robot.paper() if path is None else Robot.from_file(path)


def check_simulable(robot: Robot, knee: str, source: str) -> None:
    """Fail before any work if MuJoCo cannot model the robot's knee (``validate.mjcf``: the
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
    robot = _robot(args.robot)
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


def optimum_line(knee: str, criterion: str, speed: float, optimum) -> str:
    """An optimum in three lines: its step; both criteria on the check grid (``costs`` in
    its gait file, what the comparisons use); its criterion on the solver's samples
    (``optimizer.value``, what ranked the starts; left out for a result without it)."""
    from biped.records.comparison import (
        CHECK_SAMPLES_PER_STEP,
        NELDER_MEAD_SAMPLES_PER_STEP,
        SOLVER_SAMPLES_PER_STEP,
    )
    from biped.records.units import CRITERION_UNITS

    ev = optimum.evaluation
    lines = [
        f"{knee} knee, {criterion}-optimal gait at {speed} m/s: period "
        f"{optimum.step.period:.4f} s, step {optimum.step.step_length:.4f} m",
        f"  costs, on the check grid ({CHECK_SAMPLES_PER_STEP} samples per step; the "
        f"comparisons use them): sthenic {ev.sthenic:.6g} N²·m·s, energy {ev.energy:.6g} J",
    ]
    samples = (
        f"{SOLVER_SAMPLES_PER_STEP} per step; it ranks the starts"
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
    from biped.optimization.optimize import optimize
    from biped.optimization.problem import GaitProblem
    from biped.records import gait_file

    robot = _robot(args.robot)
    problem = GaitProblem(Biped(robot, args.knee), args.speed, args.criterion, safety(args))
    check_output(args.out)
    print(f"optimizing {problem.describe()} ({args.method}, seed {args.seed})...", file=sys.stderr)
    optimum = optimize(problem, **budget(args))
    ev = optimum.evaluation
    print(optimum_line(args.knee, args.criterion, args.speed, optimum))
    report = optimum.report
    print(report.summary())
    if report.converged and report.method == "ipopt" and not report.confirmed:
        print(
            "warning: the best value was reached by a single start; more --starts may "
            "find a better optimum",
            file=sys.stderr,
        )
    if not report.converged:
        message = f"biped optimize: the solver did not converge ({report.method}: {report.status})"
        if optimum.feasible:
            path = gait_file.write_json(args.out, gait_file.to_dict(optimum, robot, args.seed))
            message += f"; {path} is written but is not a certified optimum"
        else:
            worst = ", ".join(f"{k} = {v:.3g}" for k, v in ev.violations().items())
            message += f"; the result is infeasible (Ψ < 0: {worst}), no file written"
        print(message, file=sys.stderr)
        return 1
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
    """Optimal gaits over a range of speeds, both knees and both criteria, on all cores
    (or on a Dask cluster with --dask tcp://HOST:PORT).

    Each optimization is saved as it completes; run the same command again to resume.
    Progress on stderr, with the time elapsed and an estimate of the time left: a bar on a
    terminal, else a line at most every 10 s.
    """
    from biped.runtime.runner import check_dask
    from biped.studies.paper_method import FOLDER, SETTINGS, check_paper_method, run_paper_method
    from biped.studies.paper_method import SPEED as PAPER_METHOD_SPEED
    from biped.studies.sweep import INDEPENDENT, MANIFEST, run_sweep
    from biped_cli.progress import Progress

    robot = _robot(args.robot)
    check_folder(args.out, "--out")
    # at the sweep's speed nearest the paper's optima
    paper_speed = float(min(args.speeds, key=lambda v: abs(v - PAPER_METHOD_SPEED)))
    if args.paper_seeds:  # refused before the sweep runs, not after
        check_paper_method(args.out, robot, paper_speed, args.paper_seeds, args.knees, safety(args))
    if args.dask is not None:
        check_dask(args.dask)
    points = run_sweep(
        args.out,
        robot,
        args.speeds,
        args.knees,
        args.criteria,
        seed=args.seed,
        starts=args.starts,
        safety=safety(args),
        jobs=args.jobs,
        dask=args.dask,
        progress=lambda total: Progress(total, "sweep"),
    )
    runs = []
    if args.paper_seeds:
        runs = run_paper_method(
            args.out,
            robot,
            speed=paper_speed,
            seeds=args.paper_seeds,
            knees=args.knees,
            criteria=args.criteria,
            safety=safety(args),
            jobs=args.jobs,
            dask=args.dask,
            progress=lambda total: Progress(total, "paper's method"),
        )

    def files(n: int) -> str:
        return f"{n} gait file{'' if n == 1 else 's'}"

    paper = f", {FOLDER}/ ({SETTINGS} and {files(len(runs))})" if runs else ""
    print(  # the folder's files, once: a file per optimization is too many to name
        f"sweep results in {args.out}: {MANIFEST}, {files(len(points))} "
        f"<knee>-<criterion>-<speed>.json, {INDEPENDENT}/ (each point's first solve){paper}"
    )
    return 0


def cmd_figures(args) -> int:
    """PNG figures reproducing the paper's Figs. 4-8 and a comparison table (markdown)."""
    from pathlib import Path

    from biped.pages.figures import make_figures
    from biped.records import gait_file

    check_folder(args.out, "--out")
    takes = "--sweep a folder of the gait files that biped sweep writes"
    for gait in sorted(Path(args.sweep).glob("*-*.json")):  # each its parameters' gait
        gait_file.read_consistent(gait, takes)
    for path in make_figures(args.sweep, args.out):
        print(f"wrote {path}")
    return 0


def _validate_and_record(
    gait: dict,
    steps: int,
    rrd,
    video=None,
    gif=None,
    spawn=False,
    connect=None,
    source=None,
    model=None,
):
    """Every check of a gait (``gait_file.read`` or ``gait_file.to_dict``: in memory) on
    ``model`` (an MJCF path; None: ``validate.model.model_spec``'s default), its recording at
    ``rrd`` (also streamed to a viewer with ``spawn`` or ``connect``) and, if asked, the video
    of its walk at ``video`` (MP4) and ``gif``. ``source``: the gait file, named as the
    recording's owner (``biped_cli.outputs``).

    Returns the validation and its report (the checks as JSON with their ``units``, the
    recording's and video's paths).
    """
    from biped_cli.outputs import claim
    from validate.record import record
    from validate.report import as_json, validate
    from validate.units import report_units

    result = validate(gait, steps=steps, model=model)
    written = record(
        rrd,
        result.biped,
        result.step,
        result.simulation,
        result.contact,
        result.checks,
        gait,
        spawn=spawn,
        connect=connect,
    )
    if source is not None:
        claim(written, source)
    checks = as_json(result.checks)
    report = {
        **checks,
        "units": report_units(checks),
        "recording": str(written),
        "provenance": provenance(),
    }
    if video is not None or gif is not None:
        from validate.video import write_video

        files = write_video(
            video, result.biped, result.step, result.simulation, result.checks, gif=gif
        )
        report["video"] = [str(path) for path in files]
    return result, report


def read_gaits(paths: list, model: str | None = None) -> list[dict]:
    """The gait files at ``paths`` (``biped validate``, ``biped robustness``), checked before
    any work: each readable, its samples, costs and constraints its parameters', its knee
    one MuJoCo can model, and ``model`` (an MJCF path, if given) one it can be played on.

    Raises BipedError naming the file (and ``--model``).
    """
    from biped.records import gait_file

    gaits = [gait_file.read_consistent(path) for path in paths]
    for path, gait in zip(paths, gaits, strict=True):
        check_simulable(gait["robot"], gait["knee"], f"gait file {path!r}")
    if model is not None:
        from validate.model import model_spec
        from validate.samples import gait_biped

        for path, gait in zip(paths, gaits, strict=True):
            try:
                model_spec(gait, gait_biped(gait), model)
            except BipedError as error:
                raise BipedError(f"--model, gait file {path!r}: {error}") from None
    return gaits


def cmd_validate(args) -> int:
    """Cross-check gait files in MuJoCo and record each for rerun.

    Checks, on the MJCF of --model (default: the committed model of the gait's knee for the
    Table 1 robot, the one generated from the gait's robot otherwise): the model is the
    gait's robot; the file's torques, ground wrench, ZMP and impact against MuJoCo's
    dynamics; each step replayed with the file's torques (the share of every joint's torque
    its servo had to add); a forward walk with contact over --steps steps (every step lands
    and advances, no fall, no slip, the stance foot flat, no scuff of the swing foot); the
    same walk at half and twice the servo stiffness. Prints a table per gait (or JSON with
    --json) and writes a rerun recording per gait (--spawn, --connect: also to a viewer) and,
    with --video, the video of the walk; exits 0 only when every check of every gait passes,
    1 otherwise. A gait file whose samples, costs, constraints or feasibility are not those
    of its parameters is refused before any work (exit 2, naming the field).
    """
    import json
    from pathlib import Path

    from biped_cli.outputs import check_owner, output_name, recording_lines
    from biped_cli.progress import Progress

    if args.rrd and len(args.gait) > 1:
        raise BipedError(f"--rrd names one recording: allowed with one gait (got {len(args.gait)})")
    if args.video and len(args.gait) > 1:
        raise BipedError(f"--video names one video: allowed with one gait (got {len(args.gait)})")
    if args.gif and not args.video:
        raise BipedError("--gif writes beside the --video: allowed with --video FILE.mp4")
    if args.video:
        from validate.video import check_suffix

        check_suffix(args.video, "--video", ".mp4", " (--gif writes a GIF beside it)")
        check_output(args.video, "--video")
    gif = str(Path(args.video).with_suffix(".gif")) if args.gif else None
    gaits = read_gaits(args.gait, args.model)
    recordings = [
        Path(args.rrd) if args.rrd else Path(DEFAULT_RECORDINGS) / f"{output_name(path)}.rrd"
        for path in args.gait
    ]
    duplicated = {str(p) for p in recordings if recordings.count(p) > 1}
    if duplicated:
        raise BipedError(
            f"gait files in folders of the same name would share the recording "
            f"{sorted(duplicated)[0]!r}: allowed gait files of distinct folder or file names"
        )
    for rrd, path in zip(recordings, args.gait, strict=True):
        check_output(str(rrd), "--rrd")
        check_owner(rrd, path)  # never another gait's recording
    reports, passed = {}, 0
    with Progress(len(args.gait), "validate") as bar:
        for path, gait, rrd in zip(args.gait, gaits, recordings, strict=True):
            bar.update(note=path)
            try:
                result, reports[path] = _validate_and_record(
                    gait,
                    args.steps,
                    rrd,
                    args.video,
                    gif,
                    args.spawn,
                    args.connect,
                    path,
                    args.model,
                )
            except BipedError as error:
                raise BipedError(f"gait file {path!r}: {error}") from None
            written = reports[path]["recording"]
            passed += result.passed
            bar.clear()
            if not args.json:
                print(f"{path}: {gait['knee']} knee, {gait['criterion']}, {gait['speed']} m/s")
                for check in result.checks:
                    print("  " + check.line())
                for line in recording_lines(written):
                    print(line, flush=True)
                for video in reports[path].get("video", []):
                    print(f"video {video}", flush=True)
            bar.advance()
    if args.json:
        print(json.dumps(reports[args.gait[0]] if len(args.gait) == 1 else reports, indent=1))
    elif len(args.gait) > 1:
        print(f"{passed} of {len(args.gait)} gaits pass every check")
    return 0 if passed == len(args.gait) else 1


def cmd_pipeline(args) -> int:
    """The whole pipeline at one walking speed, for each knee: optimal gait (as
    ``biped optimize``), validation in MuJoCo (as ``biped validate``: inverse dynamics,
    impact, forward walk with contact), its rerun recording and the video of its walk; then
    the two knees compared.

    Writes, per knee, the gait file and the validation report (JSON) in --out and the
    recording and the video (MP4, unless --no-video) in --recordings; prints where they are.
    Exits 0 only when every gait is feasible and passes every check, 1 otherwise.
    """
    from pathlib import Path

    from biped.optimization.optimize import check_speed, optimize
    from biped.optimization.problem import GaitProblem
    from biped.records import gait_file
    from biped.records.comparison import DIFFERENCE, relative_change
    from biped_cli.outputs import check_owner, recording_lines

    robot = _robot(args.robot)
    out, recordings = Path(args.out), Path(args.recordings)
    for knee in args.knees:
        check_speed(Biped(robot, knee), args.speed)
    for knee in args.knees:
        check_simulable(robot, knee, f"--robot {args.robot!r}" if args.robot else "robot")
    check_folder(args.out, "--out")
    check_folder(args.recordings, "--recordings")
    for knee in args.knees:  # never another gait's recording
        name = f"{knee}-{args.criterion}-{args.speed:.3f}"
        check_owner(recordings / f"{name}.rrd", out / f"{name}.json", "--recordings")
    passed, costs, written, optima = True, {}, [], {}
    for knee in args.knees:
        name = f"{knee}-{args.criterion}-{args.speed:.3f}"
        print(f"[{knee}] optimizing at {args.speed} m/s ({args.criterion})...", flush=True)
        problem = GaitProblem(Biped(robot, knee), args.speed, args.criterion, safety(args))
        given = [o.variables for o in optima.values() if np.all(np.isfinite(o.variables))]
        optimum = optimize(problem, given=given, **budget(args))
        optima[knee] = optimum
        ev = optimum.evaluation
        print(
            f"[{knee}] sthenic {ev.sthenic:.4g} N²·m·s, energy {ev.energy:.4g} J, period "
            f"{optimum.step.period:.4f} s, step {optimum.step.step_length:.4f} m "
            f"({optimum.seconds:.1f} s)"
        )
        print(f"[{knee}] {optimum.report.summary()}")
        if not optimum.report.converged:
            print(f"[{knee}] FAIL  the solver did not converge: {optimum.report.status}")
            passed = False
            continue
        if not optimum.feasible:
            worst = ", ".join(f"{k} = {v:.3g}" for k, v in ev.violations().items())
            print(f"[{knee}] FAIL  optimum infeasible: {worst}")
            passed = False
            continue
        costs[knee] = optimum.costs()
        gait = gait_file.to_dict(optimum, robot, seed=args.seed)
        gait_path = gait_file.write_json(out / f"{name}.json", gait)
        print(f"[{knee}] validating {args.steps} steps in MuJoCo...", flush=True)
        video = None if args.no_video else recordings / f"{name}.mp4"
        result, report = _validate_and_record(
            gait,  # in memory: the file written is this content
            args.steps,
            recordings / f"{name}.rrd",
            video,
            source=gait_path,
        )
        for check in result.checks:
            print(f"[{knee}]   " + check.line())
        report_path = gait_file.write_json(
            out / f"{name}.report.json", {**report, "gait": str(gait_path)}
        )
        written.append((knee, gait_path, report_path, report))
        passed = passed and result.passed
    if getattr(args, "design", False):  # --design: the knee radii optimised too
        from biped_cli.design import pipeline_design

        passed = pipeline_design(args, robot, optima, out, recordings) and passed
    if len(costs) == 2:
        revolute, rolling = costs["revolute"], costs["rolling"]
        changes = ", ".join(
            f"{criterion} {relative_change(rolling[criterion], revolute[criterion]):+.1f} %"
            for criterion in CRITERIA
        )
        print(f"rolling vs revolute knee, {args.criterion}-optimal gaits: {changes} ({DIFFERENCE})")
    for knee, gait_path, report_path, report in written:  # every file written, once
        print(f"{knee:9} gait {gait_path}, report {report_path}")
        for line in recording_lines(report["recording"]):
            print(f"{knee:9} {line}")
        for video in report.get("video", []):
            print(f"{knee:9} video {video}")
    print("all checks passed" if passed else "some checks FAILED")
    return 0 if passed else 1
