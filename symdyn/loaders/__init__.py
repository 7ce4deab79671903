"""Loaders from robot description formats onto the general model of `symdyn.robot`."""

from .robot_file import load_robot, robot_from_data

__all__ = ["load_robot", "robot_from_data"]
