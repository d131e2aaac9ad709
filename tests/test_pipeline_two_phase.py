"""``biped pipeline --double-support``: each knee's two-phase optimum, started from its
single-support optimum, written, validated in MuJoCo and recorded as the single-support gait
is, both printed side by side, and the exit status the verdict of every gait's checks.

The physics of the two-phase walk is not asserted here (whether its checks pass): what the
pipeline does with it is.
"""

import dataclasses
import json
from pathlib import Path
from types import SimpleNamespace

import pytest

from biped.model.criteria import PAPER_SAFETY
from biped.model.robot import Robot
from biped.records import two_phase_file
from biped.records.gait_file import Gait
from biped.records.validation_report import ValidationReport
from biped_cli import main
from validate import workflows
from validate.checks.checks import Check

SHARE = (0.1, 0.4)  # [1] the double support's share of the step
LANDING = "zero-speed"
NAME = "rolling-sthenic-0.300"
TWO_PHASE_NAME = f"{NAME}-double-support"
# The MuJoCo checks of a two-phase gait (``validate.checks.validation.two_phase_checks``).
CHECKS = ("model", "inverse_dynamics", "knee_loads", "impact", "feedforward", "forward", "gains")


def _pipeline(folder: Path) -> workflows.Pipeline:
    """The rolling knee at 0.3 m/s with double support, one start, 2 steps, no video."""
    return workflows.Pipeline(
        Robot.paper(), 0.3, ("rolling",), "sthenic", PAPER_SAFETY, 2, folder / "out",
        folder / "recordings", {"seed": 0, "starts": 1, "method": "ipopt"}, video=False,
        double_support=SHARE, landing=LANDING,
    )  # fmt: skip


@pytest.fixture(scope="module")
def run(tmp_path_factory):
    """The pipeline run once; its single-support optimum and two-phase solve kept."""
    folder = tmp_path_factory.mktemp("pipeline")
    kept = {}
    solve, optimum = two_phase_file.solve, workflows._optimum

    def keep(name, function):
        return lambda *args: kept.setdefault(name, function(*args))

    said = []
    with pytest.MonkeyPatch.context() as patch:
        patch.setattr(two_phase_file, "solve", keep("solve", solve))
        patch.setattr(workflows, "_optimum", keep("optimum", optimum))
        passed = workflows.run_pipeline(_pipeline(folder), said.append)
    out = folder / "out"
    return SimpleNamespace(
        out=out, recordings=folder / "recordings", said=said, passed=passed, **kept
    )


def _report(run, name: str) -> dict:
    return json.loads((run.out / f"{name}.report.json").read_text())


def test_the_two_phase_gait_is_written_validated_and_recorded(run):
    """The two-phase gait file reads back consistent (its figures its parameters'), of the
    knee, speed, share range and landing asked; its report lists every MuJoCo check of a
    two-phase walk (at most the steps asked walked) and names the file and its recording, claimed by it."""
    path = run.out / f"{TWO_PHASE_NAME}.json"
    gait = Gait.read(path, two_phase=True, consistent=True)
    double = gait.double_support
    assert gait.knee == "rolling" and gait.speed == 0.3 and double.landing == LANDING
    # the share within its bounds, to IPOPT's constraint tolerance on the scaled bound
    assert tuple(double.share_range) == SHARE
    assert SHARE[0] - 1e-8 <= double.share <= SHARE[1] + 1e-8, double.share
    assert gait.optimizer.status == "converged"
    report = _report(run, TWO_PHASE_NAME)
    assert all(name in report for name in (*CHECKS, "orbit")), sorted(report)
    assert 1 <= report["forward"]["steps"] <= 2 and report["gait"] == str(path)
    recording = run.recordings / f"{TWO_PHASE_NAME}.rrd"
    assert report["recording"] == str(recording) and recording.stat().st_size > 0
    owner = json.loads(Path(f"{recording}.source.json").read_text())
    assert str(path) in json.dumps(owner)
    assert any(str(recording) in line for line in run.said)


def test_the_comparison_shows_both_optima_of_the_files(run):
    """The line comparing the knee's optima prints the single-support file's C_Γ beside the
    two-phase file's, over the step."""
    single = Gait.read(run.out / f"{NAME}.json")
    double = Gait.read(run.out / f"{TWO_PHASE_NAME}.json", two_phase=True).double_support
    costs = f"{single.costs.sthenic:10.4f} / {double.sthenic:10.4f}"
    [line] = [line for line in run.said if line.startswith("[double support]") and costs in line]
    assert " rolling " in line and f"{double.share:.3f}" in line


def test_the_verdict_is_every_checks(run):
    """The pipeline passes only when both gaits' reports pass; its last line names each
    failed check of each gait."""
    reports = {label: _report(run, name) for label, name in (
        ("rolling", NAME), ("rolling two phases", TWO_PHASE_NAME)
    )}  # fmt: skip
    assert run.passed == all(report["passed"] for report in reports.values())
    last = run.said[-1]
    if run.passed:
        assert last == "all checks passed"
        return
    assert last.startswith("some checks FAILED: ")
    for label, report in reports.items():
        failed = [name for name in (*CHECKS, "orbit") if not report[name]["passed"]]
        assert not failed or f"{label}: {', '.join(failed)}" in last


def _validated(failing: str | None):
    """A stand-in for ``validate_and_record``: the two-phase gait fails the check named
    ``failing`` (None: every gait passes)."""

    def validated(gait, rrd, *, steps, video, source):
        Path(rrd).parent.mkdir(parents=True, exist_ok=True)
        Path(rrd).write_bytes(b"a recording")
        failed = gait.two_phase and failing is not None
        checks = [Check(failing if failed else "model", not failed, {})]
        return SimpleNamespace(checks=checks, passed=not failed), ValidationReport(
            checks=(), recording=str(rrd)
        )

    return validated


def _none(solved):
    """``solved`` with no start converged to a feasible optimum."""
    result = dataclasses.replace(solved.result, best=None, checked=None, feasible=0, at_best=0)
    return dataclasses.replace(solved, result=result, gait=None)


@pytest.mark.parametrize(
    "failing, no_optimum, code, last",
    [
        (None, False, 0, "all checks passed"),
        ("orbit", False, 1, "some checks FAILED: rolling two phases: orbit"),
        (None, True, 1, "some checks FAILED: rolling two phases: no optimum"),
    ],
)
def test_the_exit_status_is_the_verdict(
    run, tmp_path, monkeypatch, capsys, failing, no_optimum, code, last
):
    """biped pipeline --double-support exits 0 when every gait passes; 1, naming it, when
    the two-phase gait fails a check or has no optimum (said as a FAIL, never skipped)."""
    solved = _none(run.solve) if no_optimum else run.solve
    monkeypatch.setattr(workflows, "_optimum", lambda *args: run.optimum)
    monkeypatch.setattr(two_phase_file, "solve", lambda *args: solved)
    monkeypatch.setattr(workflows, "validate_and_record", _validated(failing))
    argv = ["pipeline", "--knees", "rolling", "--double-support", "0.1:0.4", "--landing"]
    argv += [LANDING, "--steps", "2", "--starts", "1", "--no-video"]
    assert main(argv + ["--out", str(tmp_path / "o"), "--recordings", str(tmp_path / "r")]) == code
    printed = capsys.readouterr().out.splitlines()
    assert printed[-1] == last
    written = (tmp_path / "o" / f"{TWO_PHASE_NAME}.json").exists()
    assert written != no_optimum
    if no_optimum:
        assert any("[rolling two phases] FAIL  no two-phase optimum" in line for line in printed)
