"""Motor sizing: a gait's requirements per joint, the lightest combination, refusals."""

import json
from importlib import resources

import numpy as np
import pytest

from biped.model.actuators import AK80_MOTOR, Actuator
from biped.model.sizing import Requirement, choose, load_catalog
from biped_cli.main import main
from tests.conftest import gait_of, optimal_gait


@pytest.fixture(scope="module")
def gait_path(tmp_path_factory):
    """The rolling knee's optimal gait at 0.3 m/s, as a file."""
    path = tmp_path_factory.mktemp("size") / "rolling.json"
    gait_of(optimal_gait("rolling")).write(path)
    return path


def _package_catalog() -> dict:
    return json.loads(resources.files("biped.model").joinpath("catalog.json").read_text())


def _catalog(tmp_path, peak_torque: float, name="weak.json"):
    """The package's catalog with its AK80-6 alone, its peak torque ``peak_torque`` at the
    joint (N·m)."""
    content = _package_catalog()
    entry = next(e for e in content["actuators"] if e["name"] == "AK80-6")
    sheet = entry["datasheet"]
    sheet["peak_torque [N·m]"] = peak_torque
    sheet["rated_torque [N·m]"] = min(sheet["rated_torque [N·m]"], peak_torque)
    content["actuators"] = [entry]
    path = tmp_path / name
    path.write_text(json.dumps(content))
    return path


def test_package_catalog_holds_cited_datasheets():
    """The shipped catalog: integrated actuators of several gear ratios, each cited, every
    field of its datasheet or assumed and named; the default actuator is its AK80-64."""
    catalog = load_catalog()
    assert len(catalog) == 7 and all("http" in c.source for c in catalog)
    assert sorted({c.actuator.gear_ratio for c in catalog}) == [6.0, 8.0, 9.0, 39.0, 64.0]
    ak80_64 = next(c.actuator for c in catalog if c.name == "AK80-64 KV80")
    assert Actuator.default() == ak80_64
    assert (ak80_64.gear_ratio, ak80_64.peak_torque, ak80_64.continuous_torque) == (64, 120, 48)
    assert ak80_64.rotor_inertia == pytest.approx(564.5e-7) and ak80_64.mass == 0.85
    assert ak80_64.max_speed == pytest.approx(75 * 2 * np.pi / 60)  # its no-load speed
    assert ak80_64.coulomb_friction == 4.7  # its back-drive torque


def _printed_precision(value: float) -> float:
    """Half a unit of the last digit a datasheet's figure is printed with, relative."""
    decimals = len(repr(float(value)).split(".")[1].rstrip("0")) if "." in repr(value) else 0
    return 0.5 * 10.0**-decimals / abs(value)


def _motor_constant_errors(content) -> dict:
    """Each entry's k_t / √R against the motor constant K_m its datasheet prints, relative,
    and what the printed digits of the three allow."""
    errors = {}
    for entry in content["actuators"]:
        printed = entry.get("checks", {}).get("motor_constant [N·m/√W]")
        if printed is not None:
            actuator = Actuator.from_datasheet(entry)
            km = actuator.torque_constant / np.sqrt(actuator.resistance)
            sheet = entry["datasheet"]
            allowed = (
                _printed_precision(printed)
                + _printed_precision(sheet["torque_constant [N·m/A]"])
                + 0.5 * _printed_precision(next(v for k, v in sheet.items() if "resistance" in k))
            )
            errors[entry["name"]] = (abs(km / printed - 1.0), allowed)
    return errors


def test_datasheet_figures_agree_with_their_motor_constant():
    """Where a datasheet prints K_m, the k_t and phase-to-phase R read from it (units
    converted) give it within the digits printed: a figure typed or converted wrong does not
    (the AK80-64's resistance read in Ω instead of mΩ)."""
    content = _package_catalog()
    errors = _motor_constant_errors(content)
    assert len(errors) == 5 and all(error <= allowed for error, allowed in errors.values())
    wrong = next(e for e in content["actuators"] if e["name"] == "AK80-64 KV80")
    sheet = wrong["datasheet"]
    sheet["phase_to_phase_resistance [Ω]"] = sheet.pop("phase_to_phase_resistance [mΩ]")
    error, allowed = _motor_constant_errors(content)["AK80-64 KV80"]
    assert error > 0.9 > allowed


def test_a_no_load_speed_beyond_the_back_emf_is_noted():
    """A datasheet's no-load speed is at most the speed at which the back-EMF k_t N θ̇ reaches
    the supply voltage (within the digits printed), or its entry notes that it is not: the
    AK80-64's 75 rpm is 1.42 times what its k_t allows at 48 V (the voltage limit binds)."""
    for entry in _package_catalog()["actuators"]:
        actuator = Actuator.from_datasheet(entry)
        back_emf = actuator.supply_voltage / (actuator.torque_constant * actuator.gear_ratio)
        sheet = entry["datasheet"]
        speed = next(v for k, v in sheet.items() if "speed" in k)
        digits = _printed_precision(sheet["torque_constant [N·m/A]"]) + _printed_precision(speed)
        beyond = actuator.max_speed / back_emf - 1.0 > digits
        assert not beyond or "no-load speed" in entry.get("note", ""), entry["name"]
        if entry["name"] == "AK80-64 KV80":
            assert beyond and actuator.max_speed / back_emf == pytest.approx(1.424, abs=1e-3)


def test_earlier_catalog_of_motors_and_gears_still_reads(tmp_path):
    """A catalog of format biped-actuator-catalog/1: every motor behind every gear, its joint
    torques N η times the motor's."""
    content = {
        "format": "biped-actuator-catalog/1",
        "motors": {"AK80": {**AK80_MOTOR, "source": "https://example.org/ak80"}},
        "gears": [
            {"name": "6:1", "ratio": 6.0, "efficiency": 0.9, "mass": 0.485},
            {"name": "36:1", "ratio": 36.0, "efficiency": 0.81, "mass": 0.605},
        ],
    }
    path = tmp_path / "old.json"
    path.write_text(json.dumps(content))
    catalog = load_catalog(path)
    assert [c.name for c in catalog] == ["AK80 6:1", "AK80 36:1"]
    peak = 36 * 0.81 * AK80_MOTOR["motor_peak_torque"]
    assert catalog[1].actuator.peak_torque == pytest.approx(peak)


def _edit(change):
    """The package's catalog content with its first entry (the AK80-6) changed."""

    def edited():
        content = _package_catalog()
        change(content, content["actuators"][0], content["actuators"][0]["datasheet"])
        return json.dumps(content)

    return edited


def _rename(old, new):
    return lambda c, e, d: d.update({new: d.pop(old)})


@pytest.mark.parametrize(
    "text, needle",
    [
        (
            _edit(_rename("weight [g]", "weight [rpm]")),
            "'weight [rpm]' = 485: allowed 'weight [g]' or 'weight [kg]'",
        ),
        (_edit(_rename("weight [g]", "weight")), "'weight' = 485: allowed 'weight [g]' or"),
        (_edit(_rename("weight [g]", "mass [g]")), "'mass [g]' = 485: allowed a figure of"),
        (_edit(lambda c, e, d: d.update({"no_load_speed [rpm]": 300})), "gives max_speed again"),
        (
            _edit(lambda c, e, d: e["assumed"].update(mass=1.0)),
            "assumed 'mass' = 1.0 gives mass again",
        ),
        (
            _edit(lambda c, e, d: d.update({"weight [g]": -485})),
            "datasheet 'weight [g]' = -485 is invalid: allowed >= 0",
        ),
        (
            _edit(lambda c, e, d: d.update({"peak_torque [N·m]": 1})),
            "datasheet 'peak_torque [N·m]' = 1 is invalid: allowed >= continuous_torque",
        ),
        (_edit(lambda c, e, d: d.update({"weight [g]": 10**400})), "'weight [g]' = 1000"),
        (_edit(lambda c, e, d: d.pop("voltage [V]")), "no supply_voltage: allowed each field"),
        (_edit(lambda c, e, d: e.pop("source")), "actuators[0].source = None: allowed a text"),
        (
            _edit(lambda c, e, d: e.update(asumed={})),
            "actuators[0] has 'asumed': allowed name, source",
        ),
        (
            _edit(lambda c, e, d: c["actuators"].append("AK80")),
            "actuators[7] = 'AK80': allowed a table",
        ),
        (
            _edit(lambda c, e, d: c["actuators"].append(dict(e))),
            "actuators[7].name = 'AK80-6': allowed a name of its own",
        ),
        (
            _edit(lambda c, e, d: c.update(actuators=[])),
            "allowed a list 'actuators' of one entry or more",
        ),
        (
            lambda: '{"format": "biped-actuator-catalog/2", "format": "x"}',
            "key 'format' written twice",
        ),
    ],
)
def test_bad_catalog_entry_is_one_line_naming_it(gait_path, tmp_path, capsys, text, needle):
    """A catalog entry a datasheet does not give (a figure in a unit not its own, given twice,
    out of range, missing, an entry of other keys, a key written twice): one line on stderr
    naming the figure as the file has it, exit 2."""
    path = tmp_path / "bad.json"
    path.write_text(text())
    assert main(["size", str(gait_path), "--catalog", str(path)]) == 2
    err = capsys.readouterr().err.strip()
    assert needle in err and str(path) in err and "\n" not in err and "internal" not in err


def test_requirement_of_both_joints_of_a_kind():
    """A kind's peak and RMS torque cover its stance and swing joint: RMS over two steps."""
    n = 5
    torques = np.zeros((n, 6))
    torques[:, 1], torques[:, 4] = 3.0, -4.0  # the knees
    weights = np.full(n, 0.25)  # a step of 1 s
    r = Requirement.of("knee", torques, np.ones((n, 6)), np.zeros((n, 6)), weights, 1.25)
    assert r.peak_torque == 4.0
    assert r.rms_torque == pytest.approx(np.sqrt((9 + 16) * 1.25 / 2.5))


def test_size_chooses_the_lightest_combination_with_the_margin(gait_path, capsys):
    """biped size gives every joint of the optimal gait the lightest combination meeting
    its requirements by 20 %, and the total mass of six actuators."""
    assert main(["size", str(gait_path)]) == 0
    out = capsys.readouterr().out
    assert out.count("AK80-6 (0.485 kg") == 3  # the nearly passive optimum: the lightest
    assert "total actuator mass: 2.910 kg" in out


def test_torque_above_every_peak_is_refused_naming_joint_and_limit(gait_path, tmp_path, capsys):
    """A catalog whose motors' peak torque is below the gait's: the joint and the limit are
    named, exit 1."""
    catalog = _catalog(tmp_path, peak_torque=2.7)
    assert main(["size", str(gait_path), "--catalog", str(catalog)]) == 1
    out = capsys.readouterr().out
    assert "no combination drives the hip: peak torque" in out
    assert "no combination drives the knee" not in out  # its 2.1 N·m x 1.2 fits


def test_choose_names_every_limit_no_candidate_meets():
    """Torque and speed both beyond the catalog: both named."""
    n = 3
    torques, rates = np.full((n, 6), 500.0), np.full((n, 6), 100.0)
    r = Requirement.of("ankle", torques, rates, np.zeros((n, 6)), np.full(n, 0.1), 0.3)
    choice = choose(r, load_catalog(), 0.2)
    assert choice.candidate is None
    assert "peak torque 500" in choice.reason and "peak speed 100" in choice.reason


@pytest.mark.parametrize(
    "content, needle",
    [("{", "not valid JSON"), ('{"format": "x"}', "biped-actuator-catalog/2")],
)
def test_bad_catalog_is_one_line_exit_2(gait_path, tmp_path, capsys, content, needle):
    """A catalog that is not one: one line on stderr naming it, exit 2."""
    path = tmp_path / "bad.json"
    path.write_text(content)
    assert main(["size", str(gait_path), "--catalog", str(path)]) == 2
    err = capsys.readouterr().err.strip()
    assert needle in err and str(path) in err and "\n" not in err


def test_size_warns_of_a_single_start_optimum_and_its_comparison(tmp_path, capsys):
    """A gait whose optimum one start alone reached: a warning on stderr naming the file and
    --starts, as biped optimize gives, and the knees' comparison says it is not certified;
    of two confirmed optima, neither."""
    import dataclasses

    gaits = {knee: gait_of(optimal_gait(knee)) for knee in ("rolling", "revolute")}
    assert all(g.optimizer.starts_at_best >= 2 for g in gaits.values())
    paths = [g.write(tmp_path / f"{knee}.json") for knee, g in gaits.items()]
    assert main(["size", *map(str, paths)]) == 0
    out, err = capsys.readouterr()
    assert "warning" not in err and "not a certified comparison" not in out
    rolling = gaits["rolling"]
    single = dataclasses.replace(
        rolling, optimizer=dataclasses.replace(rolling.optimizer, starts_at_best=1)
    )
    single.write(paths[0])
    assert main(["size", *map(str, paths)]) == 0
    out, err = capsys.readouterr()
    assert f"warning: {paths[0]}: its optimum is reached by a single start" in err
    assert "more --starts" in err and str(paths[1]) not in err
    [line] = [line for line in out.splitlines() if line.startswith("  rolling vs revolute")]
    assert line.endswith(
        "; not a certified comparison (rolling: reached by a single start (1 of "
        f"{rolling.optimizer.starts} starts))"
    )
