"""Robots for the derivation benchmark (bench/derive.py) and their sympy.physics.mechanics twins.

* `generic_arm(n)`: an n-joint spatial arm in standard DH, every joint revolute,
  twists cycling 0, +pi/2, -pi/2, nonzero a and d, numeric masses, centres of
  mass and diagonal inertias (given in DH frame i, converted to the body frame
  as a loader would).
* `puma560_symbolic()`: the PUMA 560 geometry of examples/puma560.yaml (or the
  standard DH table if the file or loader is missing) with every link's mass,
  centre of mass (3) and inertia tensor (6) replaced by free symbols, written in
  DH frame i and converted to the body frame. Motor inertia and friction are
  left out so that all three methods derive the same rigid-body equations.
* `kane_model(robot)`: the same chain in sympy.physics.mechanics (frames,
  points, rigid bodies, gravity as forces, u_i = qd_i), ready for KanesMethod.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass, replace
from pathlib import Path

import sympy as sp

from symdyn.model.robot import Friction, Link, Motor, Robot
from symdyn.spatial.transform import Transform, rot_x

__all__ = ["generic_arm", "puma560_symbolic", "kane_model", "KaneModel", "PUMA_FILE"]

PUMA_FILE = Path(__file__).resolve().parent.parent / "examples" / "puma560.yaml"
GRAVITY = (0, 0, -9.81)
_TWISTS = (sp.S.Zero, sp.pi / 2, -sp.pi / 2)
_INERTIA_KEYS = ("xx", "xy", "xz", "yy", "yz", "zz")


def _dh_link(a, alpha, d, prev_frame: Transform) -> tuple[Transform, sp.ImmutableMatrix, Transform]:
    """(placement, axis, frame) of a standard-DH revolute row with theta offset 0."""
    try:
        from symdyn.parsers.dh import dh_link
    except ImportError:  # fall back to the same construction written out
        placement = prev_frame @ Transform.tz(d)
        frame = Transform.tx(a) @ Transform.rx(alpha)
        return placement, sp.ImmutableMatrix([0, 0, 1]), frame
    return dh_link("standard", "revolute", a, alpha, d, 0, prev_frame)


def _to_body(frame: Transform, com, inertia) -> tuple[sp.ImmutableMatrix, sp.ImmutableMatrix]:
    """Centre of mass and inertia given in DH frame i, re-expressed in the body frame."""
    from symdyn.parsers.dh import to_body

    return to_body(frame, com, inertia)


def _link(name: str, a, alpha, d, prev: Transform, mass, com, inertia) -> Link:
    placement, axis, frame = _dh_link(a, alpha, d, prev)
    com_b, inertia_b = _to_body(frame, com, inertia)
    return Link(
        name=name,
        joint="revolute",
        placement=placement,
        axis=sp.ImmutableMatrix(axis),
        mass=sp.sympify(mass),
        com=com_b,
        inertia=inertia_b,
        frame=frame,
    )


def generic_arm(n: int) -> Robot:
    """A generic n-joint spatial arm with numeric inertial parameters (see the module docstring)."""
    links = []
    prev = Transform.identity()
    for i in range(n):
        k = i + 1
        a = sp.Float(round(0.30 - 0.02 * i, 4))
        d = sp.Float(round(0.10 + 0.03 * ((i * 5) % 4), 4))
        alpha = _TWISTS[i % 3]
        mass = sp.Float(round(4.0 - 0.4 * i, 4))
        com = [sp.Float(round(v, 4)) for v in (-0.45 * float(a), 0.01 * k, 0.02 - 0.005 * i)]
        inertia = sp.diag(*[sp.Float(round(v, 5)) for v in (0.05 / k, 0.06 / k, 0.03 / k)])
        link = _link(f"link{k}", a, alpha, d, prev, mass, com, inertia)
        prev = link.frame
        links.append(link)
    return Robot(name=f"generic{n}", links=tuple(links), gravity=sp.ImmutableMatrix(GRAVITY))


def _puma_geometry() -> list[tuple[sp.Expr, sp.Expr, sp.Expr]]:
    """(a, alpha, d) per link: the standard PUMA 560 DH table (Corke, mdl_puma560.m)."""
    a = [0, 0.4318, 0.0203, 0, 0, 0]
    d = [0, 0, 0.15005, 0.4318, 0, 0]
    alpha = [sp.pi / 2, 0, -sp.pi / 2, sp.pi / 2, -sp.pi / 2, 0]
    return [(sp.sympify(x), al, sp.sympify(y)) for x, al, y in zip(a, alpha, d, strict=True)]


def _inertial_symbols(k: int) -> tuple[sp.Symbol, list[sp.Symbol], sp.Matrix, list[sp.Symbol]]:
    m = sp.Symbol(f"m_{k}")
    com = [sp.Symbol(f"c{ax}_{k}") for ax in "xyz"]
    I = {key: sp.Symbol(f"I{key}_{k}") for key in _INERTIA_KEYS}
    tensor = sp.Matrix(
        [
            [I["xx"], I["xy"], I["xz"]],
            [I["xy"], I["yy"], I["yz"]],
            [I["xz"], I["yz"], I["zz"]],
        ]
    )
    return m, com, tensor, [m, *com, *I.values()]


def puma560_symbolic() -> tuple[Robot, str]:
    """The PUMA 560 with all 60 inertial parameters symbolic, and where its geometry came from."""
    base = None
    if PUMA_FILE.exists():
        try:
            from symdyn.parsers.robot_file import load_robot
        except ImportError:
            load_robot = None
        if load_robot is not None:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")  # the file's implausible-inertia warnings
                base = load_robot(PUMA_FILE).resolved()
    links, params = [], []
    if base is not None:
        origin = f"geometry from {PUMA_FILE.relative_to(PUMA_FILE.parent.parent)}"
        for k, link in enumerate(base.links, start=1):
            m, com, tensor, syms = _inertial_symbols(k)
            com_b, inertia_b = _to_body(link.frame, com, tensor)
            links.append(
                replace(link, mass=m, com=com_b, inertia=inertia_b, friction=Friction(), motor=Motor())
            )
            params += syms
        gravity = base.gravity
    else:
        origin = "geometry from the built-in standard PUMA 560 DH table"
        prev = Transform.identity()
        for k, (a, alpha, d) in enumerate(_puma_geometry(), start=1):
            m, com, tensor, syms = _inertial_symbols(k)
            link = _link(f"link{k}", a, alpha, d, prev, m, com, tensor)
            prev = link.frame
            links.append(link)
            params += syms
        gravity = sp.ImmutableMatrix(GRAVITY)
    robot = Robot(name="puma560_symbolic", links=tuple(links), gravity=gravity, params=tuple(params))
    return robot, origin


# --------------------------------------------------------------------------- sympy.physics.mechanics


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
