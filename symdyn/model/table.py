"""A robot as a text table, one row per link, as the Robotics Toolbox prints a DH table.

Each row shows the link's joint (R or P, or the joint it mimics), its parent, the joint's
constant placement in the parent's body frame (translation and URDF roll-pitch-yaw of
`Link.placement`, R = Rz(yaw) Ry(pitch) Rx(roll)), the axis in the link's body frame, the mass
and the free parameters the link names, and, when any link gives one, the joint's range
(`Link.limits`, "-" for a link without). Numbers get 4 significant digits, symbols print as
written; nothing is expanded or simplified, so the table stays fast for long chains.
The model is described in docs/python-api.md, "The model".
"""

from __future__ import annotations

import math
import re
from collections.abc import Sequence
from pathlib import PurePath

import sympy as sp

from ..spatial.transform import Transform, coordinate_axis, rpy_matrix

__all__ = ["robot_table", "number_text"]

_NUMBER = re.compile(r"(?<![\w.])\d+\.\d+(?:e[-+]?\d+)?")
_AXES = "xyz"
_IDENTITY = sp.ImmutableMatrix(sp.eye(3))


def number_text(x) -> str:
    """A number with 4 significant digits, an expression as written with its decimals shortened."""
    e = sp.sympify(x)
    if e.is_number and e.is_real is not False:
        try:
            return _short(float(e))
        except TypeError:
            pass
    return _NUMBER.sub(lambda m: _short(float(m.group())), str(e))


def _short(v: float) -> str:
    text = f"{v:.4g}"
    return "0" if text == "-0" else text


def _angle(s: sp.Expr, c: sp.Expr) -> sp.Expr | float | None:
    """atan2(s, c) without simplifying: a number, a for (+-sin a, cos a), or None."""
    if s.is_number and c.is_number:
        return sp.atan2(s, c)
    sign = 1
    if isinstance(s, sp.Mul) and s.args[0] == -1:
        s, sign = -s, -1
    if isinstance(s, sp.sin) and c == sp.cos(s.args[0]):
        return sign * s.args[0]
    return None


def _rpy(R: sp.ImmutableMatrix) -> tuple | None:
    """(roll, pitch, yaw) with R = Rz(yaw) Ry(pitch) Rx(roll), or None when not compact."""
    if all(x.is_number for x in R):
        m = [[float(R[i, j]) for j in range(3)] for i in range(3)]
        pitch = math.atan2(-m[2][0], math.hypot(m[0][0], m[1][0]))
        if math.hypot(m[0][0], m[1][0]) < 1e-12:  # gimbal lock: put the whole turn into yaw
            return 0.0, pitch, math.atan2(-m[0][1], m[1][1])
        return math.atan2(m[2][1], m[2][2]), pitch, math.atan2(m[1][0], m[0][0])
    if R[2, 0] != 0:
        return None  # symbolically, only turns without pitch stay compact: R = Rz(yaw) Rx(roll)
    roll, yaw = _angle(R[2, 1], R[2, 2]), _angle(R[1, 0], R[0, 0])
    if roll is None or yaw is None or rpy_matrix(roll, 0, yaw) != R:
        return None
    return roll, 0, yaw


def placement_text(placement: Transform) -> str:
    """`xyz (x, y, z) rpy (r, p, y)` of a joint placement, each part left out when zero."""
    parts = []
    if any(x != 0 for x in placement.p):
        parts.append("xyz (" + ", ".join(number_text(x) for x in placement.p) + ")")
    if placement.R != _IDENTITY:
        rpy = _rpy(placement.R)
        if rpy is None:
            parts.append("R " + str(placement.R.tolist()))
        elif any(a != 0 for a in rpy):
            parts.append("rpy (" + ", ".join(number_text(a) for a in rpy) + ")")
    return " ".join(parts) or "-"


def axis_text(axis) -> str:
    """+z, -x, ... for a coordinate axis, else the three components."""
    coord = coordinate_axis(axis)
    if coord is not None:
        k, sign = coord
        return ("+" if sign > 0 else "-") + _AXES[k]
    return "(" + ", ".join(number_text(x) for x in axis) + ")"


def _link_params(link, params: Sequence[sp.Symbol]) -> str:
    """The free parameters among the link's fields, in the robot's order."""
    atoms: set = set()
    fields = (
        *link.placement.R,
        *link.placement.p,
        *link.axis,
        link.mass,
        *link.com,
        *link.inertia,
        *link.friction.coefficients(),
        link.motor.inertia,
        link.motor.gear_ratio,
        *(link.limits or ()),
    )
    for x in fields:
        atoms |= sp.sympify(x).free_symbols
    return ", ".join(str(p) for p in params if p in atoms)


def _joint_text(link, links) -> str:
    kind = "R" if link.joint == "revolute" else "P"
    m = link.mimic
    if m is None:
        return kind
    return f"{kind} mimic of {links[m.joint].name} ({number_text(m.multiplier)}, {number_text(m.offset)})"


def _header(robot) -> str:
    joints = f"{robot.n} joint" + ("" if robot.n == 1 else "s")
    if robot.nb != robot.n:
        joints += f" ({robot.nb} bodies)"
    if getattr(robot, "floating", False):
        joints += f" on a floating base '{robot.base_body.name}' (NQ {robot.nq}, NV {robot.nv})"
    shown = [str(p) for p in robot.params[:8]] + (["..."] if len(robot.params) > 8 else [])
    free = f"{len(robot.params)} free parameter" + ("" if len(robot.params) == 1 else "s")
    if shown:
        free += " (" + ", ".join(shown) + ")"
    gravity = "(" + ", ".join(number_text(g) for g in robot.gravity) + ")"
    source = f", from {PurePath(robot.source).name}" if robot.source else ""
    return f"Robot {robot.name}: {joints}, {free}, gravity {gravity}{source}"


def robot_table(robot) -> str:
    """The robot as a header line and a table with one row per link (Robot.__repr__).

    Args:
        robot: a symdyn.model.robot.Robot (a chain or a tree, with or without mimic joints).

    Returns:
        The text, rows in the order of Robot.links, link numbers from 1.
    """
    names = [link.name for link in robot.links]
    ranged = any(link.limits is not None for link in robot.links)
    titles = ("#", "link", "joint", "parent", "placement", "axis", "mass", "params")
    rows = [titles + (("limits",) if ranged else ())]
    for i, (link, parent) in enumerate(zip(robot.links, robot.parents, strict=True)):
        limits = "-" if link.limits is None else "[" + ", ".join(number_text(x) for x in link.limits) + "]"
        rows.append(
            (
                str(i + 1),
                link.name,
                _joint_text(link, robot.links),
                "base" if parent < 0 else names[parent],
                placement_text(link.placement),
                axis_text(link.axis),
                number_text(link.mass),
                _link_params(link, robot.params) or "-",
                *([limits] if ranged else []),
            )
        )
    widths = [max(len(r[k]) for r in rows) for k in range(len(rows[0]))]
    lines = [" | ".join(c.ljust(w) for c, w in zip(r, widths, strict=True)).rstrip() for r in rows]
    lines.insert(1, "-+-".join("-" * w for w in widths))
    return "\n".join([_header(robot), *lines])
