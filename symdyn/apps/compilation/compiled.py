"""The derived dynamics as compiled functions, bound to numbers for the robot's parameters.

`CompiledDynamics` (symdyn.apps.compilation.compile) holds the robot's generated C, compiled and
cached, so every evaluation of M(q), V(q, qd) = C(q, qd) qd, G(q), F(qd), the inverse
dynamics tau = M qdd + V + G + F and the forward dynamics qdd = M^-1 (tau - V - G - F)
is straight-line C (or the generated NumPy module without a C compiler), never SymPy.
Joint quantities are in joint space (rad or m); the robot's base frame fixes gravity.
This module adds `compiled_dynamics` (a Robot or a CompiledDynamics) and `with_parameters`.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import replace
from typing import TYPE_CHECKING

from ...errors import SymdynError
from .compile import CompiledDynamics

if TYPE_CHECKING:
    from ...model.robot import Robot

__all__ = ["CompiledDynamics", "compiled_dynamics", "with_parameters"]


def with_parameters(robot: Robot, values: Mapping[str, float] | None) -> Robot:
    """`robot` with the named parameters set to numbers (free ones or ones the file gave a value).

    The result has those parameters as values (no longer free). A value the file
    wrote as an expression of another parameter keeps the number it had.
    """
    import sympy as sp

    from ...model.parameter_names import parameter_number
    from ...model.physical import check_values  # here: a warm run from the cache imports no SymPy

    if not values:
        return robot
    known = {str(s): s for s in (*robot.params, *(s for s, _ in robot.values))}
    unknown = [k for k in values if str(k) not in known]
    if unknown:
        names = ", ".join(sorted(known)) or "none"
        raise SymdynError(f"unknown parameter(s) {', '.join(map(str, unknown))} (robot parameters: {names})")
    numbers = {}
    for k, v in values.items():
        numbers[known[str(k)]] = sp.Float(parameter_number(str(k), v), 17)
    # the values pass the robot file's physical checks (mass >= 0, a possible inertia tensor, ...)
    check_values(robot, numbers)
    old = {s: sp.sympify(v).xreplace(numbers) for s, v in robot.values}
    old.update(numbers)
    return replace(
        robot,
        params=tuple(p for p in robot.params if p not in numbers),
        values=tuple(old.items()),
    )


def compiled_dynamics(robot: Robot | CompiledDynamics, params=None) -> CompiledDynamics:
    """A CompiledDynamics for a Robot (or the given one unchanged when params is None)."""
    if isinstance(robot, CompiledDynamics):
        if params is None:
            return robot
        robot = robot.robot
    from ...model.robot import Robot

    if not isinstance(robot, Robot):
        raise SymdynError(f"expected a Robot, not {type(robot).__name__}")
    return CompiledDynamics(robot, params)
