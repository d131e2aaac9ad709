"""biped report of a two-phase gait: its page names both phases beside the single support
optimum, draws both phases over the whole step with the double support shaded over exactly
its share, says the checks not run as unknown, and leaves single-support pages as they were."""

import dataclasses
import json
from pathlib import Path

import numpy as np
import pytest
from matplotlib.patches import Rectangle

from biped import Robot
from biped.pages import two_phase_figures as tpf
from biped.pages.page import FIGURE_NAMES, Page, markdown, page_figures
from biped.records.gait_file import Gait
from biped_cli import main
from tests.conftest import gait_of, optimal_gait, two_phase_gait

NOT_BUILT = "not run: MuJoCo's walk of a two-phase gait is not built"


@pytest.fixture(scope="module")
def written(tmp_path_factory):
    """A two-phase gait file with a validation report beside it (three checks not run) and
    the single support optimum of its knee and speed, both given to 'biped report'."""
    root = tmp_path_factory.mktemp("two-phase-page")
    gait = two_phase_gait("rolling")
    two, single = root / "two.json", root / "single.json"
    gait.write(two)
    gait_of(optimal_gait("rolling"), Robot.paper()).write(single)
    report = {
        "model": {"mass_difference": 0.0, "problems": 0, "passed": True},
        **{
            name: {"passed": False, "notes": [NOT_BUILT], "causes": ["not run"]}
            for name in ("forward", "gains", "orbit")
        },
        "passed": False,
        "units": {"model.mass_difference": "kg", "model.problems": "1"},
    }
    (root / "two.report.json").write_text(json.dumps(report))
    out = root / "pages"
    assert main(["report", str(two), str(single), "--out", str(out)]) == 0
    return gait, out, (out / f"{two.parent.name}-two.md").read_text()


def test_page_names_both_phases_beside_the_single_support_optimum(written):
    """The page names both phases, the landing and its impulses per foot, each foot's
    margins, and the share, step length, cadence and joints' work per metre beside the single
    support optimum's."""
    gait, _, text = written
    single = gait_of(optimal_gait("rolling"), Robot.paper())
    assert "single support then double support" in text
    assert "## Landing" in text and "an impact that stops both feet" in text
    assert "| rear |" in text and "| front |" in text and "Ix [N·s]" in text
    ix, iz = gait.double_support.landing_impulse[3:5]  # the front foot's
    assert f"| {abs(ix) / iz:.3g} |" in text  # the friction its landing needs
    share = gait.double_support.share
    assert f"| double support's share T_ds / (T + T_ds) | {share:.4g} | 0 | 1 |" in text
    step = gait.period + gait.double_support.duration
    assert f"| cadence | {60 / step:.4g} | {60 / single.period:.4g} | steps/min |" in text
    assert f"| step length S | {gait.step_length:.4g} | {single.step_length:.4g} | m |" in text
    work = gait.double_support.energy_per_metre, single.costs.energy_per_metre
    assert f"per metre C_E / S over the step | {work[0]:.4g} | {work[1]:.4g} | J/m |" in text
    for name in gait.parameters:
        assert f"| {name} | " in text


def test_page_figures_exist_and_are_not_blank(written):
    """Each figure of both phases is linked from the page, written, and has ink."""
    from PIL import Image

    _, out, text = written
    folder = next(p for p in out.iterdir() if p.is_dir() and p.name.endswith("-two"))
    for name in tpf.FIGURE_NAMES:
        assert f"({folder.name}/{name})" in text
        pixels = np.asarray(Image.open(folder / name).convert("RGB"))
        assert pixels.std() > 20, name


def test_checks_not_run_are_unknown_never_passed(written):
    """The validation's checks not built for two phases read NOT RUN (unknown), the verdict
    says how many of those run pass."""
    _, _, text = written
    assert "1 of the 1 checks run pass; not run, unknown: forward, gains, orbit" in text
    for name in ("forward", "gains", "orbit"):
        assert f"### {name}: NOT RUN (unknown)" in text
        assert f"### {name}: PASS" not in text


def _shaded(figure) -> list[tuple[float, float]]:
    """The double support's shading of each panel: (start, end) in t / (T + T_ds)."""
    spans = []
    for ax in figure.axes:
        patches = [p for p in ax.patches if p.get_label() == tpf.SHADE_LABEL]
        assert len(patches) == 1
        patch = patches[0]
        if isinstance(patch, Rectangle):
            spans.append((patch.get_x(), patch.get_x() + patch.get_width()))
        else:  # a polygon spanning the axes' height
            x = patch.get_xy()[:, 0]
            spans.append((float(x.min()), float(x.max())))
    return spans


def _share_of(gait) -> float:
    """T_ds / (T + T_ds) from the gait's parameters."""
    period, dwell = gait.parameters["period"], gait.parameters["double_support"]
    return dwell / (period + dwell)


def test_shading_spans_exactly_the_phase_share():
    """On every panel the shading ends the step and spans the double support's share, which
    the file's parameters give; the double support's samples are drawn inside it and the
    single support's outside. A gait whose phase lasts otherwise is shaded otherwise."""
    gait = two_phase_gait("rolling")
    share = _share_of(gait)
    assert gait.double_support.share == pytest.approx(share, rel=1e-12)
    for name, figure in tpf.two_phase_figures(gait).items():
        for start, end in _shaded(figure):
            assert end == pytest.approx(1.0, abs=1e-12), name
            assert end - start == pytest.approx(share, rel=1e-9), name
    start, end = tpf.phase_span(gait)
    assert tpf.double_time(gait)[[0, -1]] == pytest.approx([start, end], abs=1e-12)
    assert tpf.single_time(gait).max() == pytest.approx(start, abs=1e-12)
    longer = dataclasses.replace(gait.double_support, duration=2.0 * gait.double_support.duration)
    wrong = dataclasses.replace(gait, double_support=longer)
    (start, end), *_ = _shaded(tpf.two_phase_figures(wrong)[tpf.TORQUES])
    assert abs((end - start) - share) > 0.05  # the check above would fail it


def test_a_single_support_page_is_unchanged():
    """A gait of single support gets the same figures and no word of a double support."""
    gait = gait_of(optimal_gait("rolling"), Robot.paper())
    assert not gait.two_phase
    page = Page(name="single", source=Path("logs/pipeline/single.json"), gait=gait)
    assert list(page_figures(page)) == list(FIGURE_NAMES)
    text = markdown(page, Path("logs/reports"))
    assert "double support" not in text and "## Parameters" in text


def test_a_two_phase_page_does_not_take_a_single_support_gait_of_another_speed(written):
    """The single support shown beside is of the same knee, robot and speed, else none."""
    from biped.pages.two_phase_page import single_of

    gait = two_phase_gait("rolling")
    single = gait_of(optimal_gait("rolling"), Robot.paper())
    assert single_of(gait, [gait, single]) is single
    assert single_of(gait, [dataclasses.replace(single, speed=0.31)]) is None
    assert single_of(gait, [dataclasses.replace(single, knee="revolute")]) is None
    assert isinstance(single, Gait)


def test_a_zero_speed_landing_is_said_without_impulses():
    """A zero-speed landing's page says nothing jumps and draws its landing as such."""
    from biped.pages.two_phase_page import two_phase_markdown

    gait = two_phase_gait("rolling", landing="zero-speed")
    page = Page(name="zero", source=Path("logs/zero.json"), gait=gait)
    text = two_phase_markdown(page, Path("logs/reports"))
    assert "at zero foot speed" in text and "Ix [N·s]" not in text
    figure = tpf.two_phase_figures(gait)[tpf.TORQUES]
    labels = {line.get_label() for ax in figure.axes for line in ax.lines}
    assert "landing (zero-speed)" in labels
