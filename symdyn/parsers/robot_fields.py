"""The fields of a robot file, read and checked in written order (docs/robot-files.md).

`RobotFileReader` walks the data of a robot file (as from symdyn.parsers.yaml_text)
once, in the order it was written: the top-level keys, then each link's keys. Every
number-or-expression goes through the whitelisting parser of
`symdyn.model.expressions`, and the parameter names met are recorded in order of
appearance (`order`), which fixes the order of `Robot.params`. Unknown keys, wrong
kinds and bad names raise SymdynError naming file, link and field. The values are
kept as written; symdyn.parsers.robot_file builds the Robot from them.
"""

from __future__ import annotations

import re
from collections.abc import Iterable
from dataclasses import dataclass, field

import sympy as sp

from ..errors import SymdynError, link_fields
from ..model.angles import snap_angle
from ..model.contacts import Contact, contacts_from
from ..model.expressions import check_parameter_name, is_c_identifier, parse_expression_names
from ..model.limits import check_limits
from ..model.robot import JOINT_TYPES
from ..spatial.transform import Transform
from .dh import CONVENTIONS
from .frame_fields import FrameData, read_base, read_frames
from .loop_fields import LoopData, read_actuated, read_loops
from .source import check_link_count, did_you_mean

__all__ = [
    "TOP_KEYS",
    "LINK_KEYS",
    "INERTIA_KEYS",
    "FRICTION_KEYS",
    "MOTOR_KEYS",
    "MIMIC_KEYS",
    "LinkData",
    "RobotFileReader",
]

TOP_KEYS = (
    "name",
    "convention",
    "gravity",
    "base",
    "parameters",
    "links",
    "frames",
    "loops",
    "actuated",
    "contacts",
)
LINK_KEYS = (
    "name",
    "parent",
    "joint",
    "gamma",
    "b",
    "a",
    "alpha",
    "d",
    "theta",
    "mass",
    "com",
    "inertia",
    "friction",
    "motor",
    "mimic",
    "limits",
)
INERTIA_KEYS = ("ixx", "iyy", "izz", "ixy", "ixz", "iyz")
FRICTION_KEYS = ("viscous", "coulomb")
MOTOR_KEYS = ("inertia", "gear_ratio")
MIMIC_KEYS = ("joint", "multiplier", "offset")
_AXES = ("x", "y", "z")
_LINK_NAME = re.compile(r"[A-Za-z0-9_][A-Za-z0-9_.\-]*\Z")
LINK_NAME = _LINK_NAME  # the pattern of a link name, for the other robot-file readers


@dataclass
class LinkData:
    """One link entry as written: parent, DH row, inertial data, friction, motor, mimic and joint
    range (defaults for omitted keys). `parent` is the name written (None: null); `parent_given`
    whether it was."""

    index: int
    name: str
    parent: str | None = None
    parent_given: bool = False
    joint: str = ""
    gamma: sp.Expr = sp.S.Zero
    b: sp.Expr = sp.S.Zero
    a: sp.Expr = sp.S.Zero
    alpha: sp.Expr = sp.S.Zero
    d: sp.Expr = sp.S.Zero
    theta: sp.Expr = sp.S.Zero
    mass: sp.Expr = sp.S.Zero
    com: tuple[sp.Expr, ...] = (sp.S.Zero,) * 3
    inertia: dict[str, sp.Expr] = field(default_factory=dict)
    viscous: sp.Expr = sp.S.Zero
    coulomb: sp.Expr = sp.S.Zero
    coulomb_minus: sp.Expr | None = None  # set by `coulomb: [plus, minus]` (direction-dependent)
    motor_inertia: sp.Expr = sp.S.Zero
    gear_ratio: sp.Expr = sp.S.One
    mimic: tuple[str, sp.Expr, sp.Expr] | None = None  # (link name, multiplier, offset)
    limits: tuple[sp.Expr, sp.Expr] | None = None  # (lower, upper) as written


class RobotFileReader:
    """One pass over the document in written order, recording name appearances."""

    def __init__(self, file: str | None) -> None:
        self.file = file
        self.order: list[str] = []  # names in order of appearance (with repeats)
        self.values: dict[str, sp.Expr] = {}
        self.value_names: dict[str, tuple[str, ...]] = {}
        self.name: str | None = None
        self.convention = "standard"
        self.gravity: tuple[sp.Expr, ...] | None = None
        self.links: list[LinkData] = []
        self.base = Transform.identity()
        #: a floating base's body as read: (mass, com, inertia components), None for a fixed base
        self.base_body: tuple[sp.Expr, tuple[sp.Expr, ...], dict[str, sp.Expr]] | None = None
        self.frames: list[FrameData] = []
        self.loops: list[LoopData] = []
        self.actuated: tuple[str, ...] | None = None
        self.contacts: tuple[Contact, ...] = ()

    # -- helpers
    def error(self, message: str, *, link: LinkData | None = None, field: str | None = None):
        return SymdynError(
            message,
            file=self.file,
            **link_fields(link),
            field=field,
        )

    def expr(self, value: object, field: str, link: LinkData | None = None) -> sp.Expr:
        expr, names = parse_expression_names(
            value,
            file=self.file,
            **link_fields(link),
            field=field,
        )
        self.order.extend(names)
        return expr

    def angle(self, value: object, field: str, link: LinkData) -> sp.Expr:
        """A DH angle (rad), parsed like `expr`; a decimal multiple of pi/2 made exact (snap_angle)."""
        return snap_angle(
            self.expr(value, field, link),
            file=self.file,
            link_index=link.index,
            link_name=link.name,
            field=field,
        )

    def vector(self, value: object, field: str, link: LinkData | None = None):
        if not isinstance(value, list) or len(value) != 3:
            got = f"{len(value)} entries" if isinstance(value, list) else _kind(value)
            raise self.error(
                f"expected a list of 3 numbers or expressions [x, y, z], got {got}",
                link=link,
                field=field,
            )
        return tuple(self.expr(v, f"{field}.{ax}", link) for v, ax in zip(value, _AXES, strict=True))

    def mapping(
        self,
        value: object,
        allowed: Iterable[str],
        field: str | None,
        link: LinkData | None = None,
    ) -> dict:
        """A mapping with only `allowed` keys (null counts as empty)."""
        allowed = tuple(allowed)
        if value is None:
            return {}
        if not isinstance(value, dict):
            raise self.error(
                f"expected a mapping with keys {', '.join(allowed)}, got {_kind(value)}",
                link=link,
                field=field,
            )
        for key in value:
            if key not in allowed:
                where = f"{field}.{key}" if field else str(key)
                raise self.error(_unknown_key(key, allowed), link=link, field=where)
        return value

    # -- the document
    def read(self, data: object) -> None:
        if not isinstance(data, dict):
            got = "an empty document" if data is None else _kind(data)
            raise self.error(f"the top level must be a mapping (name, links, ...), got {got}")
        self.mapping(data, TOP_KEYS, None)
        for key in ("name", "links"):
            if key not in data:
                raise self.error("missing required field", field=key)
        for key, value in data.items():
            getattr(self, f"_read_{key}")(value)
        if not self.links and self.base_body is None:  # a floating base alone is a rigid body
            raise self.error("a robot needs at least one link (or a floating base)", field="links")

    def _read_name(self, value: object) -> None:
        if not isinstance(value, str):
            raise self.error(f"robot name must be a string, got {_kind(value)}", field="name")
        if not re.match(r"[A-Za-z_][A-Za-z0-9_]*\Z", value):
            raise self.error(
                f"robot name '{value}' is not a valid C identifier (letters, digits and "
                "underscores, not starting with a digit)",
                field="name",
            )
        if not is_c_identifier(value):
            raise self.error(f"robot name '{value}' is a C keyword", field="name")
        if value.startswith("__") or re.match(r"_[A-Z]", value):
            raise self.error(
                f"robot name '{value}' is reserved in C (leading __ or _ and a capital)",
                field="name",
            )
        self.name = value

    def _read_convention(self, value: object) -> None:
        if value not in CONVENTIONS:
            raise self.error(
                f"convention must be 'standard' or 'modified' (DH) or 'poe', not {value!r}",
                field="convention",
            )
        self.convention = value

    def _read_gravity(self, value: object) -> None:
        self.gravity = self.vector(value, "gravity")

    def _read_base(self, value: object) -> None:
        self.base, body = read_base(self, value)
        if body is None:
            return
        mass = self.expr(body["mass"], "base.mass") if "mass" in body else sp.S.Zero
        com = self.vector(body["com"], "base.com") if "com" in body else (sp.S.Zero,) * 3
        entries = self.mapping(body.get("inertia"), INERTIA_KEYS, "base.inertia")
        self.base_body = (mass, com, {k: self.expr(v, f"base.inertia.{k}") for k, v in entries.items()})

    def _read_frames(self, value: object) -> None:
        self.frames = read_frames(self, value, _LINK_NAME)

    def _read_loops(self, value: object) -> None:
        self.loops = read_loops(self, value, _LINK_NAME)

    def _read_actuated(self, value: object) -> None:
        self.actuated = read_actuated(self, value, _LINK_NAME)

    def _read_contacts(self, value: object) -> None:
        """`contacts:` a list of {name, frame, type: point | 6d} (symdyn.model.contacts); the frames
        are checked against the robot's when it is built."""
        try:
            self.contacts = contacts_from(value)
        except SymdynError as e:
            raise self.error(e.reason) from None

    def _read_parameters(self, value: object) -> None:
        if value is None:
            return
        if not isinstance(value, dict):
            raise self.error(
                f"expected a mapping of parameter names to values, got {_kind(value)}",
                field="parameters",
            )
        for key, v in value.items():
            fld = f"parameters.{key}"
            name = check_parameter_name(key, file=self.file, field=fld)
            self.order.append(name)
            if v is None:
                continue
            if isinstance(v, (list, dict)):
                raise self.error(
                    f"a parameter value must be a number, an expression or null, got {_kind(v)}",
                    field=fld,
                )
            start = len(self.order)
            self.values[name] = self.expr(v, fld)
            self.value_names[name] = tuple(dict.fromkeys(self.order[start:]))

    def _read_links(self, value: object) -> None:
        if not isinstance(value, list):
            raise self.error(f"expected a list of links, got {_kind(value)}", field="links")
        check_link_count(len(value), "links", self.file)
        names: dict[str, int] = {}
        for i, raw in enumerate(value, start=1):
            link = self._read_link(i, raw)
            if link.name in names:
                raise self.error(
                    f"duplicate link name '{link.name}' (also link {names[link.name]})",
                    link=link,
                    field="name",
                )
            names[link.name] = i
            self.links.append(link)

    def _read_link(self, i: int, raw: object) -> LinkData:
        given = raw.get("name") if isinstance(raw, dict) else None
        link = LinkData(index=i, name=given if isinstance(given, str) else f"link{i}")
        if not isinstance(raw, dict):
            raise self.error(f"a link must be a mapping, got {_kind(raw)}", link=link)
        self.mapping(raw, LINK_KEYS, None, link)
        for key in ("joint", "mass"):
            if key not in raw:
                raise self.error("missing required field", link=link, field=key)
        for key, value in raw.items():
            if key == "name":
                if not isinstance(value, str) or not _LINK_NAME.match(value):
                    raise self.error(
                        f"link name must be letters, digits, '_', '.' or '-', got {value!r}",
                        link=link,
                        field="name",
                    )
            elif key == "joint":
                if value not in JOINT_TYPES:
                    raise self.error(
                        f"joint must be 'revolute' or 'prismatic', not {value!r}",
                        link=link,
                        field="joint",
                    )
                link.joint = value
            elif key == "parent":
                if value is not None and not (isinstance(value, str) and _LINK_NAME.match(value)):
                    raise self.error(
                        f"parent must be the name of a link listed before this one, 'base' or null, "
                        f"got {_kind(value)}",
                        link=link,
                        field="parent",
                    )
                link.parent, link.parent_given = value, True
            elif key == "mimic":
                self._read_mimic(value, link)
            elif key == "limits":
                self.limits(value, link)
            elif key in ("alpha", "theta", "gamma"):
                setattr(link, key, self.angle(value, key, link))
            elif key in ("a", "d", "b", "mass"):
                setattr(link, key, self.expr(value, key, link))
            elif key == "com":
                link.com = self.vector(value, "com", link)
            elif key == "inertia":
                entries = self.mapping(value, INERTIA_KEYS, "inertia", link)
                link.inertia = {k: self.expr(v, f"inertia.{k}", link) for k, v in entries.items()}
            elif key == "friction":
                self._read_friction(value, link)
            elif key == "motor":
                entries = self.mapping(value, MOTOR_KEYS, "motor", link)
                for k, v in entries.items():
                    attr = "motor_inertia" if k == "inertia" else k
                    setattr(link, attr, self.expr(v, f"motor.{k}", link))
        return link

    def _read_friction(self, value: object, link: LinkData) -> None:
        """friction: {viscous: b, coulomb: c} or {viscous: b, coulomb: [c_plus, c_minus]}, the
        second form direction-dependent (both magnitudes; their signs are checked once
        parameters have values, symdyn.parsers.robot_file)."""
        entries = self.mapping(value, FRICTION_KEYS, "friction", link)
        if "viscous" in entries:
            link.viscous = self.expr(entries["viscous"], "friction.viscous", link)
        if "coulomb" not in entries:
            return
        coulomb = entries["coulomb"]
        if not isinstance(coulomb, list):
            link.coulomb = self.expr(coulomb, "friction.coulomb", link)
            return
        if len(coulomb) != 2:
            raise self.error(
                "expected one number (symmetric) or a list of 2 numbers or expressions [c_plus, c_minus] "
                f"(magnitudes for positive and negative joint rates), got {_count(len(coulomb))}",
                link=link,
                field="friction.coulomb",
            )
        link.coulomb = self.expr(coulomb[0], "friction.coulomb.plus", link)
        link.coulomb_minus = self.expr(coulomb[1], "friction.coulomb.minus", link)

    def limits(self, value: object, link: LinkData) -> None:
        """limits: [lower, upper], the joint's range in rad or m (null: none). Whether they are
        numbers with lower < upper is checked once parameters have values (`check_limits`)."""
        if value is None:
            return
        if not isinstance(value, list) or len(value) != 2:
            got = f"{len(value)} entries" if isinstance(value, list) else _kind(value)
            raise self.error(
                f"expected [lower, upper], two numbers or expressions (rad or m), got {got}",
                link=link,
                field="limits",
            )
        link.limits = (self.expr(value[0], "limits.lower", link), self.expr(value[1], "limits.upper", link))

    def check_limits(self, link: LinkData, subs: dict) -> None:
        """Refuse a range that is not two numbers lower < upper once parameters have values."""
        if link.limits is not None:
            check_limits([v.xreplace(subs) for v in link.limits], file=self.file, **link_fields(link))

    def _read_mimic(self, value: object, link: LinkData) -> None:
        """mimic: {joint: LINK, multiplier: k, offset: o}, q_link = k q_LINK + o (null: none)."""
        if value is None:
            return
        entries = self.mapping(value, MIMIC_KEYS, "mimic", link)
        joint = entries.get("joint")
        if "joint" not in entries:
            raise self.error(
                "missing required field (the name of the link whose joint is followed)",
                link=link,
                field="mimic.joint",
            )
        if not isinstance(joint, str):
            raise self.error(
                f"expected the name of a link, got {_kind(joint)}", link=link, field="mimic.joint"
            )
        factors = {"multiplier": sp.S.One, "offset": sp.S.Zero}
        for k, v in entries.items():
            if k != "joint":
                factors[k] = self.expr(v, f"mimic.{k}", link)
        link.mimic = (joint, factors["multiplier"], factors["offset"])


def _count(k: int) -> str:
    return f"{k} entry" if k == 1 else f"{k} entries"


def _kind(value: object) -> str:
    if value is None:
        return "null"
    if isinstance(value, bool):
        return f"the boolean {value}"
    if isinstance(value, list):
        return "a list"
    if isinstance(value, dict):
        return "a mapping"
    if isinstance(value, str):
        return f"the string {value!r}"
    return f"{type(value).__name__} {value!r}"


def _unknown_key(key: object, allowed: tuple[str, ...]) -> str:
    return f"unknown key '{key}'{did_you_mean(str(key), allowed)}; allowed: {', '.join(allowed)}"
