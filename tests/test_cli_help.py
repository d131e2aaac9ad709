"""The ``biped`` parsers, walked option by option: negative numbers reach every number check,
every option says what it is, its unit and its default, and the terms of the help are defined.
"""

import argparse

import pytest

from biped_cli import main
from biped_cli.args import (
    CERTIFIED_HELP,
    CRITERION_HELP,
    VALUE_MARK,
    numbers_as_values,
    value_text,
)
from biped_cli.main import build_parser

# Number-like values with a minus sign, in the forms the number options take.
NEGATIVE = ("-1", "-0.1", "-.5", "-1e-3", "-0.1,0.2", "-0.1:0.3:3", "-inf")
# Argument types of quantities with a unit, and the unit their help must name.
UNITS = {"speed": "m/s", "speeds": "m/s", "metres": "[m]", "radii": "[m]"}


def _options():
    """(command, action) of every option of every command, but --help and --debug."""
    parser = build_parser()
    found = []
    for name, command in parser.command_parsers.items():
        for action in command._actions:
            if isinstance(action, argparse._HelpAction) or action.dest == "debug":
                continue
            found.append((name, command, action))
    return found


def _typed():
    """Options whose values go through a type: every option taking a number."""
    return [
        pytest.param(name, action.option_strings[0], id=f"{name} {action.option_strings[0]}")
        for name, _, action in _options()
        if action.option_strings and action.type is not None
    ]


def _help(command, action) -> str:
    """The help of ``action`` as --help prints it (%(default)s and the like expanded)."""
    return command._get_formatter()._expand_help(action) if action.help else ""


def _documented():
    return [
        pytest.param(command, action, id=f"{name} {'/'.join(action.option_strings) or action.dest}")
        for name, command, action in _options()
    ]


@pytest.mark.parametrize("value", NEGATIVE)
@pytest.mark.parametrize("command, option", _typed())
def test_negative_numbers_reach_the_number_check(command, option, value):
    """A negative number after any typed option, spelt '--opt V' or '--opt=V', is handed to
    that option's own check, never read as an unknown option."""
    for argv in ([command, option, value], [command, f"{option}={value}"]):
        parser = build_parser()
        action = next(
            a for a in parser.command_parsers[command]._actions if option in a.option_strings
        )
        seen = []
        check = action.type

        def spy(text, check=check, seen=seen):
            seen.append(text)
            return check(text)

        action.type = spy
        try:
            parser.parse_args(argv)
        except SystemExit:
            pass  # a refused value, or a required option left out: either way after the check
        assert seen == [value], argv


def test_negative_speeds_are_named_in_both_spellings(capsys):
    """`sweep --speeds -0.1,0.2` and `--speeds=-0.1,0.2` both say the speeds must be > 0."""
    for argv in (["sweep", "--speeds", "-0.1,0.2"], ["sweep", "--speeds=-0.1,0.2"]):
        assert main(argv) == 2
        err = capsys.readouterr().err.strip()
        assert len(err.splitlines()) == 1 and "'-0.1,0.2'" in err and "> 0" in err, err


def test_negative_numbers_are_given_to_their_option():
    """A negative number after an option taking a value becomes its value ('='); one of
    several values (``--vary KNOB SCALES``) is marked and read back as given; a number after
    a flag, a word and what follows ``--`` are left as they are."""
    takes = {"--speeds": None, "--vary": 2, "--connect": "?"}
    given = ["--speeds", "-0.1,0.2", "--vary", "kp", "-1", "--connect", "-inf", "--json", "-1"]
    out = numbers_as_values(given + ["--", "--speeds", "-2"], takes)
    assert out[:5] == ["--speeds=-0.1,0.2", "--vary", "kp", VALUE_MARK + "-1", "--connect=-inf"]
    assert out[5:] == ["--json", "-1", "--", "--speeds", "-2"]
    assert [value_text(v) for v in out[1:4]] == ["--vary", "kp", "-1"]
    assert numbers_as_values(["--vary", "-1", "2"], takes) == ["--vary", VALUE_MARK + "-1", "2"]


@pytest.mark.parametrize("command, action", _documented())
def test_every_option_says_what_it_is_and_its_default(command, action):
    """Every option has a help text; one with a default (not a flag, not required) states it,
    the value itself when it is a number or a word; one taking a value has a metavar of its
    own or lists its choices; one of a quantity with a unit names the unit."""
    text = _help(command, action)
    assert text.strip(), "no help"
    flag = action.nargs == 0
    if not flag and not action.required:
        assert "default" in text, text
        default = action.default
        if isinstance(default, (int, float, str)) and not isinstance(default, bool):
            shown = f"{default:g}" if isinstance(default, float) else str(default)
            assert shown in text, (shown, text)
    if not flag and action.choices is None:
        assert action.metavar is not None and action.metavar != action.dest.upper(), action.metavar
    unit = UNITS.get(getattr(action.type, "__name__", ""))
    if unit:
        assert unit in text, text


def test_criterion_and_certified_are_defined_where_used():
    """Every command with a criterion option defines both criteria with their units and the
    default; every command whose help says 'certified' defines it."""
    parser = build_parser()
    for name, command in parser.command_parsers.items():
        page = " ".join(command.format_help().split())
        if "--criterion" in page or "--criteria" in page:
            assert " ".join(CRITERION_HELP.split()) in page, name
            assert "N²·m·s" in page and "per metre walked" in page and "[J" in page, name
            assert "default sthenic" in page or "default: sthenic" in page, name
        if "certified" in page:
            assert " ".join(CERTIFIED_HELP.split()) in page, name


@pytest.mark.parametrize(
    "argv, named",
    [
        (["design-map", "--speeds", "0.3,0.3"], "speeds: 0.3 m/s given twice"),
        (["design-map", "--speeds", "0.3001,0.3004"], "0.3001 and 0.3004 m/s are both 0.300"),
        (["sweep", "--speeds", "0.2,0.3,0.2"], "speeds: 0.2 m/s given twice"),
        (["design-map", "--r1", "0.1,0.05,0.1"], "r1: 0.1 m given twice"),
    ],
)
def test_a_repeated_value_is_named(capsys, tmp_path, argv, named):
    """A list of speeds or radii that must be distinct names the value given twice (or the
    two that share a file name), in one line, exit 2, nothing written."""
    out = tmp_path / "out"
    assert main([*argv, "--out", str(out)]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and named in err and "allowed" in err, err
    assert not out.exists()


def test_a_solver_command_imports_neither_mujoco_nor_scipy(tmp_path):
    """``biped optimize`` parses and runs without importing what other commands' options or
    the paper's method need (MuJoCo, scipy, matplotlib: 0.8 s of every process); those
    commands' parsers still get their options when they are looked up."""
    import subprocess
    import sys

    script = (
        "import sys\n"
        "from biped_cli.main import build_parser, main\n"
        "status = main(['optimize', '--knee', 'revolute', '--speed', '0.3', '--starts', '1',\n"
        f"              '--out', {str(tmp_path / 'gait.json')!r}])\n"
        "print(status, sorted({m.split('.')[0] for m in sys.modules} & "
        "{'mujoco', 'scipy', 'matplotlib'}))\n"
        "orbit = build_parser().command_parsers['orbit']\n"
        "print(any('--phases' in a.option_strings for a in orbit._actions))\n"
    )
    lines = subprocess.run(
        [sys.executable, "-c", script], check=True, capture_output=True, text=True
    ).stdout.splitlines()
    assert lines[-2:] == ["0 []", "True"]
