"""Fuzzing the ``biped`` command: whatever the arguments, no traceback and exit 0, 1 or 2.

Argument vectors are drawn (seeded) from the real parser's commands and options, each with at
least one value meant to be wrong. The work itself (optimisation, sweep, MuJoCo, figures) is
replaced by a stand-in that stops the command, so the test checks what happens before it:
every refusal is one line on stderr.
"""

import argparse
import random

import numpy as np
import pytest

from biped_cli import build_parser, main

TRIALS = 300
# Values tried for every option, right or wrong depending on the option.
WORDS = [
    "-1",
    "0",
    "1",
    "3",
    "0.3",
    "0.05",
    "1e-9",
    "1e308",
    "-1e308",
    "nan",
    "inf",
    "-inf",
    "abc",
    "",
    " ",
    "99999999999999999999999",
    "1" * 5000,
    "0.1:0.3:3",
    "0.3:0.1",
    "0:1:0",
    "0.2,0.2",
    "0.2,-0.1",
    "1e999",
    "☃",
    "-",
]


class WorkStarted(BaseException):
    """Raised by the stand-in for the real work: not an Exception, so no guard catches it."""


def _stand_in(*args, **kwargs):
    raise WorkStarted


# The work a command may start, by module: every name bound to one of these functions in a
# module of the project (``from x import optimize`` binds its own) is replaced.
WORK = [
    ("biped.optimization.optimize", "optimize"),
    ("biped.optimization.optimize", "multistart"),
    ("biped.optimization.design", "compare"),
    ("biped.optimization.design", "optimize_design"),
    ("biped.optimization.profile_design", "compare_profile"),
    ("biped.optimization.profile_design", "optimize_profile"),
    ("biped.optimization.two_phase", "optimize_two_phase"),
    ("biped.optimization.ladder", "climb"),
    ("biped.studies.criteria_matrix", "optimize_criteria"),
    ("biped.studies.sweep", "run_sweep"),
    ("biped.studies.two_phase_sweep", "run_two_phase"),
    ("biped.studies.design_map", "run_design_map"),
    ("biped.studies.atlas", "run_atlas"),
    ("biped.studies.atlas_two_phase", "run_two_phase"),
    ("biped.pages.figures", "make_figures"),
    ("validate.checks.validation", "validate"),
    ("validate.studies.robustness", "robustness_map"),
    ("validate.studies.orbit_study", "study"),
]


@pytest.fixture
def no_work(monkeypatch):
    """The optimisers (single and two-phase, knee design and profile, the ladder of gait
    families, each criterion's optimum), the sweep, the design map, the atlas, the figures, the MuJoCo validation, the
    robustness map and the orbit study stop the command, wherever a module bound them."""
    import importlib
    import pkgutil
    import sys

    import biped
    import biped_cli
    import validate

    for package in (biped, biped_cli, validate):
        for module in pkgutil.walk_packages(package.__path__, package.__name__ + "."):
            if not module.name.endswith("__main__"):
                importlib.import_module(module.name)
    work = {id(getattr(importlib.import_module(m), name)) for m, name in WORK}
    assert len(work) == len(WORK)
    for name, module in list(sys.modules.items()):
        if name.split(".")[0] not in ("biped", "biped_cli", "validate"):
            continue
        for attribute, value in list(vars(module).items()):
            if id(value) in work:
                monkeypatch.setattr(module, attribute, _stand_in)


@pytest.fixture
def paths(tmp_path):
    """Files and folders a user might name, and those a command accepts, by option name."""
    files = {
        "robot.toml": b"r1 = 0.08\n",
        "binary.toml": b"r1 = 0.08\n\x89PNG\r\n\x1a\n\x00\xff\xfe",
        "absurd.json": b'{"trunk_mass": 1e308}',
        "flat.toml": b"r1 = 0.0\nr2 = 0.0\n",
        "unknown.toml": b"knee_radius = 0.1\n",
        "list.json": b"[1, 2]",
        "robot.yaml": b"r1: 0.1\n",
        "gait.json": b'{"format": "biped-gait/2", "knee": ',
        "other.json": b"{}",
        "text.txt": b"hello\n",
    }
    for name, content in files.items():
        (tmp_path / name).write_bytes(content)
    (tmp_path / "folder").mkdir()
    anything = [str(tmp_path / name) for name in files] + [
        str(tmp_path / "folder"),
        str(tmp_path / "new" / "out.json"),
        str(tmp_path / "text.txt" / "below.json"),
        str(tmp_path / "missing.toml"),
        "/proc/no/such/place.json",
        "",
    ]
    accepted = {
        "robot": [str(tmp_path / "robot.toml")],
        "out": [str(tmp_path / "new" / "out.json"), str(tmp_path / "new")],
        "rrd": [str(tmp_path / "new" / "walk.rrd")],
        "gait": [str(tmp_path / "gait.json")],
    }
    return anything, accepted


def _commands():
    """Each command's name and its options and positional arguments."""
    parsers = build_parser().command_parsers  # each with every argument
    return {
        name: [
            a
            for a in command._actions
            if not isinstance(a, argparse._HelpAction) and a.dest != "debug"
        ]
        for name, command in parsers.items()
    }


def _accepts(action, text) -> bool:
    try:
        with np.errstate(all="ignore"):
            action.type(text)
    except (argparse.ArgumentTypeError, ValueError, TypeError):
        return False
    return True


def _value(action, paths, rng, good: bool) -> list[str]:
    """Values for one option: accepted by its type or choices if ``good``, else any."""
    anything, accepted = paths
    if action.choices:
        pool = list(action.choices) if good else [*action.choices, "hinge", ""]
    elif action.type is None:
        pool = accepted.get(action.dest, [str(anything[-6])]) if good else anything
    else:
        pool = [w for w in WORDS if _accepts(action, w)] if good else WORDS
    count = rng.randint(1, 3) if action.nargs in ("+", "*") else 1
    if good and action.nargs in ("+", "*") and action.choices:
        return rng.sample(pool, min(count, len(pool)))  # distinct
    return [rng.choice(pool or WORDS) for _ in range(count)]


def _argv(rng, commands, paths, trial):
    """A command with some options given good values, and one option or argument given any
    value (often a wrong one); trial after trial, each option of each command in turn."""
    pairs = [(name, action) for name in sorted(commands) for action in commands[name]]
    name, bad = pairs[trial % len(pairs)]
    actions = commands[name]
    argv = [name]
    for action in actions:
        given = action is bad or not action.option_strings or action.required
        if not given and rng.random() < 0.6:
            continue
        if action.option_strings:
            argv.append(rng.choice(action.option_strings))
        if action.nargs != 0:
            argv += _value(action, paths, rng, good=action is not bad)
    if rng.random() < 0.05:
        argv.append(rng.choice(["--unknown", "-x", "extra"]))
    return argv


def test_no_traceback_escapes_the_cli(capsys, no_work, paths):
    """200 seeded argument vectors: exit 0, 1 or 2 (or the work starts), never a traceback;
    every exit 2 is exactly one line on stderr."""
    rng = random.Random(20240610)
    commands = _commands()
    assert {"demo", "optimize", "sweep", "validate", "pipeline", "figures"} <= set(commands)
    outcomes = {}
    for trial in range(TRIALS):
        argv = _argv(rng, commands, paths, trial)
        try:
            code = main(argv)
        except WorkStarted:
            code = "work"
        captured = capsys.readouterr()
        assert "Traceback" not in captured.err, (argv, captured.err)
        assert code in (0, 1, 2, "work"), (argv, code, captured.err)
        if code == 2:
            lines = captured.err.strip().splitlines()
            assert len(lines) == 1 and lines[0].startswith("biped"), (argv, captured.err)
            assert "internal error" not in lines[0], (argv, lines[0])
        outcomes[code] = outcomes.get(code, 0) + 1
    assert outcomes.get(2, 0) > TRIALS // 3, outcomes
    # valid commands were drawn too: they start the work (only demo ends at once, with 0)
    assert outcomes.get("work", 0) > 10, outcomes


def test_the_stand_in_would_be_caught(capsys, no_work):
    """The fuzz test's stand-in does stop a valid command (so 'work' means work started)."""
    argv = ["optimize", "--knee", "rolling", "--speed", "0.3", "--out", "/tmp/never.json"]
    with pytest.raises(WorkStarted):
        main(argv)
    assert "optimizing" in capsys.readouterr().err
