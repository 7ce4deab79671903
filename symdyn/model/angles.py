"""Angles written as decimals, made exact where they are a multiple of pi/2 (docs/robot-files.md).

Robot descriptions written by programs or copied from printed tables carry right
angles as decimals: 1.5707963267948966 (Python's or MATLAB's pi/2), 3.14159265359,
or 1.5708 as a table prints it. SymPy keeps cos(1.5707963267948966) = 6.1e-17 as a
live term, so every product it enters survives into the generated code (the PUMA 560
with its twists written that way needs 652 operations for its inverse dynamics, not 434).
`snap_angle` is the one rule both loaders apply to the angles of a description:

* an angle within SNAP_TOLERANCE = 1e-9 rad of a multiple k pi/2 becomes that exact
  multiple (SymPy's k*pi/2), so that its sine and cosine are exactly 0 or +-1;
* an angle within WARN_TOLERANCE = 1e-3 rad of a nonzero multiple of pi/2, but not
  within 1e-9 (1.5708, -3.1416), is kept as written and a `SymdynWarning` names the
  file, the link, the field and the multiple to write instead. Angles near 0 are not
  warned about: a printed table shows a rounded zero as 0, so a small nonzero angle
  there is meant (a calibration offset, say);
* a constant that is neither a rational number nor a rational multiple of pi (pi**2/4,
  sqrt(2), sin(1), 0.3*pi) is evaluated to a double first, and the two rules above apply to that
  double: SymPy cannot simplify the sine of such a constant, and keeping cos(pi**2/4) as a
  symbol makes the derivation of a seven-joint arm run for minutes; a constant that does not
  evaluate to a finite real number is a SymdynError naming the file, link and field;
* every other value is returned unchanged: exact values (0, 1, pi/2, pi/3), expressions
  with parameters, angles farther than 1e-3 rad from every multiple of pi/2, and
  angles beyond LARGEST = 1e4 rad (no description has them; far out, doubles
  could not tell 1e-9 rad).

The loaders apply it to the DH twist alpha and angle theta of every link of a robot
file (symdyn.parsers.robot_fields; for a revolute joint theta is the offset of q, for
a prismatic one the fixed angle) and to the roll, pitch and yaw of every URDF
<origin> (symdyn.parsers.urdf_elements). Lengths and masses never pass through it,
nor do parameter values: an angle given as a parameter is used as its value is written.
"""

from __future__ import annotations

import math
import warnings

import sympy as sp

from ..errors import SymdynError, SymdynWarning, location

__all__ = ["SNAP_TOLERANCE", "WARN_TOLERANCE", "LARGEST", "snap_angle", "constant_angle"]

#: Angles this close (rad) to a multiple of pi/2 become that exact multiple.
SNAP_TOLERANCE = 1e-9
#: Angles this close (rad) to a nonzero multiple of pi/2, but not snapped, are warned about.
WARN_TOLERANCE = 1e-3
#: Larger angles (rad) are left alone: no description has them, and far out doubles cannot tell 1e-9.
LARGEST = 1e4
_TOLERANCE_TEXT = f"{SNAP_TOLERANCE:.0e}".replace("e-0", "e-")  # "1e-9"


def snap_angle(
    value: sp.Expr,
    *,
    file: str | None = None,
    link_index: int | None = None,
    link_name: str | None = None,
    field: str | None = None,
    angle: str | None = None,
    line: int | None = None,
    expressions: bool = True,
) -> sp.Expr:
    """`value` (an angle in rad), or the exact multiple k*pi/2 within SNAP_TOLERANCE of it.

    Only constants (no symbol) that are not exact (a rational number or a rational multiple
    of pi) are considered, as the double they evaluate to (`constant_angle`). file,
    link_index, link_name and field locate the angle in the warning; `angle` names it
    within the field (e.g. "pitch" of an rpy triple) and `line` is the line of the file.
    With `expressions` the format accepts expressions, and the warning suggests writing
    the multiple as one (pi/2); otherwise (URDF) it suggests the double nearest to the
    multiple (1.5707963267948966).
    """
    value = constant_angle(value, file=file, link_index=link_index, link_name=link_name, field=field)
    if value.free_symbols or not value.is_Float:
        return value
    x = float(value)
    if not abs(x) <= LARGEST:
        return value
    k = round(x / (math.pi / 2))
    distance = abs(x - k * (math.pi / 2))
    exact = sp.Integer(k) * sp.pi / 2
    if distance <= SNAP_TOLERANCE:
        return exact
    if k != 0 and distance <= WARN_TOLERANCE:
        where = location(file, link_index, link_name, field)
        what = f"{angle} " if angle else ""
        spelling = str(exact) if expressions else repr(float(exact))
        at_line = f" (line {line})" if line else ""
        warnings.warn(
            f"{where + ': ' if where else ''}{what}{x!r} rad is {distance:.2g} rad from {exact}, so it is "
            f"kept as written (only angles within {_TOLERANCE_TEXT} rad of a multiple of pi/2 are made "
            f"exact); write {spelling} if {exact} is meant{at_line}",
            SymdynWarning,
            stacklevel=2,
        )
    return value


def constant_angle(value: sp.Expr, **where) -> sp.Expr:
    """`value`, or the double nearest to it if it is a constant other than a float, a rational
    number or a rational multiple of pi (pi**2/4, sqrt(2), 0.3*pi); SymdynError (naming `where`: file,
    link_index, link_name, field) if such a constant is not a finite real number. The rule
    `snap_angle` applies first; the robot loader applies it to an angle that a parameter's value
    makes constant."""
    if value.free_symbols or value.is_Float or value.is_Rational or (value / sp.pi).is_Rational:
        return value
    try:
        x = complex(value.evalf(17))
    except (TypeError, ValueError):
        x = complex(math.nan)
    if x.imag != 0 or not math.isfinite(x.real):
        raise SymdynError(f"angle {value} is not a finite real number", **where)
    return sp.Float(x.real)
