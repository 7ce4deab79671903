"""What every subcommand shares: the robot argument (a robot file, a URDF or xacro, an MJCF file)
and its loader."""

from __future__ import annotations

import argparse
import math

__all__ = [
    "add_robot_argument",
    "add_contacts_argument",
    "load_robot_argument",
    "xacro_arguments",
    "METHODS",
    "FLOATING_COMMANDS",
    "whole_number",
]

#: symdyn.dynamics.METHODS, spelled here so that building the parser imports no SymPy
#: (tests/test_cli.py checks that the two agree).
METHODS = ("newton-euler", "lagrange")
#: the commands that handle a floating robot (docs/floating-base.md)
FLOATING_COMMANDS = ("derive", "generate", "simulate", "identify", "draw")


def load_robot_argument(args: argparse.Namespace):
    """A robot from a robot file, an MJCF file, or a URDF file with --base/--tip (a xacro file with
    --xacro-arg and --package-dir): recognised by its content (symdyn.parsers.by_content), whatever
    its name."""
    from ..errors import SymdynError
    from ..parsers import load
    from ..progress import stage as progress_stage

    floating = getattr(args, "floating", False)
    with progress_stage(f"loading {args.robot}"):
        robot = load(
            args.robot,
            base=args.base,
            tip=args.tip,
            floating=floating,
            contacts=getattr(args, "contacts", None),
            **xacro_arguments(args),
        )
    command = getattr(args, "command", None)
    if robot.floating and command not in FLOATING_COMMANDS:
        raise SymdynError(
            f"symdyn {command}: robot '{robot.name}' has a floating base, which this command does not "
            f"handle yet ({', '.join(FLOATING_COMMANDS)} do: docs/floating-base.md)"
        )
    return robot


def xacro_arguments(args: argparse.Namespace) -> dict:
    """xacro_args and package_dirs of the loaders, from --xacro-arg NAME:=VALUE and --package-dir
    NAME=DIR (each repeatable); a malformed one is a SymdynError naming the option."""
    from ..errors import SymdynError

    out: dict = {"xacro_args": {}, "package_dirs": {}}
    for key, option, sep, given in (
        ("xacro_args", "--xacro-arg", ":=", args.xacro_arg),
        ("package_dirs", "--package-dir", "=", args.package_dir),
    ):
        for text in given or ():
            name, found, value = text.partition(sep)
            if not found or not name.strip():
                raise SymdynError(f"{option} {text!r}: expected NAME{sep}VALUE")
            out[key][name.strip()] = value
    return {key: value or None for key, value in out.items()}


def add_robot_argument(parser: argparse.ArgumentParser) -> None:
    parser.add_argument(
        "robot",
        help="robot file (YAML or JSON), URDF (or xacro) or MJCF file, recognised by its content, "
        "whatever its name",
    )
    parser.add_argument("--base", help="URDF: the link the robot hangs from (default: the root link)")
    parser.add_argument(
        "--tip",
        help="URDF: load only the chain from the base to this link (default: the whole tree)",
    )
    parser.add_argument(
        "--floating",
        action="store_true",
        help="the robot's base floats, joined to the world by a free flyer (q = [x y z qx qy qz qw, "
        "joints], v = [base twist in the base frame, joint rates]; docs/floating-base.md)",
    )
    parser.add_argument(
        "--xacro-arg",
        action="append",
        metavar="NAME:=VALUE",
        help="xacro: an argument of the file (repeatable)",
    )
    parser.add_argument(
        "--package-dir",
        action="append",
        metavar="NAME=DIR",
        help="xacro: the folder of package NAME, for $(find NAME) and package://NAME (repeatable; "
        "else ROS_PACKAGE_PATH)",
    )
    parser.add_argument(
        "--quiet",
        action="store_true",
        help="no progress reports on stderr (a command that runs for a second or more reports its "
        "stages and their time)",
    )


def add_contacts_argument(parser: argparse.ArgumentParser) -> None:
    """--contacts FRAME[:point|6d] ...: the robot's contacts with the world (docs/contacts.md)."""
    parser.add_argument(
        "--contacts",
        nargs="+",
        metavar="FRAME[:point|6d]",
        help="contacts with the world at these frames, in place of the robot file's (each named after "
        "its frame; point: 3 rows, world-aligned, the default; 6d: 6 rows in the frame's axes; "
        "docs/contacts.md)",
    )


def whole_number(text: str) -> int:
    """An integer option's value: a whole number, also written as a float ("1e6", "100.0"), so
    that its range is checked (and named) by the command rather than refused as a spelling."""
    try:
        return int(text)
    except ValueError:
        pass
    try:
        v = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a whole number, got '{text}'") from None
    if not (math.isfinite(v) and v == int(v)):
        raise argparse.ArgumentTypeError(f"expected a whole number, got '{text}'")
    return int(v)
