"""A hardened XML reader: the element tree (tags, attributes, line numbers) of a description file.

The standard library's expat parser is used with every door to the outside shut:
a document type declaration (<!DOCTYPE ...>, which a URDF never needs) is refused,
so no entity can be declared, expanded or fetched; parameter entities and external
DTDs are never loaded either. Character data is dropped: a URDF keeps its data in
attributes. The caller limits the size of the input (symdyn.parsers.source).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from xml.parsers import expat

from ..errors import SymdynError

__all__ = ["Element", "looks_like_xml", "parse_xml"]


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


def parse_xml(raw: bytes, file: str) -> Element:
    """A tree of elements (tag, attributes, line) from hardened expat; character data is dropped."""
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
