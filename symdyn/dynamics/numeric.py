"""Numeric evaluation of a derivation: its quantities at one state, lambdified once each.

`Dynamics.evaluate` (symdyn.dynamics.joint_space) comes from `NumericEvaluation`: the compact
form over named intermediates (symdyn.symbolic.program) becomes one NumPy function per quantity,
its common subexpressions being the program's own steps. `state_vector` checks a state given as
numbers (a floating robot's q of NQ = 7 + n entries, qd and qdd of NV = 6 + n).
"""

from __future__ import annotations

import numpy as np
import sympy as sp
from sympy.printing.numpy import NumPyPrinter

from ..errors import SymdynError
from .quantities import check_quantity

__all__ = ["NumericEvaluation", "program_function", "state_vector"]

#: where a derivation keeps its `_StepPrinter` (in its cache `_compiled`, beside the functions)
_PRINTER_KEY = ("printer",)


class _StepPrinter(NumPyPrinter):
    """The printer sympy.lambdify uses for modules="numpy", with two savings.

    Sums and products are printed in the order they were built (order="none"): SymPy's default
    sorts the terms of every sum and the factors of every product first, half the time of a
    lambdify (the order does not change a value beyond rounding). And each expression is printed
    once per derivation: the intermediates of the program are shared by M, C, V, tau, bias, the
    frames and their Jacobians, which lambdify would otherwise print again for each function.
    """

    def __init__(self) -> None:
        super().__init__(
            {
                "fully_qualified_modules": False,
                "inline": True,
                "allow_unknown_functions": True,
                "user_functions": {},
                "order": "none",
            }
        )
        self._printed: dict[sp.Basic, str] = {}

    def doprint(self, expr, assign_to=None):
        if assign_to is not None or not isinstance(expr, sp.Basic):
            return super().doprint(expr, assign_to)
        text = self._printed.get(expr)
        if text is None:
            text = self._printed[expr] = super().doprint(expr)
        return text


def program_function(cache: dict, args: list, m, steps: list):
    """sympy.lambdify(args, m) over the program's `steps` (its common subexpressions), printed by
    the derivation's `_StepPrinter` (kept in its function cache `cache`)."""
    printer = cache.get(_PRINTER_KEY)
    if printer is None:
        printer = cache[_PRINTER_KEY] = _StepPrinter()
    return sp.lambdify(args, sp.Matrix(m), modules="numpy", cse=lambda exprs: (steps, exprs), printer=printer)


class NumericEvaluation:
    """The numeric methods of `Dynamics` (a mix-in: it reads the derivation's fields robot, q,
    qd, qdd, params, program, compact and the cache _compiled)."""

    def _numeric(self, name: str):
        """NumPy function of quantity `name` over the eliminated form, compiled on first use."""
        f = self._compiled.get(name)
        if f is None:
            m = self.compact[name]
            steps = self.program.needed(list(m))
            args = [list(self.q), list(self.qd), list(self.qdd), list(self.params)]
            f = self._compiled[name] = program_function(self._compiled, args, m, steps)
        return f

    def evaluate(self, name: str, q=None, qd=None, qdd=None, params=None) -> np.ndarray:
        """Numeric value of quantity `name` at one state (missing vectors are zero).

        Args:
            name: one of M, C, V, G, F, tau, bias (ALL_QUANTITIES).
            q, qd, qdd: n numbers each (joint positions, velocities, accelerations) or None.
            params: values of the free parameters `params`: a sequence in that order or a
                name -> number map; None when there are none.

        Returns:
            An (n, n) array for M and C, an (n,) array otherwise (joint space).

        Raises:
            SymdynError: an unknown name, a vector without n numbers, missing, extra or
                unknown parameters.
        """
        where = "Dynamics.evaluate"
        check_quantity(name, where)
        named = ((q, self.q, "q"), (qd, self.qd, "qd"), (qdd, self.qdd, "qdd"))
        if self.robot.floating:
            vec = [state_vector(v, len(s), label, where) for v, s, label in named]
        else:
            vec = [self.robot.joint_values(v, label, where) for v, _, label in named]
        values = self.robot.param_values(params, where)
        p = [values[s] for s in self.params]
        shape = self.compact[name].shape
        out = np.asarray(self._numeric(name)(*vec, p), dtype=float).reshape(shape)
        return out[:, 0] if name not in ("M", "C") else out


def state_vector(values, size: int, name: str, where: str) -> np.ndarray:
    """`size` numbers (None: zeros) as a float array, else a SymdynError naming the vector."""
    if values is None:
        return np.zeros(size)
    try:
        a = np.asarray(values, dtype=float)
    except (TypeError, ValueError):
        raise SymdynError(f"{where}: {name} must hold numbers, got {values!r}") from None
    if a.shape != (size,):
        raise SymdynError(f"{where}: {name} has shape {a.shape}, expected ({size},)")
    return a
