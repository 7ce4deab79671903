"""The URDF element reader: <robot>, <link> (with <inertial>) and <joint> elements as plain records.

Every link and joint of the file is read and checked here, one clear SymdynError
(file, link, field, line) per problem; the tree, the chain and the Robot are built
from these records by symdyn.parsers.urdf_tree and symdyn.parsers.urdf.

Numbers are read as doubles (Python's float(), whatever number of digits is written),
finite and at most 1e150 in absolute value: integer values below 2**53 become exact
Integers, others a Float of the double. An origin's rotation is R = Rz(yaw) Ry(pitch) Rx(roll) (the URDF
rpy convention), its entries numbers (cos(1) becomes 0.5403...). Each rpy angle
passes through symdyn.model.angles.snap_angle, the rule of the DH loader too:
within 1e-9 rad of a multiple of pi/2 it is taken as that exact multiple, so that
its sine and cosine are exactly 0 or +-1 (the 1.5707963267948966 of xacro output);
within 1e-3 rad of a nonzero multiple but not 1e-9 (1.5708) it is kept as written
with a SymdynWarning naming the file, the link, the field and the line, whether or
not that link ends up in the robot (the whole file is read).
A joint's <axis xyz> (default 1 0 0) is normalised; of several <axis> elements the first is
read and the others are ignored, with a SymdynWarning, as urdfdom (and so Pinocchio) reads them.
The <limit lower= upper=> of a revolute or prismatic joint is its range (lower and upper
default to 0, as in the URDF specification): lower < upper gives `limits`; lower = upper
(0 and 0 when neither is written) says nothing about the range, which stays None, as for a
continuous joint (whose <limit> is not read); lower > upper, Bullet's way of writing "no limit",
which urdfdom and Pinocchio load as written, is no range either, with a SymdynWarning naming the
file, the joint and the field. Its other attributes (effort, velocity) are not read.
"""

from __future__ import annotations

import math
import re
import warnings
from dataclasses import dataclass

import sympy as sp

from ..errors import SymdynError, SymdynWarning, link_fields, location
from ..model.angles import snap_angle
from ..model.bounded import MAX_MAGNITUDE
from ..model.expressions import C_KEYWORDS
from ..model.inertia import tensor_from_components
from ..spatial.transform import Transform, rpy_matrix
from .safe_xml import Element
from .source import check_link_count, did_you_mean

__all__ = [
    "JOINT_TYPES",
    "MOVABLE",
    "UrdfInertial",
    "UrdfJoint",
    "UrdfLink",
    "UrdfReader",
    "numeric",
    "urdf_robot_name",
]

JOINT_TYPES = ("revolute", "continuous", "prismatic", "fixed", "floating", "planar")
#: URDF joint type -> symdyn joint type, for the joints that move.
MOVABLE = {"revolute": "revolute", "continuous": "revolute", "prismatic": "prismatic"}
_NUMBER = re.compile(r"[+-]?(?:[0-9]+\.?[0-9]*|\.[0-9]+)(?:[eE][+-]?[0-9]+)?\Z")
_INERTIA_KEYS = ("ixx", "ixy", "ixz", "iyy", "iyz", "izz")


@dataclass
class UrdfInertial:
    """A link's <inertial>: mass, the inertial frame in the link frame, the tensor in that frame."""

    mass: sp.Expr
    origin: Transform  # the inertial frame (centre of mass, tensor axes) in the link frame
    tensor: sp.ImmutableMatrix  # about the centre of mass, inertial-frame axes


@dataclass
class UrdfLink:
    """A <link> element: its position in the file, name, line and inertial data (None without)."""

    index: int  # 1-based position among the file's <link> elements
    name: str
    line: int
    inertial: UrdfInertial | None


@dataclass
class UrdfJoint:
    """A <joint> element; `origin` is the child link frame in the parent link frame at q = 0."""

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
    limits: tuple[sp.Expr, sp.Expr] | None = None  # (lower, upper) of <limit>, lower < upper

    @property
    def movable(self) -> bool:
        return self.type in MOVABLE


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


class UrdfReader:
    """Reads the <robot> element into links and joints, with one clear error per problem."""

    def __init__(self, file: str) -> None:
        self.file = file
        self.links: dict[str, UrdfLink] = {}
        self.joints: dict[str, UrdfJoint] = {}
        self.robot_name = "robot"

    # -- errors
    def error(self, message: str, *, link: UrdfLink | None = None, field: str | None = None, line=None):
        if line:
            message = f"{message} (line {line})"
        return SymdynError(
            message,
            file=self.file,
            **link_fields(link),
            field=field,
        )

    # -- values
    def number(self, text: str | None, where: dict, line: int) -> sp.Expr:
        """A number of the file, read as a double (float(), whatever digits are written): finite and
        at most MAX_MAGNITUDE = 1e150 in absolute value; an integer value below 2**53 becomes an
        exact Integer, any other a Float of the double."""
        s = (text or "").strip()
        if not _NUMBER.match(s):
            raise self.error(f"expected a number, got {_short(repr(text))}", line=line, **where)
        x = float(s)
        if not math.isfinite(x):
            raise self.error(f"{_short(s)} is not a finite number", line=line, **where)
        if abs(x) > MAX_MAGNITUDE:
            raise self.error(
                f"{x!r} is too large (more than {MAX_MAGNITUDE:g} in absolute value)", line=line, **where
            )
        if x == int(x) and abs(x) < 2**53:
            return sp.Integer(int(x))
        return sp.Float(x)

    def vector(self, text: str | None, where: dict, line: int) -> list[sp.Expr]:
        parts = (text or "").split()
        if len(parts) != 3:
            raise self.error(f"expected 3 numbers 'x y z', got {text!r}", line=line, **where)
        return [self.number(p, where, line) for p in parts]

    def warn(self, message: str, *, link: UrdfLink | None = None, field: str | None = None, line=None):
        """A SymdynWarning naming the file, the link, the field and the line, as `error` would."""
        place = location(self.file, **link_fields(link), field=field)
        warnings.warn(f"{place}: {message} (line {line})", SymdynWarning, stacklevel=5)

    def one(self, el: Element, tag: str, where: dict, required: bool = False) -> Element | None:
        found = el.all(tag)
        if len(found) > 1:
            raise self.error(f"more than one <{tag}>", line=found[1].line, **where)
        if not found and required:
            raise self.error(f"missing <{tag}>", line=el.line, **where)
        return found[0] if found else None

    def attribute(self, el: Element, name: str, where: dict) -> str:
        if name not in el.attrib:
            raise self.error(f"<{el.tag}> needs the attribute '{name}'", line=el.line, **where)
        return el.attrib[name]

    def origin(self, parent: Element, where: dict, prefix: str) -> Transform:
        el = self.one(parent, "origin", _at(where, prefix + "origin"))
        if el is None:
            return Transform.identity()
        xyz = self.vector(el.attrib.get("xyz", "0 0 0"), _at(where, prefix + "origin.xyz"), el.line)
        rpy = self.vector(el.attrib.get("rpy", "0 0 0"), _at(where, prefix + "origin.rpy"), el.line)
        link = where.get("link")
        angles = [
            snap_angle(
                a,
                file=self.file,
                **link_fields(link),
                field=prefix + "origin.rpy",
                angle=name,
                line=el.line,
                expressions=False,
            )
            for a, name in zip(rpy, ("roll", "pitch", "yaw"), strict=True)
        ]
        R = rpy_matrix(*angles).applyfunc(numeric)  # cos(1) -> 0.5403...
        return Transform(R, sp.ImmutableMatrix(3, 1, xyz))

    # -- the document
    def read(self, root: Element) -> None:
        if root.tag == "mujoco":
            raise self.error(
                "an MJCF file (top element <mujoco>), not a URDF: read it with symdyn.load_mjcf "
                "(or symdyn.load_robot, which recognises either)"
            )
        if root.tag != "robot":
            raise self.error(
                f"an XML file whose top element is <{root.tag}>: symdyn reads URDF (top element "
                "<robot>) and robot files (YAML or JSON)"
            )
        if "name" not in root.attrib:
            raise self.error("<robot> needs the attribute 'name'", field="robot.name", line=root.line)
        self.robot_name = urdf_robot_name(root.attrib["name"])
        links = root.all("link")
        if not links:
            raise self.error("the robot has no <link>", line=root.line)
        check_link_count(len(links), "<link> elements", self.file)
        check_link_count(len(root.all("joint")), "<joint> elements", self.file)
        for i, el in enumerate(links, start=1):
            self._read_link(i, el)
        for el in root.all("joint"):
            self._read_joint(el)

    def _read_link(self, index: int, el: Element) -> None:
        name = el.attrib.get("name", "")
        link = UrdfLink(index, name or f"link{index}", el.line, None)
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
        link.inertial = UrdfInertial(mass, origin, tensor_from_components(e))

    def _read_joint(self, el: Element) -> None:
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
                f"unknown joint type '{kind}'{did_you_mean(kind, JOINT_TYPES)}; "
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
                    f"{end} link '{target}' does not exist{did_you_mean(target, self.links)}",
                    line=end_el.line,
                    **_at(where, f"{label}.{end}.link"),
                )
            ends[end] = target
        origin = self.origin(el, where, label + ".")
        axis = None
        if kind in MOVABLE:
            axis_el = self._first_axis(el, name, _at(where, label + ".axis"))
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
        self.joints[name] = UrdfJoint(
            name, el.line, kind, ends["parent"], ends["child"], origin, axis, damping, friction, mimic,
            mimic_el.line if mimic_el is not None else 0, self._limits(el, kind, where, label),
        )  # fmt: skip

    def _first_axis(self, el: Element, joint: str, where: dict) -> Element | None:
        """The joint's first <axis> (None without one); later ones are ignored with a warning, as
        urdfdom reads only the first (Pinocchio builds its model from urdfdom's)."""
        axes = el.all("axis")
        if len(axes) > 1:
            lines = ", ".join(str(a.line) for a in axes[1:])
            self.warn(
                f"joint '{joint}' has {len(axes)} <axis> elements: the first is read, as urdfdom and "
                f"Pinocchio read it, and the others (line {lines}) are ignored",
                line=axes[0].line,
                **where,
            )
        return axes[0] if axes else None

    def _limits(self, el: Element, kind: str, where: dict, label: str) -> tuple[sp.Expr, sp.Expr] | None:
        """(lower, upper) of a revolute or prismatic joint's <limit>; None without a range."""
        if kind not in ("revolute", "prismatic"):
            return None
        limit = self.one(el, "limit", _at(where, label + ".limit"))
        if limit is None:
            return None
        lower, upper = (
            self.number(limit.attrib.get(k, "0"), _at(where, f"{label}.limit.{k}"), limit.line)
            for k in ("lower", "upper")
        )
        if lower > upper:
            missing = [k for k in ("lower", "upper") if k not in limit.attrib]
            hint = f" ('{missing[0]}' is not given: URDF makes it 0)" if missing else ""
            self.warn(
                f"the lower limit {float(lower):g} is above the upper limit {float(upper):g}{hint}: "
                'read as no range (Bullet\'s "no limit"; urdfdom and Pinocchio load it as written)',
                line=limit.line,
                **_at(where, label + ".limit"),
            )
            return None
        return None if lower == upper else (lower, upper)


def _short(text: str) -> str:
    return text if len(text) <= 60 else text[:57] + "..."


def _at(where: dict, fld: str) -> dict:
    return {**where, "field": fld}


def numeric(x: sp.Expr) -> sp.Expr:
    """Exact rationals stay; other numeric constants (e.g. sqrt(2)*0.3) become Floats."""
    x = sp.sympify(x, strict=True)
    if x.is_Rational or isinstance(x, sp.Float) or x.free_symbols:
        return x
    return sp.Float(x.evalf(17), 17)
