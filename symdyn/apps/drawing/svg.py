"""A Sketch (symdyn.apps.drawing.sketch) as SVG text: deterministic, machine-readable.

Every frame marker is a group `<g class="frame KIND" data-frame="NAME" data-kind="KIND"
data-origin="x y z">` (world, metres, shortest round-trip decimals), so tools and tests read the
geometry back. Every piece of user text (robot, link and frame names) is XML-escaped, attribute
values with quotes too: a name cannot close an element or open a script.
"""

from __future__ import annotations

import re
from xml.sax.saxutils import escape, quoteattr

from .sketch import COLORS, Dot, Group, Label, Line, Sketch

__all__ = ["svg_text", "xml_text"]

#: Characters XML 1.0 forbids even escaped (controls but tab, newline, return; surrogates; U+FFFE/F).
_FORBIDDEN = re.compile("[\x00-\x08\x0b\x0c\x0e-\x1f\ud800-\udfff\ufffe\uffff]")


def xml_text(text: str) -> str:
    """User text made safe for XML: forbidden characters replaced by U+FFFD (then escaped)."""
    return _FORBIDDEN.sub("\ufffd", str(text))


def _escape(text: str) -> str:
    return escape(xml_text(text))


def _attr(text: str) -> str:
    return quoteattr(xml_text(text))


def _n(v: float) -> str:
    text = f"{v:.2f}".rstrip("0").rstrip(".")
    return "0" if text in ("-0", "") else text


def _defs() -> str:
    """Arrowheads, one per colour (marker-end)."""
    out = []
    for name in ("x", "y", "z"):
        out.append(
            f'<marker id="arrow-{name}" viewBox="0 0 10 10" refX="9" refY="5" markerWidth="7" '
            f'markerHeight="7" orient="auto-start-reverse"><path d="M0,0 L10,5 L0,10 z" '
            f'fill="{COLORS[name]}"/></marker>'
        )
    return "<defs>" + "".join(out) + "</defs>"


def _arrow_id(color: str) -> str:
    return next(k for k in ("x", "y", "z") if COLORS[k] == color)


def _item(item) -> str:
    if isinstance(item, Line):
        extra = f' stroke-dasharray="{item.dash}"' if item.dash else ""
        if item.arrow:
            extra += f' marker-end="url(#arrow-{_arrow_id(item.color)})"'
        return (
            f'<line x1="{_n(item.x1)}" y1="{_n(item.y1)}" x2="{_n(item.x2)}" y2="{_n(item.y2)}" '
            f'stroke="{item.color}" stroke-width="{_n(item.width)}" stroke-linecap="round"{extra}/>'
        )
    if isinstance(item, Dot):
        return (
            f'<circle cx="{_n(item.x)}" cy="{_n(item.y)}" r="{_n(item.r)}" fill="{item.fill}" '
            f'stroke="{item.stroke}" stroke-width="1.5"/>'
        )
    assert isinstance(item, Label), item
    sub = f'<tspan baseline-shift="sub" font-size="75%">{_escape(item.sub)}</tspan>' if item.sub else ""
    return (
        f'<text x="{_n(item.x)}" y="{_n(item.y)}" fill="{item.color}" font-size="{_n(item.size)}">'
        f"{_escape(item.text)}{sub}</text>"
    )


def _group(g: Group) -> str:
    attrs = "".join(f" {k}={_attr(v)}" for k, v in g.attrs)
    body = "".join(_item(item) for item in g.items)
    return f'<g class="{g.kind}"{attrs}>{body}</g>'


def svg_text(sketch: Sketch, view: str, q_text: str) -> str:
    """The SVG document of `sketch` (module docstring); `q_text` goes into its title."""
    title = _escape(f"{sketch.title} at q = {q_text}")
    head = (
        f'<svg xmlns="http://www.w3.org/2000/svg" width="{sketch.width}" height="{sketch.height}" '
        f'viewBox="0 0 {sketch.width} {sketch.height}" font-family="DejaVu Sans, Helvetica, sans-serif" '
        f"data-robot={_attr(sketch.title)} data-view={_attr(view)}>"
    )
    lines = [
        head,
        f"<title>{title}</title>",
        f'<rect width="{sketch.width}" height="{sketch.height}" fill="#ffffff"/>',
        _defs(),
    ]
    lines += [_group(g) for g in sketch.groups]
    lines.append("</svg>")
    return "\n".join(lines) + "\n"
