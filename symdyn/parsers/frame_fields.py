"""A robot file's `frames:` and `base:` (every convention; docs/frames.md).

    base: {xyz: [x, y, z], rpy: [r, p, y]}          # world_T_base; gravity is then in the world
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

__all__ = ["FRAME_FIELDS", "BASE_FIELDS", "FrameData", "read_frames", "read_base", "model_frames"]

FRAME_FIELDS = ("name", "link", "xyz", "rpy")
BASE_FIELDS = ("xyz", "rpy")


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


def read_base(reader, value: object) -> Transform:
    """`base: {xyz, rpy}`: the base frame in the world (null: the identity)."""
    return _placement(reader, reader.mapping(value, BASE_FIELDS, "base"), "base")


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
        clash = next((f for f in out if f.name == name), None)
        if clash is not None:
            raise reader.error(f"duplicate frame name '{name}' (also {clash.field})", field=f"{field}.name")
        out.append(FrameData(field, name, entries["link"], _placement(reader, entries, field)))
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
