"""The kinematic tree and the coordinates of a robot: parents, supports, subtrees, mimic joints.

Links are numbered 0 .. nb-1 in depth-first order, so every link comes after its parent:
`parents[i]` is Featherstone's lambda(i) (Rigid Body Dynamics Algorithms, 2008, sec. 4.1.2)
with -1 for the fixed base. A serial chain has parents (-1, 0, 1, ...). Two joints couple in M
only when one supports the other (lies on its path to the base), so M[i, j] = 0 for joints on
different branches.

A mimic joint has no coordinate of its own: its position is q_j = multiplier q_i + offset,
with q_i an independent coordinate, and its rates qd_j = multiplier qd_i, qdd_j = multiplier
qdd_i. With S the nb x n selection matrix (S[j, c(i)] = multiplier) the dynamics on the n
independent coordinates are the projection M = S^T M_b S, C = S^T C_b S, G = S^T G_b,
tau = S^T tau_b of the dynamics of the nb bodies (the offsets vanish from S because they are
constant).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import sympy as sp

__all__ = [
    "Mimic",
    "Coordinate",
    "check_parents",
    "children",
    "support",
    "subtree",
    "is_chain",
    "idle_joints",
]


@dataclass(frozen=True)
class Mimic:
    """q_this = multiplier * q_joint + offset, `joint` the index of the link whose joint is mimicked."""

    joint: int
    multiplier: sp.Expr = sp.S.One
    offset: sp.Expr = sp.S.Zero


@dataclass(frozen=True)
class Coordinate:
    """How link i's joint position follows from the independent coordinates:
    q_link = multiplier * q[index] + offset (multiplier 1, offset 0 for an independent joint)."""

    index: int
    multiplier: sp.Expr = sp.S.One
    offset: sp.Expr = sp.S.Zero


def check_parents(parents: Sequence[int]) -> str | None:
    """What is wrong with a parent array (None when it is a valid depth-first numbering)."""
    for i, p in enumerate(parents):
        if not -1 <= p < i:
            return f"link {i + 1} has parent {p + 1 if p >= 0 else p}: a parent must come before its child"
    return None


def children(parents: Sequence[int], i: int) -> list[int]:
    """The links whose parent is link i (i = -1: the links on the base)."""
    return [j for j, p in enumerate(parents) if p == i]


def support(parents: Sequence[int], i: int) -> list[int]:
    """Link i and its ancestors, from i down to the link on the base (kappa(i) reversed)."""
    out = []
    while i >= 0:
        out.append(i)
        i = parents[i]
    return out


def subtree(parents: Sequence[int], i: int) -> list[int]:
    """Link i and every link it carries, in increasing order (nu(i))."""
    inside = {i}
    for j in range(i + 1, len(parents)):
        if parents[j] in inside:
            inside.add(j)
    return sorted(inside)


def is_chain(parents: Sequence[int]) -> bool:
    """Whether the tree is a serial chain 0 <- 1 <- 2 ... in link order."""
    return all(p == i - 1 for i, p in enumerate(parents))


def idle_joints(
    parents: Sequence[int],
    massless: Sequence[bool],
    weightless: Sequence[bool],
    turns: Sequence[bool],
    geared: Sequence[bool],
) -> list[int]:
    """The links whose joint moves nothing that has inertia: a zero row and column of M.

    A unit rate of joint i moves the subtree of link i and nothing else, so M[i, i] =
    s_i^T I^c_i s_i + gear_ratio_i^2 J_m,i. It is zero, and with it the whole row (M is
    positive semi-definite), when joint i has no rotor inertia and its subtree has zero
    mass and zero rotational inertia; for a prismatic joint (which turns nothing) zero mass
    is enough. The rotors of the joints further out only add to their own diagonal entries.

    Args:
        parents: lambda(i) per link (-1: the base), parents before children.
        massless: per link, whether it has zero mass and zero rotational inertia.
        weightless: per link, whether it has zero mass (true wherever `massless` is).
        turns: per link, whether its joint is revolute.
        geared: per link, whether its joint may have rotor inertia.

    Returns:
        The indices of the idle joints, in increasing order.
    """
    empty, light = list(massless), list(weightless)
    for i in reversed(range(len(parents))):  # every child comes after its parent
        p = parents[i]
        if p >= 0:
            empty[p] = empty[p] and empty[i]
            light[p] = light[p] and light[i]
    return [i for i in range(len(parents)) if not geared[i] and (empty[i] or (light[i] and not turns[i]))]
