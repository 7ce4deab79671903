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
exactly 0 or +-1 (the 1.5707963267948966 of xacro output).

The XML is read with the standard library's expat parser, hardened: a document
type declaration (<!DOCTYPE ...>, which a URDF never needs) is refused, so no
entity can be declared, expanded or fetched; parameter entities and external
DTDs are never loaded either, and the file may be at most 64 MiB.
"""

from __future__ import annotations

import difflib
import math
import os
import re
from dataclasses import dataclass, field
from xml.parsers import expat

import sympy as sp

from ..errors import SymdynError
from ..model.expressions import C_KEYWORDS
from ..model.inertia import check_inertia, parallel_axis, rotate, tensor_from_components
from ..model.robot import DEFAULT_GRAVITY, Friction, Link, Robot
from ..spatial.transform import Transform, rot_axis, rpy_matrix
from .source import MAX_BYTES, read_source

__all__ = ["load_urdf", "urdf_robot_name", "MAX_BYTES"]

JOINT_TYPES = ("revolute", "continuous", "prismatic", "fixed", "floating", "planar")
_MOVABLE = {"revolute": "revolute", "continuous": "revolute", "prismatic": "prismatic"}
_NUMBER = re.compile(r"[+-]?(?:[0-9]+\.?[0-9]*|\.[0-9]+)(?:[eE][+-]?[0-9]+)?\Z")
_INERTIA_KEYS = ("ixx", "ixy", "ixz", "iyy", "iyz", "izz")
_SNAP_TOLERANCE = 1e-9


# --------------------------------------------------------------------------- XML


@dataclass
class _Element:
    tag: str
    attrib: dict[str, str]
    line: int
    children: list[_Element] = field(default_factory=list)

    def all(self, tag: str) -> list[_Element]:
        return [c for c in self.children if c.tag == tag]


class _RefusedError(Exception):
    pass


def _parse_xml(raw: bytes, file: str) -> _Element:
    """A tree of elements (tag, attributes, line) from hardened expat; character data is dropped."""
    parser = expat.ParserCreate()  # no namespace processing: tags as written (xacro:macro)
    parser.SetParamEntityParsing(expat.XML_PARAM_ENTITY_PARSING_NEVER)
    stack: list[_Element] = []
    roots: list[_Element] = []

    def start(tag: str, attrib: dict[str, str]) -> None:
        el = _Element(tag, attrib, parser.CurrentLineNumber)
        (stack[-1].children if stack else roots).append(el)
        stack.append(el)

    def end(tag: str) -> None:
        stack.pop()

    def doctype(name, system_id, public_id, has_internal_subset) -> None:
        raise _RefusedError(
            f"line {parser.CurrentLineNumber}: document type declarations (<!DOCTYPE>) are refused: "
            "a URDF needs none, and refusing them rules out external entities and entity expansion"
        )

    def entity_declaration(name, *args) -> None:
        raise _RefusedError(
            f"line {parser.CurrentLineNumber}: the document declares the entity '{name}'; "
            "entity declarations are refused (no external entities, no entity expansion)"
        )

    def external_entity(context, base, system_id, public_id):
        raise _RefusedError(f"line {parser.CurrentLineNumber}: external entity {system_id!r} refused")

    parser.StartElementHandler = start
    parser.EndElementHandler = end
    parser.StartDoctypeDeclHandler = doctype
    parser.EntityDeclHandler = entity_declaration  # (unreachable without a DTD: defence in depth)
    parser.UnparsedEntityDeclHandler = entity_declaration
    parser.ExternalEntityRefHandler = external_entity
    try:
        parser.Parse(raw, True)
    except expat.ExpatError as exc:
        raise SymdynError(
            f"invalid XML at line {exc.lineno}, column {exc.offset + 1}: {expat.ErrorString(exc.code)}",
            file=file,
        ) from None
    except _RefusedError as exc:
        raise SymdynError(str(exc), file=file) from None
    return roots[0]


# --------------------------------------------------------------------------- the URDF model


@dataclass
class _Inertial:
    mass: sp.Expr
    origin: Transform  # the inertial frame (centre of mass, tensor axes) in the link frame
    tensor: sp.ImmutableMatrix  # about the centre of mass, inertial-frame axes


@dataclass
class _ULink:
    index: int  # 1-based position among the file's <link> elements
    name: str
    line: int
    inertial: _Inertial | None


@dataclass
class _UJoint:
    name: str
    line: int
    type: str
    parent: str
    child: str
    origin: Transform
    axis: sp.ImmutableMatrix | None  # unit vector (movable joints only)
    damping: sp.Expr
    friction: sp.Expr
    mimic: tuple[str, sp.Expr, sp.Expr] | None  # (joint, multiplier, offset)
    mimic_line: int = 0

    @property
    def movable(self) -> bool:
        return self.type in _MOVABLE


def urdf_robot_name(name: str) -> str:
    """The URDF robot name as a C identifier: other characters become '_'; a leading digit or
    underscore gets the prefix 'robot_' / 'robot'; a C keyword the suffix '_robot'."""
    s = re.sub(r"[^A-Za-z0-9_]", "_", name)
    if not s:
        return "robot"
    if s[0].isdigit():
        s = "robot_" + s
    elif s[0] == "_":
        s = "robot" + s
    if s in C_KEYWORDS:
        s += "_robot"
    return s


def _snap_angle(x: sp.Expr) -> sp.Expr:
    """x, or the exact multiple of pi/2 within 1e-9 rad of it."""
    if not isinstance(x, sp.Float):
        return x
    k = round(float(x) / (math.pi / 2))
    if abs(float(x) - k * math.pi / 2) <= _SNAP_TOLERANCE:
        return k * sp.pi / 2
    return x


class _Reader:
    """Reads the <robot> element into links and joints, with one clear error per problem."""

    def __init__(self, file: str) -> None:
        self.file = file
        self.links: dict[str, _ULink] = {}
        self.joints: dict[str, _UJoint] = {}
        self.robot_name = "robot"

    # -- errors
    def error(self, message: str, *, link: _ULink | None = None, field: str | None = None, line=None):
        if line:
            message = f"{message} (line {line})"
        return SymdynError(
            message,
            file=self.file,
            link_index=None if link is None else link.index,
            link_name=None if link is None else link.name,
            field=field,
        )

    # -- values
    def number(self, text: str | None, where: dict, line: int) -> sp.Expr:
        s = (text or "").strip()
        if not _NUMBER.match(s):
            raise self.error(f"expected a number, got {text!r}", line=line, **where)
        x = float(s)
        if not math.isfinite(x):
            raise self.error(f"{s} is not a finite number", line=line, **where)
        if x == int(x) and abs(x) < 2**53:
            return sp.Integer(int(x))
        return sp.Float(s)

    def vector(self, text: str | None, where: dict, line: int) -> list[sp.Expr]:
        parts = (text or "").split()
        if len(parts) != 3:
            raise self.error(f"expected 3 numbers 'x y z', got {text!r}", line=line, **where)
        return [self.number(p, where, line) for p in parts]

    def one(self, el: _Element, tag: str, where: dict, required: bool = False) -> _Element | None:
        found = el.all(tag)
        if len(found) > 1:
            raise self.error(f"more than one <{tag}>", line=found[1].line, **where)
        if not found and required:
            raise self.error(f"missing <{tag}>", line=el.line, **where)
        return found[0] if found else None

    def attribute(self, el: _Element, name: str, where: dict) -> str:
        if name not in el.attrib:
            raise self.error(f"<{el.tag}> needs the attribute '{name}'", line=el.line, **where)
        return el.attrib[name]

    def origin(self, parent: _Element, where: dict, prefix: str) -> Transform:
        el = self.one(parent, "origin", _at(where, prefix + "origin"))
        if el is None:
            return Transform.identity()
        xyz = self.vector(el.attrib.get("xyz", "0 0 0"), _at(where, prefix + "origin.xyz"), el.line)
        rpy = self.vector(el.attrib.get("rpy", "0 0 0"), _at(where, prefix + "origin.rpy"), el.line)
        R = rpy_matrix(*(_snap_angle(a) for a in rpy)).applyfunc(_numeric)  # cos(1) -> 0.5403...
        return Transform(R, sp.ImmutableMatrix(3, 1, xyz))

    # -- the document
    def read(self, root: _Element) -> None:
        if root.tag != "robot":
            raise self.error(f"the top element must be <robot>, not <{root.tag}>", line=root.line)
        self._refuse_xacro(root)
        if "name" not in root.attrib:
            raise self.error("<robot> needs the attribute 'name'", field="robot.name", line=root.line)
        self.robot_name = urdf_robot_name(root.attrib["name"])
        links = root.all("link")
        if not links:
            raise self.error("the robot has no <link>", line=root.line)
        for i, el in enumerate(links, start=1):
            self._read_link(i, el)
        for el in root.all("joint"):
            self._read_joint(el)

    def _refuse_xacro(self, root: _Element) -> None:
        stack = [root]
        while stack:
            el = stack.pop()
            if el.tag.startswith("xacro:"):
                raise self.error(
                    f"<{el.tag}> is a xacro macro: expand the file with xacro first", line=el.line
                )
            stack.extend(el.children)

    def _read_link(self, index: int, el: _Element) -> None:
        name = el.attrib.get("name", "")
        link = _ULink(index, name or f"link{index}", el.line, None)
        where = {"link": link}
        if not name:
            raise self.error("<link> needs a non-empty attribute 'name'", field="name", line=el.line, **where)
        if name in self.links:
            other = self.links[name]
            raise self.error(
                f"duplicate link name '{name}' (also link {other.index}, line {other.line})",
                field="name",
                line=el.line,
                **where,
            )
        self.links[name] = link
        inertial = self.one(el, "inertial", where)
        if inertial is None:
            return
        mass_el = self.one(inertial, "mass", _at(where, "inertial.mass"), required=True)
        mass = self.number(
            self.attribute(mass_el, "value", _at(where, "inertial.mass.value")),
            _at(where, "inertial.mass.value"),
            mass_el.line,
        )
        origin = self.origin(inertial, where, "inertial.")
        tensor_el = self.one(inertial, "inertia", _at(where, "inertial.inertia"), required=True)
        e = {
            k: self.number(
                self.attribute(tensor_el, k, _at(where, f"inertial.inertia.{k}")),
                _at(where, f"inertial.inertia.{k}"),
                tensor_el.line,
            )
            for k in _INERTIA_KEYS
        }
        link.inertial = _Inertial(mass, origin, tensor_from_components(e))

    def _read_joint(self, el: _Element) -> None:
        name = el.attrib.get("name", "")
        child_el = el.all("child")
        child_name = child_el[0].attrib.get("link") if len(child_el) == 1 else None
        link = self.links.get(child_name) if child_name else None
        label = f"joint({name or '?'})"
        where = {"link": link, "field": label}
        if not name:
            raise self.error("<joint> needs a non-empty attribute 'name'", line=el.line, **where)
        if name in self.joints:
            raise self.error(
                f"duplicate joint name '{name}' (also at line {self.joints[name].line})",
                line=el.line,
                **where,
            )
        kind = el.attrib.get("type")
        if kind is None:
            raise self.error(
                "<joint> needs the attribute 'type'", line=el.line, **_at(where, label + ".type")
            )
        if kind not in JOINT_TYPES:
            raise self.error(
                f"unknown joint type '{kind}'{_suggest(kind, JOINT_TYPES)}; "
                f"URDF joint types: {', '.join(JOINT_TYPES)}",
                line=el.line,
                **_at(where, label + ".type"),
            )
        ends = {}
        for end in ("parent", "child"):
            end_where = _at(where, f"{label}.{end}")
            end_el = self.one(el, end, end_where, required=True)
            target = self.attribute(end_el, "link", _at(where, f"{label}.{end}.link"))
            if target not in self.links:
                raise self.error(
                    f"{end} link '{target}' does not exist{_suggest(target, self.links)}",
                    line=end_el.line,
                    **_at(where, f"{label}.{end}.link"),
                )
            ends[end] = target
        origin = self.origin(el, where, label + ".")
        axis = None
        if kind in _MOVABLE:
            axis_el = self.one(el, "axis", _at(where, label + ".axis"))
            axis_where = _at(where, label + ".axis.xyz")
            if axis_el is None:
                v = [sp.Integer(1), sp.Integer(0), sp.Integer(0)]
            else:
                v = self.vector(self.attribute(axis_el, "xyz", axis_where), axis_where, axis_el.line)
            norm2 = sum(x**2 for x in v)
            if float(norm2) < 1e-24:
                raise self.error(
                    "the joint axis is zero", line=axis_el.line if axis_el else el.line, **axis_where
                )
            axis = sp.ImmutableMatrix(3, 1, [x / sp.sqrt(norm2) for x in v])
        damping = friction = sp.S.Zero
        dyn = self.one(el, "dynamics", _at(where, label + ".dynamics"))
        if dyn is not None:
            values = {}
            for key in ("damping", "friction"):
                fld = _at(where, f"{label}.dynamics.{key}")
                values[key] = self.number(dyn.attrib.get(key, "0"), fld, dyn.line)
                if values[key] < 0:
                    raise self.error(f"must not be negative (got {values[key]})", line=dyn.line, **fld)
            damping, friction = values["damping"], values["friction"]
        mimic = None
        mimic_el = self.one(el, "mimic", _at(where, label + ".mimic"))
        if mimic_el is not None:
            master = self.attribute(mimic_el, "joint", _at(where, label + ".mimic.joint"))
            factors = [
                self.number(mimic_el.attrib.get(k, d), _at(where, f"{label}.mimic.{k}"), mimic_el.line)
                for k, d in (("multiplier", "1"), ("offset", "0"))
            ]
            mimic = (master, factors[0], factors[1])
        self.joints[name] = _UJoint(
            name, el.line, kind, ends["parent"], ends["child"], origin, axis, damping, friction, mimic,
            mimic_el.line if mimic_el is not None else 0,
        )  # fmt: skip


def _at(where: dict, fld: str) -> dict:
    return {**where, "field": fld}


def _suggest(name: str, names) -> str:
    close = difflib.get_close_matches(name, list(names), n=1)
    return f" (did you mean '{close[0]}'?)" if close else ""


# --------------------------------------------------------------------------- the tree


class _Tree:
    """Parent and child joints of every link; refuses graphs that are not one tree."""

    def __init__(self, reader: _Reader) -> None:
        self.reader = reader
        self.links = reader.links
        self.joints = reader.joints
        self.parent: dict[str, _UJoint] = {}
        self.children: dict[str, list[_UJoint]] = {name: [] for name in self.links}
        for j in self.joints.values():
            child = self.links[j.child]
            if j.parent == j.child:
                raise reader.error(
                    f"joint '{j.name}' joins link '{j.child}' to itself (a cycle)",
                    link=child,
                    field=f"joint({j.name}).child",
                    line=j.line,
                )
            if j.child in self.parent:
                other = self.parent[j.child]
                raise reader.error(
                    f"link '{j.child}' is the child of two joints, '{other.name}' (line {other.line}) "
                    f"and '{j.name}': a URDF is a tree, not a closed loop",
                    link=child,
                    field=f"joint({j.name}).child",
                    line=j.line,
                )
            self.parent[j.child] = j
            self.children[j.parent].append(j)
        self._check_tree()

    def _check_tree(self) -> None:
        roots = [name for name in self.links if name not in self.parent]
        reached: set[str] = set()
        stack = list(roots)
        while stack:
            name = stack.pop()
            reached.add(name)
            stack.extend(j.child for j in self.children[name])
        unreached = [name for name in self.links if name not in reached]
        if unreached:  # each link has at most one parent: what no root reaches lies on a cycle
            cycle = [unreached[0]]
            while True:
                nxt = self.parent[cycle[-1]].parent
                if nxt in cycle:
                    cycle = cycle[cycle.index(nxt) :] + [nxt]
                    break
                cycle.append(nxt)
            cycle.reverse()  # parent -> child order
            j = self.parent[cycle[1]]
            raise self.reader.error(
                "the joints form a cycle: " + " -> ".join(cycle) + " (a URDF is a tree)",
                link=self.links[cycle[1]],
                field=f"joint({j.name}).child",
                line=j.line,
            )
        if len(roots) > 1:
            raise self.reader.error(
                f"the links form {len(roots)} separate trees, with roots {', '.join(roots)}: "
                "a URDF has one root link (is a joint missing?)"
            )
        self.root = roots[0]

    def path(self, base: str, tip: str) -> list[_UJoint] | None:
        """The joints from base down to tip, or None if tip is not below base."""
        joints = []
        name = tip
        while name != base:
            if name not in self.parent:
                return None
            j = self.parent[name]
            joints.append(j)
            name = j.parent
        return joints[::-1]

    def leaves(self, base: str) -> list[str]:
        out, stack = [], [base]
        while stack:
            name = stack.pop()
            kids = self.children[name]
            if not kids and name != base:
                out.append(name)
            stack.extend(j.child for j in kids)
        return sorted(out, key=lambda name: self.links[name].index)  # file order


def _link_name(reader: _Reader, name: str | None, what: str) -> str:
    if not isinstance(name, str) or name not in reader.links:
        raise SymdynError(
            f"{what} link {name!r} is not a link of the robot{_suggest(str(name), reader.links)}",
            file=reader.file,
        )
    return name


def _default_tip(tree: _Tree, base: str) -> str:
    """The single leaf below base; leaves whose movable joints are a prefix of another's don't count."""
    leaves = tree.leaves(base)
    if not leaves:
        raise SymdynError(f"the base link '{base}' has no links below it", file=tree.reader.file)
    chains = {leaf: tuple(j.name for j in tree.path(base, leaf) if j.movable) for leaf in leaves}
    best: dict[tuple[str, ...], str] = {}
    for leaf in leaves:
        c = chains[leaf]
        if any(o != c and o[: len(c)] == c for o in chains.values()):
            continue  # hangs by fixed joints from a longer chain: merged or locked either way
        best.setdefault(c, leaf)
    if len(best) == 1:
        return next(iter(best.values()))
    candidates = list(best.values())
    common = _common_ancestor(tree, base, candidates)
    hint = f", or '{common}' to lock everything below it" if common else ""
    raise SymdynError(
        f"the tree below '{base}' has several leaf links ending different chains: "
        f"{', '.join(candidates)}; choose the tip (tip=... or --tip LINK){hint}",
        file=tree.reader.file,
    )


def _common_ancestor(tree: _Tree, base: str, leaves: list[str]) -> str | None:
    paths = [[base] + [j.child for j in tree.path(base, leaf)] for leaf in leaves]
    common = None
    for names in zip(*paths, strict=False):
        if len(set(names)) != 1:
            break
        common = names[0]
    return None if common == base else common


# --------------------------------------------------------------------------- building


def _locked_transform(tree: _Tree, joint: _UJoint, chain: set[str]) -> Transform:
    """origin @ motion of an off-chain joint held at its locked position (0, or a mimic's offset)."""
    if joint.type in ("floating", "planar"):
        raise tree.reader.error(
            f"joint '{joint.name}' is {joint.type}: symdyn handles revolute, continuous, prismatic "
            "and fixed joints only (choose a base below it, or another tip)",
            link=tree.links[joint.child],
            field=f"joint({joint.name}).type",
            line=joint.line,
        )
    if joint.type == "fixed":
        return joint.origin
    value = _locked_value(tree, joint, chain)
    if joint.type == "prismatic":
        motion = Transform.from_translation(list(joint.axis * value))
    else:
        motion = Transform.from_rotation(rot_axis(list(joint.axis), value))
    return joint.origin @ motion


def _locked_value(tree: _Tree, joint: _UJoint, chain: set[str], seen: tuple[str, ...] = ()) -> sp.Expr:
    """The position of a locked joint: 0, or multiplier * (its master's position) + offset."""
    if joint.mimic is None:
        return sp.S.Zero
    master_name, multiplier, offset = joint.mimic
    master = tree.joints.get(master_name)
    where = {
        "link": tree.links[joint.child],
        "field": f"joint({joint.name}).mimic.joint",
        "line": joint.mimic_line,
    }
    if master is None:
        raise tree.reader.error(
            f"mimics joint '{master_name}', which does not exist{_suggest(master_name, tree.joints)}",
            **where,
        )
    if master.name in chain:
        raise tree.reader.error(
            f"mimic joint '{joint.name}' follows the chain joint '{master.name}': symdyn does not "
            "couple joints (choose a tip whose chain includes neither, or lock both)",
            **where,
        )
    if master.name == joint.name or master.name in seen:
        raise tree.reader.error("mimic joints follow each other in a cycle", **where)
    if master.type not in _MOVABLE:
        return offset
    return multiplier * _locked_value(tree, master, chain, (*seen, joint.name)) + offset


def _body_parts(tree: _Tree, start: str, path: set[str], chain: set[str]) -> list[tuple[str, Transform]]:
    """(link, body_T_link) of every link rigidly attached to `start` once off-chain joints are locked."""
    parts = []
    stack = [(start, Transform.identity())]
    while stack:
        name, T = stack.pop()
        parts.append((name, T))
        for j in reversed(tree.children[name]):
            if j.name in path:
                if j.movable:
                    continue  # the next body of the chain
                stack.append((j.child, T @ j.origin))
            else:
                stack.append((j.child, T @ _locked_transform(tree, j, chain)))
    return parts


def _merge(
    parts: list[tuple[_Inertial, Transform]],
) -> tuple[sp.Expr, sp.ImmutableMatrix, sp.ImmutableMatrix]:
    """Mass, centre of mass and inertia about it (body axes) of rigidly joined inertials."""
    items = []
    for inertial, T in parts:
        frame = T @ inertial.origin  # the inertial frame in the body frame
        tensor = inertial.tensor if sp.eye(3) == frame.R else rotate(inertial.tensor, frame.R)
        if inertial.mass == 0 and tensor == sp.zeros(3, 3):
            continue  # a massless frame adds nothing
        items.append((inertial.mass, frame.p, sp.ImmutableMatrix(tensor)))
    if not items:
        zero = sp.ImmutableMatrix(sp.zeros(3, 1))
        return sp.S.Zero, zero, sp.ImmutableMatrix(sp.zeros(3, 3))
    if len(items) == 1:
        return items[0]
    mass = sum((m for m, _, _ in items), sp.S.Zero)
    if mass == 0:
        com = sp.ImmutableMatrix(sp.zeros(3, 1))
    else:
        com = sp.ImmutableMatrix(sum((m * c for m, c, _ in items), sp.zeros(3, 1)) / mass)
    tensor = sp.zeros(3, 3)
    for m, c, inertia in items:
        tensor += parallel_axis(inertia, m, list(c - com))
    return mass, com, sp.ImmutableMatrix(tensor)


def _numeric(x: sp.Expr) -> sp.Expr:
    """Exact rationals stay; other numeric constants (e.g. sqrt(2)*0.3) become Floats."""
    x = sp.sympify(x, strict=True)
    if x.is_Rational or isinstance(x, sp.Float) or x.free_symbols:
        return x
    return sp.Float(x.evalf(17), 17)


def _check_inertials(reader: _Reader, names: list[str]) -> None:
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


def _build(reader: _Reader, digest: str, base: str | None, tip: str | None) -> Robot:
    tree = _Tree(reader)
    base = tree.root if base is None else _link_name(reader, base, "base")
    tip = _default_tip(tree, base) if tip is None else _link_name(reader, tip, "tip")
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
        parts = _body_parts(tree, j.child, path_names, chain)
        _check_inertials(reader, [name for name, _ in parts])
        mass, com, inertia = _merge(
            [(reader.links[n].inertial, T) for n, T in parts if reader.links[n].inertial is not None]
        )
        links.append(
            Link(
                name=child.name,
                joint=_MOVABLE[j.type],
                placement=fixed @ j.origin,
                axis=j.axis,
                mass=_numeric(mass),
                com=com.applyfunc(_numeric),
                inertia=inertia.applyfunc(_numeric),
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
    reader = _Reader(file)
    reader.read(_parse_xml(raw, file))
    return _build(reader, digest, base, tip)
