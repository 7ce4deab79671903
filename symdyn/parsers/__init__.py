"""Loaders from robot description formats onto the general model of `symdyn.model.robot`."""

from __future__ import annotations

import os

from ..errors import SymdynError
from ..model.robot import Robot
from .poe import robot_from_poe
from .robot_file import load_robot, robot_from_data
from .urdf import load_urdf

__all__ = ["load", "load_robot", "load_urdf", "robot_from_data", "robot_from_poe"]


def load(path: str | os.PathLike, base: str | None = None, tip: str | None = None) -> Robot:
    """A robot from a robot file (YAML/JSON) or, by its .urdf suffix, a URDF file."""
    if str(path).lower().endswith(".urdf"):
        return load_urdf(path, base=base, tip=tip)
    if base or tip:
        raise SymdynError(f"{path}: a base or tip link applies to URDF files only")
    return load_robot(path)
