"""The README and the pages of docs/ show what exists: their images are there and not blank,
every command and option of their command tables is one the program accepts, docs/cli.md
names every command, the README is a short front door linking every page of docs/, and
every page links back to it."""

import re
from pathlib import Path

import numpy as np
import pytest

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


def commands() -> dict:
    """The program's commands, by name, each its parser (with every argument)."""
    return build_parser().command_parsers


def command_rows(text: str) -> list:
    """The rows of a Markdown page's command tables: those starting with "| `biped "."""
    return [line for line in text.splitlines() if line.startswith("| `biped ")]


def check_command_table(rows: list):
    """Each `biped COMMAND --option` of the rows, and each `--option` quoted in a row, parses as
    a command with that option."""
    choices = commands()
    for line in rows:
        cell = line.split("`")[1]
        words = cell.split()
        assert words[1] in choices, cell
        options = {o for a in choices[words[1]]._actions for o in a.option_strings}
        for word in words[2:]:
            if word.startswith("--"):
                assert word.strip("[]") in options, (cell, word)
        for option in re.findall(r"`(--[a-z-]+)", line):
            assert option in options, (cell, option)


def test_command_table_names_real_commands_and_options():
    """Each `biped COMMAND --option` of the README's command table parses as a command with
    that option."""
    rows = command_rows(README)
    assert len(rows) >= 8
    check_command_table(rows)
    assert len(rows) <= 16
    mangled = ["| `biped pipeline --no-such-option` | x |"]
    with pytest.raises(AssertionError):
        check_command_table(mangled)


def test_cli_page_names_every_command_with_real_options():
    """docs/cli.md's table has a row for every command of the program, and each of its
    commands and options parses; a command left out would fail."""
    rows = command_rows((ROOT / "docs" / "cli.md").read_text(encoding="utf-8"))
    check_command_table(rows)
    named = {line.split("`")[1].split()[1] for line in rows}
    assert named == set(commands())


def links(page: Path) -> set:
    """The Markdown pages a page links to (not images, not web addresses), as paths from the
    repository's root, anchors left out."""
    text = page.read_text(encoding="utf-8")
    found = re.findall(r"(?<!!)\[[^\]]*\]\(([^)#]+\.md)(?:#[^)]*)?\)", text)
    targets = set()
    for link in found:
        target = (page.parent / link).resolve()
        targets.add(target.relative_to(ROOT).as_posix() if target.is_relative_to(ROOT) else link)
    return targets


def test_readme_is_a_short_front_door_to_every_page():
    """The README is at most 220 lines, links every page of docs/ and the CHANGELOG, and each
    of its links to a page leads to a file that exists; a page left out or a link to a page
    moved would fail."""
    assert len(README.splitlines()) <= 220
    linked = links(ROOT / "README.md")
    assert {f"docs/{page.name}" for page in DOCS} | {"CHANGELOG.md"} <= linked
    for target in linked:
        assert (ROOT / target).is_file(), target


def test_every_page_links_back_to_the_readme_and_to_pages_that_exist():
    """Each page of docs/ says what it covers and links back to the README in its opening
    lines, and every page it links to exists."""
    assert DOCS
    for page in DOCS:
        opening = "\n".join(page.read_text(encoding="utf-8").splitlines()[:8])
        assert "](../README.md)" in opening, page.name
        for target in links(page):
            assert (ROOT / target).is_file(), (page.name, target)


# A source file named in prose (``validate/walk/simulate.py``) and a module run as a program
# (``python -m validate.scene.mjcf``), a line break allowed after ``-m``.
SOURCE_PATH = re.compile(r"\b((?:biped|biped_cli|validate|benchmarks|tests)/[\w/]+\.py)\b")
PROGRAM = re.compile(r"python\s+-m\s+((?:biped|biped_cli|validate|benchmarks)(?:\.\w+)*)")


def named_sources(text: str) -> set:
    """The source files (paths from the root) that a page names, as files or as programs."""
    modules = {name.replace(".", "/") for name in PROGRAM.findall(text)}
    programs = {m + ".py" if not (ROOT / m).is_dir() else m + "/__main__.py" for m in modules}
    return set(SOURCE_PATH.findall(text)) | programs


def test_source_files_and_programs_the_pages_name_exist():
    """Every source file and every ``python -m`` module the README and docs/ name is in the
    tree (a module moved to a subpackage without its mentions fails); the old place of the
    MJCF writer, ``validate/mjcf.py``, would be named."""
    named = set().union(*(named_sources(p.read_text(encoding="utf-8")) for p in DOCS))
    named |= named_sources(README)
    assert {"validate/walk/simulate.py", "validate/scene/mjcf.py"} <= named
    assert sorted(path for path in named if not (ROOT / path).is_file()) == []
    stale = named_sources("run python -m validate.mjcf --check")
    assert stale == {"validate/mjcf.py"} and not (ROOT / "validate/mjcf.py").exists()


def test_robot_file_example_is_the_catalogs_actuator():
    """docs/actuators.md's robot file reads, its [actuator] the catalog's AK10-9 V3.0 (to the
    digits written), its knees' resistance changed; a field of another actuator would not
    match."""
    import dataclasses
    import tomllib

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


def unnamed_modules(architecture: str) -> list:
    """The modules of the three packages whose name the architecture page does not say."""
    words = set(re.findall(r"\w+", architecture))
    modules = [
        path
        for package in ("biped", "validate", "biped_cli")
        for path in sorted((ROOT / package).rglob("*.py"))
        if path.stem not in {"__init__", "__main__"}
    ]
    return [m.relative_to(ROOT).as_posix() for m in modules if m.stem not in words]


def test_the_architecture_page_names_every_module():
    """docs/architecture.md matches the code: every module of biped/, validate/ and biped_cli/
    is named there (a module added without its place on the page fails, as the page with
    one module's name taken out shows)."""
    page = (ROOT / "docs" / "architecture.md").read_text(encoding="utf-8")
    assert unnamed_modules(page) == []
    assert unnamed_modules(re.sub(r"\bstaging\b", "", page)) == ["biped/studies/staging.py"]
