"""Joint symbols q1..qn, qd1..qdn, qdd1..qddn (1-based names, as printed and as accepted in files)."""

from __future__ import annotations

import sympy as sp

__all__ = ["joint_symbols"]


def joint_symbols(n: int) -> tuple[sp.Matrix, sp.Matrix, sp.Matrix]:
    """The column vectors (q, qd, qdd) of plain SymPy symbols for an n-joint robot."""
    q = sp.Matrix([sp.Symbol(f"q{i}") for i in range(1, n + 1)])
    qd = sp.Matrix([sp.Symbol(f"qd{i}") for i in range(1, n + 1)])
    qdd = sp.Matrix([sp.Symbol(f"qdd{i}") for i in range(1, n + 1)])
    return q, qd, qdd
