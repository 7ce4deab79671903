"""URDF -> `symdyn.model.robot.Robot`: the tree below a base link on a fixed base, or one chain of it.

The URDF joint frame is the child link's frame, so each URDF link frame becomes
a symdyn body frame unchanged (`Link.frame` is the identity):

* every movable joint (revolute, continuous = revolute, prismatic) below the base
  gives one `Link`, named after its child link. Its parent is the link of the
  nearest movable joint above it (-1, the base, when only fixed joints lie between
  it and the base link). Its `placement` is the product of the fixed-joint origins
  from that parent's link down to the joint, times the joint's own origin (xyz,
  rpy = Rz(yaw) Ry(pitch) Rx(roll)); its `axis` is the joint's <axis xyz>
  (default 1 0 0), normalised;
* joint order: depth first from the base, the child joints of each link in the
  order of their names: the order of urdfdom, and so of Pinocchio
  (symdyn.parsers.urdf_tree);
* links joined to a moving link by fixed joints are merged into it (a fixed
  subtree carried by a movable link merges into that link): masses add, centres
  of mass average, and each inertia tensor is rotated into the body axes and moved
  to the common centre of mass by the parallel-axis theorem
  (symdyn.parsers.urdf_merge). The inertial <origin> (xyz and rpy) is honoured; a
  link without <inertial> is massless, as the URDF specification allows, with a
  SymdynWarning when its whole body is (no link fixed to it has one either) and it
  carries a joint away from its frame: in the middle of a chain, a massless link is
  almost always a mistake;
* a <mimic joint= multiplier= offset=> makes the link's `mimic`: q = multiplier *
  q_master + offset with master an independent loaded joint (a mimic of a mimic is
  composed; symdyn.parsers.urdf_mimic). The master may come later in joint order;
* every link merged into a body, or fixed to the base link, keeps its frame under its own
  name (`Robot.frames`, symdyn.model.frames; the base link and the links fixed to it are
  frames on the base), as Pinocchio keeps BODY frames;
* the base link and everything rigidly fixed to it is the ground: its mass does
  not enter the dynamics; links that are not below the base are ignored. The whole
  file must be well formed (XML, numbers, one tree), but inertial data is checked
  (symdyn.inertia.check_inertia: errors and warnings) only for the links that move,
  so a bad tensor on, say, a mobile base's antenna does not refuse its arm;
* <dynamics damping="" friction=""> become friction.viscous and friction.coulomb;
  <limit lower="" upper=""> of a revolute or prismatic joint becomes the link's `limits`
  (lower = upper, the URDF defaults 0 and 0: no range; symdyn.parsers.urdf_elements);
  effort and velocity limits, transmissions, visual and collision elements (and their
  meshes) are ignored: nothing is ever fetched, from disk or the network.

Default base: the root link. A tip cuts one chain out of the tree instead: the
movable joints on the path from the base to the tip, in that order; everything
that hangs off the chain (side branches, whatever lies below the tip) is merged
into the chain link it hangs from, its joints locked at zero (a mimic joint at
its offset, when its master is locked too).

A floating robot (floating=True, --floating): the base link floats, joined to the world by a free
flyer (symdyn.model.free_flyer); a floating joint that joins the root to it through fixed joints
(world -> base_link) is that free flyer, and the base link with the links fixed to it is the
floating base's body (`Robot.base_body`), whose mass enters the dynamics.

Refused, naming the joint: floating and planar joints in the loaded part (a
floating root joint, such as world -> base_link, without floating=True, with the hint to load
it with --floating or the part below it with --base); a mimic of an unknown,
fixed or unloaded joint, and mimic cycles; a locked joint that mimics a joint of
the chain. Numbers are read as doubles (finite, at most 1e150 in absolute
value): integer values as Integer, others as the Float of the double; an rpy
angle within 1e-9 rad of a multiple of pi/2 is taken as that exact multiple, so
that its sine and cosine are exactly 0 or +-1
(the 1.5707963267948966 of xacro output), and one within 1e-3 rad of a nonzero
multiple but not 1e-9 (1.5708) warns (symdyn.model.angles).

A xacro file (named *.xacro, or a <robot> holding <xacro:...> elements) is first expanded by
the `xacro` package in a child process, with the arguments and package folders given
(symdyn.parsers.xacro_expand); the URDF it makes is then read as below.

The XML is read with the standard library's expat parser, hardened: a document
type declaration (<!DOCTYPE ...>, which a URDF never needs) is refused, so no
entity can be declared, expanded or fetched; parameter entities and external
DTDs are never loaded either, and the file may be at most 64 MiB.

The work is shared by six modules: symdyn.parsers.safe_xml (the XML),
symdyn.parsers.urdf_elements (links, joints, inertials), symdyn.parsers.urdf_tree
(the tree and its order), symdyn.parsers.urdf_merge (rigid parts merged),
symdyn.parsers.urdf_mimic (mimic joints) and this one (the assembly into a Robot).
"""

from __future__ import annotations

import os
import warnings
from collections.abc import Mapping

import sympy as sp

from ..errors import SymdynError, SymdynWarning, location
from ..model.contacts import with_contacts
from ..model.frames import Frame
from ..model.inertia import check_inertia
from ..model.robot import DEFAULT_GRAVITY, BaseBody, Friction, Link, Mimic, Robot
from ..spatial.transform import Transform
from .safe_xml import Element, looks_like_xml, parse_xml
from .source import MAX_BYTES, read_source
from .urdf_elements import MOVABLE, UrdfJoint, UrdfReader, numeric, urdf_robot_name
from .urdf_merge import body_parts, merge_inertials
from .urdf_mimic import mimic_error, resolve_mimic
from .urdf_tree import UrdfTree, link_name
from .xacro_expand import expand_xacro, is_xacro

__all__ = ["load_urdf", "urdf_from_bytes", "urdf_from_root", "urdf_robot_name", "MAX_BYTES"]


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


def _warn_massless(reader: UrdfReader, tree: UrdfTree, parts: list[tuple[str, Transform]]) -> None:
    """A SymdynWarning when a moving body (its link and the links fixed to it, `parts`: name and
    body_T_link) has no <inertial> at all yet carries a joint away from its frame: a massless link in
    the middle of a chain. The URDF specification allows it, but it is almost always a mistake.

    Not warned: a frame link without <inertial> fixed to a body that has one (a tool or camera
    frame), and a massless link whose child joints sit at its origin (the intermediate links of a
    spherical or universal joint built from revolute ones)."""
    names = {name for name, _ in parts}
    if any(reader.links[name].inertial is not None for name in names):
        return
    away = [
        j.name
        for name, T in parts
        for j in tree.children[name]
        if j.child not in names and any(x.is_zero is not True for x in (T @ j.origin).p)
    ]
    if away:
        link = reader.links[parts[0][0]]
        joints = ", ".join(f"'{name}'" for name in away)
        warnings.warn(
            f"{location(reader.file, link.index, link.name)}: has no <inertial>, so it is massless, "
            f"yet it carries joint {joints} at a distance; the URDF specification allows this, but in "
            "the middle of a chain it is almost always a forgotten <inertial>",
            SymdynWarning,
            stacklevel=5,
        )


def _refuse_unmodelled(
    reader: UrdfReader, tree: UrdfTree, joints: list[UrdfJoint], base: str, where: str
) -> None:
    """A floating or planar joint among `joints` (the loaded part) is refused, naming it."""
    for j in joints:
        if j.type not in ("floating", "planar"):
            continue
        if all(k.type == "fixed" for k in tree.path(base, j.parent)):  # the robot's own floating base
            hint = (
                f"load it as a floating base with --floating (floating=True), or the robot below it on a "
                f"fixed base with --base {j.child}"
                if j.type == "floating"
                else f"planar bases are out of scope: load the robot below it with --base {j.child}"
            )
        else:
            hint = "choose a base below it (--base), or a tip (--tip) whose chain does not carry it"
        raise reader.error(
            f"joint '{j.name}' {where} is a {j.type} joint: symdyn handles revolute, continuous, "
            f"prismatic and fixed joints only; {hint}",
            link=reader.links[j.child],
            field=f"joint({j.name}).type",
            line=j.line,
        )


def _loaded(
    reader: UrdfReader, tree: UrdfTree, base: str, tip: str | None, floating: bool = False
) -> tuple[list[UrdfJoint], str]:
    """The movable joints that become links, in joint order, and where they lie (for messages).
    A floating base may have none (a single rigid body: a quadrotor's frame); a fixed one may not."""
    if tip is None:
        joints = tree.depth_first(base)
        where = f"below the base '{base}'"
        if not joints and not floating:
            raise SymdynError(f"the base link '{base}' has no links below it", file=reader.file)
        if not floating and not any(j.movable for j in joints):
            raise SymdynError(f"no movable joint below the base link '{base}'", file=reader.file)
    else:
        tip = link_name(reader, tip, "tip")
        if tip == base:
            raise SymdynError(f"the tip link '{tip}' is the base link", file=reader.file)
        joints = tree.path(base, tip)
        if joints is None:
            raise SymdynError(f"the tip link '{tip}' is not below the base link '{base}'", file=reader.file)
        where = f"on the chain from '{base}' to '{tip}'"
        if not any(j.movable for j in joints):
            raise SymdynError(
                f"no movable joint between the base '{base}' and the tip '{tip}'", file=reader.file
            )
    _refuse_unmodelled(reader, tree, joints, base, where)
    return [j for j in joints if j.movable], where


def _mimic(reader: UrdfReader, joint: UrdfJoint, index: dict[str, int], where: str) -> Mimic | None:
    """The link's Mimic (the index of its independent master among the loaded links), or None."""
    followed = resolve_mimic(reader, joint)
    if followed is None:
        return None
    master, multiplier, offset = followed
    if master.name not in index:
        raise mimic_error(
            reader,
            joint,
            f"follows joint '{master.name}', which is not loaded: it is not {where} "
            "(cut away by --base or --tip; choose them so that both joints are loaded)",
        )
    return Mimic(index[master.name], multiplier, offset)


def _floating_root(reader: UrdfReader, tree: UrdfTree, base: str) -> str:
    """The floating base's link: `base`, or the child of the floating joint that joins it (through
    fixed joints only) to the world, such as world -> base_link: that joint is the free flyer."""
    stack = [base]
    while stack:
        name = stack.pop()
        for j in tree.children[name]:
            if j.type == "floating":
                return j.child
            if j.type == "fixed":
                stack.append(j.child)
    return base


def _base_body(reader: UrdfReader, tree: UrdfTree, base: str) -> BaseBody:
    """The floating base's body: the base link and the links fixed to it, merged."""
    parts = _fixed_parts(tree, base)
    _check_inertials(reader, [name for name, _ in parts])
    mass, com, inertia = merge_inertials(
        [(reader.links[n].inertial, T) for n, T in parts if reader.links[n].inertial is not None]
    )
    return BaseBody(base, numeric(mass), com.applyfunc(numeric), inertia.applyfunc(numeric))


def _build(
    reader: UrdfReader, digest: str, base: str | None, tip: str | None, floating: bool = False
) -> Robot:
    tree = UrdfTree(reader)
    base = tree.root if base is None else link_name(reader, base, "base")
    if floating:
        if tip is not None:
            raise SymdynError(
                "a floating robot is the whole tree below its base: give no tip (--tip) with --floating",
                file=reader.file,
            )
        base = _floating_root(reader, tree, base)
    loaded, where = _loaded(reader, tree, base, tip, floating)
    index = {j.name: i for i, j in enumerate(loaded)}

    links: list[Link] = []
    frames = [Frame(name, -1, T) for name, T in _fixed_parts(tree, base)]
    for i, j in enumerate(loaded):
        carrier, fixed = tree.carrier(j, index, base)
        parent = -1 if carrier is None else index[carrier.name]
        parts = body_parts(tree, j.child, index)
        frames += [Frame(name, i, T) for name, T in parts[1:]]
        _check_inertials(reader, [name for name, _ in parts])
        _warn_massless(reader, tree, parts)
        mass, com, inertia = merge_inertials(
            [(reader.links[n].inertial, T) for n, T in parts if reader.links[n].inertial is not None]
        )
        links.append(
            Link(
                name=j.child,
                joint=MOVABLE[j.type],
                placement=fixed @ j.origin,
                axis=j.axis,
                mass=numeric(mass),
                com=com.applyfunc(numeric),
                inertia=inertia.applyfunc(numeric),
                friction=Friction(j.damping, j.friction),
                parent=None if parent == i - 1 else parent,
                mimic=_mimic(reader, j, index, where),
                limits=j.limits,
                joint_name=j.name,
            )
        )
    return Robot(
        name=reader.robot_name,
        links=tuple(links),
        gravity=sp.ImmutableMatrix(3, 1, list(DEFAULT_GRAVITY)),
        source=reader.file,
        source_sha256=digest,
        convention="urdf",
        frames=tuple(frames),
        floating=floating,
        base_body=_base_body(reader, tree, base) if floating else BaseBody(base),
    )


def _fixed_parts(tree: UrdfTree, base: str) -> list:
    """(link, base_T_link) of the base link and the links fixed to it (fixed joints only): the
    frames of the ground."""
    parts, stack = [], [(base, Transform.identity())]
    while stack:
        name, T = stack.pop()
        parts.append((name, T))
        stack += [(j.child, T @ j.origin) for j in reversed(tree.children[name]) if j.type == "fixed"]
    return parts


def load_urdf(
    path: str | os.PathLike,
    base: str | None = None,
    tip: str | None = None,
    xacro_args: Mapping[str, str] | None = None,
    package_dirs: Mapping[str, str] | None = None,
    floating: bool = False,
    contacts: object = None,
) -> Robot:
    """Read a URDF file and return the tree below `base`, or the chain from `base` to `tip`, as a `Robot`.

    floating=True: the base link (default the root link; the child of a floating joint that joins
    the root to the world, such as world -> base_link) is a floating base joined to the world by a
    free flyer (symdyn.model.free_flyer), its mass and inertia (and those of the links fixed to it)
    part of the dynamics; no tip then.

    base: a link name (default: the root link); tip: a link below it (default: none,
    the whole tree; see the module documentation). A xacro file (named *.xacro, or declaring
    the xacro namespace) is expanded first by the `xacro` package (pip install 'symdyn[xacro]'),
    with the arguments `xacro_args` ({name: value}, as xacro's name:=value) and the package
    folders `package_dirs` ({package: folder}, for $(find pkg) and package://pkg; then
    ROS_PACKAGE_PATH): symdyn.parsers.xacro_expand. Raises SymdynError naming file,
    link and field for bad input; warns with SymdynWarning for implausible inertial
    data of the links used. The robot's name is the URDF name made a C identifier.
    `symdyn.load_robot` reads a URDF too (it recognises one by its content). contacts: the robot's
    contacts with the world (symdyn.model.contacts; docs/contacts.md).
    """
    file, raw, digest = read_source(path, "URDF file")
    robot = urdf_from_bytes(
        raw, file, digest, base, tip, xacro_args=xacro_args, package_dirs=package_dirs, floating=floating
    )
    return with_contacts(robot, contacts)


def urdf_from_bytes(
    raw: bytes,
    file: str,
    digest: str,
    base: str | None,
    tip: str | None,
    floating: bool = False,
    **xacro: Mapping[str, str] | None,
) -> Robot:
    """The `Robot` of a URDF file's bytes (`file` names it in messages, `digest` is their sha256);
    `xacro`: xacro_args and package_dirs of a xacro file (see load_urdf)."""
    if not looks_like_xml(raw):
        raise SymdynError(
            "not a URDF: the file does not start with an XML element ('<'); "
            "a robot file (YAML or JSON) is read by symdyn.load_robot",
            file=file,
        )
    return urdf_from_root(parse_xml(raw, file), file, digest, base, tip, floating=floating, **xacro)


def urdf_from_root(
    root: Element,
    file: str,
    digest: str,
    base: str | None,
    tip: str | None,
    xacro_args: Mapping[str, str] | None = None,
    package_dirs: Mapping[str, str] | None = None,
    floating: bool = False,
) -> Robot:
    """The `Robot` of a URDF file's parsed top element (`file` names it, `digest` is its sha256);
    a xacro file is expanded first (its digest is then the expanded URDF's)."""
    for what, value in (("base", base), ("tip", tip)):
        if value is not None and not isinstance(value, str):
            raise SymdynError(f"{what} must be a link name, not {value!r}", file=file)
    if root.tag == "robot" and is_xacro(file, root):
        raw, digest = expand_xacro(file, xacro_args, package_dirs)
        root = parse_xml(raw, file)
    elif xacro_args or package_dirs:
        raise SymdynError("xacro arguments and package folders apply to xacro files only", file=file)
    reader = UrdfReader(file)
    reader.read(root)
    return _build(reader, digest, base, tip, floating)
