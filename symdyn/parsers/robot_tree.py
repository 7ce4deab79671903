"""The tree and the mimic joints of a robot file: `parent:` and `mimic:` names made link indices.

Links are listed parent first, so a link's index is its position in the file and its
parent (Featherstone's lambda(i), -1 for the base) is an earlier one: by default the
previous link (a serial chain), or the link `parent:` names (null, or `base` unless a
link has that name: the base).
DH rows of a tree follow Khalil's notation in the modified convention: each row is
relative to the frame of the link's parent (symdyn.parsers.dh). The standard convention
puts frame i at the far end of link i, on the axis of joint i+1, so it cannot carry two
branches: with it `parent:` may only name the previous link, and `gamma`/`b` are refused.

`mimic: {joint: LINK, multiplier: k, offset: o}` makes the link's joint follow LINK's:
q = k q_LINK + o. A mimic of a mimic is composed (symdyn.parsers.mimic_chain); an
unknown link and cycles are refused. Errors name the file, the link and the field.
"""

from __future__ import annotations

import sympy as sp

from ..model.robot import Mimic
from .mimic_chain import follow_mimics, number_text
from .robot_fields import LinkData, RobotFileReader
from .source import did_you_mean

__all__ = ["link_parents", "link_mimics"]

_BASE = "base"


def link_parents(reader: RobotFileReader) -> list[int]:
    """The parent index of every link (-1: the base), checked against the links' order."""
    index = {ld.name: i for i, ld in enumerate(reader.links)}
    parents = []
    for i, ld in enumerate(reader.links):
        parent = i - 1 if not ld.parent_given else _parent(reader, ld, i, index)
        if reader.convention == "standard":
            if parent != i - 1:
                before = f"link '{reader.links[i - 1].name}'" if i else "the base"
                raise reader.error(
                    f"with convention: standard a link hangs from the link before it ({before}): "
                    "standard DH puts frame i at the far end of link i, on the axis of joint i+1, "
                    "so it cannot carry two branches; write the tree with convention: modified",
                    link=ld,
                    field="parent",
                )
            for key in ("gamma", "b"):
                if getattr(ld, key) != 0:
                    raise reader.error(
                        f"{key} (Khalil's tree parameter) needs convention: modified", link=ld, field=key
                    )
        parents.append(parent)
    return parents


def _parent(reader: RobotFileReader, ld: LinkData, i: int, index: dict[str, int]) -> int:
    name = ld.parent
    if name is None or (name == _BASE and _BASE not in index):  # a link named base is that link
        return -1
    if name == ld.name:
        raise reader.error("a link cannot be its own parent", link=ld, field="parent")
    if name not in index:
        hint = did_you_mean(name, [*index, _BASE])
        raise reader.error(f"parent '{name}' is not a link of the robot{hint}", link=ld, field="parent")
    if index[name] > i:
        raise reader.error(
            f"parent '{name}' is listed after this link (as link {index[name] + 1}): list every link "
            "after its parent",
            link=ld,
            field="parent",
        )
    return index[name]


def link_mimics(reader: RobotFileReader) -> list[Mimic | None]:
    """Each link's Mimic (the index of the independent link it follows), or None."""
    links = reader.links
    index = {ld.name: i for i, ld in enumerate(links)}

    def master_of(name: str) -> tuple[str, sp.Expr, sp.Expr] | None:
        ld = links[index[name]]
        if ld.mimic is not None and ld.mimic[0] not in index:
            hint = did_you_mean(ld.mimic[0], index)
            raise reader.error(
                f"link '{ld.mimic[0]}' does not exist{hint}; mimic.joint names the link whose joint "
                "is followed",
                link=ld,
                field="mimic.joint",
            )
        return ld.mimic

    def cycle_error(name: str, cycle: list[str]):
        return reader.error(
            "mimic joints follow each other in a cycle: " + " -> ".join(cycle),
            link=links[index[name]],
            field="mimic.joint",
        )

    def chain_error(name: str, master: str, end: str, k: sp.Expr, o: sp.Expr):
        return reader.error(
            f"link '{master}' is a mimic joint itself: follow '{end}' directly, with "
            f"mimic: {{joint: {end}, multiplier: {number_text(k)}, offset: {number_text(o)}}}",
            link=links[index[name]],
            field="mimic.joint",
        )

    out: list[Mimic | None] = []
    for ld in links:
        followed = follow_mimics(ld.name, master_of, cycle_error, chain_error)
        out.append(None if followed is None else Mimic(index[followed[0]], *followed[1:]))
    return out
