"""Workflows: a gait from the optimizer to its file, to MuJoCo, to its recording and video.

``validate_and_record``: every check of one gait (``validate.checks.validation``), its
recording (``validate.outputs.record``) claimed by its gait file (``validate.outputs.outputs``),
its video and report.
``run_pipeline``: ``biped pipeline`` whole, each knee's optimal gait at one speed written,
validated and recorded, with double support each knee's two-phase optimum too (started from
it, ``biped.records.two_phase_file.solve``), the knee's radii optimised too with a design
problem, the knees compared; it prints (``say``) as it goes. The command line checks the
input before; nothing here parses options. May import ``biped`` and ``validate``, never
``biped_cli``.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from biped.model.criteria import Safety
from biped.model.robot import Robot
from biped.records.gait_file import Gait, write_json
from biped.records.validation_report import ValidationReport


def validate_and_record(
    gait: Gait,
    rrd: str | Path,
    *,
    steps: int,
    video: str | Path | None = None,
    gif: str | Path | None = None,
    spawn: bool = False,
    connect: str | None = None,
    source: str | Path | None = None,
    model=None,
    settings=None,
):
    """Every check of a gait on ``model`` (an MJCF path; None: ``validate.scene.model.model_spec``'s
    default), its recording at ``rrd`` (also streamed to a viewer with ``spawn`` or
    ``connect``) and, if asked, the video of its walk at ``video`` (MP4) and ``gif``.
    ``source``: the gait file, named as the recording's owner (``validate.outputs.outputs``);
    ``settings``: the walks' gains (``validate.walk.simulate.WalkSettings``; None: the
    validation's).

    Returns the validation and its report (``biped.records.validation_report``: the checks
    with their units, the recording's and video's paths).
    """
    from biped.records.provenance import provenance
    from validate.checks import checks, validation
    from validate.outputs.outputs import claim
    from validate.outputs.record import record

    walk = checks.WALK if settings is None else settings
    result = validation.validate(gait, steps=steps, model=model, settings=walk)
    written = record(rrd, result, spawn=spawn, connect=connect)
    if source is not None:
        claim(written, source)
    report = validation.validation_report(result.checks).with_files(
        recording=str(written), provenance=provenance()
    )
    if video is not None or gif is not None:
        from validate.outputs import video as videos

        paths = videos.write_video(video, result, gif=gif)
        report = report.with_files(video=tuple(str(path) for path in paths))
    return result, report


def files_lines(
    report: ValidationReport, gait_path: Path | None = None, report_path=None
) -> list[str]:
    """What a workflow prints of the files it wrote for a gait: the gait file and its
    report (if given), the recording (and its owner record), the videos."""
    from validate.outputs.outputs import recording_lines

    return [
        *([f"gait {gait_path}, report {report_path}"] if gait_path is not None else []),
        *(
            recording_lines(report.recording)
            if report.recording is not None
            else ["no recording (the recording of a two-phase walk is not built)"]
        ),
        *(f"video {video}" for video in report.video or ()),
    ]


@dataclass(frozen=True)
class Pipeline:
    """What ``biped pipeline`` runs: the optimal gait of each knee at one speed, validated.

    Gait files and reports go to ``out``, recordings and videos to ``recordings``, each
    named ``<knee>-<criterion>-<speed>``; ``design``: also the knee's radii optimised
    (``biped.optimization.design``), named ``design-<criterion>-<speed>``;
    ``double_support``: also each knee's two-phase optimum (single then double support,
    ``biped.optimization.two_phase``) with that share range and ``landing``, named
    ``<knee>-<criterion>-<speed>-double-support`` (``two_phase_name``).
    """

    robot: Robot
    speed: float  # [m/s]
    knees: tuple
    criterion: str
    safety: Safety
    steps: int  # steps walked in MuJoCo
    out: Path
    recordings: Path
    budget: dict  # ``optimize``'s keyword arguments: seed, starts, method...
    video: bool = True  # an MP4 of each walk
    design: object = None  # a ``biped.optimization.design.DesignProblem``, or None
    # the gaits' family (``biped.model.gait``): a spline's interior knots, or a ``Bezier``
    family: object = 1
    # (least, largest) T_ds / (T + T_ds) [1] of the two-phase optima; None: single support only
    double_support: tuple | None = None
    landing: str = "impact"  # of the two-phase optima (``biped.model.two_phase.LANDINGS``)

    def name(self, knee: str) -> str:
        """The name of a knee's files ('design' for the designed gait)."""
        return f"{knee}-{self.criterion}-{self.speed:.3f}"

    def two_phase_name(self, knee: str) -> str:
        """The name of a knee's two-phase gait's files."""
        return f"{self.name(knee)}-double-support"

    def names(self) -> list[str]:
        """The names of the knees' files, two-phase gaits' included."""
        two = self.double_support is not None
        return [self.name(k) for k in self.knees] + [
            self.two_phase_name(k) for k in self.knees if two
        ]

    def validated(self, label: str, gait_path: Path, gait: Gait, say: Callable) -> tuple:
        """Validate the gait written at ``gait_path`` (``gait``: its record) as the
        pipeline's ``label`` gait; write its report. Returns (the names of the checks it
        failed, its lines of the files written)."""
        name = gait_path.stem
        say(f"[{label}] validating {self.steps} steps in MuJoCo...")
        video = self.recordings / f"{name}.mp4" if self.video else None
        stale = self.recordings / f"{name}.mp4"
        if video is None and stale.is_file():  # an earlier run's, beside the new recording
            stale.unlink()
            say(f"[{label}] removed {stale}, an earlier run's video (no video this run)")
        rrd = self.recordings / f"{name}.rrd"
        result, report = validate_and_record(
            gait, rrd, steps=self.steps, video=video, source=gait_path
        )
        for check in result.checks:
            say(f"[{label}]   " + check.line())
        report_path = write_json(
            self.out / f"{name}.report.json", report.with_files(gait=str(gait_path)).to_dict()
        )
        failed = tuple(check.name for check in result.checks if not check.passed)
        return failed, files_lines(report, gait_path, report_path)


def run_pipeline(pipeline: Pipeline, say: Callable[[str], None] = print) -> bool:
    """Run the pipeline (``Pipeline``), printing with ``say``; whether every gait is certified
    and passes every check (the last line names each gait that is not, or its checks that
    failed)."""
    from biped.optimization.knees import compare_knees, knee_lines

    failures, optima, written, two_phase = [], {}, {}, {}
    for knee in pipeline.knees:
        optima[knee] = optimum = _optimum(pipeline, knee, optima, say)
        if not _certified(knee, optimum, say):
            failures.append(f"{knee}: not certified")
            continue
        gait = Gait.from_optimum(optimum, pipeline.robot)
        gait_path = gait.write(pipeline.out / f"{pipeline.name(knee)}.json")
        # validated in memory: the file written is this record
        failed, written[knee] = pipeline.validated(knee, gait_path, gait, say)
        failures += [f"{knee}: {', '.join(failed)}"] if failed else []
    if pipeline.double_support is not None:  # each knee's, from its optimum just found
        for knee in pipeline.knees:
            two_phase[knee] = _two_phase_stage(pipeline, knee, optima[knee], failures, say)
    if pipeline.design is not None and not _design_stage(pipeline, optima, say):
        failures.append("design")
    if len(written) == 2:  # both knees' optima certified: each cost, its uncertainty, verdict
        say("[knees] re-solving both optima on a finer grid and more tightly...")
        differences = compare_knees({knee: optima[knee] for knee in written})
        for line in knee_lines(differences, pipeline.speed, pipeline.criterion):
            say(line)
    if two_phase:
        for line in _two_phase_table(pipeline, optima, two_phase).splitlines():
            say(f"[double support] {line}")
    for knee, lines in written.items():  # every file written, once
        for line in lines:
            say(f"{knee:9} {line}")
    for knee, (_, lines) in two_phase.items():
        for line in lines:
            say(f"{knee:9} {line}")
    say("some checks FAILED: " + "; ".join(failures) if failures else "all checks passed")
    return not failures


def _two_phase_stage(pipeline: Pipeline, knee: str, optimum, failures: list, say: Callable):
    """The knee's two-phase optimum from its single-support ``optimum``, written and
    validated as the single-support gaits are; a failure appended to ``failures``. Returns
    (the two-phase gait, None: none; its lines of the files written)."""
    from biped.optimization.two_phase import TwoPhaseProblem
    from biped.records import two_phase_file

    label = f"{knee} two phases"
    if not optimum.certified:
        say(f"[{label}] FAIL  not solved: its start, the single-support optimum, is not certified")
        failures.append(f"{label}: not solved")
        return None, []
    low, high = pipeline.double_support
    say(
        f"[{label}] optimizing single then double support ({low:g} to {high:g} of the step, "
        f"{pipeline.landing} landing)..."
    )
    two = TwoPhaseProblem(optimum.problem, pipeline.double_support, landing=pipeline.landing)
    seed, starts = pipeline.budget["seed"], pipeline.budget["starts"]
    solved = two_phase_file.solve(two, optimum.variables, optimum.value, starts, seed)
    say(f"[{label}] setup {solved.setup_seconds:.1f} s, solves {solved.result.seconds:.1f} s")
    if solved.gait is None:
        say(f"[{label}] FAIL  {solved.failure()}")
        failures.append(f"{label}: no optimum")
        return None, []
    say(f"[{label}] {solved.line(optimum.value)}")
    gait_path = solved.gait.write(pipeline.out / f"{pipeline.two_phase_name(knee)}.json")
    failed, lines = pipeline.validated(label, gait_path, solved.gait, say)  # in memory
    failures += [f"{label}: {', '.join(failed)}"] if failed else []
    return solved.gait, lines


def _two_phase_table(pipeline: Pipeline, optima: dict, two_phase: dict) -> str:
    """Each knee's single-support and two-phase optima side by side and, with both knees,
    the knees' difference with and without double support (as ``biped sweep
    --double-support`` prints them: ``TwoPhaseSweepSummary.table``)."""
    from biped.records.two_phase_sweep import PointSummary, TwoPhaseSweepSummary
    from biped.studies.two_phase_sweep import differences, phases_of

    rows = []
    for knee, (gait, _) in two_phase.items():
        optimum = optima[knee]
        single = Gait.from_optimum(optimum, pipeline.robot) if optimum.certified else None
        why = "" if gait else "no two-phase optimum" if single else "single support not certified"
        rows.append(
            PointSummary(knee, pipeline.speed, phases_of(single, False), phases_of(gait, True), why)
        )
    summary = TwoPhaseSweepSummary(
        pipeline.double_support, pipeline.landing, tuple(rows), differences(rows)
    )
    return summary.table()


def _optimum(pipeline: Pipeline, knee: str, optima: dict, say: Callable):
    """The knee's optimal gait, also started from the optima of the knees before it."""
    from biped.model.dynamics import Biped
    from biped.optimization.optimize import confirm, optimize
    from biped.optimization.problem import GaitProblem

    say(f"[{knee}] optimizing at {pipeline.speed} m/s ({pipeline.criterion})...")
    model = Biped(pipeline.robot, knee)
    problem = GaitProblem(
        model, pipeline.speed, pipeline.criterion, pipeline.safety, knots=pipeline.family
    )
    given = [o.variables for o in optima.values() if np.all(np.isfinite(o.variables))]
    optimum = confirm(problem, optimize(problem, given=given, **pipeline.budget), given)
    ev = optimum.evaluation
    say(
        f"[{knee}] sthenic {ev.sthenic:.4g} N²·m·s, energy {ev.energy:.4g} J, period "
        f"{optimum.step.period:.4f} s, step {optimum.step.step_length:.4f} m "
        f"({optimum.seconds:.1f} s)"
    )
    say(f"[{knee}] {optimum.report.summary()}")
    return optimum


def _certified(knee: str, optimum, say: Callable) -> bool:
    """Whether the optimum converged and is feasible; says why not."""
    if not optimum.report.converged:
        say(f"[{knee}] FAIL  the solver did not converge: {optimum.report.status}")
        return False
    if not optimum.feasible:
        say(f"[{knee}] FAIL  optimum infeasible: {optimum.evaluation.violations_line()}")
        return False
    return True


def _design_stage(pipeline: Pipeline, optima: dict, say: Callable) -> bool:
    """The radii optimised at the pipeline's speed, the table of the revolute knee, the
    Table 1 radii and the optimal radii (the pipeline's own optima where certified), and the
    designed gait written and validated in MuJoCo as the knees' are. Returns whether every
    step passed."""
    from biped.optimization.design import bound_notes, compare
    from validate.outputs.outputs import check_owner

    problem, name = pipeline.design, pipeline.name("design")
    rrd, gait_path = pipeline.recordings / f"{name}.rrd", pipeline.out / f"{name}.json"
    check_owner(rrd, gait_path, "--recordings")
    say(f"[design] optimizing the knee radii at {pipeline.speed} m/s ({pipeline.criterion})...")
    given = {
        label: optima[knee] if knee in optima and optima[knee].certified else None
        for label, knee in (("revolute", "revolute"), ("reference", "rolling"))
    }
    seed, starts = pipeline.budget["seed"], pipeline.budget["starts"]
    comparison = compare(problem, seed=seed, starts=starts, **given)
    design = comparison.design
    for line in comparison.table().splitlines() + bound_notes(problem, design):
        say(f"[design] {line}")
    say(f"[design] {comparison.radii_line()}")
    say(f"[design] {design.report.summary()}")
    if not design.certified:
        say(f"[design] FAIL  the design is not certified: {design.report.status}")
        return False
    gait = Gait.from_design(comparison)
    gait.write(gait_path)
    failed, lines = pipeline.validated("design", gait_path, gait, say)  # in memory, as the knees
    for line in lines:  # every file written, once
        say(f"[design] {line}")
    return not failed and not comparison.uncertified()
