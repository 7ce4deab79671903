"""Spatial inertias over SymPy expressions: a body's mass, first moment and rotational inertia
about the origin of the frame they are expressed in.

For a body of mass m with centre of mass c and rotational inertia I_c about c (one frame),

    h   = m c                                  (first moment)
    I_o = I_c + m (c^T c 1 - c c^T)            (about the origin: the parallel-axis theorem,
                                                R. Grupen, "Dynamics" (2015), slide 8)

and the 6x6 spatial inertia [[I_o, [h x]], [[h x]^T, m 1]] (Featherstone, Rigid Body
Dynamics Algorithms (2008), sec. 2.13) is kept as the triple (m, h, I_o). Composite bodies,
momenta and the rate of change of an inertia (symdyn.algorithms.crba, .coriolis) are built
from the operations here; rotating a tensor into another frame (R J R^T, slide 10) is
symdyn.algorithms.frames' job, because it names intermediates.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import NamedTuple

import sympy as sp

from . import vectors as v3
from .motion import Force, Motion

__all__ = [
    "SpatialInertia",
    "origin_inertia",
    "body_inertia",
    "scaled_inertia",
    "apply_inertia",
    "inertia_rate",
    "shifted_rotational_inertia",
]

Rows = Sequence[Sequence[sp.Expr]]  # a 3x3 matrix by rows, named or not


class SpatialInertia(NamedTuple):
    """(m, h, I): mass, first moment h = m c and rotational inertia about the frame's origin."""

    mass: sp.Expr
    first_moment: v3.Vec
    inertia: Rows


def origin_inertia(mass, com, inertia_com) -> v3.Mat:
    """I_o = I_c + m (c^T c 1 - c c^T): the rotational inertia about the frame's origin.

    Args:
        mass: m.
        com: the centre of mass c (three entries), in the body frame.
        inertia_com: I_c (3x3), about the centre of mass, body-frame axes.

    Returns:
        I_o (rows of a symmetric 3x3), about the body-frame origin, body-frame axes
        (parallel-axis theorem: Grupen (2015), slide 8; Craig, Introduction to Robotics
        (3rd ed., 2005), sec. 6.3).
    """
    m = sp.sympify(mass)
    c = v3.vec(com)
    Ic = v3.mat(inertia_com)
    cc = v3.dot(c, c)
    return tuple(
        tuple(Ic[r][s] + v3.product(m, (cc if r == s else 0) - v3.product(c[r], c[s])) for s in range(3))
        for r in range(3)
    )  # type: ignore[return-value]


def body_inertia(mass, com, inertia_com) -> SpatialInertia:
    """The spatial inertia (m, m c, I_o) of a body about its frame's origin (see `origin_inertia`)."""
    m = sp.sympify(mass)
    return SpatialInertia(m, v3.scale(m, v3.vec(com)), origin_inertia(m, com, inertia_com))


def scaled_inertia(k: sp.Expr, inertia: SpatialInertia) -> SpatialInertia:
    """k (m, h, I) for a scalar k, entry by entry."""
    m, h, I = inertia
    return SpatialInertia(
        v3.product(k, m), v3.scale(k, h), tuple(tuple(v3.product(k, x) for x in row) for row in I)
    )


def apply_inertia(inertia: SpatialInertia, v: Motion) -> Force:
    """The spatial inertia times a motion: I v = (I_o w + h x u, m u - h x w).

    Args:
        inertia: (m, h, I_o) about the origin of frame F, F's axes.
        v: a motion (w, u) in frame F (u: velocity of F's origin).

    Returns:
        The force (moment about F's origin, force) in frame F: the momentum for a velocity v,
        the force that accelerates the body for an acceleration v (Featherstone 2008, sec. 2.13).
    """
    m, h, I = inertia
    w, u = v
    return Force(v3.add(v3.mul(I, w), v3.cross(h, u)), v3.sub(v3.scale(m, u), v3.cross(h, w)))


def inertia_rate(inertia: SpatialInertia, v: Motion) -> SpatialInertia:
    """The rate of change v x* I - I v x of a spatial inertia moving with the motion v.

    With v = (w, u) and I = (m, h, I_o) in one frame, the rate is a zero-mass spatial inertia

        dh = w x h + m u,   dI = [w x] I_o - I_o [w x] - ([u x][h x] + [h x][u x])

    (mass is conserved). Args and result are in the same frame as `inertia`; dI is given by
    rows (not yet named), dh unnamed too.
    """
    m, h, I = inertia
    w, u = v
    dh = v3.add(v3.cross(w, h), v3.scale(m, u))
    columns = [v3.cross(w, (I[0][c], I[1][c], I[2][c])) for c in range(3)]  # [w x] I by columns
    K = [[columns[c][r] for c in range(3)] for r in range(3)]
    uh2 = v3.product(2, v3.dot(u, h))
    dI = tuple(
        tuple(
            v3.sum_terms(
                (K[r][c], K[c][r], -v3.product(u[r], h[c]), -v3.product(h[r], u[c]), uh2 if r == c else 0)
            )
            for c in range(3)
        )
        for r in range(3)
    )
    return SpatialInertia(sp.S.Zero, dh, dI)


def _skew_squared(p: v3.Vec) -> list[list[sp.Expr]]:
    """[p x]^2 = p p^T - (p^T p) 1."""
    pp = v3.dot(p, p)
    return [[v3.product(p[r], p[c]) - (pp if r == c else 0) for c in range(3)] for r in range(3)]


def _symmetric_cross(u: v3.Vec, p: v3.Vec) -> list[list[sp.Expr]]:
    """[u x][p x] + [p x][u x] = u p^T + p u^T - 2 (u . p) 1."""
    up = v3.dot(u, p)
    return [
        [
            v3.sum_terms((v3.product(u[r], p[c]), v3.product(p[r], u[c]), -2 * up if r == c else 0))
            for c in range(3)
        ]
        for r in range(3)
    ]


def shifted_rotational_inertia(
    own: Rows, child_rotated: Rows, child_moment_rotated: v3.Vec, child_mass: sp.Expr, p: v3.Vec
) -> list[list[sp.Expr]]:
    """The rotational inertia about a parent origin of a body plus a child moved there.

    With the child's inertia and first moment already turned into the parent's axes
    (J' = R J R^T, h' = R h) and p the child's origin in the parent frame,

        I = I_own + J' - [h' x][p x] - [p x][h' x] - m_child [p x]^2

    the rotational block of X^T I_child X, X the motion transform from parent to child
    coordinates (Featherstone 2008, sec. 2.13; the parallel-axis theorem of Grupen (2015),
    slide 8, for a body whose centre of mass is not at its origin).

    Returns:
        I (rows, unnamed), about the parent's origin, parent axes.
    """
    cross = _symmetric_cross(child_moment_rotated, p)
    pp = _skew_squared(p)
    return [
        [
            v3.sum_terms((own[r][k], child_rotated[r][k], -cross[r][k], -v3.product(child_mass, pp[r][k])))
            for k in range(3)
        ]
        for r in range(3)
    ]
