"""A robot file's `frames:` and `base:` (every convention; docs/frames.md).

    base: {xyz: [x, y, z], rpy: [r, p, y]}          # world_T_base; gravity is then in the world
    base: floating                                  # a floating base (docs/floating-base.md)
    base: {floating: true, mass: m, com: [..], inertia: {ixx: ..}}   # ... with its body's inertia
    frames:
      - {name: tool, link: link6, xyz: [0, 0, 0.1], rpy: [0, 0, 0]}   # link6_T_tool

xyz in m; rpy in rad as in URDF, R = Rz(y) Ry(p) Rx(r); both optional (zero). A frame's placement
is written in its link's frame (the convention's frame i: the DH frame i, PoE's {i}), or in the
base frame with `link: base`. Names are unique across links and frames and follow the rule of
link names. Every field is checked here, naming file, field and value.
"""

from __future__ import annotations

from dataclasses import dataclass

import sympy as sp

from ..model.angles import snap_angle
from ..model.frames import Frame
from ..model.robot import Link
from ..spatial.transform import Transform, rpy_matrix
from .source import did_you_mean

__all__ = [
    "FRAME_FIELDS",
    "BASE_FIELDS",
    "FLOATING_FIELDS",
    "FrameData",
    "read_frames",
    "read_base",
    "model_frames",
]

FRAME_FIELDS = ("name", "link", "xyz", "rpy")
BASE_FIELDS = ("xyz", "rpy")
#: the fields of a floating base: the flag, then its body's mass, centre of mass and inertia
FLOATING_FIELDS = ("floating", "mass", "com", "inertia")


@dataclass(frozen=True)
class FrameData:
    """One `frames:` entry as written: its field prefix (frames[k]) for messages."""

    field: str
    name: str
    link: str
    placement: Transform


def _placement(reader, entries: dict, field: str) -> Transform:
    """Transform(Rz(y) Ry(p) Rx(r), xyz) from the optional xyz and rpy of a mapping."""
    xyz = entries.get("xyz")
    p = reader.vector(xyz, f"{field}.xyz") if xyz is not None else (0, 0, 0)
    rpy = entries.get("rpy")
    if rpy is None:
        return Transform.from_translation(p)
    if not (isinstance(rpy, list) and len(rpy) == 3):
        reader.vector(rpy, f"{field}.rpy")  # raises, saying what was expected
    snapped = []
    for a, k in zip(rpy, ("r", "p", "y"), strict=True):
        where = f"{field}.rpy.{k}"
        snapped.append(snap_angle(reader.expr(a, where), file=reader.file, field=where))
    return Transform(rpy_matrix(*snapped), sp.ImmutableMatrix(3, 1, list(p)))


def read_base(reader, value: object) -> tuple[Transform, dict | None]:
    """`base:` the base frame in the world and, for a floating base, the fields of its body.

    `{xyz, rpy}` (null: the identity) places a fixed base: (placement, None). `floating`, or
    `{floating: true, mass, com, inertia}`, makes the base float: (identity, the body's fields as
    written, maybe empty); a placement beside it is refused (the base's pose is coordinates).
    """
    if value == "floating":
        return Transform.identity(), {}
    if isinstance(value, str):
        raise reader.error(
            f"expected 'floating' or a mapping {{xyz, rpy}} (or {{floating: true, mass, com, inertia}}), "
            f"got {value!r}",
            field="base",
        )
    entries = reader.mapping(value, BASE_FIELDS + FLOATING_FIELDS, "base")
    floating = entries.get("floating", False)
    if not isinstance(floating, bool):
        raise reader.error(f"expected true or false, got {floating!r}", field="base.floating")
    if not floating:
        body = next((k for k in FLOATING_FIELDS[1:] if k in entries), None)
        if body is not None:
            raise reader.error(
                "a fixed base is the ground: its body's mass, com and inertia apply to a floating base "
                "(floating: true)",
                field=f"base.{body}",
            )
        return _placement(reader, entries, "base"), None
    placed = next((k for k in BASE_FIELDS if k in entries), None)
    if placed is not None:
        raise reader.error(
            "a floating base has no placement in the world (its position and orientation are "
            "coordinates): remove it, or make the base fixed",
            field=f"base.{placed}",
        )
    return Transform.identity(), {k: v for k, v in entries.items() if k != "floating"}


def read_frames(reader, value: object, pattern) -> list[FrameData]:
    """`frames:` a list of {name, link, xyz, rpy}; names checked against `pattern` (link names')
    and unique among the frames (against the links in `model_frames`)."""
    if value is None:
        return []
    if not isinstance(value, list):
        raise reader.error(
            f"expected a list of frames {{name, link, xyz, rpy}}, got {value!r}", field="frames"
        )
    out: list[FrameData] = []
    seen: dict[str, FrameData] = {}  # by name: a file of 30,000 frames was quadratic here
    for k, raw in enumerate(value):
        field = f"frames[{k}]"
        entries = reader.mapping(raw, FRAME_FIELDS, field)
        if not entries:
            raise reader.error("expected a mapping {name, link, xyz, rpy}, got an empty one", field=field)
        for key in ("name", "link"):
            text = entries.get(key)
            if not (isinstance(text, str) and pattern.match(text)):
                what = "missing required field" if key not in entries else f"must be a name, got {text!r}"
                raise reader.error(what, field=f"{field}.{key}")
        name = entries["name"]
        clash = seen.get(name)
        if clash is not None:
            raise reader.error(f"duplicate frame name '{name}' (also {clash.field})", field=f"{field}.name")
        out.append(FrameData(field, name, entries["link"], _placement(reader, entries, field)))
        seen[name] = out[-1]
    return out


def model_frames(reader, frames: list[FrameData], links: list[Link]) -> tuple[Frame, ...]:
    """The model's frames: each placement moved into its link's body frame (link.frame @ T)."""
    index = {link.name: i for i, link in enumerate(links)}
    out = []
    for f in frames:
        if f.name in index:
            raise reader.error(
                f"frame name '{f.name}' is the name of link {index[f.name] + 1} (names are unique "
                "across links and frames)",
                field=f"{f.field}.name",
            )
        if f.link == "base":
            out.append(Frame(f.name, -1, f.placement))
            continue
        k = index.get(f.link)
        if k is None:
            raise reader.error(
                f"no link named '{f.link}'{did_you_mean(f.link, list(index) + ['base'])}",
                field=f"{f.field}.link",
            )
        out.append(Frame(f.name, k, links[k].frame @ f.placement))
    return tuple(out)
