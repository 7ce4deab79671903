"""simulate's --animate, --frames and --view (symdyn.cli.apps calls these): the run's motion as an
HTML page or a GIF (symdyn.apps.drawing.animate)."""

from __future__ import annotations

import argparse
from collections.abc import Callable

from ..errors import SymdynError
from .common import whole_number

__all__ = ["check_animation", "write_animation", "animation_arguments", "VIEWS"]

#: symdyn.apps.drawing.sketch.VIEWS, spelled here so that building the parser imports no NumPy.
VIEWS = ("iso", "front", "side", "top")


def check_animation(args: argparse.Namespace) -> None:
    """Refuse a bad --animate path or --frames before a simulation runs."""
    from ..apps.drawing.animate import ANIMATION_FORMATS, MAX_FRAMES
    from ..apps.drawing.draw import picture_format
    from ..apps.output import check_output

    if args.animate is None:
        for flag in ("frames", "view"):
            if getattr(args, flag) is not None:
                raise SymdynError(f"--{flag} applies with --animate only")
        return
    check_output(args.animate, "--animate")
    picture_format(args.animate, ANIMATION_FORMATS, "--animate")
    if args.frames is not None and not 1 <= args.frames <= MAX_FRAMES:
        raise SymdynError(f"--frames {args.frames}: must be from 1 to {MAX_FRAMES:,}")


def write_animation(args: argparse.Namespace, robot, traj, load: Callable[[], object]) -> None:
    """simulate --animate: the run's motion to an HTML page or a GIF (symdyn.apps.drawing.animate);
    `load()` gives the Robot when `robot` is the cache's RobotInfo."""
    from ..apps.compilation.compile import RobotInfo
    from ..apps.drawing.animate import animate

    if isinstance(robot, RobotInfo):  # the plant came from the cache: the picture needs the Robot
        robot = load()
    forces = getattr(traj, "contact_forces", None)
    frames = 60 if args.frames is None else args.frames
    animate(robot, traj.t, traj.q, args.animate, frames=frames, view=args.view or "iso", forces=forces)
    print(args.animate)


def animation_arguments(s: argparse.ArgumentParser) -> None:
    """simulate's --animate, --frames and --view."""
    s.add_argument(
        "--animate",
        metavar="FILE",
        help="also write the motion as a self-contained HTML page (.html: three.js, a time slider, "
        "play/pause) or an animated GIF (.gif), with the tool frame's path",
    )
    s.add_argument("--frames", type=whole_number, help="--animate: the number of pictures (default 60)")
    s.add_argument("--view", choices=VIEWS, help="--animate: the view (default iso)")
