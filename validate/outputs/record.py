"""Rerun recordings of a validation: MuJoCo's walk in 3D beside the gait's ghost, the torques
joint by joint, the ground reaction and a summary of the gait and its checks.

Entity paths, on the timeline ``time`` (seconds of simulation):

    world/ground                          the floor (a thin slab) and lines every 0.5 m
    world/mujoco/<body>                   pose of each body of MuJoCo's robot (Transform3D)
    world/mujoco/<body>/geometry          its geoms in the body's frame, in the model's colours
                                          (Capsules3D, Boxes3D, Cylinders3D: the knee discs)
    world/analytic/<body>[/geometry]      the gait at the phase the controller followed, drawn
                                          the same way as a pale ghost ``GHOST_OFFSET`` behind
    world/contact/force                   MuJoCo's ground reaction on the stance foot, an arrow
                                          from the centre of pressure (``ARROW_SCALE`` m per N)
    world/contact/zmp                     the gait's ZMP, a point on the stance sole
    torques/Γ<i>_<joint>/analytic         the gait's torque Γ_i [N·m]
    torques/Γ<i>_<joint>/mujoco           MuJoCo's: feedforward + feedback
    torques/Γ<i>_<joint>/feedforward      MuJoCo's motor (the gait's torque at the phase)
    torques/Γ<i>_<joint>/feedback         MuJoCo's servos
    torques/Γ<i>_<joint>/landing          marks the landing windows (first 10 % of each step)
    ground/{Fx,Fz}/{analytic,mujoco}      ground reaction on the stance foot [N]
    zmp/{analytic,mujoco,heel,toe}        ZMP, centre of pressure and the foot's ends, from the
                                          stance ankle [m]
    phase                                 the gait's time the controller follows, over T
    feet/{Fx,Fz}/{stance,swing}_{analytic,mujoco}
                                          a two-phase walk's ground force on each foot of
                                          the step [N]: the stance foot (the rear one in
                                          double support) and the swing foot (the front
                                          one once landed), the gait's beside MuJoCo's
    support/{analytic,mujoco}             a two-phase walk's feet on the floor, 1 (single
                                          support) or 2 (double support)
    summary                               the gait's parameters, criteria and every check
    orbit/{unit_circle,radius,band,axes}  the complex plane of the orbit check's multipliers:
    orbit/multipliers                     the unit circle, ρ and ρ ± 2 spreads, the
                                          multipliers μ (y up: Im μ; ``validate.checks.orbit``)
    torque_key                            the torque plots' series in words (their legend)

``blueprint()`` lays them out: the 3D view following the robot, one plot per joint with its
y range fixed to the bulk of the gait's torques (the landings' spikes run off it rather than
flatten it), Fx and Fz in plots of their own (ranged the same way), the ZMP, the phase and
the summary, and the multipliers in the complex plane; a two-phase walk adds each foot's Fx
and Fz and the supports below them. The time plots open on the last
``SHOWN_STEPS`` steps (zoom out for the whole walk); every series of a plot has a colour of
its own, and where two run together the gait's (widest) shows around MuJoCo's feedforward
and MuJoCo's torque (narrowest) drawn over them.
A legend in a plot has room of its own above the curves; the torques' legend would be taller
than their plots and is a key in words beside them (``torque_key``).
"""

from __future__ import annotations

import shutil
import socket
import sys
import warnings
from pathlib import Path
from urllib.parse import urlsplit

import mujoco
import numpy as np
import rerun as rr
import rerun.blueprint as rrb

from biped.errors import ViewerWarning
from biped.model.dynamics import JOINTS, Biped
from biped.model.robot import SOLE_EDGES
from biped.records.gait_file import Gait
from biped.runtime.files import atomic_path
from validate.checks.checks import LANDING
from validate.checks.units import PROFILES
from validate.scene.mapping import mapping
from validate.scene.mjcf import HIP_OFFSET, SIDES
from validate.walk.contact import SAMPLE_EVERY
from validate.walk.samples import GaitSamples
from validate.walk.simulate import Simulation, reference_along

FRAME_EVERY = 20  # draw the robots every 20 simulation steps (50 Hz)
APPLICATION = "biped_validation"
# rerun's viewer, and the address ``connect_grpc`` streams to when given none.
VIEWER = "rerun"
DEFAULT_VIEWER = "rerun+http://127.0.0.1:9876/proxy"
# Longest wait [s] for a viewer (--spawn, --connect) to take the recording.
VIEWER_TIMEOUT = 10.0
# Longest wait [s] for --connect's address to accept a connection before streaming: where
# nothing listens, rerun's own connection waits 5 s, its flush more and its disconnect 5 s.
PROBE_TIMEOUT = 2.0
# Series colours, the same in every plot (RGB), and line widths [UI points]: the gait's
# widest, so that it shows around the series drawn over it where they run together.
ANALYTIC_COLOR = (80, 140, 230)
MUJOCO_COLOR = (230, 120, 60)
FEEDFORWARD_COLOR = (70, 170, 90)
FEEDBACK_COLOR = (200, 60, 160)
LANDING_COLOR = (150, 150, 150)
# A two-phase walk's swing (front) foot: the gait's and MuJoCo's.
SWING_ANALYTIC_COLOR = (150, 110, 220)
SWING_MUJOCO_COLOR = (230, 200, 60)
SOLE_COLORS = {"heel": (120, 120, 120), "toe": (215, 215, 215)}  # the ZMP plot's sole edges
ANALYTIC_WIDTH = 7.0
FEEDFORWARD_WIDTH = 3.0
MUJOCO_WIDTH = 1.5
FEEDBACK_WIDTH = 1.5
EDGE_WIDTH = 1.0
# Range of the multipliers' view, both axes, and its colours (RGB): axes, unit circle, ρ,
# ρ ± 2 spreads, the multipliers (light on the viewer's dark background).
ORBIT_BOUNDS = (-1.25, 1.25)
ORBIT_AXES, ORBIT_UNIT, ORBIT_RADIUS = (120, 120, 120), (235, 235, 235), (244, 162, 97)
ORBIT_BAND, ORBIT_POINTS = (42, 157, 143), (233, 196, 106)
# The time plots open on the last SHOWN_STEPS steps of the walk.
SHOWN_STEPS = 2
# Room above the curves of a plot with a legend (ground reaction, ZMP), a fraction of their
# range; the torque plots' key is a text of its own (``TORQUE_KEY``).
LEGEND_ROOM = 0.9
# The gait's ghost: pale and translucent (RGBA), this far behind MuJoCo's robot (+y) [m].
GHOST_COLOR = (235, 235, 245, 110)
GHOST_OFFSET = 0.35
FORCE_COLOR = (220, 40, 40)
ZMP_COLOR = (30, 200, 230)
GROUND_COLOR = (120, 122, 128)
# Length of the ground-reaction arrow per newton [m/N]: the weight (687 N) is 0.69 m.
ARROW_SCALE = 1e-3
# The torque plots show the gait's torques away from the landings, widened by this fraction
# of their span on each side, and at least this span [N·m].
TORQUE_MARGIN = 0.25
TORQUE_MIN_SPAN = 2.0
# The torque plots' key, in words: their legend is taller than a plot.
TORQUE_KEY = f"""\
Last {SHOWN_STEPS} steps (zoom out: the walk)

- **blue**, widest: the gait
- **green**: feedforward (the gait)
- **orange**, thin: MuJoCo (ff + fb)
- **magenta**: feedback (servos)
- **grey** squares: landings
"""


def torque_series_path(i: int, joint: str) -> str:
    return f"torques/Γ{i + 1}_{joint}"


def torque_range(analytic: np.ndarray, steady: np.ndarray) -> tuple[float, float]:
    """y range [N·m] of a torque plot: the gait's torque away from the landings (``steady``),
    widened by ``TORQUE_MARGIN`` of its span each side, at least ``TORQUE_MIN_SPAN`` wide."""
    values = analytic[steady] if np.any(steady) else analytic
    low, high = float(values.min()), float(values.max())
    pad = max(TORQUE_MARGIN * (high - low), (TORQUE_MIN_SPAN - (high - low)) / 2, 0.0)
    return low - pad, high + pad


def with_legend_room(low: float, high: float) -> tuple[float, float]:
    """A plot's y range with ``LEGEND_ROOM`` of it added on top, where its legend goes."""
    return low, high + LEGEND_ROOM * (high - low)


def blueprint(
    ranges: dict | None = None, window: tuple | None = None, feet: bool = False
) -> rrb.Blueprint:
    """The 3D walk above the ground reaction (Fx, Fz), ZMP and phase (with ``feet``, a
    two-phase walk's: each foot's Fx and Fz and the supports below them); one plot per
    joint's torque (no legend: too tall for a plot, it would cover the curves) above their
    key, in words, and the summary.

    Args:
        ranges: y range (low, high) of a plot, by its origin (a torque's path, ``ground/Fx``,
            ``zmp``); a plot with a legend gets ``LEGEND_ROOM`` on top of it.
        window: the time plots' x range at first, (start, end) [s]; None: the whole walk.
    """
    ranges = ranges or {}

    def axis_x(span):
        if span is None:
            return None
        start, end = (rrb.TimeRangeBoundary.absolute(seconds=float(t)) for t in span)
        return rrb.TimeAxis(view_range=rr.encodings.TimeRange(start, end), zoom_lock=False)

    def plot(origin, name, legend=True):
        span = ranges.get(origin)
        if span is not None and legend:
            span = with_legend_room(*span)
        return rrb.TimeSeriesView(
            origin=origin,
            name=name,
            plot_legend=rrb.PlotLegend(corner=rrb.Corner2D.LeftTop, visible=legend),
            axis_x=axis_x(window),
            axis_y=rrb.ScalarAxis(range=span, zoom_lock=False),
        )

    torque_views = [
        plot(torque_series_path(i, joint), f"Γ{i + 1} {joint.replace('_', ' ')} [N·m]", False)
        for i, joint in enumerate(JOINTS)
    ]
    key = rrb.TextDocumentView(origin="torque_key", name="torque plots [N·m]")
    ground = [
        rrb.Horizontal(
            plot("ground/Fx", "ground Fx [N]"),
            plot("ground/Fz", "ground Fz [N]"),
            plot("zmp", "ZMP, CoP [m]"),
            rrb.TimeSeriesView(origin="phase", name="phase [T]"),
        )
    ]
    if feet:
        ground.append(
            rrb.Horizontal(
                plot("feet/Fx", "each foot's Fx [N]"),
                plot("feet/Fz", "each foot's Fz [N]"),
                rrb.TimeSeriesView(origin="support", name="feet on the floor [1]"),
            )
        )
    return rrb.Blueprint(
        rrb.Horizontal(
            rrb.Vertical(
                rrb.Spatial3DView(
                    origin="world",
                    name="MuJoCo's walk, the gait's ghost behind",
                    eye_controls=rrb.EyeControls3D(
                        position=(0.6, -3.2, 1.3),
                        look_target=(0.6, 0.0, 0.8),
                        eye_up=(0.0, 0.0, 1.0),
                        tracking_entity="world/mujoco/trunk",
                    ),
                ),
                *ground,
                row_shares=[2] + [1] * len(ground),
            ),
            rrb.Vertical(
                rrb.Grid(*torque_views, grid_columns=2),
                rrb.Horizontal(
                    key,
                    rrb.TextDocumentView(origin="summary", name="gait and checks"),
                    rrb.Spatial2DView(
                        origin="orbit",
                        name="Floquet multipliers μ (Re, Im) [1]",
                        visual_bounds=rrb.VisualBounds2D(
                            x_range=ORBIT_BOUNDS, y_range=ORBIT_BOUNDS
                        ),
                    ),
                    column_shares=[1, 1, 1.4],
                ),
                row_shares=[2.4, 1],
            ),
            column_shares=[3, 2],
        ),
        collapse_panels=True,
    )


def _xyzw(wxyz: np.ndarray) -> np.ndarray:
    """MuJoCo's quaternions (w, x, y, z) in rerun's order (x, y, z, w)."""
    return np.asarray(wxyz)[..., [1, 2, 3, 0]]


def _rgba(model: mujoco.MjModel, geom: int) -> np.ndarray:
    matid = model.geom_matid[geom]
    rgba = model.mat_rgba[matid] if matid >= 0 else model.geom_rgba[geom]
    return np.round(255 * np.asarray(rgba)).astype(np.uint8)


# The rerun archetype of each kind of visual geom (MuJoCo's geom type), with its options.
ARCHETYPES = {
    int(mujoco.mjtGeom.mjGEOM_CAPSULE): (rr.Capsules3D, {}),
    int(mujoco.mjtGeom.mjGEOM_BOX): (rr.Boxes3D, {"fill_mode": "solid"}),
    int(mujoco.mjtGeom.mjGEOM_CYLINDER): (rr.Cylinders3D, {"fill_mode": "solid"}),
}


def _shape(model: mujoco.MjModel, g: int) -> dict:
    """A capsule, box or cylinder geom's fields of its archetype, in its body's frame (a
    capsule from the end of its axis, as rerun draws it)."""
    kind, size, pos = model.geom_type[g], model.geom_size[g], model.geom_pos[g]
    if kind == mujoco.mjtGeom.mjGEOM_BOX:
        return {"centers": pos, "half_sizes": size[:3]}
    if kind == mujoco.mjtGeom.mjGEOM_CYLINDER:
        return {"centers": pos, "radii": size[0], "lengths": 2 * size[1]}
    rotation = np.zeros(9)
    mujoco.mju_quat2Mat(rotation, model.geom_quat[g])
    base = pos - rotation.reshape(3, 3) @ [0.0, 0.0, size[1]]
    return {"translations": base, "radii": size[0], "lengths": 2 * size[1]}


def visual_geoms(model: mujoco.MjModel, color=None) -> dict:
    """Body name -> its visual geoms (group 2) as rerun archetypes in the body's frame, in
    the model's colours or all in ``color`` (RGBA)."""
    shapes: dict = {}
    for g in range(model.ngeom):
        body = model.geom_bodyid[g]
        if model.geom_group[g] != 2 or body == 0:
            continue
        entry = shapes.setdefault(model.body(body).name, {kind: [] for kind in ARCHETYPES})
        rgba = _rgba(model, g) if color is None else np.array(color, dtype=np.uint8)
        kind = int(model.geom_type[g])
        if kind in ARCHETYPES:
            entry[kind].append({**_shape(model, g), "q": model.geom_quat[g], "colors": rgba})
    archetypes = {}
    for body, entry in shapes.items():
        archetypes[body] = []
        for kind, found in entry.items():
            if found:
                archetype, options = ARCHETYPES[kind]
                fields = {key: [f[key] for f in found] for key in found[0] if key != "q"}
                quaternions = _xyzw(np.array([f["q"] for f in found]))
                archetypes[body].append(archetype(**fields, quaternions=quaternions, **options))
    return archetypes


def gait_qpos(biped: Biped, sim: Simulation, q: np.ndarray) -> np.ndarray:
    """MuJoCo's qpos (N, nq) of the gait's coordinates q (N, 9) along the walk: each step's
    stance leg on MuJoCo's stance side, its stance ankle on MuJoCo's at the start of the step."""
    model = sim.model
    qpos = np.zeros((len(q), model.nq))
    starts = sim.step_starts + [len(sim.time)]
    rootx = model.joint("rootx").qposadr[0]
    for j, stance in enumerate(sim.stances):
        rows = slice(starts[j], starts[j + 1])
        qpos[rows] = mapping(model, stance, biped.radii).qpos(q[rows])
        qpos[rows, rootx] += sim.ankle_x(stance)[starts[j]]
    return qpos


def _body_poses(model: mujoco.MjModel, qpos: np.ndarray, bodies: list) -> tuple:
    """World positions (N, B, 3) and quaternions (N, B, 4, wxyz) of ``bodies`` at each qpos."""
    data = mujoco.MjData(model)
    ids = [model.body(name).id for name in bodies]
    positions = np.zeros((len(qpos), len(ids), 3))
    quaternions = np.zeros((len(qpos), len(ids), 4))
    for k, row in enumerate(qpos):
        data.qpos[:] = row
        mujoco.mj_kinematics(model, data)
        positions[k], quaternions[k] = data.xpos[ids], data.xquat[ids]
    return positions, quaternions


def summary(biped: Biped, step: GaitSamples, sim: Simulation, checks, gait: Gait) -> str:
    """Markdown: the gait's parameters and criteria, then every check with its verdict."""
    lines = [f"# {biped.knee} knee, {'PASS' if all(c.passed for c in checks) else 'FAIL'}"]
    if not checks:
        lines[0] = f"# {biped.knee} knee"
    lines += ["", "## Gait", "", "| | |", "|---|---|"]
    rows = [
        ("knee", biped.knee),
        ("criterion", gait.criterion),
        ("speed [m/s]", f"{gait.speed:.3f}"),
        ("feasible", "yes" if gait.feasible else "no"),
        ("period T [s]", f"{step.period:.4f}"),
        ("step length [m]", f"{step.step_length:.4f}"),
        ("steps simulated", str(len(sim.stances))),
    ]
    rows += [(f"criterion {name}", f"{value:.4g}") for name, value in gait.costs.to_dict().items()]
    constraints = {} if gait.constraints is None else gait.constraints.to_dict()
    rows += [(f"constraint {name}", f"{value:.4g}") for name, value in constraints.items()]
    lines += [f"| {name} | {value} |" for name, value in rows]
    if checks:
        lines += ["", "## Checks", ""]
        for check in checks:
            said = f" ({', '.join(check.causes)})" if check.causes else ""
            lines += [f"### {check.name}: {'PASS' if check.passed else 'FAIL'}{said}", ""]
            lines += ["| figure | value |", "|---|---|"]
            lines += [
                f"| {name} | {_value(value)} |"
                for name, value in check.figures.items()
                if name not in PROFILES  # the torques over one step: the page draws them
            ]
            lines += [""] + [f"- {note}" for note in check.notes] + [""] * bool(check.notes)
    return "\n".join(lines)


def _value(value) -> str:
    if isinstance(value, bool):
        return "yes" if value else "no"
    if isinstance(value, (list, tuple)):  # a [low, high] range, or a list of figures
        return (" - " if len(value) == 2 else ", ").join(_value(v) for v in value)
    if isinstance(value, (float, np.floating)):
        return "n/a" if np.isnan(value) else f"{value:.4g}"
    if isinstance(value, (int, np.integer)):
        return str(int(value))
    return str(value)


def record(path: str | Path, validation, spawn: bool = False, connect: str | None = None) -> Path:
    """Write the recording of a validation (``validate.checks.validation.Validation``: its walk, the
    gait's samples drawn as the ghost, the walk's contact, and for the summary the gait and
    its checks) to ``path`` (.rrd), atomically.

    Args:
        spawn: also stream to a rerun viewer started for it.
        connect: also stream to a running viewer at this URL ("" for rerun's default).
    """
    biped, step, sim = validation.biped, validation.samples, validation.simulation
    contact, checks, gait = validation.contact, validation.checks, validation.gait
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    q_ref, torques, wrench, zmp = reference_along(step, sim)
    steady = sim.phase >= LANDING * step.period
    ranges = {
        torque_series_path(i, joint): torque_range(torques[:, i], steady)
        for i, joint in enumerate(JOINTS)
    }
    for i, name in enumerate(("Fx", "Fz")):  # MuJoCo's landing spikes run off the plot too
        ranges[f"ground/{name}"] = torque_range(wrench[:, i], steady)
    heel, toe = sorted(biped.robot.sole_edges().values())  # the sole, a little beyond
    pad = TORQUE_MARGIN * (toe - heel) / 2
    ranges["zmp"] = (heel - pad, toe + pad)
    end = float(sim.time[-1])
    window = (max(float(sim.time[0]), end - SHOWN_STEPS * step.period), end)
    recording_id = f"{biped.knee}-{path.stem}"
    feet = _feet(step, sim, wrench, steady, ranges) if step.two_phase else None
    layout = blueprint(ranges, window, feet=feet is not None)

    def log_all(rec) -> None:
        _log_torques(rec, biped, sim, torques, ranges, steady)
        _log_series(rec, biped, step, sim, contact, wrench, zmp)
        _log_world(rec, biped, sim, contact, q_ref, zmp)
        if feet is not None:
            _log_feet(rec, sim, feet)
        text = summary(biped, step, sim, checks, gait)
        rec.log("summary", rr.TextDocument(text, media_type=rr.MediaType.MARKDOWN), static=True)
        key = rr.TextDocument(TORQUE_KEY, media_type=rr.MediaType.MARKDOWN)
        rec.log("torque_key", key, static=True)
        orbit = next((check.figures for check in checks if check.name == "orbit"), None)
        if orbit is not None:
            _log_orbit(rec, orbit)

    with atomic_path(path) as tmp:
        rec = rr.RecordingStream(APPLICATION, recording_id=recording_id)
        try:
            rec.save(str(tmp), default_blueprint=layout)
        except RuntimeError as error:  # rerun reports an unwritable file this way
            raise OSError(f"cannot write the recording {str(path)!r}: {error}") from None
        log_all(rec)
        rec.flush()
        rec.disconnect()
        del rec
    if spawn or connect is not None:
        _stream(log_all, layout, recording_id, path, spawn, connect)
    return path


def _stream(log_all, layout, recording_id: str, path: Path, spawn: bool, connect) -> None:
    """The recording streamed on a stream of its own to a viewer started for it (``spawn``) or
    at ``connect``: a viewer that does not answer delays the command by at most
    ``VIEWER_TIMEOUT`` and never the file; it is a ``ViewerWarning``, the checks' results
    stand."""
    where = "the viewer it started" if spawn else f"--connect {connect or DEFAULT_VIEWER!r}"
    refused = None if spawn else _unreachable(connect or DEFAULT_VIEWER)
    if refused is not None:  # nothing listens there: said at once, not after rerun's waits
        _viewer_warning(where, f"nothing listens at that address: {refused}", path)
        return
    live = rr.RecordingStream(APPLICATION, recording_id=recording_id)
    try:
        if spawn:
            rr.spawn(executable_path=viewer_executable(), recording=live, default_blueprint=layout)
        else:
            live.connect_grpc(connect or None, default_blueprint=layout)
        log_all(live)
        live.flush(timeout_sec=VIEWER_TIMEOUT)
    except RuntimeError as error:  # rerun's way to say no viewer took it
        _viewer_warning(where, str(error), path)
    finally:
        live.disconnect()
        del live


def _viewer_warning(where: str, why: str, path: Path) -> None:
    """The ``ViewerWarning`` of a recording no viewer took: where it went, why, the file."""
    message = (
        f"{where}: no rerun viewer took the recording ({why}); it is written to "
        f"{str(path)!r}: open it with '{viewer_executable() or VIEWER} {path}'"
    )
    warnings.warn(ViewerWarning(message), stacklevel=4)


def _unreachable(url: str) -> str | None:
    """Why nothing accepts a connection at the host and port of a viewer's ``url`` within
    ``PROBE_TIMEOUT`` (the error), or None where something does or the URL names no port."""
    parts = urlsplit(url)
    if parts.hostname is None or parts.port is None:
        return None
    try:
        with socket.create_connection((parts.hostname, parts.port), timeout=PROBE_TIMEOUT):
            return None
    except OSError as error:
        return error.strerror or str(error) or type(error).__name__


def viewer_executable() -> str | None:
    """rerun's viewer: the one on PATH, else the one installed beside this Python (a virtual
    environment's, whose folder is on PATH only when it is activated); None: rerun's own
    search (which then says how to install it)."""
    found = shutil.which(VIEWER)
    if found is not None:
        return found
    beside = Path(sys.executable).parent / VIEWER
    return str(beside) if beside.is_file() else None


def _circle(radius: float, points: int = 181) -> np.ndarray:
    angle = np.linspace(0.0, 2.0 * np.pi, points)
    return radius * np.column_stack([np.cos(angle), np.sin(angle)])


def _log_orbit(rec, orbit: dict) -> None:
    """The orbit check's multipliers in the complex plane (rerun's 2D y points down: drawn
    at (Re μ, -Im μ)), the unit circle, ρ and ρ ± 2 spreads, the axes."""

    def strips(path, lines, colour, width, label=None):
        labels = None if label is None else [label]
        strip = rr.LineStrips2D(lines, colors=[colour], radii=width, labels=labels)
        rec.log(f"orbit/{path}", strip, static=True)

    strips("axes", [[(-1.2, 0.0), (1.2, 0.0)], [(0.0, -1.2), (0.0, 1.2)]], ORBIT_AXES, 0.004)
    strips("unit_circle", [_circle(1.0)], ORBIT_UNIT, 0.008)
    if "spectral_radius" not in orbit:
        label = f"no orbit: {orbit.get('verdict', '')}"
        rec.log("orbit/multipliers", rr.Points2D([(0.0, 0.0)], labels=[label]), static=True)
        return
    rho, spread = orbit["spectral_radius"], orbit["spectral_radius_spread"]
    strips("radius", [_circle(rho)], ORBIT_RADIUS, 0.006)
    strips(
        "band",
        [_circle(max(rho - 2.0 * spread, 0.0)), _circle(rho + 2.0 * spread)],
        ORBIT_BAND,
        0.003,
    )
    real, imag = np.array(orbit["multipliers_real"]), np.array(orbit["multipliers_imag"])
    slowest = f"{real[0]:.3f}" + (f"{imag[0]:+.3f}i" if abs(imag[0]) > 1e-9 else "")
    labels = [f"μ {slowest}, ρ {rho:.3f} ± {spread:.3f}"] + [""] * (len(real) - 1)
    points = rr.Points2D(
        np.column_stack([real, -imag]), radii=0.045, colors=[ORBIT_POINTS], labels=labels
    )
    rec.log("orbit/multipliers", points, static=True)


def _line(rec, path: str, name: str, color, width: float) -> None:
    """The style of the time series at ``path``: its name in the legend, colour and width."""
    rec.log(path, rr.SeriesLines(colors=color, names=name, widths=width), static=True)


def _scalars(rec, path: str, time: np.ndarray, values: np.ndarray) -> None:
    """The values of the time series at ``path`` at the simulation times ``time`` [s]."""
    indexes = [rr.TimeColumn("time", duration=time)]
    rec.send_columns(path, indexes=indexes, columns=rr.Scalars.columns(scalars=values))


def _log_torques(rec, biped: Biped, sim: Simulation, torques, ranges: dict, steady) -> None:
    """Per joint: the gait's torque, MuJoCo's, its feedforward and feedback, the landings."""
    model = sim.model
    stance_of = sim.stance_of()
    feedforward, feedback = sim.feedforward(), sim.feedback()  # JOINT_ORDER
    parts = {"feedforward": np.zeros_like(torques), "feedback": np.zeros_like(torques)}
    for stance in SIDES:
        rows = stance_of == stance
        order = mapping(model, stance, biped.radii).columns
        parts["feedforward"][rows] = feedforward[np.ix_(rows, order)]
        parts["feedback"][rows] = feedback[np.ix_(rows, order)]
    landing = np.flatnonzero(~steady)[::5]
    styles = {
        "analytic": ("gait", ANALYTIC_COLOR, ANALYTIC_WIDTH),
        "mujoco": ("MuJoCo", MUJOCO_COLOR, MUJOCO_WIDTH),
        "feedforward": ("MuJoCo feedforward", FEEDFORWARD_COLOR, FEEDFORWARD_WIDTH),
        "feedback": ("MuJoCo feedback", FEEDBACK_COLOR, FEEDBACK_WIDTH),
    }
    for i, joint in enumerate(JOINTS):
        base = torque_series_path(i, joint)
        values = {
            "analytic": torques[:, i],
            "mujoco": parts["feedforward"][:, i] + parts["feedback"][:, i],
            "feedforward": parts["feedforward"][:, i],
            "feedback": parts["feedback"][:, i],
        }
        for source, series in values.items():
            _line(rec, f"{base}/{source}", *styles[source])
            _scalars(rec, f"{base}/{source}", sim.time, series)
        marks = rr.SeriesPoints(
            colors=LANDING_COLOR, names="landing", markers="square", marker_sizes=2.0
        )
        rec.log(f"{base}/landing", marks, static=True)
        low = ranges[base][0]
        _scalars(rec, f"{base}/landing", sim.time[landing], np.full(len(landing), low))


def _log_series(rec, biped: Biped, step, sim: Simulation, contact, wrench, zmp) -> None:
    """Ground reaction, ZMP and phase plots, the gait's and MuJoCo's."""
    for name in ("Fx", "Fz"):
        _line(rec, f"ground/{name}/analytic", f"{name} gait", ANALYTIC_COLOR, ANALYTIC_WIDTH)
        _line(rec, f"ground/{name}/mujoco", f"{name} MuJoCo", MUJOCO_COLOR, MUJOCO_WIDTH)
    _line(rec, "zmp/analytic", "ZMP gait", ANALYTIC_COLOR, ANALYTIC_WIDTH)
    _line(rec, "zmp/mujoco", "CoP MuJoCo", MUJOCO_COLOR, MUJOCO_WIDTH)
    for name in SOLE_EDGES:
        _line(rec, f"zmp/{name}", f"{name} edge", SOLE_COLORS[name], EDGE_WIDTH)
    for i, name in enumerate(("Fx", "Fz")):
        _scalars(rec, f"ground/{name}/analytic", sim.time, wrench[:, i])
        sampled = ~np.isnan(contact["force"][:, i])
        _scalars(rec, f"ground/{name}/mujoco", sim.time[sampled], contact["force"][sampled, i])
    _scalars(rec, "zmp/analytic", sim.time, zmp)
    _scalars(rec, "phase", sim.time, sim.phase / step.period)
    sampled = ~np.isnan(contact["cop"])
    _scalars(rec, "zmp/mujoco", sim.time[sampled], contact["cop"][sampled])
    for name, value in biped.robot.sole_edges().items():
        _scalars(rec, f"zmp/{name}", sim.time, np.full(len(sim.time), value))


def _feet(step: GaitSamples, sim: Simulation, wrench, steady, ranges: dict) -> dict:
    """A two-phase walk's feet (``validate.walk.contact.feet_reaction``): each foot's force,
    the gait's and MuJoCo's, and the supports, by their series' paths; their plots' ranges
    added to ``ranges``."""
    from validate.walk.contact import feet_reaction

    mujoco_feet = feet_reaction(sim)
    gait = {"stance": wrench[:, :2], "swing": step.at("swing_wrench", sim.phase)[:, :2]}
    series = {}
    for i, name in enumerate(("Fx", "Fz")):
        both = np.concatenate([gait["stance"][:, i], gait["swing"][:, i]])
        ranges[f"feet/{name}"] = torque_range(both, np.concatenate([steady, steady]))
        for role in ("stance", "swing"):
            series[f"feet/{name}/{role}_analytic"] = gait[role][:, i]
            series[f"feet/{name}/{role}_mujoco"] = mujoco_feet[role][:, i]
    series["support/analytic"] = np.where(sim.phase >= step.landing, 2.0, 1.0)
    series["support/mujoco"] = mujoco_feet["supports"]
    return series


# The style of each series of ``_feet``: its name, colour and width, by the path's end.
FEET_STYLES = {
    "stance_analytic": ("stance foot, gait", ANALYTIC_COLOR, ANALYTIC_WIDTH),
    "stance_mujoco": ("stance foot, MuJoCo", MUJOCO_COLOR, MUJOCO_WIDTH),
    "swing_analytic": ("swing foot, gait", SWING_ANALYTIC_COLOR, FEEDFORWARD_WIDTH),
    "swing_mujoco": ("swing foot, MuJoCo", SWING_MUJOCO_COLOR, MUJOCO_WIDTH),
    "analytic": ("gait", ANALYTIC_COLOR, ANALYTIC_WIDTH),
    "mujoco": ("MuJoCo", MUJOCO_COLOR, MUJOCO_WIDTH),
}


def _log_feet(rec, sim: Simulation, feet: dict) -> None:
    """Each foot's Fx and Fz, the gait's and MuJoCo's, and the supports (``_feet``)."""
    for path, values in feet.items():
        _line(rec, path, *FEET_STYLES[path.rsplit("/", 1)[1]])
        sampled = ~np.isnan(values)
        _scalars(rec, path, sim.time[sampled], values[sampled])


def _log_world(rec, biped: Biped, sim: Simulation, contact, q_ref, zmp) -> None:
    """The 3D scene: floor, MuJoCo's robot, the gait's ghost, ground reaction and ZMP."""
    model = sim.model
    frames = np.arange(0, len(sim.time), FRAME_EVERY)
    frame_time = [rr.TimeColumn("time", duration=sim.time[frames])]
    # Floor: a slab under the walk, lines across it every 0.5 m.
    start, end = float(sim.hip_x().min()) - 1.0, float(sim.hip_x().max()) + 1.0
    rec.log(
        "world/ground",
        rr.Boxes3D(
            centers=[((start + end) / 2, 0.0, -0.005)],
            half_sizes=[((end - start) / 2, 0.6, 0.005)],
            colors=[GROUND_COLOR],
            fill_mode="solid",
        ),
        static=True,
    )
    marks = np.arange(np.floor(start * 2) / 2, end, 0.5)
    rec.log(
        "world/ground/lines",
        rr.LineStrips3D(
            [[(x, -0.6, 0.001), (x, 0.6, 0.001)] for x in marks], colors=[(90, 92, 98)], radii=0.003
        ),
        static=True,
    )
    geometry = {"mujoco": visual_geoms(model), "analytic": visual_geoms(model, GHOST_COLOR)}
    bodies = list(geometry["mujoco"])
    robots = {
        "mujoco": sim.qpos[frames],
        "analytic": gait_qpos(biped, sim, q_ref[frames]),
    }
    for name, qpos in robots.items():
        positions, quaternions = _body_poses(model, qpos, bodies)
        if name == "analytic":
            positions[..., 1] += GHOST_OFFSET
        for b, body in enumerate(bodies):
            rec.log(f"world/{name}/{body}/geometry", *geometry[name][body], static=True)
            rec.send_columns(
                f"world/{name}/{body}",
                indexes=frame_time,
                columns=rr.Transform3D.columns(
                    translation=positions[:, b], quaternion=_xyzw(quaternions[:, b])
                ),
            )
    # Ground reaction from the centre of pressure, in single support (none in double).
    stance_of = sim.stance_of()
    y = np.where(stance_of == "left", HIP_OFFSET, -HIP_OFFSET)
    ankle_x = np.zeros(len(sim.time))
    for side in SIDES:
        rows = stance_of == side
        ankle_x[rows] = sim.ankle_x(side)[rows]
    sampled = np.arange(0, len(sim.time), SAMPLE_EVERY)
    single = np.isfinite(contact["cop"][sampled])
    rows = sampled[single]
    origins = np.stack([ankle_x[rows] + contact["cop"][rows], y[rows], np.zeros(len(rows))], axis=1)
    force = contact["force"][rows]
    vectors = ARROW_SCALE * np.stack([force[:, 0], np.zeros(len(rows)), force[:, 1]], axis=1)
    rec.log(
        "world/contact/force", rr.Arrows3D.from_fields(colors=FORCE_COLOR, radii=0.008), static=True
    )
    rec.send_columns(
        "world/contact/force",
        indexes=[rr.TimeColumn("time", duration=sim.time[sampled])],
        columns=rr.Arrows3D.columns(origins=origins, vectors=vectors).partition(single.astype(int)),
    )
    points = np.stack(
        [ankle_x[frames] + zmp[frames], y[frames], np.full(len(frames), 0.002)], axis=1
    )
    rec.log("world/contact/zmp", rr.Points3D.from_fields(colors=ZMP_COLOR, radii=0.02), static=True)
    rec.send_columns(
        "world/contact/zmp", indexes=frame_time, columns=rr.Points3D.columns(positions=points)
    )
