"""Mimic joints followed to the independent joint at the end of their chain, the factors composed.

A mimic joint a has no coordinate of its own: q_a = k_ab q_b + o_ab. When its master b is a
mimic joint too (q_b = k_bc q_c + o_bc), substituting gives one relation with c:

    q_a = (k_ab k_bc) q_c + (k_ab o_bc + o_ab)

and so on to the first joint that moves on its own. Both loaders (URDF <mimic>, robot-file
`mimic:`) use this walk; each supplies how to read one step and the error for a cycle.
"""

from __future__ import annotations

from collections.abc import Callable

import sympy as sp

__all__ = ["follow_mimics"]

#: name -> (master name, multiplier, offset) of a mimic joint, None for an independent joint
Step = Callable[[str], tuple[str, sp.Expr, sp.Expr] | None]


def follow_mimics(
    start: str, master_of: Step, cycle_error: Callable[[str, list[str]], Exception]
) -> tuple[str, sp.Expr, sp.Expr] | None:
    """(independent joint, multiplier, offset) with q_start = multiplier * q_joint + offset, or
    None when `start` moves on its own. `master_of` reads one step (and raises for a bad master);
    `cycle_error(name, cycle)` is the error for joint `name`, whose master closes `cycle`."""
    step = master_of(start)
    if step is None:
        return None
    multiplier, offset = sp.S.One, sp.S.Zero
    followed = [start]
    while step is not None:
        master, k, o = step
        if master in followed:
            raise cycle_error(followed[-1], [*followed[followed.index(master) :], master])
        # q_start = multiplier q_current + offset and q_current = k q_master + o
        multiplier, offset = multiplier * k, multiplier * o + offset
        followed.append(master)
        step = master_of(master)
    return followed[-1], multiplier, offset
