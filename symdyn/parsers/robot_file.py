"""The robot description file (YAML; JSON is valid YAML) -> `symdyn.model.robot.Robot`.

The format is documented in docs/robot-files.md. Loading is data
only: the text is read with ``yaml.safe_load`` and every number-or-expression
goes through the whitelisting parser of `symdyn.model.expressions`; nothing from the
file is executed.

Free parameters (`Robot.params`) are ordered by first appearance in the
document as written: the top-level keys in their written order, lists in
order, mapping keys in their written order (a parameter's own key counts as
an appearance), and within an expression left to right. A name with a value
in `parameters` is not free; its value (which may use other parameters) is
resolved and stored in `Robot.values`, in file order.
"""

from __future__ import annotations

import difflib
import json
import os
import re
from collections.abc import Iterable
from dataclasses import dataclass, field

import sympy as sp
import yaml

from ..errors import SymdynError
from ..model.expressions import (
    check_parameter_name,
    is_c_identifier,
    parse_expression_names,
)
from ..model.inertia import check_inertia, tensor_from_components
from ..model.robot import DEFAULT_GRAVITY, JOINT_TYPES, Friction, Link, Motor, Robot
from ..spatial.transform import Transform
from .dh import CONVENTIONS, dh_link, to_body
from .source import read_source

__all__ = ["load_robot", "robot_from_data"]

TOP_KEYS = ("name", "convention", "gravity", "parameters", "links")
LINK_KEYS = (
    "name",
    "joint",
    "a",
    "alpha",
    "d",
    "theta",
    "mass",
    "com",
    "inertia",
    "friction",
    "motor",
)
INERTIA_KEYS = ("ixx", "iyy", "izz", "ixy", "ixz", "iyz")
FRICTION_KEYS = ("viscous", "coulomb")
MOTOR_KEYS = ("inertia", "gear_ratio")
_AXES = ("x", "y", "z")
_LINK_NAME = re.compile(r"[A-Za-z0-9_][A-Za-z0-9_.\-]*\Z")
#: Largest resolved parameter value (nodes of its expression tree / bits of a number).
_MAX_NODES = 20000
_MAX_BITS = 8192


# --------------------------------------------------------------------------- reading


def load_robot(path: str | os.PathLike) -> Robot:
    """Read a robot description file (YAML or JSON) and return the `Robot`.

    Raises SymdynError (naming file, link and field) for any bad input; warns
    with SymdynWarning for implausible inertial data.
    """
    file, raw, digest = read_source(path, "robot file")
    try:
        text = raw.decode("utf-8-sig")
    except UnicodeDecodeError as exc:
        raise SymdynError(f"not UTF-8 text (bad byte at offset {exc.start})", file=file) from None
    data = _parse_text(text, file)
    return _build(data, file, digest)


def robot_from_data(data: dict, source: str | None = None) -> Robot:
    """Build a `Robot` from already-loaded file data (a dict as from yaml.safe_load).

    `source` names the origin in messages and becomes `Robot.source`.
    """
    return _build(data, None if source is None else str(source), None)


def _parse_text(text: str, file: str) -> object:
    try:
        loader = yaml.SafeLoader(text)
        try:
            node = loader.get_single_node()
            _check_duplicate_keys(node, file)
            return None if node is None else loader.construct_document(node)
        finally:
            loader.dispose()
    except yaml.YAMLError as exc:
        if text.lstrip().startswith("{"):
            # Tab-indented JSON is valid JSON but not YAML; read it as the JSON it is.
            return _parse_json(text, file)
        mark = getattr(exc, "problem_mark", None) or getattr(exc, "context_mark", None)
        parts = [getattr(exc, "context", None), getattr(exc, "problem", None)]
        problem = ", ".join(p for p in parts if p) or str(exc)
        if mark is not None:
            raise SymdynError(
                f"invalid YAML at line {mark.line + 1}, column {mark.column + 1}: {problem}",
                file=file,
            ) from None
        raise SymdynError(f"invalid YAML: {problem}", file=file) from None
    except RecursionError:
        raise SymdynError("invalid YAML: nested too deeply", file=file) from None


def _parse_json(text: str, file: str) -> object:
    def pairs(items: list[tuple[str, object]]) -> dict:
        out: dict = {}
        for k, v in items:
            if k in out:
                raise SymdynError(f"duplicate key '{k}'", file=file, field=k)
            out[k] = v
        return out

    try:
        return json.loads(text, object_pairs_hook=pairs)
    except json.JSONDecodeError as exc:
        raise SymdynError(
            f"invalid JSON at line {exc.lineno}, column {exc.colno}: {exc.msg}", file=file
        ) from None
    except RecursionError:
        raise SymdynError("invalid JSON: nested too deeply", file=file) from None


def _check_duplicate_keys(root: yaml.Node | None, file: str) -> None:
    """yaml.safe_load silently keeps the last of repeated keys; a robot file must not repeat."""
    seen: set[int] = set()
    # (node, path of keys/indices from the top, (link index, link name) or None)
    stack: list[tuple[yaml.Node, tuple, tuple | None]] = [] if root is None else [(root, (), None)]
    while stack:
        node, path, link = stack.pop()
        if id(node) in seen:
            continue
        seen.add(id(node))
        if isinstance(node, yaml.MappingNode):
            keys: dict[tuple[str, str], int] = {}
            for key_node, value_node in node.value:
                key = getattr(key_node, "value", "?")
                if isinstance(key_node, yaml.ScalarNode) and key != "<<":
                    k = (key_node.tag, key)
                    if k in keys:
                        inner = path[2:] if link else path
                        raise SymdynError(
                            f"duplicate key '{key}' at line {key_node.start_mark.line + 1} "
                            f"(first at line {keys[k]})",
                            file=file,
                            link_index=link[0] if link else None,
                            link_name=link[1] if link else None,
                            field=".".join(str(x) for x in (*inner, key)),
                        )
                    keys[k] = key_node.start_mark.line + 1
                stack.append((value_node, (*path, key), link))
        elif isinstance(node, yaml.SequenceNode):
            for i, item in enumerate(node.value):
                item_link = link
                if path == ("links",):
                    item_link = (i + 1, _link_node_name(item, i + 1))
                stack.append((item, (*path, i), item_link))


def _link_node_name(node: yaml.Node, index: int) -> str:
    if isinstance(node, yaml.MappingNode):
        for key_node, value_node in node.value:
            if getattr(key_node, "value", None) == "name" and isinstance(value_node, yaml.ScalarNode):
                return str(value_node.value)
    return f"link{index}"


# --------------------------------------------------------------------------- parsing


@dataclass
class _LinkData:
    index: int
    name: str
    joint: str = ""
    a: sp.Expr = sp.S.Zero
    alpha: sp.Expr = sp.S.Zero
    d: sp.Expr = sp.S.Zero
    theta: sp.Expr = sp.S.Zero
    mass: sp.Expr = sp.S.Zero
    com: tuple[sp.Expr, ...] = (sp.S.Zero,) * 3
    inertia: dict[str, sp.Expr] = field(default_factory=dict)
    viscous: sp.Expr = sp.S.Zero
    coulomb: sp.Expr = sp.S.Zero
    motor_inertia: sp.Expr = sp.S.Zero
    gear_ratio: sp.Expr = sp.S.One


class _Reader:
    """One pass over the document in written order, recording name appearances."""

    def __init__(self, file: str | None) -> None:
        self.file = file
        self.order: list[str] = []  # names in order of appearance (with repeats)
        self.values: dict[str, sp.Expr] = {}
        self.value_names: dict[str, tuple[str, ...]] = {}
        self.name: str | None = None
        self.convention = "standard"
        self.gravity: tuple[sp.Expr, ...] | None = None
        self.links: list[_LinkData] = []

    # -- helpers
    def error(self, message: str, *, link: _LinkData | None = None, field: str | None = None):
        return SymdynError(
            message,
            file=self.file,
            link_index=None if link is None else link.index,
            link_name=None if link is None else link.name,
            field=field,
        )

    def expr(self, value: object, field: str, link: _LinkData | None = None) -> sp.Expr:
        expr, names = parse_expression_names(
            value,
            file=self.file,
            link_index=None if link is None else link.index,
            link_name=None if link is None else link.name,
            field=field,
        )
        self.order.extend(names)
        return expr

    def vector(self, value: object, field: str, link: _LinkData | None = None):
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
        link: _LinkData | None = None,
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
                f"convention must be 'standard' or 'modified', not {value!r}", field="convention"
            )
        self.convention = value

    def _read_gravity(self, value: object) -> None:
        self.gravity = self.vector(value, "gravity")

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
        if not value:
            raise self.error("a robot needs at least one link", field="links")
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

    def _read_link(self, i: int, raw: object) -> _LinkData:
        given = raw.get("name") if isinstance(raw, dict) else None
        link = _LinkData(index=i, name=given if isinstance(given, str) else f"link{i}")
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
            elif key in ("a", "alpha", "d", "theta", "mass"):
                setattr(link, key, self.expr(value, key, link))
            elif key == "com":
                link.com = self.vector(value, "com", link)
            elif key == "inertia":
                entries = self.mapping(value, INERTIA_KEYS, "inertia", link)
                link.inertia = {k: self.expr(v, f"inertia.{k}", link) for k, v in entries.items()}
            elif key == "friction":
                entries = self.mapping(value, FRICTION_KEYS, "friction", link)
                for k, v in entries.items():
                    setattr(link, k, self.expr(v, f"friction.{k}", link))
            elif key == "motor":
                entries = self.mapping(value, MOTOR_KEYS, "motor", link)
                for k, v in entries.items():
                    attr = "motor_inertia" if k == "inertia" else k
                    setattr(link, attr, self.expr(v, f"motor.{k}", link))
        return link


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
    msg = f"unknown key '{key}'"
    close = difflib.get_close_matches(str(key), allowed, n=1)
    if close:
        msg += f" (did you mean '{close[0]}'?)"
    return msg + f"; allowed: {', '.join(allowed)}"


# --------------------------------------------------------------------------- building


def _resolve_values(reader: _Reader) -> dict[str, sp.Expr]:
    """Substitute parameter values into each other; refuse cycles and runaway growth."""
    values = reader.values
    deps = {n: [m for m in reader.value_names[n] if m in values] for n in values}
    resolved: dict[str, sp.Expr] = {}
    state: dict[str, int] = {}  # 1 = on the stack, 2 = done
    for root in values:
        if state.get(root) == 2:
            continue
        stack: list[tuple[str, int]] = [(root, 0)]
        path: list[str] = [root]
        state[root] = 1
        while stack:
            node, k = stack[-1]
            if k < len(deps[node]):
                stack[-1] = (node, k + 1)
                nxt = deps[node][k]
                if state.get(nxt) == 1:
                    cycle = path[path.index(nxt) :] + [nxt]
                    raise reader.error(
                        "parameter values depend on each other in a cycle: " + " -> ".join(cycle),
                        field=f"parameters.{nxt}",
                    )
                if state.get(nxt) != 2:
                    state[nxt] = 1
                    stack.append((nxt, 0))
                    path.append(nxt)
                continue
            stack.pop()
            path.pop()
            state[node] = 2
            mapping = {sp.Symbol(m): resolved[m] for m in deps[node]}
            value = values[node].xreplace(mapping) if mapping else values[node]
            _check_size(value, reader, f"parameters.{node}")
            resolved[node] = value
    return {n: resolved[n] for n in values}


def _check_size(expr: sp.Expr, reader: _Reader, field: str) -> None:
    for count, sub in enumerate(sp.preorder_traversal(expr)):
        if count > _MAX_NODES:
            raise reader.error("value grows too large after substituting parameters", field=field)
        if sub.is_Rational and max(int(sub.p).bit_length(), int(sub.q).bit_length()) > _MAX_BITS:
            raise reader.error("value grows too large after substituting parameters", field=field)
    if expr.has(sp.zoo, sp.oo, -sp.oo, sp.nan):
        raise reader.error(f"value is not finite after substituting parameters ({expr})", field=field)


def _number(expr: sp.Expr) -> float | None:
    """A float if `expr` has no free symbols, else None."""
    if expr.free_symbols:
        return None
    try:
        return float(expr)
    except TypeError:
        return None


def _check_link_numbers(reader: _Reader, link: _LinkData, tensor: sp.ImmutableMatrix, subs: dict) -> None:
    """Refuse impossible numbers of a link (`tensor`: its inertia as written) once parameters have values."""
    mass = link.mass.xreplace(subs)
    check_inertia(mass, tensor.xreplace(subs), file=reader.file, link_index=link.index, link_name=link.name)
    for fld, value in (
        ("friction.viscous", link.viscous),
        ("friction.coulomb", link.coulomb),
        ("motor.inertia", link.motor_inertia),
    ):
        x = _number(value.xreplace(subs))
        if x is not None and x < 0:
            raise reader.error(f"must not be negative (got {x:g})", link=link, field=fld)
    x = _number(link.gear_ratio.xreplace(subs))
    if x is not None and x == 0:
        raise reader.error("gear ratio must not be zero", link=link, field="motor.gear_ratio")


def _build(data: object, file: str | None, digest: str | None) -> Robot:
    reader = _Reader(file)
    reader.read(data)
    values = _resolve_values(reader)
    subs = {sp.Symbol(n): v for n, v in values.items()}
    params = tuple(sp.Symbol(n) for n in dict.fromkeys(reader.order) if n not in values)

    links: list[Link] = []
    prev = Transform.identity()
    for ld in reader.links:
        tensor = tensor_from_components(ld.inertia)
        _check_link_numbers(reader, ld, tensor, subs)
        placement, axis, frame = dh_link(reader.convention, ld.joint, ld.a, ld.alpha, ld.d, ld.theta, prev)
        prev = frame
        com, inertia = to_body(frame, ld.com, tensor)
        links.append(
            Link(
                name=ld.name,
                joint=ld.joint,
                placement=placement,
                axis=axis,
                mass=ld.mass,
                com=com,
                inertia=inertia,
                friction=Friction(ld.viscous, ld.coulomb),
                motor=Motor(ld.motor_inertia, ld.gear_ratio),
                frame=frame,
            )
        )

    gravity = reader.gravity
    if gravity is None:
        gravity = DEFAULT_GRAVITY
    assert reader.name is not None
    return Robot(
        name=reader.name,
        links=tuple(links),
        gravity=sp.ImmutableMatrix(3, 1, list(gravity)),
        params=params,
        values=tuple((sp.Symbol(n), v) for n, v in values.items()),
        source=file,
        source_sha256=digest,
        convention=reader.convention,
    )
