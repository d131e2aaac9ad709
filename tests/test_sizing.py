"""Motor sizing: a gait's requirements per joint, the lightest combination, refusals."""

import json
from importlib import resources

import numpy as np
import pytest

from biped.model.sizing import Requirement, choose, load_catalog
from biped_cli.main import main
from tests.conftest import gait_of, optimal_gait


@pytest.fixture(scope="module")
def gait_path(tmp_path_factory):
    """The rolling knee's optimal gait at 0.3 m/s, as a file."""
    path = tmp_path_factory.mktemp("size") / "rolling.json"
    gait_of(optimal_gait("rolling")).write(path)
    return path


def _catalog(tmp_path, peak_torque: float, name="weak.json"):
    """The package's catalog with one motor whose peak torque is ``peak_torque`` at the
    motor (N·m) and one gear, 6:1."""
    content = json.loads(resources.files("biped.model").joinpath("catalog.json").read_text())
    motor = content["motors"]["AK80"]
    motor["motor_peak_torque"] = peak_torque
    motor["motor_continuous_torque"] = min(motor["motor_continuous_torque"], peak_torque)
    content["gears"] = content["gears"][:1]
    path = tmp_path / name
    path.write_text(json.dumps(content))
    return path


def test_package_catalog_every_motor_behind_every_gear():
    """The shipped catalog gives each motor behind each gear, each motor cited."""
    catalog = load_catalog()
    assert len(catalog) == 5 and all("http" in c.source for c in catalog)
    ratios = sorted(c.actuator.gear_ratio for c in catalog)
    assert ratios == [6.0, 9.0, 36.0, 64.0, 100.0]


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
    assert out.count("AK80 6:1") == 3  # the nearly passive optimum: the lightest for all
    assert "total actuator mass: 2.910 kg" in out


def test_torque_above_every_peak_is_refused_naming_joint_and_limit(gait_path, tmp_path, capsys):
    """A catalog whose motors' peak torque is below the gait's: the joint and the limit are
    named, exit 1."""
    catalog = _catalog(tmp_path, peak_torque=0.5)  # 6 x 0.9 x 0.5 = 2.7 N·m at the joint
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
    [("{", "not valid JSON"), ('{"format": "x"}', "biped-actuator-catalog/1")],
)
def test_bad_catalog_is_one_line_exit_2(gait_path, tmp_path, capsys, content, needle):
    """A catalog that is not one: one line on stderr naming it, exit 2."""
    path = tmp_path / "bad.json"
    path.write_text(content)
    assert main(["size", str(gait_path), "--catalog", str(path)]) == 2
    err = capsys.readouterr().err.strip()
    assert needle in err and str(path) in err and "\n" not in err
