"""`symdyn derive ROBOT --steps [--at q=.. qd=.. qdd=..]`: the derivation step by step."""

from __future__ import annotations

import argparse
import sys

from ..apps.checking.steps import derivation_steps
from ..apps.checking.steps_output import STEP_FORMATS
from ..errors import SymdynError
from .common import load_robot_argument
from .derive_loops import loop_report, with_loops

__all__ = ["parse_at", "cmd_derive_steps"]


def parse_at(items: list[str]) -> dict[str, object]:
    """`q=0.1,0.2 qd=0,1 qdd=1,0 m1=2` -> {"q": [0.1, 0.2], ..., "m1": 2.0} (numbers only)."""
    out: dict[str, object] = {}
    for item in items:
        name, sep, text = item.partition("=")
        if not sep or not name or not text:
            raise SymdynError(f"--at: expected NAME=VALUE[,VALUE...], got {item!r}")
        try:
            values = [float(x) for x in text.split(",")]
        except ValueError:
            raise SymdynError(f"--at: {name} must be numbers separated by commas, got {text!r}") from None
        if name in out:
            raise SymdynError(f"--at: {name} given twice")
        out[name] = values if name in ("q", "qd", "qdd") else _scalar(name, values)
    return out


def _scalar(name: str, values: list[float]) -> float:
    if len(values) != 1:
        raise SymdynError(f"--at: parameter {name} takes one number, got {len(values)}")
    return values[0]


def cmd_derive_steps(args: argparse.Namespace) -> int:
    if not args.steps:
        raise SymdynError("--at gives the state of --steps; add --steps")
    robot = load_robot_argument(args)
    if robot.floating:
        raise SymdynError(
            f"derive --steps: robot '{robot.name}' has a floating base; --steps shows a fixed base"
        )
    simplify = None if args.simplify == "auto" else args.simplify == "yes"
    at = parse_at(args.at) if args.at else None
    loops = loop_report(robot)  # generate's check of the loops; the steps are the tree's
    steps = derivation_steps(robot, args.method, at=at, simplify=simplify)
    sys.stdout.write(with_loops(loops, STEP_FORMATS[args.format](steps), args.format))
    return 0
