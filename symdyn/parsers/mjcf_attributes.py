"""The numbers of an MJCF file as written, before MuJoCo's compiler changes them.

MuJoCo's compiler loses some bad numbers on the way to the compiled model that symdyn reads
(symdyn.parsers.mjcf_compile): it reads `nan` as 0 (pos="nan 0 0" compiles to the origin, with a
warning only) and normalises a joint axis whose squared norm overflows (axis="1e200 1e200 0") to
zero. So the attributes of the file itself, and of the files it includes, are checked:

* every number written in a numeric attribute is finite (no nan, inf, or 1e400, which a double
  reads as inf); string attributes (names, references to other elements, files, types) are not
  numbers and are not read;
* every direction (a joint's or site's `axis`, an orientation's `zaxis`, the axis of an
  `axisangle`, each of the two axes of `xyaxes`) has a squared norm that is neither zero nor
  overflowing, so that MuJoCo can normalise it.

SymdynError names the file, the element (its name when it has one), the attribute and its line.
"""

from __future__ import annotations

import math
import os
from collections.abc import Iterator

from ..errors import SymdynError
from .safe_xml import Element, parse_xml
from .source import read_source

__all__ = ["check_attributes"]

#: attributes whose values are text (names, references, files, types), never numbers
_TEXT = frozenset(
    [
        "name",
        "class",
        "childclass",
        "model",
        "file",
        "prefix",
        "suffix",
        "content_type",
        "meshdir",
        "texturedir",
        "assetdir",
        "joint",
        "joint1",
        "joint2",
        "body",
        "body1",
        "body2",
        "site",
        "site1",
        "site2",
        "geom",
        "geom1",
        "geom2",
        "tendon",
        "tendon1",
        "tendon2",
        "actuator",
        "mesh",
        "hfield",
        "material",
        "texture",
        "target",
        "objname",
        "refname",
        "slidersite",
        "cranksite",
        "jointinparent",
        "sidesite",
        "key",
        "plugin",
        "instance",
        "skin",
        "flex",
        "type",
        "mode",
    ]
)
#: direction attributes: (attribute, the slices of its numbers that are one direction each)
_DIRECTIONS = {
    "axis": (slice(0, 3),),
    "zaxis": (slice(0, 3),),
    "axisangle": (slice(0, 3),),
    "xyaxes": (slice(0, 3), slice(3, 6)),
}
#: how deep <include> may nest (MuJoCo refuses recursive includes itself)
_MAX_INCLUDE_DEPTH = 20


def check_attributes(raw: bytes, file: str) -> None:
    """Refuse a non-finite number or a degenerate direction written in the MJCF file `file` (its
    bytes `raw`) or in a file it includes (see the module documentation)."""
    _check_tree(parse_xml(raw, file), file, os.path.dirname(file), 0)


def _check_tree(root: Element, file: str, folder: str, depth: int) -> None:
    for el in _elements(root):
        if el.tag == "include" and "file" in el.attrib:
            _check_include(el.attrib["file"], folder, depth)
        for key, text in el.attrib.items():
            if key not in _TEXT:
                _check_value(el, key, text, file)


def _check_include(name: str, folder: str, depth: int) -> None:
    """The included file, relative to the top file's folder as MuJoCo resolves it, when it can be
    read (MuJoCo reports a missing one itself)."""
    path = os.path.join(folder, name)
    if depth >= _MAX_INCLUDE_DEPTH or not os.path.isfile(path):
        return
    included, raw, _ = read_source(path, "MJCF file")
    _check_tree(parse_xml(raw, included), included, folder, depth + 1)


def _elements(root: Element) -> Iterator[Element]:
    stack = [root]
    while stack:
        el = stack.pop()
        yield el
        stack.extend(reversed(el.children))


def _numbers(text: str) -> list[float] | None:
    """The attribute's numbers, or None when it is not a list of numbers (a word, a path)."""
    try:
        return [float(token) for token in text.split()]
    except ValueError:
        return None


def _check_value(el: Element, key: str, text: str, file: str) -> None:
    values = _numbers(text)
    if not values:
        return
    fld = f"{el.tag}({el.attrib['name']}).{key}" if el.attrib.get("name") else f"{el.tag}.{key}"
    where = f"line {el.line}"
    for token, x in zip(text.split(), values, strict=True):
        if not math.isfinite(x):
            raise SymdynError(
                f"{where}: {token!r} is not a finite number (MuJoCo would read a nan as 0 and an "
                "overflow as inf)",
                file=file,
                field=fld,
            )
    for part in _DIRECTIONS.get(key, ()):
        direction = values[part]
        if len(direction) != 3:
            continue  # MuJoCo reports a wrong count itself
        squared = math.fsum(x * x for x in direction)
        if not 0 < squared < math.inf:
            raise SymdynError(
                f"{where}: the direction {' '.join(text.split()[part])} has a squared norm that "
                f"{'is zero' if squared == 0 else 'overflows'}: MuJoCo cannot normalise it",
                file=file,
                field=fld,
            )
