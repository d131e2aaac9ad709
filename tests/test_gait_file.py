"""Gait files: written with their provenance, read back with errors that name the bad field."""

import dataclasses
import json
import tempfile
from pathlib import Path

import pytest

from biped import Biped, Robot
from biped.errors import BipedError
from biped.model.actuators import Actuators
from biped.optimization.optimize import checked
from biped.pages.page import drive_lines
from biped.records import gait_file
from biped.records.gait_file import Gait
from biped.records.provenance import PACKAGE
from tests.conftest import edited_gait_file, refusal, small_optimum
from validate.scene.model import committed_model


@pytest.fixture(scope="module")
def content():
    """The JSON content of a rolling-knee gait file at 0.3 m/s."""
    optimum = small_optimum("rolling")
    return json.loads(json.dumps(Gait.from_optimum(optimum, Robot.paper()).to_dict()))


def test_gait_file_round_trip_with_provenance(content, tmp_path):
    """A written gait file reads back; it records the versions that produced it."""
    path = gait_file.write_json(tmp_path / "g.json", content)
    gait = gait_file.read(path)
    assert gait.knee == "rolling" and gait.samples.q.shape[1] == 9
    record = gait.provenance
    assert record["package"] == PACKAGE and record["version"]
    assert record["numpy"] and record["scipy"] and record["python"] and record["command"]
    assert {"casadi", "mujoco", "platform"} <= set(record)


def _corrupt(content, tmp_path, change):
    return refusal(gait_file.read, edited_gait_file(content, tmp_path, change, "edited.json"))


def test_nan_in_samples_is_named_not_finite(content, tmp_path):
    """A NaN in samples.q names samples.q, where, and says it is not finite."""
    edited = json.loads(json.dumps(content))
    edited["samples"]["q"][5][2] = float("nan")
    path = tmp_path / "nan.json"
    path.write_text(json.dumps(edited))  # NaN, as Python's json writes it
    with pytest.raises(BipedError, match=r"samples\.q\[5, 2\] = nan is not finite"):
        gait_file.read(path)


def test_short_samples_t_blames_samples_t(content, tmp_path):
    """A samples.t shorter than the other samples is the one named."""
    message = _corrupt(content, tmp_path, lambda g: g["samples"]["t"].pop())
    assert "samples.t has" in message and "the other samples" in message


def test_short_samples_q_blames_samples_q(content, tmp_path):
    """The field that differs from the others is named, whichever it is."""
    message = _corrupt(content, tmp_path, lambda g: g["samples"]["q"].pop())
    assert "samples.q has" in message


def test_unwalkable_speed_names_the_field(content, tmp_path):
    """A speed of 50 m/s names the field speed and what is allowed."""

    def change(gait):
        gait["speed"] = 50
        gait["step_length"] = 50 * gait["period"]

    message = _corrupt(content, tmp_path, change)
    assert "speed = 50" in message and "allowed" in message


@pytest.mark.parametrize(
    "change, needle",
    [
        (lambda g: g.update(step_length=g["step_length"] * 2), "step_length"),
        (lambda g: g.update(speed=1e-9, step_length=1e-9 * g["period"]), "speed = 1e-09"),
        (lambda g: g["costs"].update(sthenic=10**400), "costs"),
        (lambda g: g["robot"].update(trunk_mass=1e308), "trunk_mass"),
        (lambda g: g["samples"].update(zmp=[[0.0]] * len(g["samples"]["t"])), "samples.zmp"),
        (lambda g: g["samples"].pop("wrench"), "samples.wrench missing"),
        (lambda g: g["optimizer"].pop("starts"), "optimizer.starts missing"),
        (lambda g: g["optimizer"].update(iterations="many"), "optimizer is not a solver's"),
        (lambda g: g.update(constraints=[1.0]), "constraints = [1.0], allowed an object"),
        (lambda g: g.update(impact="none"), "impact = 'none', allowed an object"),
        (lambda g: g["samples"].update(t=[-x for x in g["samples"]["t"]]), "samples.t"),
        (lambda g: g.update(period=g["period"] * 2, step_length=g["step_length"] * 2), "period"),
    ],
)
def test_bad_fields_are_named(content, tmp_path, change, needle):
    """Inconsistent or absurd fields are refused naming the field and the file."""
    assert needle in _corrupt(content, tmp_path, change)


def test_deeply_nested_json_is_one_error(tmp_path):
    """JSON nested beyond Python's recursion limit is refused as invalid JSON."""
    path = tmp_path / "deep.json"
    path.write_text("[" * 100_000 + "]" * 100_000)
    with pytest.raises(BipedError, match="not valid JSON"):
        gait_file.read(path)


def _other_files() -> dict:
    """The content of each of the project's other JSON files, as its writer makes it, by
    what the refusal must call it."""
    from biped.model.criteria import PAPER_SAFETY
    from biped.studies import design_map, paper_method, sweep
    from validate.checks.checks import Check
    from validate.checks.validation import validation_report
    from validate.studies import robustness

    robot = Robot.paper()
    limits = {
        name: robustness.Limit(name, "1", (0.0, 1.0), 0.5, 0.6, ("fell",), False, 4)
        for name in robustness.LIMITS
    }
    walked = robustness.RobustnessMap(
        robustness.RobustnessSettings(), 0.6, 1.5, 1.0, 30.0, (), limits
    )
    report = validation_report(
        [Check("model", True, {}), Check("inverse_dynamics", True, {"max_zmp_error": 0.0})]
    ).to_dict()
    point = design_map.MapPoint("revolute", 0.3)
    return {
        "a sweep's record": sweep.Settings(robot, PAPER_SAFETY, (0.3,), 0, 1).to_dict(),
        "a design map's record": design_map.MapSettings(
            robot, "sthenic", PAPER_SAFETY, (0.3,), (0.0,), (0.0,), (0.05, 0.05), 0, 1
        ).to_dict(),
        "the record of the paper's method's runs": paper_method.PaperMethod(
            robot, PAPER_SAFETY, 0.3, 1
        ).to_dict(),
        "a robustness map": {"gait": "logs/rk.json", **walked.to_dict()},
        "a validation report": {**report, "gait": "logs/rk.json"},
        "the validation reports of several gait files": {"a.json": report, "b.json": report},
        "one optimization of a design map": {
            "point": design_map._point_dict(point),
            "certified": True,
        },
        **_more_other_files(),
    }


def _more_other_files() -> dict:
    """The atlas's records, the table of optima, the catalog, an orbit study and a
    recording's owner record, as their writers make them, by what the refusal must call
    them."""
    from importlib import resources

    from biped.records.atlas_optimum import AtlasOptimum
    from biped.studies import atlas
    from validate.checks.units import OrbitFigures
    from validate.outputs.outputs import claim
    from validate.studies import orbit_study

    def shipped(package, name):
        return json.loads(resources.files(package).joinpath(name).read_text())

    optimum = small_optimum("rolling")
    gait = Gait.from_optimum(optimum, Robot.paper())
    settings = atlas.Settings(
        Robot.paper(), (0.3,), (0.0,), (0.0,), ("sthenic",), 1, 0, 1
    ).to_dict()
    with tempfile.TemporaryDirectory() as folder:
        source = gait.write(Path(folder) / "g.json")
        owner = json.loads(claim(Path(folder) / "g.rrd", source).read_text())
    return {
        "an atlas's record": settings,
        "one optimization of an atlas": AtlasOptimum.from_optimum(optimum, 1.0).to_dict(),
        "a table of optima": shipped("biped.optimization", "optima.json"),
        "a catalog of actuators": shipped("biped.model", "catalog.json"),
        "an orbit study": orbit_study.OrbitStudy.of(
            "g.json", gait, None, [None], [orbit_study.StudiedOrbit(None, OrbitFigures("x"))]
        ).to_dict(),
        "a recording's owner record": owner,
    }


@pytest.mark.parametrize("kind", list(_other_files()))
def test_a_file_of_another_kind_is_named_not_called_corrupt(kind, tmp_path):
    """A valid JSON file of another kind is refused in one line saying what it is and what a
    gait file is, never that it is corrupt."""
    path = tmp_path / "other.json"
    path.write_text(json.dumps(_other_files()[kind]))
    with pytest.raises(BipedError) as error:
        gait_file.read(path)
    message = str(error.value)
    assert message.startswith(f"{str(path)!r} is {kind} (which biped ")
    assert f"not a gait file: allowed {gait_file.GAIT_FILE}" in message
    assert "corrupt" not in message and "\n" not in message


def test_a_gait_file_of_another_version_says_so(content, tmp_path):
    """A gait file of another format version is named as such, with the version read."""
    message = _corrupt(content, tmp_path, lambda g: g.update(format="biped-gait/1"))
    assert "has format 'biped-gait/1', another version's" in message
    assert repr(gait_file.FORMAT) in message and "corrupt" not in message


def test_report_and_figures_say_what_the_file_is_and_what_they_take(tmp_path, capsys):
    """`biped report` given a robustness map and `biped figures --sweep` given a design
    map's folder exit 2 with one line naming the file, what it is and what they take."""
    from biped_cli import main

    other = _other_files()
    robustness_map = tmp_path / "logs-rk.json"
    robustness_map.write_text(json.dumps(other["a robustness map"]))
    assert main(["report", str(robustness_map), "--out", str(tmp_path / "reports")]) == 2
    error = capsys.readouterr().err
    assert error.count("\n") == 1 and f"{str(robustness_map)!r} is a robustness map" in error
    assert "allowed a gait file" in error and "corrupt" not in error
    folder = tmp_path / "design-map"
    folder.mkdir()
    (folder / "design-map.json").write_text(json.dumps(other["a design map's record"]))
    (folder / "revolute-0.300.json").write_text(
        json.dumps(other["one optimization of a design map"])
    )
    assert main(["figures", "--sweep", str(folder), "--out", str(tmp_path / "figures")]) == 2
    error = capsys.readouterr().err
    assert error.count("\n") == 1 and "design-map.json' is a design map's record" in error
    assert "allowed --sweep a folder of the gait files that biped sweep writes" in error
    assert not (tmp_path / "figures").exists() and not (tmp_path / "reports").exists()


def test_a_gait_file_of_format_2_without_actuators_reads_with_the_set_of_its_time(
    content, tmp_path
):
    """A gait file of format 2 whose robot names no actuators was computed with the default
    set of its time (``Actuators.legacy``): it reads, consistent, with that set. The same file
    read as format 3 (the catalog's default set) is refused: its electrical figures are not
    the default set's."""
    optimum = small_optimum("rolling")
    legacy = dataclasses.replace(Robot.paper(), actuators=Actuators.legacy())
    problem = dataclasses.replace(optimum.problem, model=Biped(legacy, "rolling"))
    then = checked(problem, None, optimum.report, optimum.parameters)
    old = Gait.from_optimum(then, legacy).to_dict()
    del old["robot"]["actuators"]
    old["units"] = {k: v for k, v in old["units"].items() if not k.startswith("robot.actuators")}
    old["format"] = "biped-gait/2"
    gait = gait_file.read_consistent(gait_file.write_json(tmp_path / "old.json", old))
    assert gait.robot.actuators == Actuators.legacy() != Actuators.default()
    assert gait.costs.electrical == old["costs"]["electrical"]
    assert "## Drive (the earlier default set's actuators" in "\n".join(drive_lines(gait))
    assert committed_model(Biped(gait.robot, "rolling")) == committed_model(gait.biped)
    assert committed_model(gait.biped) is not None  # the body is Table 1's
    old["format"] = gait_file.FORMAT
    message = refusal(gait_file.read_consistent, gait_file.write_json(tmp_path / "new.json", old))
    assert "inconsistent: costs.electrical = " in message


def test_a_gait_file_written_before_the_knee_loads_reads_without_them(content, tmp_path):
    """The knee loads came after format 3's files (an added block, as the electrical figures):
    a file without them reads, consistent, with none (null when written back)."""
    old = json.loads(json.dumps(content))
    del old["knee_loads"]
    old["units"] = {k: v for k, v in old["units"].items() if not k.startswith("knee_loads.")}
    gait = gait_file.read_consistent(gait_file.write_json(tmp_path / "old.json", old))
    assert gait.knee_loads is None and old["format"] == gait_file.FORMAT
    assert gait.to_dict()["knee_loads"] is None


@pytest.mark.parametrize(
    "command, kind",
    [("orbit", "a table of optima"), ("robustness", "one optimization of an atlas")],
)
def test_orbit_and_robustness_name_a_file_of_another_kind(command, kind, tmp_path, capsys):
    """`biped orbit` and `biped robustness` given the table of optima or an atlas's record
    exit 2 with one line naming what it is, never calling it corrupt."""
    from biped_cli import main

    path = tmp_path / "other.json"
    path.write_text(json.dumps(_other_files()[kind]))
    assert main([command, str(path), "--out", str(tmp_path / "out")]) == 2
    error = capsys.readouterr().err
    assert error.count("\n") == 1 and f"{str(path)!r} is {kind} (which biped " in error
    assert "corrupt" not in error and not (tmp_path / "out").exists()


# Reading a gait file in a process where CasADi and MuJoCo cannot be imported (``None`` in
# ``sys.modules`` makes ``import`` raise): its figures recomputed from its parameters and
# checked (``read_consistent``), then the same process trying to load the solver.
_READ_WITHOUT_SOLVER_OR_SIMULATOR = """
import sys
sys.modules["casadi"] = None
sys.modules["mujoco"] = None
from biped.records import gait_file
gait = gait_file.read_consistent(sys.argv[1])
print(gait.costs.sthenic)
try:
    import biped.optimization.optimize
except ImportError:
    print("no solver")
"""


def test_reading_a_gait_file_needs_neither_casadi_nor_mujoco(content, tmp_path):
    """A gait file reads and is checked against its parameters with CasADi and MuJoCo
    blocked (the simulator's side and a reader need no solver); the solver itself does not
    load there (the block holds)."""
    import subprocess
    import sys

    path = gait_file.write_json(tmp_path / "gait.json", content)
    done = subprocess.run(
        [sys.executable, "-c", _READ_WITHOUT_SOLVER_OR_SIMULATOR, str(path)],
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert done.returncode == 0, done.stderr
    value, blocked = done.stdout.split()[:2], done.stdout.splitlines()[1]
    assert float(value[0]) == pytest.approx(content["costs"]["sthenic"], rel=1e-12)
    assert blocked == "no solver"
