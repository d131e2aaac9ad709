"""``biped report GAIT.json ... [--out DIR]``: one Markdown page per gait file, with figures.

The page (``biped.pages.page``) is named from the gait file's path as its recording is
(``validate.outputs.outputs``). Its validation is the report beside the gait file,
``<gait>.report.json`` (``biped pipeline`` writes it), else the one ``biped validate`` writes
beside the gait's default recording, when that recording is the gait's as it is now; its
links are the recording and videos that report names, or the
recording ``biped validate`` writes by default, each only if it exists and was made from this
gait file as it is now.
"""

from __future__ import annotations

import json
from pathlib import Path

from biped.errors import BipedError
from biped_cli import checks
from biped_cli.args import add_command, add_gaits
from biped_cli.commands import DEFAULT_RECORDINGS

DEFAULT_REPORTS = "logs/reports"


def validation_path(gait_path: str | Path) -> Path:
    """The validation report beside a gait file: ``<name>.report.json``."""
    gait_path = Path(gait_path)
    return gait_path.with_name(f"{gait_path.stem}.report.json")


def validation_file(gait_path: str | Path) -> Path | None:
    """A gait file's validation report: the one beside it (``validation_path``, the
    pipeline's), else the one ``biped validate`` writes beside the gait's default recording
    when that recording was made from the gait file as it is now; None without either."""
    from validate.outputs.outputs import belongs_to, output_name, report_path

    beside = validation_path(gait_path)
    if beside.exists():
        return beside
    recording = Path(DEFAULT_RECORDINGS) / f"{output_name(gait_path)}.rrd"
    found = report_path(recording)
    return found if found.exists() and belongs_to(recording, gait_path) else None


def read_validation(path: Path | None):
    """A validation report (``biped.records.validation_report.ValidationReport``), None if
    there is none; BipedError if it is not one. A report from before the ``units`` map gets
    the units of ``validate.checks.units``."""
    from dataclasses import replace

    from biped.records.validation_report import ValidationReport, is_report
    from validate.checks.units import figure_units

    if path is None or not path.exists():
        return None
    try:
        content = json.loads(path.read_text(encoding="utf-8"))
    except (OSError, ValueError) as error:
        raise BipedError(f"validation report {str(path)!r} cannot be read: {error}") from None
    if not is_report(content):
        raise BipedError(
            f"validation report {str(path)!r} is not one: allowed the JSON of 'biped validate "
            "--json' (with 'passed')"
        )
    try:
        report = ValidationReport.from_dict(content)
    except ValueError as error:
        raise BipedError(f"validation report {str(path)!r} is not one: {error}") from None
    if isinstance(content.get("units"), dict):
        return report
    checks = tuple(replace(c, units=figure_units(c.name, c.figures)) for c in report.checks)
    return replace(report, checks=checks)


def links(gait_path: Path, validation) -> list:
    """The recording and videos of a gait that exist and were made from it as it is now."""
    from biped.pages.page import Link
    from validate.outputs.outputs import belongs_to, open_command, output_name

    found = []
    recording = None if validation is None else validation.recording
    if recording is None:
        recording = str(Path(DEFAULT_RECORDINGS) / f"{output_name(gait_path)}.rrd")
    videos = () if validation is None else validation.video or ()
    recording = Path(recording)
    if recording.exists():
        owned = belongs_to(recording, gait_path)
        if owned is None:
            found.append(Link("recording", recording, "no owner record: gait unchecked"))
        elif owned:
            found.append(Link("recording", recording, f"open with: {open_command(recording)}"))
        owned_videos = owned is not False
    else:
        owned_videos = True  # a video named by the report, the recording gone
    for video in videos:
        if Path(video).exists() and owned_videos:
            found.append(Link(f"video ({Path(video).suffix[1:]})", Path(video)))
    return found


def cmd_report(args) -> int:
    """Write one Markdown page per gait file into --out, with its figures: the parameters by
    name, the criteria, the ligament load each knee needs (N, in stance and in swing) and the
    tightest margin of each constraint (where in the step), the torques, angles, ground
    reaction and constraints over the step; the verdict and figures of its validation in
    MuJoCo when <gait>.report.json lies beside it (biped pipeline's) or beside its recording
    (biped validate's, if the recording is of the gait as it is now); links to its recording
    and video. A two-phase gait's page shows both phases over the whole step, the landing,
    both feet, beside the single support gait of the same knee, robot and speed given with it.
    All pages are written, or none.
    """
    from biped.pages.page import Page, write_pages
    from biped.pages.two_phase_page import single_of
    from biped.records import gait_file
    from validate.outputs.outputs import output_name

    pages = []
    for path in args.gait:  # every input read and checked before any work
        gait = gait_file.read_consistent(path, two_phase=True)  # its figures its parameters'
        found = validation_file(path)
        validation = read_validation(found)
        pages.append(
            Page(
                name=output_name(path),
                source=Path(path),
                gait=gait,
                validation=validation,
                validation_source=found if validation is not None else None,
                links=links(Path(path), validation),
            )
        )
    gaits = [page.gait for page in pages]
    for page in pages:  # a two-phase gait beside the single support optimum given with it
        if page.gait.two_phase:
            page.single = single_of(page.gait, gaits)
    names = [page.name for page in pages]
    checks.claim_derived(args, "--out", names, "page", gaits="gait files")
    for written in write_pages(pages, args.out):
        print(f"wrote {written}")
    return 0


def add_parser(commands) -> None:
    parser = add_command(commands, "report", "one Markdown page per gait, with figures", cmd_report)
    add_gaits(parser)
    what = "folder of the pages and their figures"
    checks.add_folder(parser, "--out", DEFAULT_REPORTS, what, claims=checks.DERIVED)
