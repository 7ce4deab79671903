"""Loading a robot description by its content, whatever the file's name: XML whose top element is
<robot> is a URDF (symdyn.parsers.urdf), <mujoco> is MJCF (refused: not read yet), anything else
a robot file (YAML or JSON, symdyn.parsers.robot_file)."""

from __future__ import annotations

import os

from ..errors import SymdynError
from ..model.robot import Robot
from .robot_file import robot_from_bytes
from .safe_xml import looks_like_xml
from .source import read_source
from .urdf import urdf_from_bytes

__all__ = ["load_robot"]


def load_robot(path: str | os.PathLike, base: str | None = None, tip: str | None = None) -> Robot:
    """Read a robot file (YAML or JSON) or a URDF, recognised by its content, and return the `Robot`.

    A file that starts with an XML element ('<') is read as a URDF (`symdyn.load_urdf`, with
    `base` and `tip`: see there); an MJCF file (top element <mujoco>) or other XML is refused
    with a SymdynError naming the file. Anything else is a robot file, which takes neither
    `base` nor `tip`. Raises SymdynError (naming file, link and field) for any bad input; warns
    with SymdynWarning for implausible inertial data.
    """
    file, raw, digest = read_source(path, "robot file")
    if looks_like_xml(raw):
        return urdf_from_bytes(raw, file, digest, base, tip)
    if base is not None or tip is not None:
        raise SymdynError("a base or tip link applies to URDF files only (this is a robot file)", file=file)
    return robot_from_bytes(raw, file, digest)
