"""Joint ranges: a link's `limits` = (lower, upper), checked to be two numbers lower < upper.

A range is in rad for a revolute joint and in m for a prismatic one. The robot file writes it as
`limits: [lower, upper]` (numbers or expressions of parameters that have values), the URDF as
<limit lower= upper=>; symdyn.model.robot.Link keeps it as written and Robot.joint_ranges gives
the numbers per independent coordinate. Only significance pruning uses ranges
(symdyn.algorithms.pruning): the dynamics hold at every q.
"""

from __future__ import annotations

import math

import sympy as sp

from ..errors import SymdynError

__all__ = ["check_limits"]


def check_limits(limits, **where) -> tuple[float, float]:
    """A joint range as two floats lower < upper.

    Args:
        limits: (lower, upper), numbers or SymPy expressions without free symbols.
        where: file, link_index, link_name and field (default "limits") for the message
            (symdyn.errors.location).

    Raises:
        SymdynError: not two entries, an entry that names a parameter without a value or is
            not a finite real number, or lower >= upper.
    """
    where.setdefault("field", "limits")
    items = list(limits)
    if len(items) != 2:
        raise SymdynError(f"limits must be [lower, upper], got {len(items)} entries", **where)
    values, texts = [], []
    for v in items:
        e = sp.sympify(v)
        if e.free_symbols:
            names = ", ".join(sorted(map(str, e.free_symbols)))
            raise SymdynError(
                f"limits must be numbers, but {e} names parameters without a value ({names})", **where
            )
        try:
            values.append(float(e))
        except TypeError:
            raise SymdynError(f"limits must be real numbers, got {e}", **where) from None
        texts.append(f"{values[-1]:.4g}" if e.is_Number else f"{e} = {values[-1]:.4g}")
    lo, hi = values
    if not (math.isfinite(lo) and math.isfinite(hi)):
        raise SymdynError(f"limits must be finite, got [{texts[0]}, {texts[1]}]", **where)
    if not lo < hi:
        raise SymdynError(f"the lower limit {texts[0]} must be below the upper limit {texts[1]}", **where)
    return lo, hi
