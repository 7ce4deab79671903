"""URDF -> `symdyn.model.robot.Robot`: one serial chain of a URDF tree, from a base link to a tip link.

The URDF joint frame is the child link's frame, so each URDF link frame becomes
a symdyn body frame unchanged (`Link.frame` is the identity):

* a movable joint (revolute, continuous = revolute, prismatic) of the chain gives
  one `Link`, named after its child link; its `placement` is the product of the
  fixed-joint origins between the previous movable link (or the base) and the
  joint, times the joint's own origin (xyz, rpy = Rz(yaw) Ry(pitch) Rx(roll));
  its `axis` is the joint's <axis xyz> (default 1 0 0), normalised;
* links joined to a chain link by fixed joints are merged into it, and so is
  everything that hangs off the chain (side branches and whatever lies below
  the tip), its joints locked at zero (a mimic joint at multiplier * 0 + offset):
  masses add, centres of mass average, and each inertia tensor is rotated into
  the body axes and moved to the common centre of mass by the parallel-axis
  theorem (symdyn.inertia.rotate, parallel_axis). The inertial <origin> (xyz and
  rpy) is honoured;
* the base link and everything rigidly fixed to it is the ground: its mass does
  not enter the dynamics; links that are not below the base are ignored. The whole
  file must be well formed (XML, numbers, one tree), but inertial data is checked
  (symdyn.inertia.check_inertia: errors and warnings) only for the links that move,
  so a bad tensor on, say, a mobile base's antenna does not refuse its arm;
* <dynamics damping="" friction=""> become friction.viscous and friction.coulomb;
  limits, transmissions, visual and collision elements (and their meshes) are
  ignored: nothing is ever fetched, from disk or the network.

Default base: the root link. Default tip: the single leaf below the base; leaves
that hang by fixed joints only from another leaf's chain do not count (they give
the same dynamics). Several different chains are an error naming the candidates.

Floating and planar joints, and mimic joints that would have to move with the
chain, are refused. Numbers are read as exact SymPy numbers: integers as
Integer, others as Float of the written text; an rpy angle within 1e-9 rad of a
multiple of pi/2 is taken as that exact multiple, so that its sine and cosine are
exactly 0 or +-1 (the 1.5707963267948966 of xacro output), and one within 1e-3 rad
of a nonzero multiple but not 1e-9 (1.5708) warns (symdyn.model.angles).

The XML is read with the standard library's expat parser, hardened: a document
type declaration (<!DOCTYPE ...>, which a URDF never needs) is refused, so no
entity can be declared, expanded or fetched; parameter entities and external
DTDs are never loaded either, and the file may be at most 64 MiB.

The work is shared by four modules: symdyn.parsers.safe_xml (the XML),
symdyn.parsers.urdf_elements (links, joints, inertials), symdyn.parsers.urdf_tree
(the tree, the chain, the merging) and this one (the assembly into a Robot).
"""

from __future__ import annotations

import os

import sympy as sp

from ..errors import SymdynError
from ..model.inertia import check_inertia
from ..model.robot import DEFAULT_GRAVITY, Friction, Link, Robot
from ..spatial.transform import Transform
from .safe_xml import parse_xml
from .source import MAX_BYTES, read_source
from .urdf_elements import MOVABLE, UrdfReader, numeric, urdf_robot_name
from .urdf_tree import UrdfTree, body_parts, default_tip, link_name, merge_inertials

__all__ = ["load_urdf", "urdf_robot_name", "MAX_BYTES"]


def _check_inertials(reader: UrdfReader, names: list[str]) -> None:
    """Impossible inertial data (error) and implausible data (warning) of the links that move."""
    for name in names:
        link = reader.links[name]
        if link.inertial is not None:
            check_inertia(
                link.inertial.mass,
                link.inertial.tensor,
                file=reader.file,
                link_index=link.index,
                link_name=link.name,
            )


def _build(reader: UrdfReader, digest: str, base: str | None, tip: str | None) -> Robot:
    tree = UrdfTree(reader)
    base = tree.root if base is None else link_name(reader, base, "base")
    tip = default_tip(tree, base) if tip is None else link_name(reader, tip, "tip")
    if tip == base:
        raise SymdynError(f"the tip link '{tip}' is the base link", file=reader.file)
    path = tree.path(base, tip)
    if path is None:
        raise SymdynError(f"the tip link '{tip}' is not below the base link '{base}'", file=reader.file)
    movable = [j for j in path if j.movable]
    if not movable:
        raise SymdynError(f"no movable joint between the base '{base}' and the tip '{tip}'", file=reader.file)
    for j in path:
        if j.type in ("floating", "planar") or j.mimic is not None:
            what = f"a {j.type} joint" if j.mimic is None else f"a mimic joint (of '{j.mimic[0]}')"
            raise reader.error(
                f"joint '{j.name}' on the chain from '{base}' to '{tip}' is {what}: symdyn handles "
                "independent revolute, continuous, prismatic and fixed joints only",
                link=reader.links[j.child],
                field=f"joint({j.name}).{'type' if j.mimic is None else 'mimic'}",
                line=j.line if j.mimic is None else j.mimic_line,
            )
    path_names = {j.name for j in path}
    chain = {j.name for j in movable}

    links: list[Link] = []
    fixed = Transform.identity()  # previous body frame -> the current link on the path
    for j in path:
        if not j.movable:
            fixed = fixed @ j.origin
            continue
        child = reader.links[j.child]
        if child.inertial is None:
            raise reader.error(
                "missing <inertial>: a link moved by a joint of the chain needs mass and inertia "
                "(write <inertial> with mass 0 and a zero tensor for a massless link)",
                link=child,
                field="inertial",
                line=child.line,
            )
        parts = body_parts(tree, j.child, path_names, chain)
        _check_inertials(reader, [name for name, _ in parts])
        mass, com, inertia = merge_inertials(
            [(reader.links[n].inertial, T) for n, T in parts if reader.links[n].inertial is not None]
        )
        links.append(
            Link(
                name=child.name,
                joint=MOVABLE[j.type],
                placement=fixed @ j.origin,
                axis=j.axis,
                mass=numeric(mass),
                com=com.applyfunc(numeric),
                inertia=inertia.applyfunc(numeric),
                friction=Friction(j.damping, j.friction),
            )
        )
        fixed = Transform.identity()
    return Robot(
        name=reader.robot_name,
        links=tuple(links),
        gravity=sp.ImmutableMatrix(3, 1, list(DEFAULT_GRAVITY)),
        source=reader.file,
        source_sha256=digest,
        convention="urdf",
    )


def load_urdf(path: str | os.PathLike, base: str | None = None, tip: str | None = None) -> Robot:
    """Read a URDF file and return the serial chain from `base` to `tip` as a `Robot`.

    base: a link name (default: the root link); tip: a link below it (default: the
    single leaf; see the module documentation). Raises SymdynError naming file,
    link and field for bad input; warns with SymdynWarning for implausible inertial
    data of the links used. The robot's name is the URDF name made a C identifier.
    """
    file, raw, digest = read_source(path, "URDF file")
    for what, value in (("base", base), ("tip", tip)):
        if value is not None and not isinstance(value, str):
            raise SymdynError(f"{what} must be a link name, not {value!r}", file=file)
    reader = UrdfReader(file)
    reader.read(parse_xml(raw, file))
    return _build(reader, digest, base, tip)
