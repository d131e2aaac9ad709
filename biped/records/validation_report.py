"""The validation report of a gait in MuJoCo (``validate.checks.validation.validation_report``
makes it; ``biped validate`` and ``biped pipeline`` write it as ``<name>.report.json``,
``biped report`` reads it onto a gait's page): one ``CheckResult`` per check, each figure
with its unit, and the files the validation wrote.

One codec: ``ValidationReport.to_dict`` writes the JSON, ``ValidationReport.from_dict`` reads
it back. The JSON holds one object per check (its figures, ``passed``, ``notes``, ``causes``),
the verdict ``passed`` (every check passed), the ``units`` map (``"forward.max_slip": "m"``,
notation of ``biped.model.units``), then, where known, the ``recording``, the
``provenance``, the ``video`` paths and the ``gait`` file.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field, replace

# The keys of a report that are not checks.
FILES = ("recording", "provenance", "video", "gait")
NOT_CHECKS = ("passed", "units", *FILES)


@dataclass(frozen=True)
class CheckResult:
    """One check of a gait as its report holds it.

    ``figures``: name -> value (numbers, booleans, lists, [low, high] ranges; None: not
    measured), in the check's order; ``units``: name -> the unit of each figure that has one
    (``biped.model.units`` notation: "m", "N·m", a list for a list of mixed units);
    ``notes``: sentences that go with the verdict; ``causes``: why it fails, in words of
    ``validate.checks.checks.CAUSES`` (empty when it passes).
    """

    name: str
    passed: bool
    figures: Mapping[str, object] = field(default_factory=dict)
    units: Mapping[str, object] = field(default_factory=dict)
    notes: tuple[str, ...] = ()
    causes: tuple[str, ...] = ()

    def to_dict(self) -> dict:
        """The check's JSON object: its figures, then ``passed``, ``notes``, ``causes``."""
        return {
            **self.figures,
            "passed": bool(self.passed),
            "notes": list(self.notes),
            "causes": list(self.causes),
        }

    @classmethod
    def from_dict(cls, name: str, content: dict, units: Mapping) -> CheckResult:
        """The check ``name`` of a report's JSON; ``units``: the report's ``units`` map."""
        figures = {k: v for k, v in content.items() if k not in ("passed", "notes", "causes")}
        return cls(
            name,
            bool(content["passed"]),
            figures,
            {k: units[f"{name}.{k}"] for k in figures if f"{name}.{k}" in units},
            tuple(content.get("notes") or ()),
            tuple(content.get("causes") or ()),
        )


@dataclass(frozen=True)
class ValidationReport:
    """The checks of a gait in MuJoCo, in the order they ran, and the files written with
    them (None: not named): its ``recording`` (rerun), the ``provenance`` of the run
    (``biped.records.provenance``), its ``video`` files and the ``gait`` file validated."""

    checks: tuple[CheckResult, ...]
    recording: str | None = None
    provenance: Mapping | None = None
    video: tuple[str, ...] | None = None
    gait: str | None = None

    @property
    def passed(self) -> bool:
        """Every check passed."""
        return all(check.passed for check in self.checks)

    def check(self, name: str) -> CheckResult | None:
        """The check ``name`` (``forward``, ``orbit``...), None if it was not run."""
        return next((check for check in self.checks if check.name == name), None)

    def failed(self) -> tuple[str, ...]:
        """The names of the checks that failed, in order."""
        return tuple(check.name for check in self.checks if not check.passed)

    def with_files(self, **files) -> ValidationReport:
        """The same checks with the files of ``FILES`` given."""
        return replace(self, **files)

    def to_dict(self) -> dict:
        """The report's JSON: each check, ``passed``, ``units``, then the files known."""
        content = {check.name: check.to_dict() for check in self.checks}
        content["passed"] = self.passed
        content["units"] = {
            f"{check.name}.{name}": unit
            for check in self.checks
            for name, unit in check.units.items()
        }
        files = {
            "recording": self.recording,
            "provenance": None if self.provenance is None else dict(self.provenance),
            "video": None if self.video is None else list(self.video),
            "gait": self.gait,
        }
        content.update({key: value for key, value in files.items() if value is not None})
        return content

    @classmethod
    def from_dict(cls, content: dict) -> ValidationReport:
        """The report of its JSON (``to_dict``'s; a report from before the ``units`` map
        reads with none). ValueError if ``content`` is not a report (``is_report``) or its
        ``passed`` is not that of its checks."""
        if not is_report(content):
            raise ValueError("not a validation report: allowed an object with 'passed'")
        units = content.get("units") if isinstance(content.get("units"), dict) else {}
        checks = tuple(
            CheckResult.from_dict(name, value, units)
            for name, value in content.items()
            if name not in NOT_CHECKS and isinstance(value, dict) and "passed" in value
        )
        videos = content.get("video")
        report = cls(
            checks,
            _text(content.get("recording")),
            content.get("provenance") if isinstance(content.get("provenance"), dict) else None,
            tuple(v for v in videos if isinstance(v, str)) if isinstance(videos, list) else None,
            _text(content.get("gait")),
        )
        if report.passed != content["passed"]:
            failed = ", ".join(report.failed()) or "none"
            raise ValueError(
                f"'passed' is {str(content['passed']).lower()} but the checks that failed "
                f"are: {failed}"
            )
        return report


def _text(value) -> str | None:
    return value if isinstance(value, str) else None


def is_report(content) -> bool:
    """Whether ``content`` (a JSON value) is a validation report: an object with the verdict
    ``passed``, true or false."""
    return isinstance(content, dict) and isinstance(content.get("passed"), bool)
