"""What every subcommand shares: the robot argument (a robot file or a URDF) and its loader."""

from __future__ import annotations

import argparse

__all__ = ["add_robot_argument", "load_robot_argument", "METHODS"]

#: symdyn.dynamics.METHODS, spelled here so that building the parser imports no SymPy
#: (tests/test_cli.py checks that the two agree).
METHODS = ("newton-euler", "lagrange")


def load_robot_argument(args: argparse.Namespace):
    """A robot from a robot file, or from a URDF file with --base/--tip: recognised by its content
    (symdyn.parsers.loading), whatever its name."""
    from ..parsers import load

    return load(args.robot, base=args.base, tip=args.tip)


def add_robot_argument(parser: argparse.ArgumentParser) -> None:
    parser.add_argument(
        "robot", help="robot file (YAML or JSON) or URDF file, recognised by its content, whatever its name"
    )
    parser.add_argument("--base", help="URDF: the link the robot hangs from (default: the root link)")
    parser.add_argument(
        "--tip",
        help="URDF: load only the chain from the base to this link (default: the whole tree)",
    )
