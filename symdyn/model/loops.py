"""Closed kinematic loops: the joints of a spanning tree (the robot's links) plus closures.

A `Loop` closes the tree: a point fixed to link `link` coincides with a point fixed to link
`to` (or to the base, `to` = -1) for every admissible configuration (Khalil and Dombre,
"Modeling, Identification and Control of Robots" (2002), ch. 7: the closed-loop structure is
cut at one joint per loop into a spanning tree, and the cut joints become closure equations):

    type "point":  p_link(q) - p_to(q) = 0             3 equations (a spherical or revolute cut joint)
    type "weld":   the two frames coincide             6 equations (a rigid cut)

`point` and `to_point` are written in each link's body frame here (the loader moves a robot
file's points, given in the convention frame, into it); `frames()` gives them as two frames
(symdyn.model.frames.Frame) named `<loop>:a` and `<loop>:b`, whose axes are the two links'
body axes (a weld makes these coincide).

`Robot.actuated` lists the links whose joints are driven (their coordinates q_a); the other
joints are passive (q_p), given by the closure from q_a. Redundant closure equations and the
mobility are found by symdyn.algorithms.closed_loops.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import sympy as sp

from ..errors import SymdynError
from ..spatial.transform import Transform
from .frames import Frame

__all__ = ["Loop", "LOOP_TYPES", "check_loops", "loop_path"]

#: The closure types and the number of equations each gives.
LOOP_TYPES = {"point": 3, "weld": 6}


@dataclass(frozen=True)
class Loop:
    """One closure: `point` on link `link` coincides with `to_point` on link `to` (-1: base);
    both points in the body frame of their link (module docstring)."""

    name: str
    link: int
    point: sp.ImmutableMatrix
    to: int
    to_point: sp.ImmutableMatrix
    type: str = "point"

    @property
    def equations(self) -> int:
        """3 (point) or 6 (weld) closure equations before redundant ones are dropped."""
        return LOOP_TYPES[self.type]

    def frames(self) -> tuple[Frame, Frame]:
        """The two frames that the closure makes coincide: on `link`, then on `to`."""
        return (
            Frame(f"{self.name}:a", self.link, Transform.from_translation(list(self.point))),
            Frame(f"{self.name}:b", self.to, Transform.from_translation(list(self.to_point))),
        )

    def subs(self, mapping: Mapping) -> Loop:
        x = dict(mapping)
        return Loop(
            self.name, self.link, self.point.xreplace(x), self.to, self.to_point.xreplace(x), self.type
        )


def check_loops(robot_name: str, link_names: Sequence[str], mimics: Sequence[bool], loops, actuated) -> None:
    """Refuse loops on links that do not exist, repeated loop names, a loop from a link to
    itself, and `actuated` links that do not exist, repeat or are mimic joints.

    Raises:
        SymdynError: naming the robot and the loop (or the actuated link).
    """
    nb = len(link_names)
    seen = set()
    for loop in loops:
        where = f"robot '{robot_name}': loop '{loop.name}'"
        if loop.name in seen:
            raise SymdynError(f"{where}: another loop has this name")
        seen.add(loop.name)
        if loop.type not in LOOP_TYPES:
            raise SymdynError(f"{where}: type must be one of {', '.join(LOOP_TYPES)}, got {loop.type!r}")
        if not 0 <= loop.link < nb or not -1 <= loop.to < nb:
            raise SymdynError(f"{where}: is on a link that does not exist")
        if loop.link == loop.to:
            raise SymdynError(f"{where}: closes link '{link_names[loop.link]}' on itself")
    if actuated is None:
        return
    if len(set(actuated)) != len(actuated):
        raise SymdynError(f"robot '{robot_name}': actuated: a link is listed twice")
    for i in actuated:
        if not 0 <= i < nb:
            raise SymdynError(f"robot '{robot_name}': actuated: link {i + 1} does not exist")
        if mimics[i]:
            raise SymdynError(
                f"robot '{robot_name}': actuated: link '{link_names[i]}' is a mimic joint (it has "
                "no coordinate of its own)"
            )


def loop_path(parents: Sequence[int], a: int, b: int) -> list[int]:
    """The links on the tree path between link a and link b (-1: the base): the joints the loop
    closed by a and b moves, each once."""

    def ancestors(i: int) -> list[int]:
        out = []
        while i >= 0:
            out.append(i)
            i = parents[i]
        return out

    up_a, up_b = ancestors(a), ancestors(b)
    common = set(up_a) & set(up_b)
    return [i for i in up_a if i not in common] + [i for i in up_b if i not in common]
