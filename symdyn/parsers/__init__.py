"""Loaders from robot description formats onto the general model of `symdyn.model.robot`."""

from __future__ import annotations

from .loading import load_robot
from .mjcf import load_mjcf
from .poe import robot_from_poe
from .robot_file import robot_from_data
from .urdf import load_urdf

__all__ = ["load", "load_mjcf", "load_robot", "load_urdf", "robot_from_data", "robot_from_poe"]

#: the name the command line and `symdyn.generate` use (one loader: by content)
load = load_robot
