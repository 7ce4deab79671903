"""The run-time inputs of the compiled contact functions checked before the C reads them.

The generated contact functions (docs/contacts.md) take `active`, NCONTACT numbers that multiply
the rows of the KKT system: only 0 (free) and 1 (held) mean anything, any other number (0.5, NaN,
inf) gives forces that are no contact's without a word. The impulse functions also take `e`, the
restitution, meaningful in [0, 1]. `contact_checked` wraps a method of symdyn.compile that takes
them so that a wrong size, a value that is not 0 or 1, or a restitution outside [0, 1] (or not
finite) is one SymdynError naming the function, the argument and the values, before the C runs.
One state costs a few microseconds (two NumPy reductions); a batch, a pass over its masks.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from ...errors import SymdynError

__all__ = ["CONTACT_INPUTS", "check_mask", "check_restitution", "contact_checked"]

#: the names of the generated functions' run-time contact inputs
CONTACT_INPUTS = ("active", "e")


def check_mask(active, ncontact: int, where: str) -> np.ndarray:
    """`active` as floats when its last axis has `ncontact` entries, each exactly 0 or 1; else
    SymdynError naming `where`."""
    try:
        a = np.asarray(active, dtype=float)
    except (TypeError, ValueError):
        what = type(active).__name__
        raise SymdynError(f"{where}: active must be {ncontact} numbers 0 or 1, got {what}") from None
    if a.ndim == 0 or a.shape[-1] != ncontact:
        raise SymdynError(
            f"{where}: active must have {ncontact} entries (one per contact), got shape {a.shape}"
        )
    bad = (a != 0.0) & (a != 1.0)
    if bad.any():
        raise SymdynError(
            f"{where}: active must be 0 (free) or 1 (held) for each contact, got {a[bad].flat[0]!r}"
        )
    return a


def check_restitution(e, where: str) -> np.ndarray:
    """`e` as floats when its last axis has one entry, finite and in [0, 1]; else SymdynError."""
    try:
        a = np.asarray(e, dtype=float)
    except (TypeError, ValueError):
        what = type(e).__name__
        raise SymdynError(f"{where}: the restitution e must be a number in [0, 1], got {what}") from None
    if a.ndim == 0 or a.shape[-1] != 1:
        raise SymdynError(f"{where}: the restitution e must have shape (1,) or (..., 1), got {a.shape}")
    bad = ~((a >= 0.0) & (a <= 1.0))
    if bad.any():
        raise SymdynError(f"{where}: the restitution e must be in [0, 1], got {a[bad].flat[0]!r}")
    return a


def contact_checked(f: dict, method: Callable) -> Callable:
    """`method` (the generated function described by `f`) with its `active` and `e` arguments
    checked; `method` itself when it takes neither."""
    names = [name for name, _ in f["inputs"] if name != "p"]
    sizes = dict(f["inputs"])
    checked = [(k, name) for k, name in enumerate(names) if name in CONTACT_INPUTS]
    if not checked:
        return method

    def call(*args, **options):
        for k, name in checked:
            if k >= len(args):
                break  # the method says how many arguments it takes
            if name == "active":
                check_mask(args[k], sizes["active"], f["name"])
            else:
                check_restitution(args[k], f["name"])
        return method(*args, **options)

    call.__name__ = method.__name__
    call.__doc__ = method.__doc__
    return call
