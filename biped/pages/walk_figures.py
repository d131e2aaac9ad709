"""MuJoCo's walk beside the model's, drawn from a validation report's JSON (``validate``: its
``forward`` and ``feedforward`` objects, the figures ``validate.checks.checks.walk_figures`` and
``check_feedforward`` measure).

    walk_lines        the page's section: per joint the RMS torque of the model (the gait's
                      Γ), of MuJoCo's walk (its motors and servos) and of the servos' part,
                      the servo torque the replay of one step needed against the robot's
                      torque scale; the ground force's error over the weight, the energy per
                      step of both and their ratio
    torques_figure    the model's torques over one step beside MuJoCo's (the mean over the
                      steps walked) and the servos' part, one panel per joint

A figure the report lacks (a report written before it) or could not measure (null) is n/a,
never 0.
"""

from __future__ import annotations

import numpy as np
from matplotlib.figure import Figure

from biped.model.dynamics import JOINTS
from biped.pages.figures import TIME_AXIS, bulk_limits, joint_label, note
from biped.pages.style import FONT_TITLE, WALK_TORQUES_SIZE
from biped.records.validation_report import ValidationReport

# The page's figure of the torques over one step.
TORQUES_FIGURE = "walk_torques.png"
MODEL_STYLE = dict(color="k", linewidth=1.6, label="model: the gait's Γ")
MUJOCO_STYLE = dict(color="tab:orange", linewidth=1.4, label="MuJoCo: motors + servos")
ROTOR_STYLE = dict(color="tab:green", linewidth=1.0, linestyle=":", label="its rotors' part")
SERVO_STYLE = dict(color="tab:purple", linewidth=1.0, linestyle="--", label="its servos' part")
STYLES = (MODEL_STYLE, MUJOCO_STYLE, ROTOR_STYLE, SERVO_STYLE)
# Per joint figures of the forward check (lists in ``JOINTS`` order), as ``STYLES``.
PER_JOINT = ("gait_torque_rms", "mujoco_torque_rms", "rotor_torque_rms", "servo_torque_rms")
PROFILES = (
    "gait_torque_profile",
    "mujoco_torque_profile",
    "rotor_torque_profile",
    "servo_torque_profile",
)


def _value(value, digits: int = 3) -> str:
    """A number, or n/a for one not measured (null) or absent."""
    if value is None or not isinstance(value, (int, float)) or not np.isfinite(value):
        return "n/a"
    return f"{value:.{digits}g}"


def _joint(values, j: int):
    """The ``j``-th entry of a per-joint list of the report, None if absent."""
    return values[j] if isinstance(values, list) and len(values) == len(JOINTS) else None


def _over(a, b):
    """a / b, None where either is unknown or b is 0."""
    if not all(isinstance(v, (int, float)) and np.isfinite(v) for v in (a, b)) or b == 0:
        return None
    return a / b


def _figures(report: ValidationReport | None, check: str) -> dict:
    """The figures of ``report``'s check ``check`` ({} without it)."""
    found = None if report is None else report.check(check)
    return {} if found is None else dict(found.figures)


def has_walk(report: ValidationReport | None) -> bool:
    """Whether ``report`` holds the forward check's per-joint figures."""
    forward = _figures(report, "forward")
    return all(name in forward for name in PER_JOINT)


def walk_lines(report: ValidationReport, figure: str | None = None) -> list[str]:
    """The page's section of MuJoCo's walk beside the model's (``has_walk``: none without
    it); ``figure``: the link to ``torques_figure``'s file."""
    if not has_walk(report):
        return []
    forward, replay = _figures(report, "forward"), _figures(report, "feedforward")
    steps = forward.get("steps")
    lines = [
        "### MuJoCo's walk beside the model's",
        "",
        f"The forward check's walk ({_value(steps)} steps walked, each landing's settling "
        "left out of the RMS: `validate.checks.checks.LANDING`): per joint the RMS torque of the "
        "model (the gait's Γ at the phase MuJoCo's controller followed), of MuJoCo (its "
        "motors and its servos), of the rotors' part (the motors less Γ: MuJoCo's armature, "
        "which the paper's robot lacks) and of the servos' part; and the servo "
        "torque the replay of one step with the gait's torques needed (the feedforward "
        "check), against the robot's torque scale "
        f"({_value(replay.get('torque_scale'))} N·m, its largest joint's RMS torque).",
        "",
        "| joint | model [N·m] | MuJoCo [N·m] | rotors [N·m] | servos [N·m] | "
        "servos / MuJoCo | replay's servo [N·m] | replay's servo / torque scale |",
        "|---|---|---|---|---|---|---|---|",
    ]
    for j, joint in enumerate(JOINTS):
        model, mujoco, rotor, servo = (_joint(forward[name], j) for name in PER_JOINT)
        cells = [
            _value(model),
            _value(mujoco),
            _value(rotor),
            _value(servo),
            _value(_over(servo, mujoco), 2),
            _value(replay.get(f"feedback_rms_{joint}"), 2),
            _value(replay.get(f"feedback_ratio_{joint}"), 2),
        ]
        lines += [f"| {joint_label(j, joint)} | {' | '.join(cells)} |"]
    energy, model_energy = forward.get("energy_per_step"), forward.get("analytic_energy_per_step")
    lines += [
        "",
        "| figure | model | MuJoCo | MuJoCo / model | unit |",
        "|---|---|---|---|---|",
        f"| energy per step, ∫ Σ \\|Γ θ̇\\| dt | {_value(model_energy)} | {_value(energy)} | "
        f"{_value(forward.get('energy_ratio'))} | J |",
        f"| ground force (Fx, Fz), RMS error over the weight | | "
        f"{_value(forward.get('ground_force_rms_error'))} | | weight |",
        f"| centre of pressure against the ZMP, RMS error | | "
        f"{_value(forward.get('zmp_rms_error'))} | | m |",
        f"| the servos' share of all torques | | {_value(forward.get('feedback_share'))} | | 1 |",
        "",
    ]
    if figure is not None:
        lines += [
            "The model's torques over one step beside MuJoCo's (the mean over the steps "
            "walked, at the phase its controller followed), and its rotors' and servos' "
            "parts: the landing's soft impact at the start of the step (shaded, out of the "
            "RMS) is MuJoCo's alone, the model's being an instant; MuJoCo's peaks beyond a "
            "panel are marked at its edge with their values.",
            "",
            f"![MuJoCo's torques beside the model's]({figure})",
            "",
        ]
    return lines


def has_profiles(report: ValidationReport | None) -> bool:
    """Whether ``report``'s forward check holds the torque profiles ``torques_figure`` draws."""
    forward = _figures(report, "forward")
    return all(name in forward for name in ("profile_phase", *PROFILES))


def _array(rows) -> np.ndarray:
    """A profile of the report as floats, null (not measured) as NaN."""
    return np.array([[np.nan if v is None else v for v in row] for row in rows], dtype=float)


def torques_figure(forward: dict, title: str) -> Figure:
    """The torque profiles of the forward check's figures (``forward``), one panel per
    joint: the model's, MuJoCo's, its rotors' and its servos' [N·m] over t/T; each panel
    spans the model and the bulk of MuJoCo's after the landing window (``bulk_limits``),
    MuJoCo's peaks beyond it (the landing's) marked at its edge with their values."""
    phase = np.array(forward["profile_phase"], dtype=float)
    curves = [_array(forward[name]) for name in PROFILES]
    landing = forward.get("landing_window")
    landing = float(landing) if isinstance(landing, (int, float)) else 0.0
    after = phase >= landing
    figure = Figure(figsize=WALK_TORQUES_SIZE, layout="constrained")
    axes = figure.subplots(2, 3).ravel()
    for j, (ax, joint) in enumerate(zip(axes, JOINTS, strict=True)):
        ax.axhline(0.0, color="0.8", linewidth=0.8, zorder=0)
        if landing > 0.0:
            ax.axvspan(0.0, landing, color="0.92", zorder=0, label="landing (out of the RMS)")
        for values, style in zip(curves, STYLES, strict=True):
            ax.plot(phase, values[:, j], **style)
        # The panel spans the model over the step and MuJoCo after the landing window.
        shown = np.concatenate([curves[0][:, j], *(values[after, j] for values in curves[1:])])
        low, high = bulk_limits(shown[np.isfinite(shown)])
        ax.set_ylim(low, high)
        offset = 0
        for values, style in zip(curves[1:], STYLES[1:], strict=True):
            beyond = np.flatnonzero(np.isfinite(values[:, j]))
            beyond = beyond[(values[beyond, j] > high) | (values[beyond, j] < low)]
            if beyond.size:  # the peak of this curve beyond the panel, at its edge
                k = beyond[np.argmax(np.abs(values[beyond, j]))]
                up = values[k, j] > high
                edge = high if up else low
                ax.plot(
                    [phase[k]],
                    [edge],
                    marker="^" if up else "v",
                    color=style["color"],
                    linestyle="none",
                    clip_on=False,
                )
                place = (8, -12 - offset) if up else (8, 4 + offset)
                text = f"{'landing ' * (not after[k])}{values[k, j]:.3g} N·m"
                note(ax, text, (phase[k], edge), place, color=style["color"])
                offset += 11
        ax.set_xlim(0.0, 1.0)
        ax.set_title(joint_label(j, joint))
        ax.set_xlabel(TIME_AXIS)
        ax.set_ylabel("torque [N·m]")
        ax.grid(alpha=0.3)
    handles, labels = axes[0].get_legend_handles_labels()
    figure.legend(
        handles, labels, loc="outside lower center", ncols=len(labels), fontsize=FONT_TITLE
    )
    steps = forward.get("steps")
    figure.suptitle(
        f"{title}: the model's joint torques beside MuJoCo's over one step (the mean over "
        f"{steps} steps walked)"
    )
    return figure
