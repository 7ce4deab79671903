"""The derivative functions (docs/generated-code.md), as target-independent function rows.

    inverse_dynamics_derivatives(q, qd, qdd, p, dtau_dq, dtau_dqd)
    forward_dynamics_derivatives(q, qd, tau, p, dqdd_dq, dqdd_dqd, Minv)
    mass_matrix_inverse(q, p, Minv)
    linearize(q, qd, tau, p, A, B)

Every matrix is row-major, entry [i*cols + j] = d out_i / d in_j. linearize gives the
continuous-time linearisation of the state equation xd = f(x, tau) = (qd, FD(q, qd, tau))
about x = (q, qd) and tau:

    A = df/dx = [[0, I], [dqdd/dq, dqdd/dqd]]  (2n x 2n),   B = df/dtau = [[0], [M^-1]]  (2n x n).

The derivatives are those of symdyn.algorithms.derivatives: dtau/dq by forward mode over the
program of Newton-Euler intermediates, dtau/dqd = 2 C + dF/dqd, M^-1 by the unrolled
L D L^T factorisation (eliminated in the order forward_dynamics uses), and
dqdd/dx = -M^-1 dtau/dx with dtau/dx evaluated at qdd = FD(q, qd, tau) = M^-1 (tau - bias).
The Coulomb friction sign(qd) contributes zero (its derivative almost everywhere).

The three functions that invert M are left out, like forward_dynamics, when M is singular
by construction (Dynamics.singular_joints; symdyn.codegen.functions.build_functions warns).

A floating robot (q of NQ entries, the rest NV; docs/floating-base.md) gets all four, with
dtau/dq and dqdd/dq in the tangent space (symdyn.algorithms.derivatives.floating_effort_jacobians:
Pinocchio's computeRNEADerivatives / computeABADerivatives convention) and dtau/dqd by forward
mode; M^-1 eliminates the joints before the base. Its linearize works on the tangent space of
the state x = (q, v): the deviation of a state x from a reference solution xr(t) is
dx = (difference(qr, q), v - vr) (2 NV entries; Pinocchio's `difference`, q = qr (+) dq), and

    d(dx)/dt = A dx + B dtau,   A = [[-ad(v_b), I], [dqdd/dq, dqdd/dqd]],  B = [[0], [M^-1]],

A 2NV x 2NV, B 2NV x NV. The block -ad(v_b) sits on the base's six rows and columns only: the
local error dq of the base pose, q = qr exp(dq), turns with the base twist v_b = (nu, omega)
(base frame), d(dq)/dt = dv - ad(v_b) dq with ad(nu, omega) = [[omega x, nu x], [0, omega x]]
(Sola, Deray and Atchuthan, A micro Lie theory for state estimation in robotics (2018), the
error dynamics of X = Xr Exp(dx)); the joints' block is zero as on a fixed base. B's first six
columns are the base wrench (unactuated: zero without contacts), the others the joint efforts.
"""

from __future__ import annotations

from collections.abc import Sequence

import sympy as sp

from ..algorithms.derivatives import (
    effort_jacobians,
    elimination_order,
    floating_effort_jacobians,
    ldlt_inverse,
    matmul,
    substitute,
)
from ..algorithms.floating_frames import skew
from ..dynamics import Dynamics
from .function_rows import FunctionRow, Inputs, Output, joint_matrix_output

__all__ = ["derivative_rows", "DERIVATIVE_FUNCTION_NAMES"]

DERIVATIVE_FUNCTION_NAMES = (
    "inverse_dynamics_derivatives",
    "forward_dynamics_derivatives",
    "mass_matrix_inverse",
    "linearize",
)


def _entries(*matrices: sp.Matrix) -> tuple[sp.Expr, ...]:
    """The matrices' entries, each row-major, one matrix after the other."""
    return tuple(m[i, j] for m in matrices for i in range(m.rows) for j in range(m.cols))


def state_matrices(dq: sp.Matrix, dqd: sp.Matrix, Minv: sp.Matrix) -> tuple[sp.Matrix, sp.Matrix]:
    """A = [[0, I], [dq, dqd]] and B = [[0], [Minv]] of linearize (module docstring)."""
    n = Minv.rows
    A = sp.zeros(2 * n, 2 * n)
    A[:n, n:] = sp.eye(n)
    A[n:, :n] = dq
    A[n:, n:] = dqd
    B = sp.zeros(2 * n, n)
    B[n:, :] = Minv
    return A, B


def floating_state_matrices(
    dq: sp.Matrix, dqd: sp.Matrix, Minv: sp.Matrix, v_base: Sequence[sp.Symbol]
) -> tuple[sp.Matrix, sp.Matrix]:
    """A = [[-ad(v_b), I], [dq, dqd]] and B = [[0], [Minv]] of a floating robot's linearize on
    the tangent space (module docstring): -ad(v_b) = -[[omega x, nu x], [0, omega x]] on the base's
    six rows and columns, v_b = (nu, omega) the base twist in the base frame."""
    A, B = state_matrices(dq, dqd, Minv)
    nu, omega = sp.Matrix(v_base[:3]), sp.Matrix(v_base[3:6])
    A[:3, :3] = A[3:6, 3:6] = -skew(omega)
    A[:3, 3:6] = -skew(nu)
    return A, B


def derivative_rows(dyn: Dynamics, x: Inputs) -> list[FunctionRow]:
    """The four derivative functions of a derived robot (module docstring); only
    inverse_dynamics_derivatives when M is singular by construction.

    The intermediates are written into a copy of `dyn.program` (the derivation is not changed)
    and passed on as the rows' steps.
    """
    n = dyn.n
    c = dyn.compact
    prog = dyn.program.copy("d")
    first = len(prog.assignments)
    floating = dyn.robot.floating
    if floating:  # dtau/dq in the tangent space (NV columns)
        dq, dqd = floating_effort_jacobians(prog, list(c["tau"]), list(dyn.q), list(dyn.qd))
    else:
        dq, dqd = effort_jacobians(prog, list(c["tau"]), c["C"], list(c["F"]), list(dyn.q), list(dyn.qd))
    rows = [
        (
            "inverse_dynamics_derivatives",
            "dtau/dq and dtau/dqd of tau = M(q) qdd + V(q, qd) + G(q) + F(qd)",
            (x.q, x.qd, x.qdd, x.p),
            (
                joint_matrix_output("dtau_dq", n, "dtau_i/dq_j"),
                joint_matrix_output("dtau_dqd", n, "dtau_i/dqd_j"),
            ),
            _entries(dq, dqd),
        ),
    ]
    if not dyn.singular_joints:
        order = elimination_order(n, dyn.robot.is_chain and not floating)  # the base last when floating
        Minv = ldlt_inverse(sp.Matrix(c["M"]), order, prog, "Di")
        # qdd = FD(q, qd, tau) = M^-1 (tau - bias) with the same M^-1, then dtau/dx at that qdd
        b = sp.Matrix([prog.let(x.tau.symbols[i] - c["bias"][i], "Db") for i in range(n)])
        qdd = matmul(Minv, b, prog, "Dqdd")
        at_fd = substitute(prog, _entries(dq), dict(zip(dyn.qdd, qdd, strict=True)), "Dfd")
        ddq = matmul(-Minv, sp.Matrix(n, n, at_fd), prog, "Ddq")
        ddqd = matmul(-Minv, dqd, prog, "Ddv")  # dtau/dqd does not depend on qdd
        if floating:  # on the tangent space: the base's error turns with its twist
            A, B = floating_state_matrices(ddq, ddqd, Minv, list(dyn.qd)[:6])
        else:
            A, B = state_matrices(ddq, ddqd, Minv)
        inv_doc = "M(q)^-1 = dqdd/dtau"
        rows += [
            (
                "forward_dynamics_derivatives",
                "dqdd/dq and dqdd/dqd of qdd = FD(q, qd, tau) = M(q)^-1 (tau - V - G - F), and M(q)^-1",
                (x.q, x.qd, x.tau, x.p),
                (
                    joint_matrix_output("dqdd_dq", n, "dqdd_i/dq_j"),
                    joint_matrix_output("dqdd_dqd", n, "dqdd_i/dqd_j"),
                    joint_matrix_output("Minv", n, inv_doc),
                ),
                _entries(ddq, ddqd, Minv),
            ),
            (
                "mass_matrix_inverse",
                "M(q)^-1 by the unrolled L D L^T factorisation",
                (x.q, x.p),
                (joint_matrix_output("Minv", n, inv_doc),),
                _entries(Minv),
            ),
        ]
        linear = (
            "A = [[-ad(v_b), I], [dqdd/dq, dqdd/dqd]] on the tangent space"
            if floating
            else ("A = [[0, I], [dqdd/dq, dqdd/dqd]]")
        )
        rows.append(
            (
                "linearize",
                f"xd = f(x, tau) linearised at x = (q, qd): {linear}, B = [0; M^-1]",
                (x.q, x.qd, x.tau, x.p),
                (
                    Output("A", 2 * n, 2 * n, "df/dx", ("2n", "2n")),
                    Output("B", 2 * n, n, "df/dtau", ("2n", "n")),
                ),
                _entries(A, B),
            )
        )
    # build_functions gathers every row's steps into one program: the first row carries them all
    steps = [tuple(prog.assignments[first:])] + [()] * (len(rows) - 1)
    return [FunctionRow(*row, s, cse="derivatives") for row, s in zip(rows, steps, strict=True)]
