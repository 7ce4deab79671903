"""The sympy.physics.mechanics twin of a symdyn chain, for bench/derive.py's Kane rows.

`kane_model(robot)` builds the same chain in sympy.physics.mechanics: frames, points,
rigid bodies, gravity as a force m_i g at each centre of mass (inertial frame N), and
generalized speeds u_i = qd_i, ready for KanesMethod. Revolute joints only: the
benchmark's arms (bench/robots.py) have no other kind.
"""

from __future__ import annotations

from dataclasses import dataclass

import sympy as sp

from symdyn.model.robot import Robot
from symdyn.spatial.transform import rot_x

__all__ = ["kane_model", "KaneModel"]


@dataclass
class KaneModel:
    """The chain in sympy.physics.mechanics, with what KanesMethod needs."""

    frame: object  # inertial ReferenceFrame
    q: list  # generalized coordinates (dynamicsymbols)
    u: list  # generalized speeds u_i = qd_i
    kd_eqs: list
    bodies: list
    loads: list


def _orient_fixed(parent, R: sp.Matrix, name: str):
    """A frame fixed in `parent` with parent_R_frame = R (an x rotation when possible)."""
    from sympy.physics.mechanics import ReferenceFrame

    if sp.eye(3) == R:
        return parent
    frame = ReferenceFrame(name)
    if R[0, 0] == 1:
        angle = sp.atan2(R[2, 1], R[1, 1])
        if sp.Matrix(rot_x(angle)) == R:
            frame.orient_axis(parent, parent.x, angle)
            return frame
    frame.orient_explicit(parent, R)  # sets parent.dcm(frame) = R
    return frame


def _vector(frame, v) -> object:
    return sum((sp.sympify(c) * e for c, e in zip(v, (frame.x, frame.y, frame.z), strict=True)), 0 * frame.x)


def kane_model(robot: Robot) -> KaneModel:
    """Frames, points and rigid bodies of `robot` (revolute joints only) for KanesMethod."""
    from sympy.physics.mechanics import Point, ReferenceFrame, RigidBody, dynamicsymbols, inertia

    n = robot.n
    q = list(dynamicsymbols(f"q1:{n + 1}"))
    u = list(dynamicsymbols(f"u1:{n + 1}"))
    N = ReferenceFrame("N")
    O = Point("O")
    O.set_vel(N, 0)
    g = _vector(N, robot.gravity)
    parent, origin = N, O
    bodies, loads = [], []
    for i, link in enumerate(robot.links):
        if link.joint != "revolute":
            raise ValueError("kane_model handles revolute joints only")
        k = i + 1
        fixed = _orient_fixed(parent, sp.Matrix(link.placement.R), f"P{k}")
        B = ReferenceFrame(f"B{k}")
        axis = _vector(fixed, link.axis)
        B.orient_axis(fixed, axis, q[i])
        B.set_ang_vel(fixed, u[i] * _vector(B, link.axis))
        Oi = origin.locatenew(f"O{k}", _vector(parent, link.placement.p))
        Oi.v2pt_theory(origin, N, parent)
        Ci = Oi.locatenew(f"C{k}", _vector(B, link.com))
        Ci.v2pt_theory(Oi, N, B)
        I = sp.Matrix(link.inertia)
        dyadic = inertia(B, I[0, 0], I[1, 1], I[2, 2], I[0, 1], I[1, 2], I[0, 2])
        bodies.append(RigidBody(f"body{k}", Ci, B, link.mass, (dyadic, Ci)))
        loads.append((Ci, link.mass * g))
        parent, origin = B, Oi
    kd = [qi.diff(dynamicsymbols._t) - ui for qi, ui in zip(q, u, strict=True)]
    return KaneModel(N, q, u, kd, bodies, loads)
