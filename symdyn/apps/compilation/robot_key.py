"""The content key of a robot for the compile cache: a SHA-256 over every field but its source file.

symdyn.compile (symdyn.apps.compilation.compile) keys a cache entry by it, beside symdyn's version and code,
the compiler, its flags and the machine (symdyn.apps.compilation.build), so an unchanged robot loaded from
another file, or again, hits the same entry.
"""

from __future__ import annotations

import dataclasses

__all__ = ["robot_digest"]


def _canonical(value):
    """A deterministic, content-only description of a robot (dataclasses, tuples, SymPy objects)."""
    if dataclasses.is_dataclass(value) and not isinstance(value, type):
        return [type(value).__name__] + [
            [f.name, _canonical(getattr(value, f.name))]
            for f in dataclasses.fields(value)
            if f.name != "source"
        ]
    if isinstance(value, (tuple, list)):
        return [_canonical(v) for v in value]
    if isinstance(value, (str, int, float, bool)) or value is None:
        return value
    import sympy as sp

    return sp.srepr(value)


def robot_digest(robot) -> str:
    """SHA-256 of the robot's content (every field but the file it came from)."""
    import hashlib
    import json

    return hashlib.sha256(json.dumps(_canonical(robot)).encode()).hexdigest()
