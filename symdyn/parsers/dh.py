"""Denavit-Hartenberg rows onto the general joint model of `symdyn.model.robot`.

With theta = q + theta_offset (revolute) and d = q + d_offset (prismatic):

standard (distal; Spong, Corke):
    frame_i = frame_{i-1} Rz(theta) Tz(d) Tx(a) Rx(alpha)
    The body frame of link i is the joint frame B_i = frame_{i-1} Rz(theta) Tz(d),
    which moves with link i; link.frame = Tx(a) Rx(alpha) is DH frame i in B_i.
modified (proximal; Craig, Khalil; the row holds alpha_{i-1}, a_{i-1}, d_i, theta_i):
    frame_i = frame_{i-1} Rx(alpha) Tx(a) Rz(theta) Tz(d)
    The body frame is DH frame i itself (link.frame = identity).
    On a tree (W. Khalil and J. Kleinfinger, "A new geometric notation for open and
    closed-loop robots", ICRA 1986) frame_{i-1} is the frame of link i's parent, and
    two more parameters place the row when the parent's x axis is not the common
    normal (the parent has several children):
    frame_i = frame_parent Rz(gamma) Tz(b) Rx(alpha) Tx(a) Rz(theta) Tz(d).

In both conventions the joint axis is z of the body frame, and `prev_frame` is
the parent link's `frame` (its DH frame in its body frame; identity for a link on
the base), so a loader threads ``prev_frame = frame`` from link to link.
"""

from __future__ import annotations

import sympy as sp

from ..model.inertia import rotate
from ..spatial.transform import Transform

__all__ = ["CONVENTIONS", "Z_AXIS", "dh_link", "to_body"]

CONVENTIONS = ("standard", "modified")
Z_AXIS = sp.ImmutableMatrix([0, 0, 1])


def _exprs(*values) -> list[sp.Expr]:
    """SymPy numbers/expressions only: a string here would be evaluated by SymPy, so refuse it."""
    out = []
    for v in values:
        if isinstance(v, str):
            raise TypeError("DH values must be numbers or SymPy expressions, not strings")
        out.append(sp.sympify(v, strict=True))
    return out


def dh_link(
    convention: str,
    joint: str,
    a,
    alpha,
    d,
    theta,
    prev_frame: Transform | None = None,
    gamma=0,
    b=0,
) -> tuple[Transform, sp.ImmutableMatrix, Transform]:
    """One DH row -> (placement, axis, frame) of `symdyn.model.robot.Link`.

    `theta` is the offset for a revolute joint, `d` the offset for a prismatic one.
    `prev_frame` is the parent link's `frame` (None or identity for a link on the base).
    `gamma` and `b` (Khalil's tree parameters, modified convention only) turn and shift
    along the parent's z axis before the row.
    """
    a, alpha, d, theta, gamma, b = _exprs(a, alpha, d, theta, gamma, b)
    prev = Transform.identity() if prev_frame is None else prev_frame
    if gamma != 0 or b != 0:
        if convention != "modified":
            raise ValueError("gamma and b belong to the modified convention")
        prev = prev @ Transform.rz(gamma) @ Transform.tz(b)
    if joint not in ("revolute", "prismatic"):
        raise ValueError(f"joint must be 'revolute' or 'prismatic', not {joint!r}")
    if convention == "standard":
        placement = prev @ Transform.rz(theta) @ Transform.tz(d)
        frame = Transform.tx(a) @ Transform.rx(alpha)
    elif convention == "modified":
        placement = prev @ Transform.rx(alpha) @ Transform.tx(a) @ Transform.rz(theta) @ Transform.tz(d)
        frame = Transform.identity()
    else:
        raise ValueError(f"convention must be 'standard' or 'modified', not {convention!r}")
    return placement, Z_AXIS, frame


def to_body(frame: Transform, com, inertia) -> tuple[sp.ImmutableMatrix, sp.ImmutableMatrix]:
    """Centre of mass and inertia tensor given in DH frame i, re-expressed in the body frame.

    com_body = frame.apply(com); I_body = R I R^T with R = frame.R.
    """
    return frame.apply(com), rotate(inertia, frame.R)
