"""Command-line entry point ``biped``: one program, one subcommand per job.

Errors in the input print one line on stderr and exit with status 2.
"""

from __future__ import annotations

import argparse
import sys

import numpy as np

from biped.dynamics import JOINTS, Biped
from biped.errors import BipedError
from biped.kinematics import KNEES
from biped.robot import Robot

EXIT_BAD_INPUT = 2


def _robot(path: str | None) -> Robot:
    return Robot.paper() if path is None else Robot.from_file(path)


def demo_posture(model: Biped, hip_ahead: float = 0.05, hip_height: float = 0.86):
    """A single-support posture held still: stance leg from the inverse geometric model.

    Args:
        hip_ahead: [m] hip ahead of the stance ankle.
        hip_height: [m] hip above the ground.
    """
    hip_from_ankle = [hip_ahead, hip_height - model.robot.ankle_height]
    shank, thigh = model.leg_angles(hip_from_ankle)
    # Swing leg behind, knee bent, foot level; trunk upright.
    angles = np.array([0.0, shank, thigh, -0.15, -0.55, 0.0])
    return model.stance_state(angles)


def cmd_demo(args) -> int:
    """Print the torques, ground wrench and ZMP that hold a one-leg posture still."""
    robot = _robot(args.robot)
    knees = KNEES if args.knee is None else (args.knee,)
    names = [f"Γ {j} [N·m]" for j in JOINTS] + ["Fx [N]", "Fz [N]", "Cy [N·m]", "x_ZMP [m]"]
    columns = []
    for knee in knees:
        model = Biped(robot, knee)
        q, qd, qdd = demo_posture(model, args.hip_ahead, args.hip_height)
        torques, wrench = model.inverse_dynamics(q, qd, qdd)
        columns.append([*torques, *wrench, model.zmp(q, qd, qdd)])
    print(
        f"Robot: {robot.total_mass:.2f} kg, {robot.height:.3f} m, "
        f"knee radii r1 = {robot.r1} m, r2 = {robot.r2} m"
    )
    print(
        f"Posture held still: hip {args.hip_ahead:+.3f} m ahead of the stance ankle, "
        f"{args.hip_height:.3f} m high; swing leg behind, trunk upright.\n"
    )
    print(f"{'':22}" + "".join(f"{knee:>12}" for knee in knees))
    for i, name in enumerate(names):
        print(f"{name:22}" + "".join(f"{column[i] + 0.0:12.4f}" for column in columns))
    return 0


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="biped",
        description="Quasi-optimal gaits of planar bipeds with revolute or rolling knees.",
    )
    commands = parser.add_subparsers(dest="command", required=True, metavar="COMMAND")
    demo = commands.add_parser(
        "demo",
        help="torques, ground wrench and ZMP of a one-leg posture",
        description=cmd_demo.__doc__,
    )
    demo.add_argument("--knee", choices=KNEES, help="one knee kinematic (default: both)")
    demo.add_argument(
        "--robot", metavar="FILE", help="robot parameters, .json or .toml (default: Table 1)"
    )
    demo.add_argument(
        "--hip-ahead",
        type=float,
        default=0.05,
        metavar="M",
        help="[m] hip ahead of the stance ankle (default 0.05)",
    )
    demo.add_argument(
        "--hip-height",
        type=float,
        default=0.86,
        metavar="M",
        help="[m] hip above the ground (default 0.86)",
    )
    demo.set_defaults(run=cmd_demo)
    return parser


def main(argv: list[str] | None = None) -> int:
    """Run the ``biped`` command; returns the exit status."""
    args = build_parser().parse_args(argv)
    try:
        return args.run(args)
    except BipedError as error:
        print(f"biped {args.command}: error: {error}", file=sys.stderr)
        return EXIT_BAD_INPUT


if __name__ == "__main__":
    sys.exit(main())
