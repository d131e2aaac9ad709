"""Checks declared with their options (``biped_cli.checks``): every option naming an output
is declared with its check, and ``biped_cli.main`` runs a command's declared checks before
the command, rules first, then the outputs' checks, then their claims."""

import argparse
from pathlib import Path

import pytest

from biped.errors import BipedError
from biped.runtime import claims
from biped_cli import checks, main
from biped_cli.main import build_parser
from tests.test_claims import held_elsewhere

# The arguments each command with an output requires, none of them read before its checks
# (the gait files need not exist).
REQUIRED = {
    "optimize": ["--knee", "rolling", "--speed", "0.3"],
    "sweep": [],
    "validate": ["missing.json"],
    "pipeline": [],
    "figures": [],
    "table": [],
    "atlas": [],
    "compare-atlas": ["missing-base", "missing-rich"],
    "converge": ["--speed", "0.3"],
    "criteria": ["--speed", "0.3"],
    "design": ["--speed", "0.3"],
    "design-map": [],
    "profile-speeds": ["missing.json"],
    "report": ["missing.json"],
    "robustness": ["missing.json"],
    "orbit": ["missing.json"],
}
# A path each output is given under a file, "afile": its suffix the one its check allows.
SUFFIX = {"--video": ".mp4", "--rrd": ".rrd"}


def output_options(parser) -> list[str]:
    """The options of ``parser`` whose help says they name an output (missing folders
    created), and --gif, which names the GIF beside --video."""
    found = []
    for action in parser._actions:
        help = action.help or ""
        if checks.FOLDERS_CREATED in help or checks.FOLDER_CREATED in help:
            found.extend(action.option_strings)
        elif "--gif" in action.option_strings:
            found.append("--gif")
    return found


def undeclared_outputs(parser) -> list[str]:
    """The output options of ``parser`` without a declared check."""
    declared = {c.option for c in checks.declared(parser) if isinstance(c, checks.Output)}
    return [option for option in output_options(parser) if option not in declared]


def _commands():
    return build_parser().command_parsers


def test_every_output_option_of_every_command_is_declared_with_its_check():
    """Each option of each command naming an output is declared with its check, and each
    declared output is an option of its command; an output option added without its check
    is found."""
    seen = 0
    for name, parser in _commands().items():
        options = output_options(parser)
        assert undeclared_outputs(parser) == [], name
        declared = [c.option for c in checks.declared(parser) if isinstance(c, checks.Output)]
        assert set(declared) <= set(options), name
        seen += len(options)
    assert seen >= 17
    wrong = argparse.ArgumentParser()
    checks.add_folder(wrong, "--out", "logs/x", "folder of the results")
    wrong.add_argument("--rrd", help=f"a recording ({checks.FOLDERS_CREATED})")
    assert undeclared_outputs(wrong) == ["--rrd"]


def test_every_command_with_an_output_is_covered_here():
    """The table of required arguments names every command with a declared output."""
    with_outputs = {
        name
        for name, parser in _commands().items()
        if any(isinstance(c, checks.Output) for c in checks.declared(parser))
    }
    assert with_outputs == set(REQUIRED)


def _cases():
    for name, parser in _commands().items():
        for option in dict.fromkeys(output_options(parser)):
            if option != "--gif":
                yield name, option


@pytest.mark.parametrize(("command", "option"), list(_cases()))
def test_a_bad_output_path_is_refused_by_its_declared_check_before_the_command(
    command, option, tmp_path, monkeypatch, capsys
):
    """An output under a file, for every output option of every command: exit 2, one line
    naming the option, the path and that a folder is allowed, before the command reads its
    inputs (missing gait files) or writes anything."""
    monkeypatch.chdir(tmp_path)
    Path("afile").write_text("")
    path = f"afile/x{SUFFIX.get(option, '.json')}"
    assert main([command, *REQUIRED[command], option, path]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert err == [
        f"biped {command}: error: {option} {path!r}: 'afile' is a file, allowed a folder"
    ]
    assert sorted(p.name for p in tmp_path.iterdir()) == ["afile"]


@pytest.mark.parametrize(
    ("argv", "made", "line"),
    [
        (
            ["validate", "missing.json", "--video", "walk.mp4", "--gif"],
            "walk.gif",
            "--gif 'walk.gif' is a folder: allowed a file path",
        ),
        (
            ["design", "--speed", "0.3", "--profile", "linear", "--out", "d.json"],
            "d-circles.json",
            "--out 'd-circles.json' is a folder: allowed a file path",
        ),
        (
            ["profile-speeds", "missing.json", "--out", "rows.json"],
            "rows.png",
            "--out 'rows.png' is a folder: allowed a file path",
        ),
    ],
)
def test_an_output_named_from_another_is_checked_with_it(
    argv, made, line, tmp_path, monkeypatch, capsys
):
    """The GIF beside --video, the circles' gait file beside a profile's and the figure
    beside profile-speeds' rows are checked as declared, before the command."""
    monkeypatch.chdir(tmp_path)
    Path(made).mkdir()
    assert main(argv) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert err == [f"biped {argv[0]}: error: {line}"]


def test_rules_come_before_outputs_and_outputs_before_claims(tmp_path, monkeypatch, capsys):
    """A rule broken and an output refused: the rule's line; an output claimed by another
    run and another refused: the refusal's line (a refused run claims nothing)."""
    monkeypatch.chdir(tmp_path)
    argv = ["optimize", "--knee", "rolling", "--speed", "0.3", "--method", "nelder-mead"]
    assert main([*argv, "--starts", "3", "--out", "/dev/null"]) == 2
    assert "--starts 3: IPOPT's" in capsys.readouterr().err
    if claims.fcntl is None:
        return
    Path("afile").write_text("")
    with held_elsewhere(tmp_path / "P"):
        assert main(["pipeline", "--out", "P", "--recordings", "afile/r"]) == 2
        err = capsys.readouterr().err.strip()
        assert err.endswith("--recordings 'afile/r': 'afile' is a file, allowed a folder"), err
        assert main(["pipeline", "--out", "P", "--recordings", "R"]) == 2
        assert "--out 'P' is in use by " in capsys.readouterr().err


def test_outputs_named_from_the_inputs_are_claimed_only_as_declared(tmp_path):
    """claim_derived claims the names of an output declared DERIVED and refuses two gait
    files of one name; an output declared otherwise is a programming error, said."""
    parser = argparse.ArgumentParser()
    checks.add_folder(parser, "--out", str(tmp_path), "maps", claims=checks.DERIVED)
    checks.add_folder(parser, "--recordings", str(tmp_path / "r"), "recordings")
    args = parser.parse_args([])
    with pytest.raises(BipedError, match="would share the map 'a-x'"):
        checks.claim_derived(args, "--out", ["a-x", "b-y", "a-x"], "map")
    with pytest.raises(ValueError, match="--recordings is not declared with outputs derived"):
        checks.claim_derived(args, "--recordings", ["a"], "map")
    with pytest.raises(ValueError, match="--model is not a declared output"):
        checks.claim_derived(args, "--model", ["a"], "map")


def test_an_output_option_must_say_its_folders_are_created():
    """add_out refuses a help that does not say that missing folders are created."""
    with pytest.raises(ValueError, match="--out does not say"):
        checks.add_out(argparse.ArgumentParser(), "--out", checks.FILE, "a gait file")


@pytest.mark.parametrize("command", ["optimize", "sweep", "atlas", "pipeline"])
def test_double_support_alone_is_a_tenth_to_0_4_of_the_step_landing_at_rest(command):
    """``--double-support`` alone asks for a share of 0.1 to 0.4 of the step, and the swing
    foot lands at rest unless ``--landing impact`` is given (the impact landing's optima do
    not walk in MuJoCo); without the option, single support."""
    parser = build_parser().command_parsers[command]
    knee = (
        ["--knee", "rolling", "--speed", "0.3", "--out", "g.json"] if command == "optimize" else []
    )
    alone = parser.parse_args([*knee, "--double-support"])
    assert alone.double_support == (0.1, 0.4) and alone.landing == "zero-speed"
    given = parser.parse_args([*knee, "--double-support", "0.2:0.3", "--landing", "impact"])
    assert given.double_support == (0.2, 0.3) and given.landing == "impact"
    assert parser.parse_args(knee).double_support is None
