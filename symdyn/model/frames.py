"""Named frames fixed to the links of a robot, and the placement of its base in the world.

A `Frame` F is fixed to one link k (or to the base, k = -1) with a constant placement
k_T_F: F's origin and axes in the *body frame* of link k (symdyn.model.robot). Every link
names a frame too: its convention frame (`Link.frame`: the DH frame i of a DH file, the URDF
link frame, PoE's {i}). A robot's `frames` hold the other ones: the links a URDF merges
through fixed joints (as Pinocchio keeps BODY frames), a robot file's `frames:` entries, PoE's
`end_effector`. Names are unique across links and frames.

The robot's base frame sits in the world at `Robot.base` = world_T_base (identity unless the
robot file gives `base: {xyz, rpy}`); the pose of frame F in the world is

    world_T_F = world_T_base  base_T_k(q)  k_T_F.
"""

from __future__ import annotations

import difflib
from collections.abc import Iterable, Mapping
from dataclasses import dataclass

from ..errors import SymdynError
from ..spatial.transform import Transform

__all__ = ["Frame", "check_frame_names", "unknown_frame"]


@dataclass(frozen=True)
class Frame:
    """A frame fixed to link `link` (0-based index into Robot.links; -1: the base), at
    `placement` = k_T_F, F in the body frame of link k (or in the base frame)."""

    name: str
    link: int
    placement: Transform

    def subs(self, mapping: Mapping) -> Frame:
        return Frame(self.name, self.link, self.placement.subs(dict(mapping)))


def check_frame_names(robot_name: str, link_names: Iterable[str], frames: Iterable[Frame], nb: int) -> None:
    """Refuse a frame named like a link or another frame, or on a link that does not exist.

    Raises:
        SymdynError: naming the robot and the frame.
    """
    seen = {name: "a link" for name in link_names}
    for f in frames:
        if f.name in seen:
            raise SymdynError(f"robot '{robot_name}': frame '{f.name}' has the name of {seen[f.name]}")
        if not -1 <= f.link < nb:
            raise SymdynError(
                f"robot '{robot_name}': frame '{f.name}' is on link {f.link}, which does not exist"
            )
        seen[f.name] = "another frame"


def unknown_frame(name: object, names: Iterable[str], where: str, file: str | None = None) -> SymdynError:
    """The error for a frame name that is not among `names`, naming the near matches."""
    names = list(names)
    close = difflib.get_close_matches(str(name), names, n=3)
    hint = f" (did you mean {', '.join(repr(c) for c in close)}?)" if close else ""
    listed = ", ".join(names[:12]) + (", ..." if len(names) > 12 else "")
    return SymdynError(f"{where}: unknown frame {name!r}{hint}; the frames: {listed}", file=file)
