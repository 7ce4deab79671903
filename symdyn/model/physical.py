"""The physical checks of a link's numbers, shared by the robot file loader and run-time values.

A robot file's values are checked when it is read (symdyn.parsers.robot_file); values given
at run time for the free parameters (`simulate --params`, `symdyn.compile(robot, params)`,
`identify`'s model parameters) pass the same checks once substituted (`check_values`), so a
negative mass or an impossible inertia tensor is refused wherever it comes from.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import TYPE_CHECKING

import sympy as sp

from ..errors import SymdynError
from .friction import coulomb_fields
from .inertia import check_inertia

if TYPE_CHECKING:
    from .robot import Robot

__all__ = ["check_link_numbers", "check_values"]


def _number(expr) -> float | None:
    """A float if `expr` has no free symbols, else None."""
    expr = sp.sympify(expr)
    if expr.free_symbols:
        return None
    try:
        return float(expr)
    except TypeError:
        return None


def check_link_numbers(
    mass,
    inertia,
    nonnegative: Mapping[str, object],
    gear_ratio,
    *,
    file: str | None = None,
    link_index: int | None = None,
    link_name: str | None = None,
) -> None:
    """Refuse a link's impossible numbers (anything still symbolic is skipped).

    mass and inertia (the tensor about the centre of mass): symdyn.inertia.check_inertia;
    every entry of `nonnegative` (field name -> value: friction, motor inertia) must be >= 0;
    the gear ratio must not be zero.
    """
    where = {"file": file, "link_index": link_index, "link_name": link_name}
    check_inertia(mass, inertia, **where)
    for field, value in nonnegative.items():
        x = _number(value)
        if x is not None and x < 0:
            hint = (
                ": c_minus is a magnitude, write the Robotics Toolbox's Tc- without its sign"
                if field.endswith("minus")
                else ""
            )
            raise SymdynError(f"must not be negative (got {x:g}){hint}", field=field, **where)
    x = _number(gear_ratio)
    if x is not None and x == 0:
        raise SymdynError("gear ratio must not be zero", field="motor.gear_ratio", **where)


def check_values(robot: Robot, values: Mapping[sp.Symbol, float], where: str = "") -> None:
    """Check the robot's links with the parameters in `values` (symbol -> float) set to those
    numbers: free parameters, or ones the file gave a value for (a value written as an
    expression of them follows). Links whose numbers involve no parameter were checked when
    the file was read.

    Raises:
        SymdynError: starting with `where`, naming the values given, the link and the field,
            e.g. "parameter m1 = -1: link 1 (upper): field 'mass': mass -1.0 is negative".
    """
    if not values:
        return
    numbers = {p: sp.Float(float(v), 17) for p, v in values.items()}
    mapping = {s: sp.sympify(v).xreplace(numbers) for s, v in robot.values}
    mapping.update(numbers)
    depends = {s: sp.sympify(v).free_symbols for s, v in robot.values}
    prefix = f"{where}: " if where else ""
    for i, link in enumerate(robot.links):
        used = _closure(_symbols(link), depends) & set(numbers)
        if not used:
            continue
        try:
            _check_finite(link, mapping, i + 1)
            check_link_numbers(
                _plain(sp.sympify(link.mass).xreplace(mapping)),
                link.inertia.xreplace(mapping),
                {
                    "friction.viscous": sp.sympify(link.friction.viscous).xreplace(mapping),
                    **{
                        k: sp.sympify(v).xreplace(mapping)
                        for k, v in coulomb_fields(link.friction.coulomb, link.friction.coulomb_minus).items()
                    },
                    "motor.inertia": sp.sympify(link.motor.inertia).xreplace(mapping),
                },
                sp.sympify(link.motor.gear_ratio).xreplace(mapping),
                link_index=i + 1,
                link_name=link.name,
            )
        except SymdynError as e:
            culprits = _closure(_symbols(link, e.field), depends) & set(numbers)
            if e.reason.startswith(_DIVISION):  # name the parameters that are zero
                culprits = {p for p in culprits if float(values[p]) == 0} or culprits
            used = culprits or used
            given = ", ".join(f"{p} = {float(values[p]):g}" for p in sorted(used, key=str))
            noun = "parameters" if len(used) > 1 else "parameter"
            raise SymdynError(f"{prefix}{noun} {given}: {e}") from None


_DIVISION = "division by zero"


def _check_finite(link, mapping: Mapping[sp.Symbol, sp.Expr], index: int) -> None:
    """Refuse a field of the link that the values make infinite (x/y with y = 0 is SymPy's zoo)."""
    for field, value in _fields(link).items():
        v = sp.sympify(value)
        if v.free_symbols & set(mapping) and v.xreplace(mapping).has(sp.zoo, sp.oo, -sp.oo, sp.nan):
            written = value if not isinstance(value, sp.MatrixBase) else list(value)
            raise SymdynError(
                f"{_DIVISION}: the values make {field} = {written} infinite",
                field=field,
                link_index=index,
                link_name=link.name,
            )


def _plain(x: sp.Expr):
    """A number as a Python float (so that messages print -1.0, not 17 digits); else unchanged."""
    return float(x) if not x.free_symbols and x.is_real else x


def _closure(symbols: set, depends: Mapping[sp.Symbol, set]) -> set:
    """`symbols` and every parameter a valued one among them is written with, transitively."""
    out, todo = set(), list(symbols)
    while todo:
        s = todo.pop()
        if s not in out:
            out.add(s)
            todo.extend(depends.get(s, ()))
    return out


def _fields(link) -> dict[str, object]:
    """The link's numbers by field: its physical ones (mass, inertia, friction, motor), then its
    centre of mass and its placement in the parent (the DH or URDF geometry, as a transform)."""
    return {
        "mass": link.mass,
        "inertia": link.inertia,
        "friction.viscous": link.friction.viscous,
        **coulomb_fields(link.friction.coulomb, link.friction.coulomb_minus),
        "motor.inertia": link.motor.inertia,
        "motor.gear_ratio": link.motor.gear_ratio,
        "com": link.com,
        "placement": sp.Matrix.hstack(link.placement.R, link.placement.p),
    }


def _symbols(link, field: str | None = None) -> set:
    """The free symbols of the link's numbers (`_fields`), or of the one `field` (as
    SymdynError.field names it) when given and known."""
    fields = _fields(link)
    values = [fields[field]] if field in fields else list(fields.values())
    out: set = set()
    for value in values:
        out |= sp.sympify(value).free_symbols
    return out
