"""Options of the ``biped`` command, one helper per option that commands share, and their
argument types: each refuses a bad value with one line naming it."""

from __future__ import annotations

import argparse
import contextlib
import dataclasses
import re
from collections.abc import Mapping
from pathlib import Path

import numpy as np

from biped.errors import BipedError
from biped.model.criteria import (
    ALL_CRITERIA,
    CRITERIA,
    FRICTION_RANGE,
    MAX_CLEARANCE,
    MAX_CLEARANCE_WINDOW,
    MAX_HIP_PROGRESS,
    MAX_JOINT_MARGIN,
    MAX_KNEE_BEND,
    MAX_LANDING_SHARE,
    MAX_LANDING_SPEED,
    MAX_ZMP_MARGIN,
    PAPER_SAFETY,
    WALKABLE,
    Safety,
)
from biped.model.dynamics import Biped
from biped.model.gait import MAX_KNOTS
from biped.model.kinematics import KNEES
from biped.model.robot import Robot
from biped.optimization.comparison import CERTIFIED
from biped.optimization.problem import MIN_SPEED, max_walking_speed
from biped_cli.checks import (  # noqa: F401 (the outputs' words, for the commands)
    FOLDER_CREATED,
    FOLDERS_CREATED,
    SAME_FOLDERS,
    declare_rule,
    distinct_outputs,
)
from validate import DEFAULT_STEPS, MODEL_TIMESTEP, SERVO_KP

ROBOT_HELP = (
    "robot parameters, .json or .toml; fields left out keep Table 1 (default: Table 1); a "
    "table [actuator] sets every joint's motor and gear, [actuators.knee] (ankle, hip) one "
    "kind's (fields left out keep the default actuator's, the AK80-64 of the catalog)"
)
ACTUATOR_LIMITS_HELP = (
    "every joint's torque, speed and voltage within its motor's peak torque, top speed and "
    "supply voltage at every sample: a gait the motors cannot follow is not feasible"
)
_W = WALKABLE
WALKABLE_HELP = (
    "the walkable preset: margins at which MuJoCo's walk of the optimal gaits follows the "
    f"model (the sole lands at {_W.landing_share:g} times the walking speed at most, "
    f"friction {_W.friction:g}, clearance {_W.clearance:g} m, ZMP {_W.zmp_margin:g} m inside "
    f"the sole, hips and ankles {_W.joint_margin:g} rad from their stops, the hip at "
    f"{_W.hip_progress:g} of the walking speed at least; validate/studies/margins_study.py chose "
    "them); an option given replaces the preset's value"
)
SLOW = f"allowed {MIN_SPEED} m/s or faster (a step lasts seconds, so slower steps are mm long)"
# Most speeds of a sweep: each is an optimisation per knee and criterion.
MAX_SPEEDS = 1000
# Most steps of a forward walk in MuJoCo: 1000 steps are about 10 simulated minutes.
MAX_STEPS = 1000
STEPS_HELP = f"steps to walk, 1 to {MAX_STEPS} (default {DEFAULT_STEPS})"
# Most worker processes of a sweep.
MAX_JOBS = 256
SPEED_HELP = (
    f"[m/s] walking speed, {MIN_SPEED} m/s or faster, up to √(g·leg length) "
    f"({max_walking_speed(Biped(Robot.paper(), 'revolute')):.3g} m/s for Table 1's legs)"
)
JOBS_HELP = f"worker processes, 1 to {MAX_JOBS} (default: all cores)"
# The terms of the help pages, defined once (a definition printed whole on every page that
# uses the term; no hyphens, where argparse may break a line).
KNEE_HELP = (
    "revolute: a pin joint; rolling: the paper's rolling knee, a circle of radius r1 on the "
    "shank rolling on a circle of radius r2 on the thigh"
)
CRITERION_HELP = (
    "sthenic (the paper's eq. 30): the squared joint torques integrated over a step and divided "
    "by the step length S, (1/S) ∫ ΓᵀΓ dt, so per metre walked [N²·m·s]; energy (eq. 31): the "
    "absolute work of the joints over a step, ∫ Σ |Γ_i θ̇_i| dt [J per step]; "
    "energy-per-metre: the energy criterion divided by the step length, per metre walked [J/m]; "
    "electrical: the electrical energy the motors draw per metre walked, negative power lost "
    "(no regeneration), from the robot's actuators [J/m]"
)
KNOTS_HELP = (
    "interior knots of each angle's cubic spline: 1, the paper's (21 parameters); K more, "
    "richer gaits of 21 + 12 (K − 1) parameters (an odd K holds the paper's; 1, 3, 7, 15 "
    "each hold the one before)"
)
CERTIFIED_HELP = f"certified: {CERTIFIED}"


def add_command(commands, name: str, help: str, run):
    """The parser of the subcommand ``name`` running ``run``, whose docstring describes it."""
    parser = commands.add_parser(name, help=help, description=run.__doc__)
    parser.set_defaults(run=run)
    return parser


class Commands(Mapping):
    """The subcommands' parsers by name (argparse's ``choices`` of ``add_subparsers``), each
    completed when looked up: its arguments may be added when it is first used
    (``complete_later``), so that a command runs without the imports another's options need
    (MuJoCo's)."""

    def __init__(self, parsers: dict):
        self.parsers = parsers

    def __getitem__(self, name):
        return self.parsers[name].complete()

    def __iter__(self):
        return iter(self.parsers)

    def __len__(self):
        return len(self.parsers)


def complete_later(commands, name: str, complete) -> None:
    """Add the arguments of ``name``'s parser by ``complete(parser)`` when it is first used
    (``commands``: argparse's subcommands, whose parsers are ``biped_cli.main``'s)."""
    commands.choices[name].complete_later(complete)


# An argument argparse must hand to its option as a value, not read as an option: a number
# with a minus sign, alone or first of a list or range (-1, -.5, -1e-3, -0.1,0.2, -0.1:0.3:3,
# -inf). argparse reads only -1 and -0.1 so, and `--speeds -0.1,0.2` failed with "expected one
# argument" before the speeds' check could name the value. No option of the program starts
# like a number.
NEGATIVE_NUMBER = re.compile(r"^-(\.?\d|inf|nan)", re.IGNORECASE)
# Marks a negative number that is one of several values of an option (``--vary kp -1``), which
# argparse would read as an option and which no "=" can join to it; the option's action reads
# the value back with ``value_text``. No argument from a shell holds it.
VALUE_MARK = "\0"


def numbers_as_values(args: list[str], takes: dict) -> list[str]:
    """``args`` with each negative number (``NEGATIVE_NUMBER``) given to the option before it as
    its value: ``--speeds -0.1,0.2`` as ``--speeds=-0.1,0.2``, a value of an option of several
    (``--vary kp -1``) marked (``VALUE_MARK``). ``takes``: {option string: its nargs} of the
    options that take values; what follows ``--`` is left as it is."""
    out = []
    owed = 0  # values still owed to an option of a fixed number of several
    for index, arg in enumerate(args):
        if arg == "--":
            return out + args[index:]
        number = NEGATIVE_NUMBER.match(arg) is not None
        if owed and (number or not arg.startswith("-")):
            out.append(VALUE_MARK + arg if number else arg)
            owed -= 1
        elif number and out and out[-1] in takes:
            out[-1] = f"{out[-1]}={arg}"
        else:
            out.append(arg)
            nargs = takes.get(arg)
            owed = nargs if isinstance(nargs, int) and nargs > 1 else 0
    return out


def value_text(text: str) -> str:
    """A value as it was given (``numbers_as_values`` marks some)."""
    return text.removeprefix(VALUE_MARK)


@contextlib.contextmanager
def naming(prefix: str):
    """Within the block, a BipedError's line begins with ``prefix`` (``gait file 'a.json'``)."""
    try:
        yield
    except BipedError as error:
        raise BipedError(f"{prefix}: {error}") from None


def add_knee(parser, several: bool = False, **kwargs) -> None:
    """``--knee`` (one, required unless ``kwargs`` say otherwise) or ``--knees`` (one or both,
    default both), each knee defined in the help."""
    if several:
        _add_several(parser, "--knees", KNEES, f"knees to optimise, one or both; {KNEE_HELP}")
    else:
        parser.add_argument("--knee", choices=KNEES, help=f"knee kinematic; {KNEE_HELP}", **kwargs)


def add_criterion(parser, several: bool = False, default=CRITERIA) -> None:
    """``--criterion`` (default sthenic) or ``--criteria`` (one or more, default ``default``:
    the paper's two), each criterion defined with its unit in the help."""
    if several:
        help = f"criteria to minimise, one or more; {CRITERION_HELP}"
        _add_several(parser, "--criteria", ALL_CRITERIA, help, default)
    else:
        help = f"criterion to minimise; {CRITERION_HELP} (default %(default)s)"
        parser.add_argument("--criterion", choices=ALL_CRITERIA, default="sthenic", help=help)


def _add_several(parser, option: str, choices: tuple, help: str, default=None) -> None:
    """``option``: distinct ``choices``, one or more (default: ``default``, else all)."""
    default = _DefaultList(choices if default is None else default)
    help += f" (default: {' '.join(default)})"
    parser.add_argument(
        option, nargs="+", choices=choices, default=default, action=Distinct, help=help
    )


def add_knots(parser) -> None:
    """``--knots K``: the gait family (``biped.model.gait.KNOTS``)."""
    parser.add_argument(
        "--knots",
        type=bounded(1, MAX_KNOTS),
        default=1,
        metavar="K",
        help=f"{KNOTS_HELP}; K from 1 to {MAX_KNOTS} (default %(default)s)",
    )


FAMILIES = ("spline", "bezier")


def add_family(parser, then: str = "--degree") -> None:
    """``--family spline|bezier``: the splines' family (``--knots``) or the Bézier curves'
    (``biped.model.bezier``), whose size ``then`` names."""
    parser.add_argument(
        "--family",
        choices=FAMILIES,
        default="spline",
        help=f"the gait family: spline, a cubic spline per angle; bezier, one Bézier curve per "
        f"angle over the whole step ({then}), its ends as the spline's (default %(default)s)",
    )


def add_bezier(parser) -> None:
    """``--family spline|bezier`` and ``--degree n``: the Bézier family
    (``biped.model.bezier``) beside the splines' ``--knots``."""
    from biped.model.bezier import MAX_DEGREE, MIN_DEGREE

    add_family(parser)
    parser.add_argument(
        "--degree",
        type=bounded(MIN_DEGREE, MAX_DEGREE),
        default=None,
        metavar="N",
        help=f"degree of the Bézier curves, {MIN_DEGREE} to {MAX_DEGREE}: 9 + 6 (N − 3) "
        "parameters, each degree holding the ones below (with --family bezier, which asks "
        "for it: no default)",
    )
    declare_rule(parser, ("--degree", "--knots", "--family"), gait_family)


def gait_family(args):
    """The gait family ``--family``, ``--knots`` and ``--degree`` name; a clear error for a
    degree without a Bézier family or knots with one."""
    from biped.model.bezier import Bezier

    if args.family == "spline":
        if args.degree is not None:
            raise BipedError(f"--degree {args.degree} with --family spline: allowed with bezier")
        return args.knots
    if args.knots != 1:
        raise BipedError(f"--knots {args.knots} with --family bezier: allowed --degree N")
    if args.degree is None:
        raise BipedError("--family bezier without --degree: allowed --degree N")
    return Bezier(args.degree)


def double_support_share(text: str) -> tuple[float, float]:
    """``LOW:HIGH``, the least and largest share of the step in double support."""
    from biped.optimization.two_phase import parse_share

    try:
        return parse_share(text)
    except BipedError as error:
        raise argparse.ArgumentTypeError(str(error)) from None


def speed(text: str) -> float:
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"speed = {text!r} is not a number") from None
    if not (np.isfinite(value) and value > 0):
        raise argparse.ArgumentTypeError(f"speed = {text!r} m/s: allowed a finite speed > 0")
    if value < MIN_SPEED:
        raise argparse.ArgumentTypeError(f"speed = {text!r} m/s: {SLOW}")
    return value


def number_list(text: str, name: str, limit: int, unit: str) -> np.ndarray:
    """'START:STOP:COUNT' (COUNT from 1 to ``limit``, START <= STOP) or 'V1,V2,...' as an
    array; ``name`` and ``unit`` name them in the message of a malformed one."""
    try:
        if ":" in text:
            start, stop, count = text.split(":")
            if not 1 <= int(count) <= limit:
                raise argparse.ArgumentTypeError(
                    f"{name} = {text!r}: COUNT = {count}, allowed 1 to {limit}"
                )
            if float(start) > float(stop):  # a range runs upward: a typo, not a descent
                raise argparse.ArgumentTypeError(
                    f"{name} = {text!r}: START {start} > STOP {stop}, allowed START <= STOP"
                )
            return np.linspace(float(start), float(stop), int(count))
        return np.array([float(v) for v in text.split(",")])
    except ValueError:
        raise argparse.ArgumentTypeError(
            f"{name} = {text!r}: allowed START:STOP:COUNT or a comma-separated list{unit}"
        ) from None


def speeds(text: str) -> np.ndarray:
    """'0.15:0.45:13' (start:stop:count) or '0.2,0.3' (a list)."""
    values = number_list(text, "speeds", MAX_SPEEDS, "")
    if values.size == 0 or not np.all(np.isfinite(values) & (values > 0)):
        raise argparse.ArgumentTypeError(f"speeds = {text!r}: allowed finite speeds > 0 m/s")
    if values.size > MAX_SPEEDS:
        raise argparse.ArgumentTypeError(f"speeds = {text!r}: allowed {MAX_SPEEDS} speeds at most")
    if np.any(values < MIN_SPEED):
        raise argparse.ArgumentTypeError(
            f"speeds = {text!r}: {values.min():g} m/s is too slow: {SLOW}"
        )
    return np.round(values, 6)


class _Default(int):
    """An option's default, told apart from the same number given (``given``)."""


class _DefaultList(list):
    """A list option's default, told apart from the same list given (``given``)."""


def given(args, name: str) -> bool:
    """Whether the option ``name`` (its ``args`` attribute) was given on the command line."""
    return not isinstance(getattr(args, name), (_Default, _DefaultList))


def budget(args) -> dict:
    """The keyword arguments of ``biped.optimization.optimize.optimize`` given on the command
    line; an option given that the method would not use is refused (``check_budget``)."""
    check_budget(args)
    return {
        "seed": args.seed,
        "method": args.method,
        "starts": args.starts,
        "nelder_mead_starts": args.nelder_mead_starts,
        "max_restarts": args.restarts,
        "evaluations_per_run": args.evaluations,
    }


def check_budget(args) -> None:
    """Refuse (BipedError) an option of the budget given that the method would not use."""
    nelder_mead = args.method == "nelder-mead" or args.nelder_mead_starts > 0
    unused = [("--nelder-mead-starts", "nelder_mead_starts")]
    if not getattr(args, "design", False):  # the pipeline's design stage is IPOPT's
        unused.insert(0, ("--starts", "starts"))
    if args.method == "nelder-mead":
        for option, name in unused:
            if given(args, name):
                raise BipedError(
                    f"{option} {getattr(args, name)}: IPOPT's, allowed with --method ipopt "
                    "(--method nelder-mead runs the paper's method alone, one start)"
                )
    for option, name in [("--restarts", "restarts"), ("--evaluations", "evaluations")]:
        if given(args, name) and not nelder_mead:
            raise BipedError(
                f"{option} {getattr(args, name)}: Nelder-Mead's, allowed with --method "
                "nelder-mead or --nelder-mead-starts K"
            )


# The options of ``add_safety`` that set a field of ``Safety`` of the same name, each left at
# the preset's value (the paper's, or ``--walkable``'s) unless given.
SAFETY_OPTIONS = (
    "clearance",
    "zmp_margin",
    "knee_bend",
    "clearance_window",
    "landing_speed",
    "landing_share",
    "friction",
    "joint_margin",
    "hip_progress",
)


def safety(args) -> Safety:
    """The safety margins given on the command line: those of ``--walkable`` (``WALKABLE``) or
    the paper's, each replaced by the option given; a landing speed given replaces the
    preset's landing share (one of the two)."""
    preset = WALKABLE if getattr(args, "walkable", False) else PAPER_SAFETY
    given_ = {
        name: getattr(args, name) for name in SAFETY_OPTIONS if getattr(args, name) is not None
    }
    if "landing_speed" in given_ and "landing_share" not in given_:
        given_["landing_share"] = None
    if "landing_share" in given_ and "landing_speed" not in given_:
        given_["landing_speed"] = None
    actuators = getattr(args, "actuator_limits", False) or preset.actuator_limits
    return dataclasses.replace(preset, **given_, actuator_limits=actuators)


def add_budget(parser, sweep: bool = False):
    from biped.optimization.optimize import DEFAULT_STARTS, METHODS
    from biped.optimization.penalty import EVALUATIONS_PER_RUN, MAX_RESTARTS

    parser.add_argument(
        "--method",
        choices=("ipopt",) if sweep else METHODS,
        default="ipopt",
        help="ipopt: exact derivatives, several starts, certified optima (default %(default)s)"
        + (
            "; a sweep's points are certified optima, the paper's method runs beside them "
            "(--paper-seeds)"
            if sweep
            else "; nelder-mead: the paper's penalty method alone, to see where it stops"
        ),
    )
    add_options(
        parser,
        ("--starts", starts, _Default(DEFAULT_STARTS), "N", "IPOPT's own starts"
         + ("" if sweep else " (with --method ipopt, or a pipeline's --design)")
         + f", 1 to {MAX_STARTS}: first guesses of several step periods, then perturbations "
         f"(default {DEFAULT_STARTS}); the table of optima's starts come with them, and for "
         f"the energy criterion take the place of the first {DEFAULT_STARTS} where the table "
         f"covers the problem; {CERTIFIED_HELP}"),
        ("--seed", non_negative, 0, "N",
         "seed of the perturbed starts" + ("" if sweep else " and of Nelder-Mead")
         + " (default 0)"),
    )  # fmt: skip
    if not sweep:  # a sweep's points are IPOPT's alone (the paper's method: --paper-seeds)
        add_options(
            parser,
            ("--nelder-mead-starts", nelder_mead_starts, _Default(0), "K",
             f"IPOPT also starts from the paper's Nelder-Mead with K seeds, 0 to {MAX_SEEDS} "
             "(default 0; with --method ipopt)"),
            ("--restarts", restarts, _Default(MAX_RESTARTS), "N",
             f"Nelder-Mead restarts from the best point at most, 0 to {MAX_SEEDS} (default "
             f"{MAX_RESTARTS}); with --method nelder-mead or --nelder-mead-starts"),
            ("--evaluations", evaluations, _Default(EVALUATIONS_PER_RUN), "N",
             f"criterion evaluations per Nelder-Mead run, 1 to {MAX_EVALUATIONS} (default "
             f"{EVALUATIONS_PER_RUN}); with --method nelder-mead or --nelder-mead-starts"),
        )  # fmt: skip
        budget_options = ("--starts", "--nelder-mead-starts", "--restarts", "--evaluations")
        declare_rule(parser, budget_options, check_budget)
    add_safety(parser)


# The share of the step in double support that ``--double-support`` alone asks for: from a
# tenth of the step (people walk with 10-20 % of a stride in double support) to 0.4.
DOUBLE_SUPPORT = (0.1, 0.4)


def add_double_support(parser, help: str) -> None:
    """``--double-support [LOW:HIGH]``: alone, ``DOUBLE_SUPPORT``; ``help`` ends with what
    the command does without it."""
    low, high = DOUBLE_SUPPORT
    parser.add_argument(
        "--double-support",
        type=double_support_share,
        nargs="?",
        const=DOUBLE_SUPPORT,
        default=None,
        metavar="LOW:HIGH",
        help=f"{help}; the option alone: {low:g}:{high:g}",
    )


# How the swing foot lands with ``--double-support`` unless told: at rest. The impact
# landing's two-phase optima touch down at about 3 m/s, and MuJoCo's walks of them fall in
# their first steps (docs/gaits.md).
LANDING = "zero-speed"


def add_landing(parser) -> None:
    """``--landing``: how the swing foot lands before a double support."""
    from biped.model.two_phase import LANDINGS

    parser.add_argument(
        "--landing",
        choices=LANDINGS,
        default=LANDING,
        help="with --double-support, how the swing foot lands: impact (both feet stopped by "
        "it, the paper's impact map with both feet held; its optima touch down at about "
        "3 m/s and do not walk in MuJoCo) or zero-speed (it arrives at rest, no impact) "
        "(default %(default)s)",
    )


def add_options(parser, *options) -> None:
    """Options given as rows (option, type, default, metavar, help)."""
    for option, kind, default, metavar, help in options:
        parser.add_argument(option, type=kind, default=default, metavar=metavar, help=help)


def add_safety(parser) -> None:
    """The safety margins and walkable constraints of the optimal gait (``safety(args)``):
    each option's default is the paper's, or ``--walkable``'s."""
    walkable = WALKABLE
    parser.add_argument("--walkable", action="store_true", help=WALKABLE_HELP)
    add_options(
        parser,
        ("--clearance", clearance, None, "M", "[m] height the swing sole keeps off the ground "
         "between its lift-off and touchdown windows (--clearance-window): a third of it from "
         "the windows on, all of it from 30 %% to 70 %% of the step, at every sample of the "
         f"check grid (default 0, the paper's z >= 0; --walkable: {walkable.clearance:g})"),
        ("--clearance-window", clearance_window, None, "F", "the lift-off and touchdown "
         "windows of the clearance, a fraction of the step at each end, 0 to "
         f"{MAX_CLEARANCE_WINDOW:g} (default {walkable.clearance_window:g})"),
        ("--zmp-margin", zmp_margin, None, "M", "[m] distance the ZMP must keep inside the "
         f"sole's heel and toe (default 0; --walkable: {walkable.zmp_margin:g})"),
        ("--knee-bend", knee_bend, None, "RAD",
         f"[rad] least flexion of the stance knee over the step, 0 to {MAX_KNEE_BEND} "
         "(default 0, the paper's knee not inverted)"),
        ("--landing-speed", landing_speed, None, "M", "[m/s] largest speed of the swing sole "
         f"at touchdown, 0 to {MAX_LANDING_SPEED:g} (0: a landing without impact; default "
         "unbounded, the paper's)"),
        ("--landing-share", landing_share, None, "S", "the same bound as a share of the walking "
         f"speed: the sole lands at S times it at most, 0 to {MAX_LANDING_SHARE:g} (default "
         f"unbounded; --walkable: {walkable.landing_share:g}); one of the two"),
        ("--friction", friction, None, "MU", "friction coefficient the stance foot needs at "
         f"most, |Fx| <= MU Fz at every sample and for the landing's impulse, "
         f"{FRICTION_RANGE[0]:g} to {FRICTION_RANGE[1]:g} (default unbounded; --walkable: "
         f"{walkable.friction:g}; the MuJoCo floor's is 1)"),
        ("--joint-margin", joint_margin, None, "RAD", "[rad] least distance of every hip and "
         f"ankle to its stop (the MJCF's joint ranges), 0 to {MAX_JOINT_MARGIN:g} (default "
         f"none; --walkable: {walkable.joint_margin:g})"),
        ("--hip-progress", hip_progress, None, "P", "the hip's least forward speed, a share "
         f"of the walking speed, 0 to {MAX_HIP_PROGRESS:g} (default none; --walkable: "
         f"{walkable.hip_progress:g})"),
    )  # fmt: skip
    parser.add_argument("--actuator-limits", action="store_true", help=ACTUATOR_LIMITS_HELP)


def add_robot(parser) -> None:
    """``--robot FILE``: the robot's parameters (``robot_of(args)``)."""
    parser.add_argument("--robot", metavar="FILE", help=ROBOT_HELP)


def robot_of(args):
    """The robot of ``--robot`` (Table 1 without it); another of the project's files is
    refused, named (``not_a_robot_file``)."""
    from biped.model.robot import Robot

    if args.robot is None:
        return Robot.paper()
    not_a_robot_file(args.robot)
    return Robot.from_file(args.robot)


def not_a_robot_file(path: str) -> None:
    """Refuse a JSON file of another kind of the project's (a gait file, a table of optima)
    given as a robot file, naming its kind, not the first field a robot lacks."""
    import json

    from biped.records.gait_file import other_kind

    if Path(path).suffix.lower() != ".json":
        return
    try:
        content = json.loads(Path(path).read_text(encoding="utf-8"))
    except (OSError, ValueError, RecursionError):
        return  # Robot.from_file says what is wrong with it
    found = content.get("format") if isinstance(content, dict) else None
    gait = isinstance(found, str) and found.startswith("biped-gait/")
    kind = "a gait file (its 'robot' object is one)" if gait else other_kind(content)
    if kind is not None:
        raise BipedError(
            f"--robot {path!r} is {kind}, not a robot file: allowed a .json or .toml file of "
            "the robot's fields (r1 = 0.08 alone is one)"
        )


# [s] The shortest physics step ``--timestep`` takes (a walk at it takes 10 times the
# committed step's time), and the longest: twice the committed step, the step of the models
# before 1 ms, at which the two-phase walks' stance foot creeps (docs/gaits.md).
MIN_TIMESTEP = 1e-4
MAX_TIMESTEP = 2.0 * MODEL_TIMESTEP
TIMESTEP_HELP = (
    f"MuJoCo's physics step of the walks (the forward, gains and orbit checks; the replay "
    f"and the inverse dynamics keep their own) [s], from "
    f"{MIN_TIMESTEP:g} to {MAX_TIMESTEP:g}: the same model with its contacts, stops and "
    "knee coupling at two steps' time constant, a finer or coarser model to hold the "
    "verdicts against "
    f"(default: the model's own, {MODEL_TIMESTEP:g} s for the committed models)"
)


def ranged(name: str, low: float, high: float, unit: str = ""):
    """A finite number from ``low`` to ``high`` inclusive, named ``name`` [``unit``] in the
    message of a value refused."""
    unit = f" {unit}" if unit else ""

    def parse(text: str) -> float:
        try:
            value = float(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"{name} = {text!r} is not a number") from None
        if not (np.isfinite(value) and low <= value <= high):
            raise argparse.ArgumentTypeError(
                f"{name} = {text!r}{unit}: allowed {low:g} to {high:g}{unit}"
            )
        return value

    return parse


# ``--timestep S`` [s], from ``MIN_TIMESTEP`` to ``MAX_TIMESTEP``.
timestep = ranged("timestep", MIN_TIMESTEP, MAX_TIMESTEP, "s")


def add_timestep(parser) -> None:
    """``--timestep S`` [s]: the walks' physics step (``validate.scene.model.at_timestep``)."""
    parser.add_argument("--timestep", type=timestep, default=None, metavar="S", help=TIMESTEP_HELP)


# The range of ``--kp-scale``: the robustness map's and the orbit study's scales of the servos.
KP_SCALES = (0.25, 4.0)
KP_SCALE_HELP = (
    "the servos' stiffness in the walks (the forward, gains and orbit checks) as a multiple "
    f"of the validation's kp = {SERVO_KP:g} N·m/rad, from {KP_SCALES[0]:g} to "
    f"{KP_SCALES[1]:g}; the gains check scales it again by 0.5 and 2 (default 1)"
)


# ``--kp-scale X``, within ``KP_SCALES``.
kp_scale = ranged("kp scale", *KP_SCALES)


def add_kp_scale(parser) -> None:
    """``--kp-scale X``: the walks' servo stiffness (``WalkSettings.kp_scale``)."""
    parser.add_argument("--kp-scale", type=kp_scale, default=1.0, metavar="X", help=KP_SCALE_HELP)


def add_steps(parser) -> None:
    """``--steps N``: the steps of a forward walk in MuJoCo."""
    parser.add_argument("--steps", type=steps, default=DEFAULT_STEPS, metavar="N", help=STEPS_HELP)


def add_speed(parser, default: float | None = None) -> None:
    """``--speed V`` [m/s], required without a ``default``."""
    help = SPEED_HELP + ("" if default is None else " (default %(default)s)")
    parser.add_argument(
        "--speed", type=speed, default=default, required=default is None, metavar="V", help=help
    )


def add_speeds(parser, default: np.ndarray, shown: str) -> None:
    """``--speeds S`` [m/s], a range or a list (``speeds``)."""
    help = f"START:STOP:COUNT or a list V1,V2,... [m/s] (default {shown})"
    parser.add_argument("--speeds", type=speeds, default=default, metavar="S", help=help)


def add_gaits(parser) -> None:
    """``GAIT.json ...``: the gait files a command reads."""
    help = "gait files from optimize, sweep, pipeline"
    parser.add_argument("gait", metavar="GAIT.json", nargs="+", help=help)


def add_model(parser) -> None:
    """``--model PATH``: the MJCF to play the gaits on."""
    parser.add_argument(
        "--model",
        metavar="PATH",
        help="MJCF to play the gaits on (default: mjcf/scene_<knee>.xml when the gait's robot is "
        "Table 1, the model generated from the gait's robot otherwise)",
    )


def add_jobs(parser) -> None:
    """``--jobs N``: the worker processes of a campaign."""
    parser.add_argument("--jobs", type=jobs, default=None, metavar="N", help=JOBS_HELP)


def _read(text: str, kind, otherwise):
    """``kind(text)``, or ``otherwise`` where ``text`` is not one (a value every check
    refuses)."""
    try:
        return kind(text)
    except ValueError:
        return otherwise


def margin(name: str, high: float, unit: str = "m", low: float = 0.0):
    def parse(text: str) -> float:
        value = _read(text, float, float("nan"))
        if not (low <= value <= high):
            raise argparse.ArgumentTypeError(
                f"{f'{name} = {text!r} {unit}'.rstrip()}: allowed {low:g} to {high:g}"
            )
        return value

    return parse


clearance = margin("clearance", MAX_CLEARANCE)
zmp_margin = margin("zmp margin", MAX_ZMP_MARGIN)
knee_bend = margin("knee bend", MAX_KNEE_BEND, "rad")
clearance_window = margin("clearance window", MAX_CLEARANCE_WINDOW, "of the step")
landing_speed = margin("landing speed", MAX_LANDING_SPEED, "m/s")
landing_share = margin("landing share", MAX_LANDING_SHARE, "of the walking speed")
friction = margin("friction", FRICTION_RANGE[1], "", low=FRICTION_RANGE[0])
joint_margin = margin("joint margin", MAX_JOINT_MARGIN, "rad")
hip_progress = margin("hip progress", MAX_HIP_PROGRESS, "of the walking speed")


def bounded(low: int, high: int | None = None):
    """An integer type from ``low`` to ``high`` inclusive (no upper bound: None)."""
    allowed = f"an integer >= {low}" if high is None else f"an integer from {low} to {high}"

    def parse(text: str) -> int:
        value = _read(text, int, low - 1)
        if value < low or (high is not None and value > high):
            raise argparse.ArgumentTypeError(f"{text!r}: allowed {allowed}")
        return value

    return parse


non_negative = bounded(0)
positive = bounded(1)
# Counts of the optimizers' budget: each start, seed or restart costs up to seconds.
MAX_STARTS = 100
MAX_SEEDS = 100
MAX_EVALUATIONS = 1_000_000
starts = bounded(1, MAX_STARTS)
nelder_mead_starts = bounded(0, MAX_SEEDS)
restarts = bounded(0, MAX_SEEDS)
evaluations = bounded(1, MAX_EVALUATIONS)
steps = bounded(1, MAX_STEPS)
jobs = bounded(1, MAX_JOBS)


def metres(text: str) -> float:
    """A finite length or position [m]."""
    value = _read(text, float, float("nan"))
    if not np.isfinite(value):
        raise argparse.ArgumentTypeError(f"{text!r} m: allowed a finite number")
    return value


class Distinct(argparse.Action):
    """A list option whose values must differ (``--knees rolling rolling`` is refused)."""

    def __call__(self, parser, namespace, values, option_string=None):
        repeated = sorted({v for v in values if values.count(v) > 1})
        if repeated:
            raise argparse.ArgumentError(self, f"{repeated[0]!r} given twice: allowed each once")
        setattr(namespace, self.dest, list(values))


DASK_SCHEMES = ("tcp", "tls")
DASK_HELP = (
    "run the optimizations on the workers of this running Dask scheduler (tcp://HOST:PORT) "
    "instead of local processes; needs pip install '.[cluster]' (default: local processes, "
    "--jobs)"
)


def dask_address(text: str) -> str:
    """A Dask scheduler's address, SCHEME://HOST:PORT (checked here, reached when used)."""
    from urllib.parse import urlsplit

    allowed = "allowed tcp://HOST:PORT or tls://HOST:PORT, a Dask scheduler's address"
    try:
        parts = urlsplit(text)
        port = parts.port
    except ValueError:
        port = None
        parts = None
    if (
        parts is None
        or parts.scheme not in DASK_SCHEMES
        or not parts.hostname
        or port is None
        or not 1 <= port <= 65535
        or parts.path not in ("", "/")
        or parts.query
        or parts.fragment
        or parts.username is not None
    ):
        raise argparse.ArgumentTypeError(f"{text!r}: {allowed}")
    return text


# URL schemes of a rerun viewer (rerun's own ``connect_grpc`` refuses others).
VIEWER_SCHEMES = ("rerun", "rerun+http", "rerun+https")


def viewer_url(text: str) -> str:
    """A rerun viewer's URL, SCHEME://HOST[:PORT]/proxy; "" for rerun's local default."""
    from urllib.parse import urlsplit

    if text == "":
        return text
    try:
        parts = urlsplit(text)
        host = parts.hostname
        _ = parts.port  # a malformed port raises
    except ValueError:
        parts, host = None, None
    if parts is None or parts.scheme not in VIEWER_SCHEMES or not host:
        raise argparse.ArgumentTypeError(
            f"{text!r}: allowed a rerun viewer's URL such as rerun+http://127.0.0.1:9876/proxy "
            f"(schemes {', '.join(s + '://' for s in VIEWER_SCHEMES)}), or nothing for its "
            "local address"
        )
    return text


def campaign(args, label: str) -> dict:
    """A campaign's ``jobs`` and ``dask`` given on the command line, and its ``progress``: a
    bar named ``label``."""
    from biped_cli.progress import Progress

    return {"jobs": args.jobs, "dask": args.dask, "progress": lambda n: Progress(n, label)}


def add_dask(parser):
    """``--dask ADDRESS``: run a command's optimizations on a Dask cluster."""
    parser.add_argument(
        "--dask", type=dask_address, default=None, metavar="ADDRESS", help=DASK_HELP
    )
