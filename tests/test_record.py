"""Rerun recordings read back: the 3D robot from the model's geometry where MuJoCo has it, the
ground reaction from the foot, one torque plot per joint, the summary with every verdict."""

import mujoco
import numpy as np
import pytest
import rerun.chunk

from biped import Robot
from biped.model.dynamics import JOINTS
from biped.records import gait_file
from biped.records.gait_file import Gait
from tests.conftest import small_optimum

ROBOT = Robot.paper()


@pytest.fixture(scope="module")
def recorded(tmp_path_factory):
    """Two steps of the rolling knee's gait, validated and recorded; the chunks read back."""
    from validate.checks.validation import validate
    from validate.outputs.record import record

    folder = tmp_path_factory.mktemp("record")
    Gait.from_optimum(small_optimum("rolling"), ROBOT).write(folder / "rolling.json")
    gait = gait_file.read(folder / "rolling.json")
    result = validate(gait, steps=2)
    path = record(folder / "rolling.rrd", result)
    chunks = rerun.chunk.RrdReader(path).stream().to_chunks()
    return result, chunks, folder


def column(chunks, entity: str, name: str, timeless: bool | None = None):
    """Values of one component of an entity, row by row, and the rows' times [s] if any."""
    for chunk in chunks:
        if chunk.entity_path != entity:
            continue
        if timeless is not None and timeless != (not chunk.timeline_names):
            continue
        batch = chunk.to_record_batch()
        if name in batch.schema.names:
            times = None
            if "time" in batch.schema.names:
                times = np.array([t.value for t in batch.column("time")], dtype=float) * 1e-9
            return batch.column(name).to_pylist(), times
    raise KeyError(f"{entity} has no {name}")


def test_recording_holds_the_documented_entities(recorded):
    """3D robot and ghost per body, floor, force arrow, ZMP, four series per joint and the
    summary are in the recording, and nothing is left of its temporary file."""
    _, chunks, folder = recorded
    paths = {chunk.entity_path for chunk in chunks}
    for robot in ("mujoco", "analytic"):
        for body in ("trunk", "left_thigh", "left_shank", "left_foot", "right_thigh"):
            assert f"/world/{robot}/{body}" in paths
            assert f"/world/{robot}/{body}/geometry" in paths
    for entity in ("/world/ground", "/world/contact/force", "/world/contact/zmp", "/summary"):
        assert entity in paths
    for i, joint in enumerate(
        ("stance_ankle", "stance_knee", "stance_hip", "swing_hip", "swing_knee", "swing_ankle")
    ):
        for series in ("analytic", "mujoco", "feedforward", "feedback", "landing"):
            assert f"/torques/Γ{i + 1}_{joint}/{series}" in paths
    assert not [p for p in folder.iterdir() if p.name.endswith(".tmp")]


def test_recorded_geometry_is_where_mujoco_draws_it(recorded):
    """Capsule ends and knee-disc centres, from the recorded body poses and shapes, lie on
    MuJoCo's geoms at the same instant (to 1e-5 m, float32)."""
    result, chunks, _ = recorded
    sim = result.simulation
    model, data = sim.model, mujoco.MjData(sim.model)
    translation, times = column(chunks, "/world/mujoco/left_shank", "Transform3D:translation")
    quaternion, _ = column(chunks, "/world/mujoco/left_shank", "Transform3D:quaternion")
    k = len(times) // 2
    state = int(np.argmin(np.abs(sim.time - times[k])))
    data.qpos[:] = sim.qpos[state]
    mujoco.mj_kinematics(model, data)
    rotation = np.zeros(9)
    x, y, z, w = quaternion[k][0]
    mujoco.mju_quat2Mat(rotation, np.array([w, x, y, z]))
    pose = rotation.reshape(3, 3), np.array(translation[k][0])

    def world(point):
        return pose[0] @ np.asarray(point) + pose[1]

    base, _ = column(chunks, "/world/mujoco/left_shank/geometry", "Capsules3D:translations")
    lengths, _ = column(chunks, "/world/mujoco/left_shank/geometry", "Capsules3D:lengths")
    capsule = [
        g
        for g in range(model.ngeom)
        if model.geom_bodyid[g] == model.body("left_shank").id
        and model.geom_type[g] == mujoco.mjtGeom.mjGEOM_CAPSULE
    ][0]
    axis = data.geom_xmat[capsule].reshape(3, 3)[:, 2]
    bottom = data.geom_xpos[capsule] - model.geom_size[capsule, 1] * axis
    np.testing.assert_allclose(world(base[0][0]), bottom, atol=1e-5)
    top = data.geom_xpos[capsule] + model.geom_size[capsule, 1] * axis
    tip = world(base[0][0]) + pose[0] @ (
        rotation_of(
            column(chunks, "/world/mujoco/left_shank/geometry", "Capsules3D:quaternions")[0][0][0]
        )
        @ [0, 0, lengths[0][0]]
    )
    np.testing.assert_allclose(tip, top, atol=1e-5)
    centres, _ = column(chunks, "/world/mujoco/left_shank/geometry", "Cylinders3D:centers")
    radii, _ = column(chunks, "/world/mujoco/left_shank/geometry", "Cylinders3D:radii")
    np.testing.assert_allclose(
        world(centres[0][0]), data.geom_xpos[model.geom("left_shank_disc").id], atol=1e-5
    )
    assert radii[0][0] == pytest.approx(ROBOT.r1)


def rotation_of(xyzw) -> np.ndarray:
    x, y, z, w = xyzw
    rotation = np.zeros(9)
    mujoco.mju_quat2Mat(rotation, np.array([w, x, y, z]))
    return rotation.reshape(3, 3)


def test_ground_reaction_arrow_stands_in_the_stance_foot(recorded):
    """The arrow starts on the floor under the stance sole (heel to toe, 1 mm of slack) and
    its vertical length is the robot's weight at ARROW_SCALE, to 20 % in the median; the
    gait's ZMP point lies on the sole too."""
    from validate.outputs.record import ARROW_SCALE

    result, chunks, _ = recorded
    sim = result.simulation
    origins, times = column(chunks, "/world/contact/force", "Arrows3D:origins", timeless=False)
    vectors, _ = column(chunks, "/world/contact/force", "Arrows3D:vectors", timeless=False)
    drawn = [i for i, row in enumerate(origins) if row]
    assert len(drawn) > 0.5 * len(origins)  # single support most of the time
    stance_of = sim.stance_of()
    for i in drawn:
        k = int(np.argmin(np.abs(sim.time - times[i])))
        ankle = sim.sensor(f"{stance_of[k]}_ankle_pos")[k]
        x = origins[i][0][0] - ankle[0]
        assert -ROBOT.foot_heel - 1e-3 <= x <= ROBOT.foot_length - ROBOT.foot_heel + 1e-3
        assert origins[i][0][2] == 0.0
    weight = ROBOT.total_mass * ROBOT.gravity
    vertical = np.median([vectors[i][0][2] for i in drawn]) / ARROW_SCALE
    assert vertical == pytest.approx(weight, rel=0.2)
    points, _ = column(chunks, "/world/contact/zmp", "Points3D:positions", timeless=False)
    assert all(abs(row[0][2]) < 0.01 for row in points)


def test_summary_states_the_gait_and_every_verdict(recorded):
    """The summary names the knee, the speed, the criteria and each check with its verdict
    and, when it fails, its causes; the torques over one step are the page's, not its."""
    result, chunks, _ = recorded
    text = column(chunks, "/summary", "TextDocument:text")[0][0][0]
    assert "rolling" in text and "0.300" in text and "sthenic" in text
    for check in result.checks:
        said = f" ({', '.join(check.causes)})" if check.causes else ""
        assert f"### {check.name}: {'PASS' if check.passed else 'FAIL'}{said}\n" in text
    assert "| gait_torque_rms |" in text and "_profile |" not in text


def test_torque_range_follows_the_gait_not_the_landings():
    """A landing spike of 40 N·m does not set the plot's range around ±4 N·m torques, and a
    range from every sample would have let it."""
    from validate.outputs.record import torque_range

    t = np.linspace(0.0, 1.0, 1001)
    torque = 4.0 * np.sin(2 * np.pi * t)
    steady = t >= 0.1
    torque[:20] = 40.0  # landing
    low, high = torque_range(torque, steady)
    assert -7.0 < low < -4.0 and 4.0 < high < 7.0
    assert torque_range(torque, np.ones_like(steady))[1] > 40.0
    # A nearly flat torque still gets a readable span.
    low, high = torque_range(np.full(10, 1.0), np.ones(10, bool))
    assert high - low == pytest.approx(2.0)


def _views(path) -> dict:
    """The recording's default blueprint: {view origin: {component: value}}, each view's own
    and its properties' (``TimeAxis:view_range``, ``PlotLegend:visible``, ...) components."""
    reader = rerun.chunk.RrdReader(path)
    chunks = reader.stream(store=reader.blueprints()[0]).to_chunks()
    by_view: dict = {}
    for chunk in chunks:
        parts = chunk.entity_path.strip("/").split("/")
        if parts[0] != "view":
            continue
        batch = chunk.to_record_batch()
        components = by_view.setdefault(parts[1], {})
        for name in batch.schema.names:
            if ":" in name:
                components[name] = batch.column(name).to_pylist()[-1][0]
    return {c["ViewBlueprint:space_origin"]: c for c in by_view.values()}


def _scalars(chunks, entity: str) -> np.ndarray:
    """Every value of a series, over all its chunks."""
    values = []
    for chunk in chunks:
        batch = chunk.to_record_batch()
        if chunk.entity_path == entity and "Scalars:scalars" in batch.schema.names:
            values += [row[0] for row in batch.column("Scalars:scalars").to_pylist()]
    return np.array(values, dtype=float)


PLOTS = [f"torques/Γ{i + 1}_{joint}" for i, joint in enumerate(JOINTS)] + [
    "ground/Fx",
    "ground/Fz",
    "zmp",
]


def test_every_series_of_a_plot_has_its_own_colour_the_gait_widest(recorded):
    """In each torque, ground-reaction (Fx, Fz: a plot each) and ZMP plot no two series share
    a colour, and the gait's line is wider than any drawn over it."""
    _, chunks, folder = recorded
    assert {"ground/Fx", "ground/Fz"} <= set(_views(folder / "rolling.rrd"))
    for plot in PLOTS:
        styles = {}
        for chunk in chunks:
            series = chunk.entity_path.removeprefix(f"/{plot}/")
            if series == chunk.entity_path or chunk.timeline_names:
                continue
            batch = chunk.to_record_batch()
            if "SeriesLines:colors" in batch.schema.names:
                width = batch.column("SeriesLines:widths").to_pylist()[0][0]
                styles[series] = (batch.column("SeriesLines:colors").to_pylist()[0][0], width)
            else:  # the landings' marks
                styles[series] = (batch.column("SeriesPoints:colors").to_pylist()[0][0], 0.0)
        colours = [colour for colour, _ in styles.values()]
        assert len(styles) >= 2 and len(set(colours)) == len(colours), (plot, styles)
        others = [width for series, (_, width) in styles.items() if series != "analytic"]
        assert styles["analytic"][1] > max(others), (plot, styles)


def test_time_plots_open_on_the_last_steps_legends_clear_of_the_curves(recorded):
    """The torque, ground and ZMP plots open on the last SHOWN_STEPS steps of the walk; the
    torque plots have no legend over their curves (their key is a text beside them) and the
    others' legend has the top of the plot above the gait's curves and the sole's edges."""
    from validate.outputs.record import SHOWN_STEPS

    result, chunks, folder = recorded
    views = _views(folder / "rolling.rrd")
    end = result.simulation.time[-1]
    start = max(result.simulation.time[0], end - SHOWN_STEPS * result.samples.period)
    for plot in PLOTS:
        shown = views[plot]["TimeAxis:view_range"]
        assert shown["start"] * 1e-9 == pytest.approx(start, abs=1e-6), plot
        assert shown["end"] * 1e-9 == pytest.approx(end, abs=1e-6), plot
        if plot.startswith("torques/"):
            assert views[plot]["PlotLegend:visible"] is False, plot
            continue
        assert views[plot]["PlotLegend:visible"] is True, plot
        low, high = views[plot]["ScalarAxis:range"]
        curves = ["analytic"] + (["heel", "toe"] if plot == "zmp" else [])
        top = max(np.max(_scalars(chunks, f"/{plot}/{curve}")) for curve in curves)
        assert (high - top) / (high - low) > 0.4, plot  # the legend's room above the curves
    key = column(chunks, "/torque_key", "TextDocument:text")[0][0]
    key = key[0] if isinstance(key, list) else key
    assert "torque_key" in views
    for series in ("the gait", "feedforward", "MuJoCo (ff + fb)", "feedback", "landings"):
        assert series in key, series


def test_recording_draws_the_orbit_checks_multipliers(recorded):
    """The orbit check's multipliers in the complex plane beside the unit circle: at
    (Re μ, -Im μ) (rerun's 2D y points down), or a point saying there is no orbit."""
    result, chunks, _ = recorded
    orbit = next(check.figures for check in result.checks if check.name == "orbit")
    paths = {chunk.entity_path for chunk in chunks}
    assert {"/orbit/unit_circle", "/orbit/axes", "/orbit/multipliers"} <= paths
    points, _ = column(chunks, "/orbit/multipliers", "Points2D:positions")
    if "spectral_radius" in orbit:
        expected = np.column_stack(
            [orbit["multipliers_real"], -np.array(orbit["multipliers_imag"])]
        )
        assert np.allclose(np.array(points[0]), expected, atol=1e-6)
    else:
        assert np.allclose(np.array(points[0]), [[0.0, 0.0]])


def test_a_viewer_that_does_not_take_the_stream_is_a_warning_the_file_written(
    recorded, monkeypatch, tmp_path
):
    """--connect to an address where no viewer listens: one ViewerWarning naming the address
    and the file, which is written whole; the validation's results are not lost to an error."""
    import re
    import socket

    import validate.outputs.record
    from biped.errors import ViewerWarning

    result, _, _ = recorded
    with socket.socket() as probe:  # a port nothing listens on
        probe.bind(("127.0.0.1", 0))
        port = probe.getsockname()[1]
    url = f"rerun+http://127.0.0.1:{port}/proxy"
    monkeypatch.setattr(validate.outputs.record, "VIEWER_TIMEOUT", 0.5)
    named = f"--connect {re.escape(repr(url))}.*no rerun viewer"
    with pytest.warns(ViewerWarning, match=named) as caught:
        path = validate.outputs.record.record(tmp_path / "live.rrd", result, connect=url)
    assert str(tmp_path / "live.rrd") in str(caught[0].message)
    assert len(rerun.chunk.RrdReader(path).stream().to_chunks()) > 0


def test_connect_where_nothing_listens_warns_without_rerun_s_waits(recorded, monkeypatch, tmp_path):
    """--connect to an address where nothing listens: the warning comes within the probe's
    wait, the stream never opened (rerun's own connection, flush and disconnect wait 5 s
    and more each), the file written whole."""
    import socket
    import time

    import validate.outputs.record
    from biped.errors import ViewerWarning

    result, _, _ = recorded
    with socket.socket() as probe:  # a port nothing listens on
        probe.bind(("127.0.0.1", 0))
        port = probe.getsockname()[1]
    url = f"rerun+http://127.0.0.1:{port}/proxy"

    def opened(*args, **kwargs):
        pytest.fail("a stream opened to an address where nothing listens")

    monkeypatch.setattr(rerun.RecordingStream, "connect_grpc", opened)
    with pytest.warns(ViewerWarning, match="nothing listens at that address"):
        path = validate.outputs.record.record(tmp_path / "live.rrd", result, connect=url)
    assert len(rerun.chunk.RrdReader(path).stream().to_chunks()) > 0
    began = time.perf_counter()
    assert validate.outputs.record._unreachable(url) is not None
    assert time.perf_counter() - began < validate.outputs.record.PROBE_TIMEOUT + 0.5


def test_the_viewer_is_found_beside_this_python_when_not_on_path(monkeypatch, tmp_path):
    """Without the virtual environment's folder on PATH (not activated), --spawn starts the
    viewer installed beside the running Python; with neither, rerun's own search."""
    import sys
    from pathlib import Path

    from validate.outputs.record import viewer_executable

    monkeypatch.setenv("PATH", str(tmp_path))
    beside = Path(sys.executable).parent / "rerun"
    assert viewer_executable() == (str(beside) if beside.is_file() else None)
    fake = tmp_path / "rerun"
    fake.write_text("#!/bin/sh\n")
    fake.chmod(0o755)
    assert viewer_executable() == str(fake)


def test_spawn_starts_the_viewer_found_and_a_failed_start_is_a_warning(
    recorded, monkeypatch, tmp_path
):
    """--spawn hands rerun the viewer ``viewer_executable`` found (beside this Python when
    not on PATH); a viewer that cannot start is a ViewerWarning, the file written."""
    import validate.outputs.record
    from biped.errors import ViewerWarning

    result, _, _ = recorded
    asked = {}

    def spawn(**kwargs):
        asked.update(kwargs)
        raise RuntimeError("no display")

    monkeypatch.setattr(validate.outputs.record.rr, "spawn", spawn)
    with pytest.warns(ViewerWarning, match="the viewer it started: no rerun viewer.*no display"):
        path = validate.outputs.record.record(tmp_path / "spawned.rrd", result, spawn=True)
    assert asked["executable_path"] == validate.outputs.record.viewer_executable()
    assert path.is_file()
