"""Loading a robot description by its content, whatever the file's name: XML whose top element is
<robot> is a URDF (symdyn.parsers.urdf), <mujoco> is MJCF (symdyn.parsers.mjcf), anything else a
robot file (YAML or JSON, symdyn.parsers.robot_file)."""

from __future__ import annotations

import os
from collections.abc import Mapping
from dataclasses import replace

from ..errors import SymdynError
from ..model.contacts import with_contacts
from ..model.robot import Robot
from ..spatial.transform import Transform
from .mjcf import mjcf_from_bytes
from .robot_file import robot_from_bytes
from .safe_xml import declaration_first, looks_like_xml, parse_xml
from .source import read_source
from .urdf import urdf_from_root

__all__ = ["load_robot"]


def load_robot(
    path: str | os.PathLike,
    base: str | None = None,
    tip: str | None = None,
    floating: bool = False,
    contacts: object = None,
    **xacro: Mapping[str, str] | None,
) -> Robot:
    """Read a robot file (YAML or JSON), a URDF (or xacro) or an MJCF file, recognised by its content.

    A file that starts with an XML element ('<') is read as MJCF when its top element is
    <mujoco> (`symdyn.load_mjcf`), otherwise as a URDF (`symdyn.load_urdf`, with `base` and
    `tip`, and a xacro file expanded with the keywords xacro_args= and package_dirs=: see there;
    other XML is refused with a SymdynError naming the file). Anything else is a robot file. Only
    a URDF takes `base` and `tip`, only xacro xacro_args and package_dirs. Raises SymdynError
    (naming file, link and field) for any bad input; warns with SymdynWarning for implausible
    inertial data. floating=True: the robot's base floats, joined to the world by a free flyer
    (docs/floating-base.md): a URDF's base link (`load_urdf`), an MJCF's root body (a free joint
    there makes it floating anyway: `load_mjcf`), a robot file's base frame with a massless base
    body (write `base: floating` in the file to give the base a mass). contacts: the robot's
    contacts with the world in place of the file's (symdyn.model.contacts: Contact objects,
    {name, frame, type} mappings or 'FRAME[:point|6d]' strings; docs/contacts.md).
    """
    unknown = sorted(set(xacro) - {"xacro_args", "package_dirs"})
    if unknown:
        raise TypeError(f"load_robot() got an unexpected keyword argument '{unknown[0]}'")
    file, raw, digest = read_source(path, "robot file")
    if looks_like_xml(raw):
        raw = declaration_first(raw, file)  # warns once, not again when MuJoCo's reader parses it
        root = parse_xml(raw, file)
        if root.tag == "mujoco":
            _urdf_only(base, tip, xacro, file, "an MJCF file")
            return with_contacts(mjcf_from_bytes(raw, file, digest, floating=floating), contacts)
        return with_contacts(
            urdf_from_root(root, file, digest, base, tip, floating=floating, **xacro), contacts
        )
    _urdf_only(base, tip, xacro, file, "a robot file")
    robot = robot_from_bytes(raw, file, digest)
    return with_contacts(_floated(robot, file) if floating and not robot.floating else robot, contacts)


def _floated(robot: Robot, file: str) -> Robot:
    """A fixed-base robot made floating: its base frame joined to the world by a free flyer, the base
    body massless (a robot file's `base: floating` gives it a mass)."""
    if robot.base != Transform.identity():
        raise SymdynError(
            "a floating base has no placement in the world (its pose is the coordinates): remove "
            "'base:' or do not ask for a floating base",
            file=file,
            field="base",
        )
    return replace(robot, floating=True)


def _urdf_only(base: str | None, tip: str | None, xacro: dict, file: str, what: str) -> None:
    if base is not None or tip is not None:
        raise SymdynError(f"a base or tip link applies to URDF files only (this is {what})", file=file)
    if any(xacro.values()):
        raise SymdynError(
            f"xacro arguments and package folders apply to xacro files only (this is {what})", file=file
        )
