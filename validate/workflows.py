"""Workflows: a gait from the optimizer to its file, to MuJoCo, to its recording and video.

``validate_and_record``: every check of one gait (``validate.checks.validation``), its
recording (``validate.outputs.record``) claimed by its gait file (``validate.outputs.outputs``),
its video and report.
``run_pipeline``: ``biped pipeline`` whole, each knee's optimal gait at one speed written,
validated and recorded, the knee's radii optimised too with a design problem, the knees
compared; it prints (``say``) as it goes. The command line checks the input before; nothing
here parses options. May import ``biped`` and ``validate``, never ``biped_cli``.
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
):
    """Every check of a gait on ``model`` (an MJCF path; None: ``validate.scene.model.model_spec``'s
    default), its recording at ``rrd`` (also streamed to a viewer with ``spawn`` or
    ``connect``) and, if asked, the video of its walk at ``video`` (MP4) and ``gif``.
    ``source``: the gait file, named as the recording's owner (``validate.outputs.outputs``).

    Returns the validation and its report (``biped.records.validation_report``: the checks
    with their units, the recording's and video's paths).
    """
    from biped.records.provenance import provenance
    from validate.checks import validation
    from validate.outputs.outputs import claim
    from validate.outputs.record import record

    result = validation.validate(gait, steps=steps, model=model)
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
    (``biped.optimization.design``), named ``design-<criterion>-<speed>``.
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

    def name(self, knee: str) -> str:
        """The name of a knee's files ('design' for the designed gait)."""
        return f"{knee}-{self.criterion}-{self.speed:.3f}"

    def validated(self, label: str, gait_path: Path, gait: Gait, say: Callable) -> tuple:
        """Validate the gait written at ``gait_path`` (``gait``: its record) as the
        pipeline's ``label`` knee; write its report. Returns (passed, its lines of the files
        written)."""
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
        return result.passed, files_lines(report, gait_path, report_path)


def run_pipeline(pipeline: Pipeline, say: Callable[[str], None] = print) -> bool:
    """Run the pipeline (``Pipeline``), printing with ``say``; whether every gait is feasible
    and passes every check."""
    from biped.optimization.knees import compare_knees, knee_lines

    passed, optima, written = True, {}, {}
    for knee in pipeline.knees:
        optima[knee] = optimum = _optimum(pipeline, knee, optima, say)
        if not _certified(knee, optimum, say):
            passed = False
            continue
        gait = Gait.from_optimum(optimum, pipeline.robot)
        gait_path = gait.write(pipeline.out / f"{pipeline.name(knee)}.json")
        # validated in memory: the file written is this record
        knee_passed, written[knee] = pipeline.validated(knee, gait_path, gait, say)
        passed = passed and knee_passed
    if pipeline.design is not None:
        passed = _design_stage(pipeline, optima, say) and passed
    if len(written) == 2:  # both knees' optima certified: each cost, its uncertainty, verdict
        say("[knees] re-solving both optima on a finer grid and more tightly...")
        differences = compare_knees({knee: optima[knee] for knee in written})
        for line in knee_lines(differences, pipeline.speed, pipeline.criterion):
            say(line)
    for knee, lines in written.items():  # every file written, once
        for line in lines:
            say(f"{knee:9} {line}")
    say("all checks passed" if passed else "some checks FAILED")
    return passed


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
    passed, lines = pipeline.validated("design", gait_path, gait, say)  # in memory, as the knees
    for line in lines:  # every file written, once
        say(f"[design] {line}")
    return passed and not comparison.uncertified()
