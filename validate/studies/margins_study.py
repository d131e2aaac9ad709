"""How closely MuJoCo's walk follows the model as the walkable constraints tighten: the study
that chose the walkable preset (``biped.model.criteria.WALKABLE``).

For each operating point (knee, speed, clearance) and each setting of one knob (the sole's
largest landing speed as a share of the walking speed, the swing clearance, or the ZMP's
margin inside the sole), the certified sthenic optimum under that
setting is validated in MuJoCo (``validate.checks.validation.validate``, every check), and two
figures of its 20-step walk are kept: the servos' share of the joint torque
(``forward.feedback_share``: what the controller had to add to the gait's own torques) and
the energy per step MuJoCo spends against the model's (``forward.energy_per_step`` over
``analytic_energy_per_step``, less 1). The preset takes the loosest setting at which every
point's walk passes every check with both figures within their targets (``TARGETS``).

    python -m validate.studies.margins_study [--knob landing|clearance|zmp]
        [--out logs/margins] [--jobs N]

writes ``<knob>.json`` (one row per optimum, atomically) and ``<knob>.png`` (both figures
against the knob, a line per point, the targets dashed), and prints the rows.
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import sys
from dataclasses import dataclass
from pathlib import Path

from biped.errors import BipedError
from biped.model.criteria import Safety
from biped.runtime.files import atomic_write_text

# What the walk of a gait that a robot walks as computed must show (the numbers):
# the servos add at most a fifth of the joint torque, MuJoCo spends within 5 % of the model's
# energy per step.
TARGETS = {"feedback_share": 0.20, "energy_error": 0.05}
# The operating points: the paper's (0.3 m/s), a slow step over a 3 cm obstacle (two families
# of gaits there), a fast one.
POINTS = ((0.2, 0.03), (0.3, 0.0), (0.6, 0.01), (1.0, 0.0))
KNEES = ("revolute", "rolling")
# The knobs' settings, loosest first (None: unbounded, the paper's), and the other walkable
# constraints held meanwhile.
KNOBS = {
    "landing": {"values": (None, 2.0, 1.5, 1.0, 0.75, 0.5, 0.35), "unit": "× walking speed"},
    "clearance": {"values": (0.0, 0.005, 0.01, 0.02), "unit": "m"},
    "zmp": {"values": (0.0, 0.005, 0.01, 0.02), "unit": "m"},
}
STARTS = 5


@dataclass(frozen=True)
class Setting:
    """One optimum of the study: the point and the knob's value."""

    knob: str
    knee: str
    speed: float  # [m/s]
    clearance: float  # [m]
    value: float | None  # the knob's setting, in its unit; None: unbounded
    held: Safety  # the other walkable constraints

    def safety(self) -> Safety:
        if self.knob == "landing":
            return dataclasses.replace(
                self.held, clearance=self.clearance, landing_share=self.value
            )
        if self.knob == "zmp":
            return dataclasses.replace(self.held, clearance=self.clearance, zmp_margin=self.value)
        return dataclasses.replace(self.held, clearance=self.value)


def measure(setting: Setting) -> dict:
    """The optimum of ``setting`` and its walk's figures (a row of the study)."""
    import biped
    from biped.optimization.optimize import optimize
    from biped.optimization.problem import GaitProblem
    from biped.records.gait_file import Gait
    from validate.checks.validation import validate, validation_report

    robot = biped.Robot.paper()
    problem = GaitProblem(biped.Biped(robot, setting.knee), setting.speed, safety=setting.safety())
    optimum = optimize(problem, starts=STARTS)
    row = {**dataclasses.asdict(setting), "held": None, "certified": bool(optimum.certified)}
    row["criterion"] = float(optimum.value)
    if not optimum.certified:
        return {**row, "passed": False, "feedback_share": None, "energy_error": None}
    report = validation_report(validate(Gait.from_optimum(optimum, robot)).checks)
    forward = report.check("forward").figures
    modelled = forward["analytic_energy_per_step"]
    return {
        **row,
        "passed": report.passed,
        "failed": list(report.failed()),
        "feedback_share": forward["feedback_share"],
        "energy_error": forward["energy_per_step"] / modelled - 1.0,
        "touchdown_speed": report.check("impact").figures["landing_speed"],
        "swing_clearance": forward["swing_clearance"],
    }


def settings(knob: str, held: Safety) -> list[Setting]:
    if knob not in KNOBS:
        raise BipedError(f"knob = {knob!r}: allowed {', '.join(KNOBS)}")
    return [
        Setting(knob, knee, speed, clearance, value, held)
        for speed, clearance in POINTS
        for knee in KNEES
        for value in KNOBS[knob]["values"]
    ]


def _point(row: dict) -> tuple:
    return row["knee"], row["speed"], row["clearance"]


def never_walking(rows: list[dict]) -> list[tuple]:
    """The points (knee, speed, clearance) whose optimum meets the targets at no setting."""
    points = sorted({_point(r) for r in rows})
    return [p for p in points if not any(_meets(r) for r in rows if _point(r) == p)]


def chosen(rows: list[dict], knob: str):
    """The loosest setting at which every point that meets the targets at some setting meets
    them (``never_walking`` told apart), None if there is none."""
    left_out = set(never_walking(rows))
    for value in KNOBS[knob]["values"]:
        at = [r for r in rows if r["value"] == value and _point(r) not in left_out]
        if at and all(_meets(r) for r in at):
            return value
    return None


def _meets(row: dict) -> bool:
    return row["feedback_share"] is not None and bool(
        row["passed"]
        and row["feedback_share"] <= TARGETS["feedback_share"]
        and abs(row["energy_error"]) <= TARGETS["energy_error"]
    )


def figure(rows: list[dict], knob: str):
    """Both figures against the knob, a line per point and knee, the targets dashed and the
    chosen setting marked."""
    from matplotlib.figure import Figure

    from biped.pages.style import FONT_NOTE, MARGINS_SIZE

    values = KNOBS[knob]["values"]
    unit = KNOBS[knob]["unit"]
    # Unbounded drawn left of the others (a landing bound: the loosest is the largest).
    positions = {v: i for i, v in enumerate(values)}
    labels = ["none" if v is None else f"{v:g}" for v in values]
    fig = Figure(figsize=MARGINS_SIZE, layout="constrained")
    axes = fig.subplots(1, 2)
    panels = (
        ("feedback_share", "servos' share of the joint torque", 1.0),
        ("energy_error", "MuJoCo's energy per step / model's − 1 [%]", 100.0),
    )
    for ax, (name, title, scale) in zip(axes, panels, strict=True):
        for (speed, clearance), style in zip(POINTS, ("s--", "o-", "^:", "d-."), strict=True):
            for knee, colour in zip(KNEES, ("tab:orange", "tab:blue"), strict=True):
                line = sorted(
                    (
                        r
                        for r in rows
                        if (r["speed"], r["clearance"], r["knee"]) == (speed, clearance, knee)
                    ),
                    key=lambda r: positions[r["value"]],
                )
                xs = [positions[r["value"]] for r in line if r[name] is not None]
                ys = [scale * r[name] for r in line if r[name] is not None]
                ax.plot(
                    xs,
                    ys,
                    style,
                    color=colour,
                    label=f"{knee}, {speed:g} m/s, {100 * clearance:g} cm",
                )
                failed = [
                    (positions[r["value"]], scale * r[name])
                    for r in line
                    if r[name] is not None and not _meets(r)
                ]
                if failed:
                    ax.plot(*zip(*failed, strict=True), "x", color="k", ms=9, mew=1.5)
        target = scale * TARGETS[name]
        ax.axhline(target, color="k", ls="--", lw=0.8)
        if name == "energy_error":
            ax.axhline(-target, color="k", ls="--", lw=0.8)
        best = chosen(rows, knob)
        if best is not None:
            ax.axvline(positions[best], color="tab:green", lw=6, alpha=0.2)
        ax.set_xticks(range(len(values)), labels)
        what = {
            "landing": "the sole's largest landing speed",
            "clearance": "swing clearance",
            "zmp": "the ZMP's margin inside the sole",
        }[knob]
        ax.set_xlabel(f"{what} [{unit}]")
        ax.set_title(title)
        ax.grid(alpha=0.3)
    handles, labels = axes[0].get_legend_handles_labels()
    fig.legend(handles, labels, fontsize=FONT_NOTE, loc="outside lower center", ncol=4)
    fig.suptitle(
        "MuJoCo's 20-step walk of each sthenic optimum (dashed: the targets; ×: a check failed "
        "or a figure off its target; green: the preset)"
    )
    return fig


def main(argv=None) -> int:
    from biped.pages.style import save
    from biped.runtime.runner import run_tasks

    parser = argparse.ArgumentParser(
        prog="python -m validate.studies.margins_study", description=__doc__.split("\n\n")[0]
    )
    parser.add_argument("--knob", choices=tuple(KNOBS), default="landing")
    parser.add_argument("--out", default="logs/margins")
    parser.add_argument("--jobs", type=int, default=None)
    args = parser.parse_args(argv)
    from biped.model.criteria import WALKABLE

    # The preset held but for the knob (a landing share unbounded while it is varied).
    held = dataclasses.replace(WALKABLE, landing_share=None) if args.knob == "landing" else WALKABLE
    rows = list(run_tasks(measure, settings(args.knob, held), jobs=args.jobs, stream=None))
    order = KNOBS[args.knob]["values"]
    rows.sort(key=lambda r: (r["speed"], r["knee"], order.index(r["value"])))
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    record = {
        "knob": args.knob,
        "targets": TARGETS,
        "chosen": chosen(rows, args.knob),
        "never_walking": never_walking(rows),
        "rows": rows,
    }
    atomic_write_text(out / f"{args.knob}.json", json.dumps(record, indent=1))
    save(figure(rows, args.knob), out / f"{args.knob}.png")
    for r in rows:
        print(
            f"{r['knee']:8} {r['speed']:.2f} m/s {100 * r['clearance']:g} cm  {args.knob} "
            f"{r['value']}: C = {r['criterion']:.4g}, passed {r['passed']}, share "
            f"{r['feedback_share']}, energy error {r['energy_error']}"
        )
    written = ", ".join(str(out / f"{args.knob}.{suffix}") for suffix in ("json", "png"))
    never = ", ".join(f"{k} {v:g} m/s {100 * c:g} cm" for k, v, c in record["never_walking"])
    print(f"chosen: {record['chosen']} (meeting the targets at no setting: {never or 'none'})")
    print(f"wrote {written}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
