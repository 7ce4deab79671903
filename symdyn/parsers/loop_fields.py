"""A robot file's `loops:` and `actuated:` (every convention; docs/closed-loops.md).

    loops:
      - {name: coupler, link: coupler, point: [0.5, 0, 0], to: rocker, to_point: [0.4, 0, 0], type: point}
    actuated: [crank]

`point` is fixed to `link`, `to_point` to `to` (a link, or `base`), each written in its link's
frame (the convention's frame i, as `frames:` are; the base frame for `to: base`) in m; `type`
is `point` (the points coincide: a revolute or spherical cut joint, 3 equations; the default)
or `weld` (the two links' frames, moved to the points, coincide: 6 equations). `actuated`
names the links whose joints are driven; without it, every joint on no loop's path is. Every
field is checked here, naming file, loop and field; whether the loops can close and the
mobility are checked on the numbers (symdyn.algorithms.closed_loops).
"""

from __future__ import annotations

from dataclasses import dataclass

import sympy as sp

from ..model.loops import LOOP_TYPES, Loop
from ..model.robot import Link
from .source import did_you_mean

__all__ = ["LOOP_FIELDS", "LoopData", "read_loops", "read_actuated", "model_loops", "model_actuated"]

LOOP_FIELDS = ("name", "link", "point", "to", "to_point", "type")


@dataclass(frozen=True)
class LoopData:
    """One `loops:` entry as written; `field` (loops[k]) for messages."""

    field: str
    name: str
    link: str
    point: tuple
    to: str
    to_point: tuple
    type: str


def read_loops(reader, value: object, pattern) -> list[LoopData]:
    """`loops:` a list of {name, link, point, to, to_point, type} (module docstring)."""
    if value is None:
        return []
    if not isinstance(value, list):
        raise reader.error("expected a list of loops {name, link, point, to, to_point, type}", field="loops")
    out: list[LoopData] = []
    for k, raw in enumerate(value):
        field = f"loops[{k}]"
        entries = reader.mapping(raw, LOOP_FIELDS, field)
        for key in ("name", "link", "to"):
            text = entries.get(key)
            if not (isinstance(text, str) and pattern.match(text)):
                what = "missing required field" if key not in entries else f"must be a name, got {text!r}"
                raise reader.error(f"loop {k + 1}: {what}", field=f"{field}.{key}")
        name = entries["name"]
        field = f"loops[{k}] ({name})"
        if any(d.name == name for d in out):
            raise reader.error(f"duplicate loop name '{name}'", field=f"{field}.name")
        points = []
        for key in ("point", "to_point"):
            if key not in entries:
                raise reader.error("missing required field", field=f"{field}.{key}")
            points.append(reader.vector(entries[key], f"{field}.{key}"))
        kind = entries.get("type", "point")
        if kind not in LOOP_TYPES:
            raise reader.error(f"must be one of {', '.join(LOOP_TYPES)}, got {kind!r}", field=f"{field}.type")
        out.append(LoopData(field, name, entries["link"], points[0], entries["to"], points[1], kind))
    return out


def read_actuated(reader, value: object, pattern) -> tuple[str, ...] | None:
    """`actuated:` a list of link names (null: the default, module docstring)."""
    if value is None:
        return None
    if not isinstance(value, list) or not value:
        raise reader.error("expected a non-empty list of link names", field="actuated")
    for k, text in enumerate(value):
        if not (isinstance(text, str) and pattern.match(text)):
            raise reader.error(f"must be a link name, got {text!r}", field=f"actuated[{k}]")
        if text in value[:k]:
            raise reader.error(f"link '{text}' is listed twice", field=f"actuated[{k}]")
    return tuple(value)


def _index(reader, name: str, links: list[Link], field: str, base: bool) -> int:
    names = [link.name for link in links]
    if base and name == "base":
        return -1
    if name not in names:
        choices = names + (["base"] if base else [])
        raise reader.error(f"no link named '{name}'{did_you_mean(name, choices)}", field=field)
    return names.index(name)


def model_loops(reader, loops: list[LoopData], links: list[Link]) -> tuple[Loop, ...]:
    """The model's loops: each point moved into its link's body frame (link.frame applied)."""
    out = []
    for d in loops:
        a = _index(reader, d.link, links, f"{d.field}.link", base=False)
        b = _index(reader, d.to, links, f"{d.field}.to", base=True)
        if a == b:
            raise reader.error(f"closes link '{d.link}' on itself", field=f"{d.field}.to")
        pa = links[a].frame.apply(list(d.point))
        pb = list(d.to_point) if b < 0 else links[b].frame.apply(list(d.to_point))
        out.append(
            Loop(d.name, a, sp.ImmutableMatrix(3, 1, list(pa)), b, sp.ImmutableMatrix(3, 1, list(pb)), d.type)
        )
    return tuple(out)


def model_actuated(reader, names: tuple[str, ...] | None, links: list[Link]) -> tuple[int, ...] | None:
    """The indices of the `actuated:` links; a mimic joint is refused (no coordinate of its own)."""
    if names is None:
        return None
    out = []
    for k, name in enumerate(names):
        i = _index(reader, name, links, f"actuated[{k}]", base=False)
        if links[i].mimic is not None:
            raise reader.error(
                f"link '{name}' is a mimic joint (it has no coordinate of its own)", field=f"actuated[{k}]"
            )
        out.append(i)
    return tuple(out)
