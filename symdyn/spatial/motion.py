"""Spatial motion and force vectors over SymPy expressions, angular part first.

A motion v = (w, u) is an angular velocity w and the velocity u of the point at the
origin of the frame it is expressed in; a force f = (n, f) is a moment n about that
origin and a force f (Featherstone, Rigid Body Dynamics Algorithms (2008), ch. 2, in
the order of his Plucker coordinates). Both parts are 3-vectors of one frame;
nothing here changes frame (symdyn.algorithms.frames does). The operations are

    v x m  = (w x m_w, w x m_u + u x m_w)           motion cross motion (Featherstone 2.9)
    v x* f = (w x n + u x f, w x f)                 motion cross force  (Featherstone 2.9)
    m^T f  = m_w . n + m_u . f                      the scalar (power) product

and the joint motion subspace s = (a, 0) of a revolute and (0, a) of a prismatic joint
with unit axis a. The zero-aware 3-vector arithmetic of `symdyn.spatial.vectors` keeps
zero and unit entries from building SymPy expressions.
"""

from __future__ import annotations

from typing import NamedTuple, TypeVar

import sympy as sp

from . import vectors as v3

__all__ = [
    "Motion",
    "Force",
    "motion_subspace",
    "spatial_add",
    "spatial_sub",
    "cross_motion",
    "cross_force",
    "project",
]


class Motion(NamedTuple):
    """A spatial motion (angular velocity, velocity of the frame's origin), one frame's axes."""

    angular: v3.Vec
    linear: v3.Vec


class Force(NamedTuple):
    """A spatial force (moment about the frame's origin, force), one frame's axes."""

    angular: v3.Vec
    linear: v3.Vec


Spatial = TypeVar("Spatial", Motion, Force)


def motion_subspace(joint: str, axis) -> Motion:
    """The motion of a joint at unit rate, in the frame its axis is given in.

    Args:
        joint: "revolute" or "prismatic".
        axis: the unit joint axis a (three entries), in the body frame it moves.

    Returns:
        (a, 0) for a revolute joint, (0, a) for a prismatic one (Featherstone 2008, sec. 4.4,
        Table 4.1).
    """
    assert joint in ("revolute", "prismatic"), joint  # Robot and its loaders admit no other
    a = v3.vec(axis)
    return Motion(a, v3.ZERO3) if joint == "revolute" else Motion(v3.ZERO3, a)


def spatial_add(first: Spatial, *rest: Spatial) -> Spatial:
    """The sum of spatial vectors of one kind (motions or forces) in one frame."""
    return type(first)(
        v3.add(first.angular, *(x.angular for x in rest)), v3.add(first.linear, *(x.linear for x in rest))
    )


def spatial_sub(a: Spatial, b: Spatial) -> Spatial:
    """a - b for two spatial vectors of one kind in one frame."""
    return type(a)(v3.sub(a.angular, b.angular), v3.sub(a.linear, b.linear))


def cross_motion(v: Motion, m: Motion) -> Motion:
    """v x m = (w x m_w, w x m_u + u x m_w) for motions v = (w, u) and m in one frame.

    The rate of change of m when it moves with velocity v (Featherstone 2008, sec. 2.9).
    """
    (w, u), (mw, mu) = v, m
    return Motion(v3.cross(w, mw), v3.add(v3.cross(w, mu), v3.cross(u, mw)))


def cross_force(v: Motion, f: Force) -> Force:
    """v x* f = (w x n + u x f, w x f) for a motion v = (w, u) and a force f = (n, f), one frame.

    The rate of change of f when it moves with velocity v (Featherstone 2008, sec. 2.9).
    """
    (w, u), (n, fl) = v, f
    return Force(v3.add(v3.cross(w, n), v3.cross(u, fl)), v3.cross(w, fl))


def project(m: Motion, f: Force) -> sp.Expr:
    """m^T f = m_w . n + m_u . f: the power of f on m (a joint's share of f for m = s)."""
    return v3.sum_terms((v3.dot(m.angular, f.angular), v3.dot(m.linear, f.linear)))
