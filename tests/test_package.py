"""Package layout and entry points: the analytical package stays free of the simulator."""

import ast
import os
import sys
import tomllib
from pathlib import Path

import pytest

from biped.records.provenance import DEPENDENCIES, PACKAGE, provenance, version

ROOT = Path(__file__).resolve().parents[1]
# Packages ``biped`` must not import: the MuJoCo side and what only it needs.
FORBIDDEN = ("validate", "mujoco", "rerun", "biped_cli")


# The layers of ``biped``, lowest first: each subpackage imports only those below it.
LAYERS = ("runtime", "model", "optimization", "records", "studies", "pages")
# The layers of ``validate``, lowest first, the same way; ``workflows`` (a module) is the top.
VALIDATE_LAYERS = ("scene", "walk", "checks", "outputs", "studies", "workflows")


def imported_modules(path: Path, depth: int = 1) -> set[str]:
    """Names of the modules a Python file imports, anywhere in it, to ``depth`` parts."""
    names = set()
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"), str(path))):
        if isinstance(node, ast.Import):
            found = [alias.name for alias in node.names]
        elif isinstance(node, ast.ImportFrom) and node.level == 0 and node.module:
            # ``from validate import workflows`` imports the module validate.workflows.
            found = [node.module] + [f"{node.module}.{alias.name}" for alias in node.names]
        else:
            continue
        names.update(".".join(name.split(".")[:depth]) for name in found)
    return names


def upward_imports(root: Path, package: str = "biped", layers: tuple = LAYERS) -> dict:
    """{module: the layers of ``package`` above its own that it imports} of the tree at
    ``root``."""
    found = {}
    for layer in layers:
        above = {f"{package}.{other}" for other in layers[layers.index(layer) + 1 :]}
        for path in sorted((root / package / layer).glob("*.py")):
            offending = sorted(imported_modules(path, depth=2) & above)
            if offending:
                found[str(path.relative_to(root))] = offending
    return found


def test_each_layer_imports_only_the_layers_below_it(tmp_path):
    """No module of a biped subpackage imports a layer above its own (``LAYERS``); a module
    of the optimization layer importing the records layer is named."""
    assert upward_imports(ROOT) == {}
    wrong = tmp_path / "biped" / "optimization"
    wrong.mkdir(parents=True)
    (wrong / "design.py").write_text("from biped.records.gait_file import Gait\n")
    assert upward_imports(tmp_path) == {"biped/optimization/design.py": ["biped.records"]}


def test_each_validate_layer_imports_only_the_layers_below_it(tmp_path):
    """No module of a validate subpackage imports a layer above its own
    (``VALIDATE_LAYERS``), in either form of import; a check importing the walk's
    recording layer, a scene module importing a walk module by ``from validate.walk import``
    and a study importing the workflows are named."""
    assert upward_imports(ROOT, "validate", VALIDATE_LAYERS) == {}
    for layer, source in {
        "checks": "from validate.outputs.record import record\n",
        "scene": "def f():\n    from validate.walk import simulate\n",
        "studies": "from validate import workflows\n",
    }.items():
        (tmp_path / "validate" / layer).mkdir(parents=True)
        (tmp_path / "validate" / layer / "wrong.py").write_text(source)
    assert upward_imports(tmp_path, "validate", VALIDATE_LAYERS) == {
        "validate/checks/wrong.py": ["validate.outputs"],
        "validate/scene/wrong.py": ["validate.walk"],
        "validate/studies/wrong.py": ["validate.workflows"],
    }


def test_validate_modules_sit_in_its_layers():
    """Every module of validate/ is in a layer's subpackage but the package's own
    ``__init__`` and the workflows at the top: a module dropped beside them is outside
    the layer test."""
    loose = sorted(path.name for path in (ROOT / "validate").glob("*.py"))
    assert loose == ["__init__.py", "workflows.py"]
    folders = {path.parent.name for path in (ROOT / "validate").glob("*/*.py")}
    assert folders == set(VALIDATE_LAYERS[:-1])


def test_validate_never_imports_the_command_line():
    """No module of validate/ imports biped_cli: the command line sits above both packages."""
    modules = sorted((ROOT / "validate").rglob("*.py"))
    assert len(modules) > 20
    assert [str(p) for p in modules if "biped_cli" in imported_modules(p)] == []


def test_imported_modules_sees_nested_imports(tmp_path):
    """The import scan finds imports inside functions too (a lazy import counts)."""
    source = tmp_path / "m.py"
    source.write_text("import os.path\ndef f():\n    from validate.scene.mjcf import x\n")
    assert imported_modules(source) == {"os", "validate"}


def test_biped_never_imports_the_simulator():
    """No module of biped/ but __main__.py imports validate, mujoco, rerun or biped_cli."""
    modules = sorted((ROOT / "biped").rglob("*.py"))
    assert len(modules) > 10
    offenders = {
        str(path.relative_to(ROOT)): sorted(imported_modules(path) & set(FORBIDDEN))
        for path in modules
        if path.name != "__main__.py"
    }
    assert {k: v for k, v in offenders.items() if v} == {}


# Names with a leading underscore that a library documents as public.
PUBLIC_BY_DOCS = {"os._exit"}


def private_uses(path: Path) -> list[str]:
    """The private names (one leading underscore) a Python file imports, or reaches as an
    attribute of anything but ``self``, ``cls`` or ``super()``: another module's or
    argparse's internals (``subcommands._name_parser_map``), another object's."""
    found = []
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"), str(path))):
        if isinstance(node, ast.ImportFrom):
            names = [f"{node.module}.{a.name}" for a in node.names if _private(a.name)]
        elif isinstance(node, ast.Attribute) and _private(node.attr):
            base = node.value
            own = isinstance(base, ast.Name) and base.id in ("self", "cls")
            parent = isinstance(base, ast.Call) and ast.unparse(base.func) == "super"
            names = [] if own or parent else [ast.unparse(node)]
        else:
            continue
        found += [f"{path.name}:{node.lineno} {name}" for name in names]
    return [use for use in found if use.split(" ")[1] not in PUBLIC_BY_DOCS]


def _private(name: str) -> bool:
    return name.startswith("_") and not name.endswith("__")


def test_no_module_outside_tests_uses_a_private_name(tmp_path):
    """No module of biped, biped_cli, validate or benchmarks imports a private name or reaches
    one on another object: argparse's internals and another module's are replaced by public
    names; each wrong form is named."""
    modules = [
        p
        for root in ("biped", "biped_cli", "validate", "benchmarks")
        for p in sorted((ROOT / root).rglob("*.py"))
    ]
    assert len(modules) > 50
    assert [use for path in modules for use in private_uses(path)] == []
    wrong = tmp_path / "wrong.py"
    wrong.write_text(
        "import argparse\nfrom biped.studies.sweep import _plan\n"
        "class P(argparse.ArgumentParser):\n    def f(self, commands):\n"
        "        self._mine = super()._get_formatter()\n"
        "        commands._name_parser_map = {}\n"
    )
    assert private_uses(wrong) == [
        "wrong.py:2 biped.studies.sweep._plan",
        "wrong.py:6 commands._name_parser_map",
    ]


def test_entry_points():
    """The biped script is biped_cli:main and every package is installed."""
    project = tomllib.loads((ROOT / "pyproject.toml").read_text())
    assert project["project"]["scripts"]["biped"] == "biped_cli:main"
    assert {"biped", "biped_cli", "validate"} <= set(project["tool"]["setuptools"]["packages"])
    assert "from biped_cli import main" in (ROOT / "biped" / "__main__.py").read_text()


def test_provenance_records_versions_and_command():
    """Provenance holds this package's version, its numerical dependencies' and the command."""
    record = provenance(["biped", "sweep", "--out", "a b"])
    assert record["package"] == PACKAGE and record["version"] == version()
    assert record["command"] == "biped sweep --out 'a b'"
    assert set(DEPENDENCIES) <= set(record) and record["numpy"] and record["scipy"]
    assert record["python"] == ".".join(map(str, sys.version_info[:3]))
    assert version("no-such-distribution-here") is None


def test_provenance_does_not_import_mujoco():
    """Reading MuJoCo's version does not import it (biped stays free of the simulator)."""
    import subprocess

    code = (
        "import sys, biped.records.provenance as p; p.provenance(); print('mujoco' in sys.modules)"
    )
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=60)
    assert done.stdout.strip() == "False", done.stderr


def test_mjcf_check_reports_stale_files_without_rewriting(tmp_path, capsys, monkeypatch):
    """python -m validate.scene.mjcf --check: the repository's models are current (exit 0); a
    changed or missing file is reported and left as it is."""
    from validate.scene import mjcf

    assert mjcf.main(["--check"]) == 0
    assert "up to date" in capsys.readouterr().out
    written = mjcf.write_models(tmp_path)
    assert mjcf.stale_models(tmp_path) == []
    written[0].write_text("<mujoco/>")
    written[1].unlink()
    assert sorted(mjcf.stale_models(tmp_path)) == sorted(written[:2])
    monkeypatch.setattr(mjcf, "FOLDER", tmp_path)
    assert mjcf.main(["--check"]) == 1
    reported = capsys.readouterr().out
    assert str(written[0]) in reported and str(written[1]) in reported
    assert str(written[2]) not in reported
    assert written[0].read_text() == "<mujoco/>" and not written[1].exists()


def test_mjcf_help_exits_0(capsys):
    """python -m validate.scene.mjcf --help documents --check."""
    from validate.scene import mjcf

    with pytest.raises(SystemExit) as exit_info:
        mjcf.main(["--help"])
    assert exit_info.value.code == 0 and "--check" in capsys.readouterr().out


def test_an_installed_copy_carries_the_committed_models(tmp_path):
    """`pip install .` (not editable) installs no mjcf/ folder beside the packages: the wheel
    carries the committed models as validate/models, and an installed copy finds them
    there. (Without them the README's main job failed on a fresh machine: the pipeline
    looked for site-packages/mjcf/scene_revolute.xml.)"""
    import subprocess
    import zipfile

    built = subprocess.run(
        [sys.executable, "-m", "pip", "wheel", "--no-deps", "--no-build-isolation", "-q"]
        + ["-w", str(tmp_path / "wheel"), str(ROOT)],
        capture_output=True,
        text=True,
    )
    assert built.returncode == 0, built.stderr
    (wheel,) = (tmp_path / "wheel").glob("*.whl")
    with zipfile.ZipFile(wheel) as archive:
        archive.extractall(tmp_path / "site")
        names = set(archive.namelist())
    committed = sorted(p.name for p in (ROOT / "mjcf").glob("*.xml"))
    assert len(committed) == 4
    assert {f"validate/models/{name}" for name in committed} <= names
    assert not any(name.startswith("mjcf/") for name in names)
    program = (
        "import biped; from validate.scene.model import committed_model; "
        "print(committed_model(biped.Biped(biped.Robot.paper(), 'rolling')))"
    )
    found = subprocess.run(
        [sys.executable, "-c", program],
        capture_output=True,
        text=True,
        cwd=tmp_path,
        env={**os.environ, "PYTHONPATH": str(tmp_path / "site")},
    )
    assert found.returncode == 0, found.stderr
    path = Path(found.stdout.strip())
    assert path == tmp_path / "site" / "validate" / "models" / "scene_rolling.xml"
    assert path.read_text() == (ROOT / "mjcf" / "scene_rolling.xml").read_text()
