"""A hardened XML reader: the element tree (tags, attributes, line numbers) of a description file.

The standard library's expat parser is used with every door to the outside shut:
a document type declaration (<!DOCTYPE ...>, which a URDF never needs) is refused,
so no entity can be declared, expanded or fetched; parameter entities and external
DTDs are never loaded either. Character data is dropped: a URDF keeps its data in
attributes. The caller limits the size of the input (symdyn.parsers.source).

White space before the XML declaration (<?xml ...?>), which XML does not allow and expat refuses,
is skipped with a SymdynWarning naming the file: tinyxml2, the reader of urdfdom, Pinocchio and
MuJoCo, skips it, and files written by hand or by scripts often start with a blank line. The
declaration is moved to the start, so the lines after it keep their numbers.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass, field
from xml.parsers import expat

from ..errors import SymdynError, SymdynWarning

__all__ = ["Element", "declaration_first", "looks_like_xml", "parse_xml"]


@dataclass
class Element:
    """One XML element: its tag as written (no namespace processing), attributes and line."""

    tag: str
    attrib: dict[str, str]
    line: int
    children: list[Element] = field(default_factory=list)

    def all(self, tag: str) -> list[Element]:
        return [c for c in self.children if c.tag == tag]


def looks_like_xml(raw: bytes) -> bool:
    """Whether the bytes start, after a UTF-8 byte order mark and white space, with '<': an XML
    document (a declaration, a comment or the root element). No YAML or JSON robot file can start
    so: its top level is a mapping, and '<' starts no YAML mapping."""
    return raw.removeprefix(b"\xef\xbb\xbf").lstrip(b" \t\r\n").startswith(b"<")


class _RefusedError(Exception):
    pass


_BOM = b"\xef\xbb\xbf"
_SPACE = b" \t\r\n"


def declaration_first(raw: bytes, file: str) -> bytes:
    """The bytes with an XML declaration that white space precedes moved to the very start (the
    white space after it), so that expat reads the file and every line after the declaration keeps
    its number; unchanged otherwise. Warns naming the file and the declaration's line."""
    bom = _BOM if raw.startswith(_BOM) else b""
    rest = raw[len(bom) :]
    text = rest.lstrip(_SPACE)
    end = text.find(b"?>") + 2
    if len(text) == len(rest) or not text.startswith(b"<?xml") or end < 2:
        return raw
    space = rest[: len(rest) - len(text)]
    line = space.replace(b"\r\n", b"\n").replace(b"\r", b"\n").count(b"\n") + 1
    warnings.warn(
        f"{file}: white space before the XML declaration (line {line}) is skipped, as urdfdom, "
        "Pinocchio and MuJoCo skip it (XML requires the declaration at the very start)",
        SymdynWarning,
        stacklevel=3,
    )
    return bom + text[:end] + space + text[end:]


def parse_xml(raw: bytes, file: str) -> Element:
    """A tree of elements (tag, attributes, line) from hardened expat; character data is dropped."""
    raw = declaration_first(raw, file)
    parser = expat.ParserCreate()  # no namespace processing: tags as written (xacro:macro)
    parser.SetParamEntityParsing(expat.XML_PARAM_ENTITY_PARSING_NEVER)
    stack: list[Element] = []
    roots: list[Element] = []

    def start(tag: str, attrib: dict[str, str]) -> None:
        el = Element(tag, attrib, parser.CurrentLineNumber)
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
