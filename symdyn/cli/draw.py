"""The `symdyn draw` subcommand (its parser in `COMMANDS`).

    symdyn draw ROBOT [--q Q ...] [--view iso|front|side|top] [--params NAME=VALUE ...]
           --out FILE.svg|.png|.html

q is given like simulate's vectors (symdyn.cli.apps): nq values, a floating robot's starting
with the base's x y z qx qy qz qw; default zeros (the identity quaternion).
"""

from __future__ import annotations

import argparse

from .animation import VIEWS
from .apps import assignments_option, vector_option, with_params
from .common import add_robot_argument, load_robot_argument

__all__ = ["COMMANDS", "cmd_draw"]


def cmd_draw(args: argparse.Namespace) -> int:
    from ..algorithms.drawing import default_configuration
    from ..apps.drawing.draw import draw, picture_format
    from ..apps.output import check_output

    check_output(args.out, "--out")
    picture_format(args.out)
    robot = with_params(load_robot_argument(args), assignments_option(args.params, "--params"))
    q = vector_option(args.q, robot.nq, "--q", default=default_configuration(robot))
    draw(robot, q, args.out, view=args.view)
    print(args.out)
    return 0


def _draw_arguments(d: argparse.ArgumentParser) -> None:
    d.description = (
        "Draw the robot at q: its skeleton, joint axes, every link frame (x/y/z arrows labelled "
        "x_i, z_i), named frames, contacts, centres of mass sized by mass and, for a DH robot, "
        "the parameters a_i, d_i, alpha_i, theta_i. The format is the suffix of --out."
    )
    add_robot_argument(d)
    d.add_argument("--q", nargs="+", metavar="V", help="the configuration (default: zeros)")
    d.add_argument("--view", choices=VIEWS, default="iso", help="the view (default iso)")
    d.add_argument("--params", nargs="+", metavar="NAME=VALUE", help="parameter values (free or overriding)")
    d.add_argument("--out", required=True, help="the picture to write: FILE.svg, FILE.png or FILE.html")
    d.set_defaults(func=cmd_draw)


#: The subcommands of this module (symdyn.cli.main.COMMANDS): name -> (help, adds its arguments).
COMMANDS = {"draw": ("draw the robot with its frames (SVG, PNG, HTML)", _draw_arguments)}
