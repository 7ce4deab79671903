"""How a user's name (a robot's, a link's, a frame's) is spelled in what symdyn writes.

A name read from a URDF, an MJCF file or a robot file may hold any text: spaces, dots, a
newline, LaTeX commands, letters of any script, 250 characters. Three spellings make it safe:

- `comment_text(name)`: one line of printable ASCII for the comments and docstrings of every
  target (`?` for every other character, so that no newline, `*/`, quote or backslash survives);
- `latex_text(name)`: the same line for LaTeX, inside text (`\\texttt{}`), math
  (`\\mathrm{}`) or a `%` comment: LaTeX's special characters escaped or replaced, so that no
  command and no line of the user's text is read by TeX. Every LaTeX path of symdyn spells user
  text with it;
- `identifier(name)` and `identifiers(names)`: a name as an identifier valid in every target
  at once: C, CasADi (a letter first, no `__`, no trailing `_`: function names are
  IDENTIFIER_suffix), NumPy and JAX (Python), MATLAB/Octave (a letter first) and LaTeX labels;
  ASCII letters and digits joined by single underscores, at most MAX_IDENTIFIER characters
  (a longer one is cut and ends in a short hash of the whole name), so that file names built
  from it stay far below the file system's 255 bytes. `identifiers` keeps the identifiers of
  several names distinct: a name that changed and meets another's identifier (or a reserved
  one) gets the suffix `_` and a hash of the name, deterministically.

`short_name(name)` bounds the length of a name that is already an identifier (a robot's) the
same way, keeping it whole when it is short enough.
"""

from __future__ import annotations

import hashlib
import re
import unicodedata
from collections.abc import Iterable, Sequence

__all__ = [
    "comment_text",
    "latex_text",
    "identifier",
    "identifiers",
    "short_name",
    "MAX_IDENTIFIER",
]

#: The longest identifier made from a name (a robot's, a frame's): with the longest suffix a
#: target appends (`_operational_space_inertia.casadi`) a file name stays under 200 bytes.
MAX_IDENTIFIER = 64
_HASH_LENGTH = 8


def comment_text(name: str) -> str:
    """`name` safe inside any target's comments and docstrings: every character but letters,
    digits, spaces and ``_.:+()#@=,;<>[]|~!?^&/-`` becomes `?` (no newline, `*/`, `%`, quote or
    backslash survives)."""
    return re.sub(r"[^A-Za-z0-9_ .:+()#@=,;<>\[\]|~!?^&/-]", "?", name)


def latex_text(name: str) -> str:
    """`name` as LaTeX that typesets it (inside text, `\\texttt{}`, `\\mathrm{}` or a comment)
    and runs nothing: `comment_text(name)` with `\\`, `^`, `~` as `?` and `_ # % & { } $`
    escaped with a backslash. The only backslashes in the result are those escapes."""
    return re.sub(r"([_#%&{}$])", r"\\\1", re.sub(r"[\^~\\]", "?", comment_text(name)))


def _digest(name: str) -> str:
    return hashlib.sha256(name.encode("utf-8", "surrogatepass")).hexdigest()[:_HASH_LENGTH]


def _bounded(ident: str, name: str) -> str:
    """`ident` cut to MAX_IDENTIFIER characters, ending in `_` and the hash of `name`, when longer."""
    if len(ident) <= MAX_IDENTIFIER:
        return ident
    return ident[: MAX_IDENTIFIER - _HASH_LENGTH - 1].rstrip("_") + "_" + _digest(name)


def short_name(name: str) -> str:
    """A name that is already an identifier, cut (as `identifier` cuts) when it is longer than
    MAX_IDENTIFIER characters, else unchanged."""
    return _bounded(name, name)


def identifier(name: str, prefix: str = "frame") -> str:
    """`name` as an identifier of every target (module docstring).

    Letters with accents lose them (NFKD: `é` -> `e`); every run of other characters that are
    not ASCII letters or digits becomes one `_`, dropped at both ends; a name that then starts
    with a digit gets `prefix` and `_` in front, an empty one is `prefix`; longer than
    MAX_IDENTIFIER characters it is cut and ends in `_` and a hash of `name`. A name that is
    already such an identifier is returned unchanged.
    """
    plain = "".join(c for c in unicodedata.normalize("NFKD", name) if not unicodedata.combining(c))
    ident = "_".join(re.findall(r"[A-Za-z0-9]+", plain))
    if not ident:
        return prefix
    if ident[0].isdigit():
        ident = f"{prefix}_{ident}"
    return _bounded(ident, name)


def identifiers(names: Sequence[str], reserved: Iterable[str] = (), prefix: str = "frame") -> dict[str, str]:
    """{name: identifier} for distinct `names`, the identifiers distinct and none in `reserved`.

    A name that is its own identifier keeps it (unless reserved); every other name, in order,
    takes `identifier(name)`, or when that is taken `identifier(name)_HASH` (HASH: 8 hex digits
    of the name's SHA-256; with a counter after the name in the rare case that is taken too).
    The result depends only on `names` (and their order among names that meet), never on chance.
    """
    taken = set(reserved)
    out: dict[str, str] = {}
    for name in names:
        if identifier(name, prefix) == name and name not in taken:
            out[name] = name
            taken.add(name)
    for name in names:
        if name in out:
            continue
        ident, k = identifier(name, prefix), 0
        while ident in taken:
            salt = name if k == 0 else f"{name}\0{k}"
            ident = identifier(name, prefix)[: MAX_IDENTIFIER - _HASH_LENGTH - 1].rstrip("_")
            ident = f"{ident}_{_digest(salt)}"
            k += 1
        out[name] = ident
        taken.add(ident)
    return out
