"""Mimic joints: one step of q_follower = multiplier * q_master + offset, to an independent joint.

A mimic joint a has no coordinate of its own: q_a = k_ab q_b + o_ab, and its master b must
move on its own. When b is a mimic joint too (q_b = k_bc q_c + o_bc), the file is refused,
as Pinocchio refuses it, and the message gives the one relation to write instead:

    q_a = (k_ab k_bc) q_c + (k_ab o_bc + o_ab)

Joints that follow each other in a cycle are refused as a cycle. Both loaders (URDF <mimic>,
robot-file `mimic:`) use this check; each supplies how to read one step and its errors.
"""

from __future__ import annotations

from collections.abc import Callable

import sympy as sp

__all__ = ["follow_mimics", "number_text"]

#: name -> (master name, multiplier, offset) of a mimic joint, None for an independent joint
Step = Callable[[str], tuple[str, sp.Expr, sp.Expr] | None]
#: (follower, its master, the independent joint at the end, composed multiplier, offset) -> error
ChainError = Callable[[str, str, str, sp.Expr, sp.Expr], Exception]


def follow_mimics(
    start: str,
    master_of: Step,
    cycle_error: Callable[[str, list[str]], Exception],
    chain_error: ChainError,
) -> tuple[str, sp.Expr, sp.Expr] | None:
    """(master, multiplier, offset) with q_start = multiplier * q_master + offset, or None when
    `start` moves on its own. `master_of` reads one step (and raises for a bad master);
    `cycle_error(name, cycle)` is the error for joint `name`, whose master closes `cycle`;
    `chain_error` the error for a master that is a mimic joint itself."""
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
    if len(followed) > 2:
        raise chain_error(start, followed[1], followed[-1], multiplier, offset)
    return followed[-1], multiplier, offset


def number_text(x: sp.Expr) -> str:
    """A multiplier or offset as a user writes it: 0.1, not 0.100000000000000; pi/2 stays pi/2."""
    x = sp.sympify(x, strict=True)
    if isinstance(x, sp.Float):
        return repr(float(x))
    return sp.sstr(x)
