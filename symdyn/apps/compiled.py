"""The derived dynamics as compiled NumPy functions, bound to numbers for the robot's parameters.

The robot is derived once and its generated NumPy module (`symdyn.codegen`, target
"python") rendered in memory and loaded, so every evaluation of M(q), V(q, qd) =
C(q, qd) qd, G(q), F(qd), the inverse dynamics tau = M qdd + V + G + F and the
forward dynamics qdd = M^-1 (tau - V - G - F) is straight-line NumPy, never SymPy.
Joint quantities are in joint space (rad or m); the robot's base frame fixes gravity.
"""

from __future__ import annotations

import types
from collections.abc import Mapping
from dataclasses import replace
from functools import lru_cache

import numpy as np
import sympy as sp

from ..errors import SymdynError
from ..model.robot import Robot

__all__ = ["CompiledDynamics", "compiled_dynamics", "with_parameters"]


@lru_cache(maxsize=32)
def _generated_module(robot: Robot) -> types.ModuleType:
    """The NumPy module symdyn generates for `robot`, rendered in memory and loaded."""
    from ..codegen import render

    files = render(robot, targets=("python",))
    ((name, text),) = ((k, v) for k, v in files.items() if k.endswith("_numpy.py"))
    module = types.ModuleType(name[:-3])
    module.__file__ = f"<symdyn generated {name}>"
    # the text is symdyn's own output for a parsed robot, not user-supplied code
    exec(compile(text, module.__file__, "exec"), module.__dict__)
    return module


def with_parameters(robot: Robot, values: Mapping[str, float] | None) -> Robot:
    """`robot` with the named parameters set to numbers (free ones or ones the file gave a value).

    The result has those parameters as values (no longer free). A value the file
    wrote as an expression of another parameter keeps the number it had.
    """
    if not values:
        return robot
    known = {str(s): s for s in (*robot.params, *(s for s, _ in robot.values))}
    unknown = [k for k in values if str(k) not in known]
    if unknown:
        names = ", ".join(sorted(known)) or "none"
        raise SymdynError(f"unknown parameter(s) {', '.join(map(str, unknown))} (robot parameters: {names})")
    numbers = {known[str(k)]: sp.Float(float(v), 17) for k, v in values.items()}
    old = {s: sp.sympify(v).xreplace(numbers) for s, v in robot.values}
    old.update(numbers)
    return replace(
        robot,
        params=tuple(p for p in robot.params if p not in numbers),
        values=tuple(old.items()),
    )


class CompiledDynamics:
    """The generated NumPy functions of a robot, bound to values of its free parameters.

    Every method accepts one state (n,) or a batch (B, n), like the generated module.
    """

    def __init__(self, robot: Robot, params=None) -> None:
        self.robot = robot
        self.module = _generated_module(robot)
        values = robot.param_values(params) if robot.params else {}
        by_name = {str(k): v for k, v in values.items()}
        names = self.module.PARAM_NAMES
        self.p = np.array([by_name[n] for n in names], dtype=float) if names else None

    @property
    def n(self) -> int:
        return self.robot.n

    def mass_matrix(self, q) -> np.ndarray:
        return self.module.mass_matrix(q, self.p)

    def coriolis(self, q, qd) -> np.ndarray:
        """V(q, qd) = C(q, qd) qd."""
        return self.module.coriolis(q, qd, self.p)

    def gravity(self, q) -> np.ndarray:
        return self.module.gravity(q, self.p)

    def friction(self, qd) -> np.ndarray:
        return self.module.friction(qd, self.p)

    def inverse_dynamics(self, q, qd, qdd) -> np.ndarray:
        return self.module.inverse_dynamics(q, qd, qdd, self.p)

    def forward_dynamics(self, q, qd, tau) -> np.ndarray:
        return self.module.forward_dynamics(q, qd, tau, self.p)


def compiled_dynamics(robot: Robot | CompiledDynamics, params=None) -> CompiledDynamics:
    """A CompiledDynamics for a Robot (or the given one unchanged when params is None)."""
    if isinstance(robot, CompiledDynamics):
        if params is not None:
            return CompiledDynamics(robot.robot, params)
        return robot
    if not isinstance(robot, Robot):
        raise SymdynError(f"expected a Robot, not {type(robot).__name__}")
    return CompiledDynamics(robot, params)
