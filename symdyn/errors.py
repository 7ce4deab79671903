"""The one exception type symdyn raises for bad input, its warning type, and the words of
messages that several floors print."""

from __future__ import annotations

__all__ = [
    "SymdynError",
    "SymdynWarning",
    "location",
    "link_fields",
    "one_line",
    "shown",
    "SHOWN",
    "SINGULAR_REASONS",
]

#: Why a joint makes M(q) singular, as the end of a sentence whose subject is the joint: said by
#: the derivation (symdyn.algorithms.singular) and by the numeric oracle (symdyn.oracle) alike.
SINGULAR_REASONS = {
    "massless": "moves no mass or inertia (its subtree has neither, and the joint no rotor inertia)",
    "on_axis": (
        "moves only mass that lies on its own axis, with no rotational inertia about that axis "
        "(M has a zero on its diagonal for it)"
    ),
    "dependent": (
        "moves the bodies only as the joints before it do (its column of M is a combination of theirs)"
    ),
    "base": (
        "moves the floating base while every body with mass stands still, the joints taking the motion "
        "up (the base body and the bodies fixed to it lack the mass or inertia to resist it)"
    ),
}


def location(
    file: str | None = None,
    link_index: int | None = None,
    link_name: str | None = None,
    field: str | None = None,
) -> str:
    """Format 'file: link 2 (forearm): field inertia.ixx' for messages."""
    parts = []
    if file:
        parts.append(str(file))
    if link_index is not None:
        parts.append(f"link {link_index} ({link_name})" if link_name else f"link {link_index}")
    if field:
        parts.append(f"field '{field}'")
    return ": ".join(parts)


def link_fields(link) -> dict:
    """link_index and link_name of a loader's link record (anything with .index and .name), or
    None for both when the message concerns no link: keyword arguments for SymdynError."""
    if link is None:
        return {"link_index": None, "link_name": None}
    return {"link_index": link.index, "link_name": link.name}


class SymdynError(ValueError):
    """Bad input: a robot file, an expression, an option. The message names file, link and field."""

    def __init__(
        self,
        message: str,
        *,
        file: str | None = None,
        link_index: int | None = None,
        link_name: str | None = None,
        field: str | None = None,
    ) -> None:
        self.file = file
        self.link_index = link_index
        self.link_name = link_name
        self.field = field
        self.reason = message
        where = location(file, link_index, link_name, field)
        super().__init__(f"{where}: {message}" if where else message)


class SymdynWarning(UserWarning):
    """Implausible (but possible) input, e.g. principal moments breaking the triangle inequality."""


def one_line(text) -> str:
    """`text` with every control character (newlines, escape sequences that would drive the
    terminal, line separators) written as a Python escape, so that a message quoting a user's
    file name or robot name stays one line and cannot clear or recolour the screen."""
    return "".join(
        c if c.isprintable() or c == " " else c.encode("unicode_escape").decode("ascii") for c in str(text)
    )


#: the longest quotation of a user's value in a message (`shown`)
SHOWN = 60


def shown(value) -> str:
    """repr(value) for a message: one line (one_line), cut to SHOWN characters."""
    text = one_line(repr(value))
    return text if len(text) <= SHOWN else text[: SHOWN - 3] + "..."
