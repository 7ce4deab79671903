"""The run-time inputs of the compiled contact functions checked before the C reads them.

The generated contact functions (docs/contacts.md) take `active`, NCONTACT numbers that multiply
the rows of the KKT system: only 0 (free) and 1 (held) mean anything, any other number (0.5, NaN,
inf) gives forces that are no contact's without a word. The impulse functions also take `e`, the
restitution, meaningful in [0, 1]. `contact_checked` wraps a method of symdyn.compile that takes
them so that a wrong size, a value that is not 0 or 1, or a restitution outside [0, 1] (or not
finite) is one SymdynError naming the function, the argument and the values, before the C runs.
Baumgarte's functions (group contact_baumgarte) also take `anchor`, NCONTACT x 12 numbers (per
contact its origin, then its rotation matrix row-major; given flat or as (..., NCONTACT, 12)),
whose rotations must be orthonormal with determinant 1 to ROTATION_TOL, and `gains` (Kp, Kd),
finite and >= 0.
One state costs a few microseconds (two NumPy reductions); a batch, a pass over its masks.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from ...errors import SymdynError

__all__ = [
    "CONTACT_INPUTS",
    "ROTATION_TOL",
    "check_anchor",
    "check_gains",
    "check_mask",
    "check_restitution",
    "contact_checked",
]

#: the names of the generated functions' run-time contact inputs
CONTACT_INPUTS = ("active", "e", "anchor", "gains")
#: how far an anchor's rotation may be from orthonormal (max |R^T R - I|) and its determinant from 1
ROTATION_TOL = 1e-6


def _numbers(x, what: str, where: str) -> np.ndarray:
    """`x` as an array of floats, or SymdynError: `where`: `what`, naming the type given."""
    try:
        return np.asarray(x, dtype=float)
    except (TypeError, ValueError):
        raise SymdynError(f"{where}: {what}, got {type(x).__name__}") from None


def check_mask(active, ncontact: int, where: str) -> np.ndarray:
    """`active` as floats when its last axis has `ncontact` entries, each exactly 0 or 1; else
    SymdynError naming `where`."""
    a = _numbers(active, f"active must be {ncontact} numbers 0 or 1", where)
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
    a = _numbers(e, "the restitution e must be a number in [0, 1]", where)
    if a.ndim == 0 or a.shape[-1] != 1:
        raise SymdynError(f"{where}: the restitution e must have shape (1,) or (..., 1), got {a.shape}")
    bad = ~((a >= 0.0) & (a <= 1.0))
    if bad.any():
        raise SymdynError(f"{where}: the restitution e must be in [0, 1], got {a[bad].flat[0]!r}")
    return a


def check_anchor(anchor, size: int, where: str) -> np.ndarray:
    """`anchor` as floats of last axis `size` (NCONTACT x 12, given flat or as (..., NCONTACT, 12)),
    finite, each rotation orthonormal with determinant 1 to ROTATION_TOL; else SymdynError."""
    count = size // 12
    what = f"anchor must be {count} x 12 numbers (per contact its origin, then its rotation row-major)"
    a = _numbers(anchor, what, where)
    if a.ndim >= 2 and a.shape[-1] != size and a.shape[-2:] == (count, 12):
        a = a.reshape(*a.shape[:-2], size)
    if a.ndim == 0 or a.shape[-1] != size:
        raise SymdynError(f"{where}: {what}, got shape {a.shape}")
    if not np.all(np.isfinite(a)):
        raise SymdynError(f"{where}: anchor has entries that are not finite")
    R = a.reshape(-1, count, 12)[..., 3:].reshape(-1, count, 3, 3)
    off = np.abs(np.swapaxes(R, -1, -2) @ R - np.eye(3)).max(axis=(-2, -1))
    det = np.linalg.det(R)
    bad = np.flatnonzero((off > ROTATION_TOL) | (np.abs(det - 1.0) > ROTATION_TOL))
    if len(bad):
        i = bad[0]
        raise SymdynError(
            f"{where}: anchor of contact {i % count} is not a rotation: max |R^T R - I| "
            f"{off.flat[i]:.2g}, det {det.flat[i]:.6g} (tolerance {ROTATION_TOL:g})"
        )
    return a


def check_gains(gains, where: str) -> np.ndarray:
    """`gains` as floats of last axis 2 (Kp, Kd), finite and >= 0; else SymdynError."""
    a = _numbers(gains, "gains must be the two numbers Kp, Kd >= 0", where)
    if a.ndim == 0 or a.shape[-1] != 2:
        raise SymdynError(f"{where}: gains must be (Kp, Kd), shape (2,) or (..., 2), got shape {a.shape}")
    bad = ~((a >= 0.0) & np.isfinite(a))
    if bad.any():
        raise SymdynError(f"{where}: the gains Kp, Kd must be finite and >= 0, got {a[bad].flat[0]!r}")
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
        args = list(args)
        for k, name in checked:
            if k >= len(args):
                break  # the method says how many arguments it takes
            if name == "active":
                check_mask(args[k], sizes["active"], f["name"])
            elif name == "e":
                check_restitution(args[k], f["name"])
            elif name == "anchor":
                args[k] = check_anchor(args[k], sizes["anchor"], f["name"])
            else:
                check_gains(args[k], f["name"])
        return method(*args, **options)

    call.__name__ = method.__name__
    call.__doc__ = method.__doc__
    return call
