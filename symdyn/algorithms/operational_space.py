"""Operational-space quantities of a frame, symbolic, over named intermediates.

With J the frame's Jacobian (k chosen rows of the world-aligned 6 x n Jacobian), M the mass
matrix, h = V + G + F the joint-space bias and Jdot qd the frame's drift (same rows)
(Khatib, "A unified approach for motion and force control of robot manipulators: the
operational space formulation", IEEE J. Robotics and Automation 3(1), 1987):

    Lambda = (J M^-1 J^T)^-1                      (k x k, the operational-space inertia)
    mu + p = Lambda (J M^-1 h - Jdot qd)          (k x 1, the operational-space bias)
    Jbar   = M^-1 J^T Lambda                      (n x k, the dynamically consistent inverse)

so that Lambda xdd + mu + p = F_task for tau = J^T F_task. Both inverses come from unrolled
L D L^T factorisations without square roots (symdyn.algorithms.derivatives.ldlt_inverse): M^-1
in forward dynamics' elimination order, (J M^-1 J^T)^-1 in row order. Where J M^-1 J^T is
singular (J loses rank: a kinematic singularity, or rows the joints cannot move), a pivot of
that factorisation is zero and the entries are not finite: avoiding such configurations is the
caller's job.
"""

from __future__ import annotations

from typing import NamedTuple

import sympy as sp

from ..errors import SymdynError
from ..symbolic.program import Program
from .derivatives import elimination_order, ldlt_inverse, matmul

__all__ = ["TASK_AXES", "OperationalSpace", "operational_space", "task_rows"]

#: the rows of a world-aligned frame Jacobian: linear x, y, z, then angular rx, ry, rz
TASK_AXES = ("x", "y", "z", "rx", "ry", "rz")


def task_rows(axes, where: str) -> tuple[int, ...]:
    """The Jacobian rows of task axes "x,z,rz" or a sequence of names (None: all six).

    Raises:
        SymdynError: an unknown, repeated or missing axis.
    """
    if axes is None:
        return tuple(range(6))
    names = [a.strip() for a in axes.split(",")] if isinstance(axes, str) else [str(a).strip() for a in axes]
    names = [a for a in names if a]
    bad = [a for a in names if a not in TASK_AXES]
    if bad or not names or len(set(names)) != len(names):
        what = f"unknown axis {', '.join(bad)}" if bad else "no axis given" if not names else "repeated axis"
        raise SymdynError(f"{where}: {what} in axes {axes!r} (any of {', '.join(TASK_AXES)})")
    return tuple(TASK_AXES.index(a) for a in names)


class OperationalSpace(NamedTuple):
    """Lambda (k x k), mu + p (k x 1) and Jbar (n x k), over a program's intermediates."""

    inertia: sp.Matrix
    bias: sp.Matrix
    inverse: sp.Matrix


def operational_space(
    M: sp.Matrix, J: sp.Matrix, h: sp.Matrix, drift: sp.Matrix, is_chain: bool, program: Program
) -> OperationalSpace:
    """Lambda, mu + p and Jbar (module docstring).

    Args:
        M: n x n mass matrix; J: k x n task Jacobian; h: n x 1 bias V + G + F; drift: k x 1 Jdot qd.
        is_chain: the robot is a serial chain (M^-1's elimination order, as forward dynamics).
        program: receives the named intermediates.
    """
    Minv = ldlt_inverse(M, elimination_order(M.rows, is_chain), program, "oi")
    JMinv = matmul(J, Minv, program, "oJ")  # k x n
    k = J.rows
    A = sp.zeros(k, k)
    for a in range(k):
        for b in range(a, k):
            terms = [JMinv[a, j] * J[b, j] for j in range(J.cols) if JMinv[a, j] != 0 and J[b, j] != 0]
            A[a, b] = A[b, a] = program.let(sp.Add(*terms), "oA")
    Lam = ldlt_inverse(A, range(k), program, "oL")
    e = sp.Matrix([program.let(x, "oe") for x in JMinv * h - drift])
    bias = matmul(Lam, e, program, "ob")
    Jbar = matmul(JMinv.T, Lam, program, "oB")
    return OperationalSpace(Lam, bias, Jbar)
