"""The norm a floating base's quaternion may have at run time, and its check (NumPy only).

Every floating-base function symdyn generates reads the rotation of q / |q| through
|q|^2 = qx^2 + qy^2 + qz^2 + qw^2 (R = 1 + s (qw [u]x + [u]x^2) with s = 2 / |q|^2; integrate
divides by sqrt(|q|^2)), formed in the working precision. |q|^2 must neither overflow (|q| above
sqrt of the largest number: 1.34e154 in double, 1.84e19 in float) nor fall below the smallest
normal number, where it loses its digits and then becomes 0 (|q| below 1.49e-154 in double,
1.08e-19 in float): a quaternion of norm 1e-200 gives NaN, one of 1e200 gives R = 1 without a
word. QUATERNION_NORM keeps a margin of 1e4 in |q|^2 inside both ends (for s g and the products
qx qz s): [1e-150, 1e150] in double, [1e-18, 1e18] in float. The generated code stays as it is;
the run-time entry points symdyn controls (simulate's q0, which it then normalises, the methods of
symdyn.compile that take a configuration, the numeric oracle's floating functions) refuse a
finite quaternion whose norm is outside the range with `check_quaternions`; a quaternion with a
NaN or an infinity is passed on (NaN in, NaN out), as a joint angle would be.
"""

from __future__ import annotations

import math

import numpy as np

from ..errors import SymdynError

__all__ = [
    "QUATERNION_NORM",
    "QUATERNION",
    "quaternion_norms",
    "one_quaternion_norm",
    "check_quaternions",
    "quaternion_message",
]

#: the norms of the base quaternion the generated code's |q|^2 holds, by precision
QUATERNION_NORM = {"double": (1e-150, 1e150), "float": (1e-18, 1e18)}
#: the quaternion's entries (qx, qy, qz, qw) in a configuration q = [x, y, z, qx, qy, qz, qw, joints]
QUATERNION = slice(3, 7)


def quaternion_norms(q: np.ndarray) -> np.ndarray:
    """|(qx, qy, qz, qw)| of each configuration of q (..., NQ), without overflow or underflow."""
    x = np.asarray(q, dtype=float)[..., QUATERNION]
    return np.hypot(np.hypot(x[..., 0], x[..., 1]), np.hypot(x[..., 2], x[..., 3]))


def quaternion_message(where: str, norm: float, state: int | None = None, precision: str = "double") -> str:
    """The one line refusing a quaternion of `norm` (of batch state `state`, if any)."""
    low, high = QUATERNION_NORM[precision]
    which = "" if state is None else f" of state {state}"
    return (
        f"{where}: the base quaternion (entries 4 to 7){which} has norm {norm:.3g}, outside "
        f"[{low:g}, {high:g}], the norms whose square the generated code forms in {precision} precision "
        "(docs/floating-base.md): scale it"
    )


def check_quaternions(q, where: str, precision: str = "double") -> None:
    """SymdynError when a configuration of q ((NQ,) or (..., NQ)) has a finite quaternion whose
    norm is outside QUATERNION_NORM[precision]; names the first such state of a batch."""
    a = np.asarray(q, dtype=float)
    norms = quaternion_norms(a)
    low, high = QUATERNION_NORM[precision]
    with np.errstate(invalid="ignore"):
        bad = np.isfinite(norms) & ~((norms >= low) & (norms <= high))
    if not bad.any():
        return
    if a.ndim == 1:
        raise SymdynError(quaternion_message(where, float(norms), None, precision))
    k = int(np.flatnonzero(bad.reshape(-1))[0])
    raise SymdynError(quaternion_message(where, float(norms.reshape(-1)[k]), k, precision))


def one_quaternion_norm(q: np.ndarray) -> float:
    """quaternion_norms of one configuration (NQ,), in Python floats (a microsecond)."""
    return math.hypot(*q[QUATERNION].tolist())
