"""Pictures of a robot: `draw` (SVG, PNG, HTML of one configuration) and `animate` (HTML or GIF of
a trajectory), from the geometry of symdyn.algorithms.drawing."""

from __future__ import annotations

from .animate import animate
from .draw import draw

__all__ = ["draw", "animate"]
