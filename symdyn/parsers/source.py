"""Reading a description file's bytes, with the errors every loader gives for it (its size, and
how many links it may describe: MAX_LINKS), and the "did you mean" hint loaders add to a
misspelt name."""

from __future__ import annotations

import difflib
import hashlib
import os
from collections.abc import Iterable

from ..errors import SymdynError

__all__ = ["read_source", "did_you_mean", "check_link_count", "MAX_BYTES", "MAX_LINKS"]

#: Larger files are refused before parsing (a robot description is kilobytes).
MAX_BYTES = 64 * 2**20
#: Most links a model may have (a robot file's links, a URDF's <link> elements, an MJCF file's
#: bodies), refused before they are read one by one: loading takes milliseconds per link, and a
#: derivation's M has n^2 / 2 entries (a thousand independent pendulums derive in about 20 s;
#: real robots have tens of links, MuJoCo Menagerie's largest about a hundred bodies).
MAX_LINKS = 1000


def check_link_count(count: int, what: str, file: str | None) -> None:
    """SymdynError naming the file when a model has more than MAX_LINKS `what` ("links",
    "<link> elements", "bodies")."""
    if count > MAX_LINKS:
        raise SymdynError(
            f"{count:,} {what}: symdyn reads models of at most {MAX_LINKS:,} links (MAX_LINKS)",
            file=file,
        )


def read_source(path: str | os.PathLike, kind: str) -> tuple[str, bytes, str]:
    """(file name, its bytes, their sha256 hex digest); SymdynError naming the file otherwise.

    `kind` names what the file should be ("robot file", "URDF file") in messages.
    """
    try:
        file = str(os.fspath(path))
    except TypeError:
        raise SymdynError(f"{kind} path must be a string or path, not {path!r}") from None
    try:
        with open(file, "rb") as fh:
            raw = fh.read(MAX_BYTES + 1)
    except FileNotFoundError:
        raise SymdynError("no such file", file=file) from None
    except IsADirectoryError:
        raise SymdynError(f"is a directory, not a {kind}", file=file) from None
    except OSError as exc:
        raise SymdynError(f"cannot read file: {exc.strerror or exc}", file=file) from None
    if len(raw) > MAX_BYTES:
        raise SymdynError(f"file larger than {MAX_BYTES // 2**20} MiB", file=file)
    return file, raw, hashlib.sha256(raw).hexdigest()


def did_you_mean(name: str, names: Iterable[str]) -> str:
    """The hint " (did you mean 'x'?)" naming the closest of `names` to a misspelt `name`, or ""."""
    close = difflib.get_close_matches(name, list(names), n=1)
    return f" (did you mean '{close[0]}'?)" if close else ""
