"""The README and the pages of docs/ show what exists: their images are there and not blank,
and every command and option of the README's command table is one the program accepts."""

import argparse
import re
from pathlib import Path

import numpy as np

from biped_cli import build_parser

ROOT = Path(__file__).resolve().parent.parent
README = (ROOT / "README.md").read_text(encoding="utf-8")
DOCS = sorted((ROOT / "docs").glob("*.md"))


def images(page: Path) -> set:
    """The images a Markdown page shows, as paths from the repository's root."""
    text = page.read_text(encoding="utf-8")
    found = re.findall(r"!\[[^\]]*\]\(([^)]+)\)", text)
    return {(page.parent / image).resolve().relative_to(ROOT).as_posix() for image in found}


def test_images_exist_and_are_not_blank():
    """docs/walk.png (a frame of the walk) is the README's picture, docs/constraints.png (a
    figure) is shown on a page of docs/, every figure of docs/ is shown somewhere, and every
    image shown has ink; a flat image would not."""
    from PIL import Image

    assert images(ROOT / "README.md") == {"docs/walk.png"}
    shown = set().union(images(ROOT / "README.md"), *(images(page) for page in DOCS))
    assert "docs/constraints.png" in set().union(*(images(page) for page in DOCS))
    assert {f"docs/{p.name}" for p in (ROOT / "docs").glob("*.png")} <= shown
    for image in shown:
        pixels = np.asarray(Image.open(ROOT / image).convert("RGB"), dtype=float)
        assert pixels.std() > 20, image
    assert np.zeros((4, 4, 3)).std() == 0.0


def test_command_table_names_real_commands_and_options():
    """Each `biped COMMAND --option` of the command table parses as a command with that
    option."""
    parser = build_parser()
    sub = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction))
    table = [line for line in README.splitlines() if line.startswith("| `biped ")]
    assert len(table) >= 8
    for line in table:
        cell = line.split("`")[1]
        words = cell.split()
        assert words[1] in sub.choices, cell
        options = {o for a in sub.choices[words[1]]._actions for o in a.option_strings}
        for word in words[2:]:
            if word.startswith("--"):
                assert word.strip("[]") in options, (cell, word)
        for option in re.findall(r"`(--[a-z-]+)", line):
            assert option in options, (cell, option)


def test_robot_file_example_is_the_catalogs_actuator():
    """docs/actuators.md's robot file reads, its [actuator] the catalog's AK10-9 V3.0 (to the
    digits written), its knees' resistance changed; a field of another actuator would not
    match."""
    import dataclasses
    import tomllib

    import pytest

    from biped import Robot
    from biped.model.actuators import package_catalog

    page = (ROOT / "docs" / "actuators.md").read_text(encoding="utf-8")
    text = re.search(r"```toml\n(.*?)```", page, re.S).group(1)
    values = tomllib.loads(text)
    robot = Robot.from_mapping(values)
    catalog = package_catalog()["AK10-9 V3.0 KV60"]
    ankle = dataclasses.asdict(robot.actuators.ankle)
    assert ankle == pytest.approx(dataclasses.asdict(catalog), rel=1e-4)
    assert robot.actuators.knee == dataclasses.replace(robot.actuators.ankle, resistance=0.3)
    other = dataclasses.asdict(package_catalog()["AK70-9 V3.0 KV60"])
    assert ankle != pytest.approx(other, rel=1e-4)
