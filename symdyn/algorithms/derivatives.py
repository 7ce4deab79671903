"""Derivatives of the equations of motion, written into a straight-line program.

Inverse dynamics tau = ID(q, qd, qdd) (slide 16, tau = M qdd + V + G + F) is a program of
named intermediates (symdyn.algorithms.newton_euler). Its Jacobians dtau/dq and dtau/dqd
are obtained here by forward-mode differentiation of that program
(`symdyn.symbolic.program.Program.diff`), one independent coordinate at a time:

    dt_k/dx = sum_j (d expr_k / d t_j) dt_j/dx,

where an intermediate whose derivative is an exact zero is never named. This is where the
structure of the recursion pays: joint j's position moves only the links of its subtree
(outward pass) and the wrenches they transmit towards the base (inward pass), so the
derivative by q_j touches only those intermediates, and dtau_i/dq_j is an exact zero when
links i and j are on different branches of a tree. The Coulomb term coulomb sign(qd) is
piecewise constant: its derivative is taken as zero (exact everywhere except at qd = 0,
where it does not exist); the viscous term viscous qd is differentiated as it is. With
mimic joints the program runs on the bodies at q_b = multiplier q + offset, so the chain
rule through q_b gives the derivatives by the n independent coordinates.

Forward dynamics qdd = FD(q, qd, tau) = M^-1 (tau - V - G - F) has, by differentiating
M(q) qdd + bias(q, qd) = tau at fixed tau,

    dqdd/dx = -M^-1 dtau/dx |_(qdd = FD(q, qd, tau)),   dqdd/dtau = M^-1   (x = q or qd)

(Carpentier and Mansard, "Analytical derivatives of rigid body dynamics algorithms",
RSS 2018, sec. IV-C). M^-1 comes from the unrolled factorisation M = L D L^T (unit lower
L, diagonal D, no square roots): with X = L^-1,

    X_jj = 1,  X_ij = -(L_ij + sum_{j<k<i} L_ik X_kj),   M^-1 = X^T D^-1 X,

computed in the elimination order forward dynamics uses (symdyn.codegen.functions: last
to first on a tree, so that L and X keep the zeros of joints on different branches).
"""

from __future__ import annotations

from collections.abc import Sequence

import sympy as sp

from ..symbolic.program import Program

__all__ = [
    "jacobian",
    "effort_jacobians",
    "floating_effort_jacobians",
    "substitute",
    "ldlt_factor",
    "ldlt_inverse",
    "matmul",
    "elimination_order",
]


def jacobian(
    program: Program, outputs: Sequence[sp.Expr], variables: Sequence[sp.Symbol], hint: str
) -> sp.Matrix:
    """d outputs / d variables by forward mode over `program` (module docstring).

    Args:
        program: the program the outputs are written in; receives the derivative intermediates.
        outputs: m expressions over the program's intermediates and inputs.
        variables: k input symbols.
        hint: name hint of the derivative intermediates.

    Returns:
        The m x k Jacobian, entry (i, j) = d outputs_i / d variables_j; exact zeros where an
        output does not depend on a variable.
    """
    columns = [program.diff(list(outputs), x, f"{hint}{j + 1}_") for j, x in enumerate(variables)]
    return sp.Matrix(len(outputs), len(variables), lambda i, j: columns[j][i])


def effort_jacobians(
    program: Program,
    tau: Sequence[sp.Expr],
    C: sp.Matrix,
    F: Sequence[sp.Expr],
    q: Sequence[sp.Symbol],
    qd: Sequence[sp.Symbol],
) -> tuple[sp.Matrix, sp.Matrix]:
    """dtau/dq and dtau/dqd of tau = M(q) qdd + V(q, qd) + G(q) + F(qd) (slide 16), joint space.

    dtau/dq by forward mode (`jacobian`). dtau/dqd needs no differentiation: V is quadratic in
    qd, V_k = sum_ij Gamma^k_ij qd_i qd_j with Christoffel symbols symmetric in i, j, so
    dV_k/dqd_m = 2 sum_j Gamma^k_mj qd_j = 2 C_km, and

        dtau/dqd = 2 C(q, qd) + dF/dqd,

    with C the Christoffel-symbol matrix the derivation already has (symdyn.dynamics) and
    dF/dqd the viscous coefficients (projected onto the coordinates with mimic joints; the
    Coulomb sign contributes zero).

    Args:
        program: the program tau, C and F are written in; receives the derivative intermediates.
        tau, F: n entries each; C: n x n.
        q, qd: the n coordinate and rate symbols.

    Returns:
        (dtau/dq, dtau/dqd), n x n each, entry (i, j) = d tau_i / d x_j.
    """
    n = len(tau)
    dq = jacobian(program, tau, q, "Dq")
    dF = jacobian(program, F, qd, "DF")
    dqd = sp.Matrix(n, n, lambda i, j: program.let(2 * C[i, j] + dF[i, j], "Dv"))
    return dq, dqd


def floating_effort_jacobians(
    program: Program, tau: Sequence[sp.Expr], q: Sequence[sp.Symbol], qd: Sequence[sp.Symbol]
) -> tuple[sp.Matrix, sp.Matrix]:
    """dtau/dq (in the tangent space) and dtau/dqd of a floating robot, NV x NV each.

    Column j of dtau/dq is d/de tau(q + e delta_j) at e = 0 with + the free flyer's integration
    (Pinocchio's `integrate`, the `computeRNEADerivatives` convention): the base's translations
    (columns 0-2) do not change tau; a rotation about the base's axis k (columns 3-5) moves the
    quaternion p = (u, w) as p (x) (e_k / 2, 0), that is dp/de = ((w e_k + u x e_k) / 2, -u_k / 2),
    so the column is (dtau/dp) dp/de (forward mode over the quaternion's four inputs: tau reads
    the orientation through R^T g only); the joints' columns as on a fixed base. dtau/dqd by
    forward mode over the NV rates (the base's velocity terms are not Christoffel-symmetric in
    the base twist, so the fixed base's 2 C shortcut is not used); tau includes friction, whose
    Coulomb term contributes zero.
    """
    nv, m = len(qd), len(tau)  # m = nv for tau; any outputs of the configuration work the same way
    dquat = jacobian(program, tau, q[3:7], "Dr")
    ux, uy, uz, w = q[3:7]
    # dp/de_k for k = x, y, z: ((w e_k + u x e_k) / 2, -u_k / 2)
    P = sp.Matrix([[w, -uz, uy], [uz, w, -ux], [-uy, ux, w], [-ux, -uy, -uz]]) / 2
    rotation = sp.Matrix(m, 3, lambda i, k: program.let(sum(dquat[i, j] * P[j, k] for j in range(4)), "Dr"))
    dq = sp.zeros(m, 3).row_join(rotation).row_join(jacobian(program, tau, q[7:], "Dq"))
    dv = jacobian(program, tau, qd, "Dv")
    return dq, sp.Matrix(m, nv, lambda i, j: program.let(dv[i, j], "Dv"))


def substitute(program: Program, outputs: Sequence[sp.Expr], values: dict, hint: str) -> list[sp.Expr]:
    """The outputs with input symbols replaced by `values` (expressions of the same program):
    every intermediate they need that depends on a replaced symbol is written again with the
    replacement, the others are shared.

    Returns:
        The outputs over the new intermediates (same order).
    """
    renamed = dict(values)
    for sym, expr in program.needed(list(outputs) + list(values.values())):
        if any(s in renamed for s in expr.free_symbols):
            renamed[sym] = program.let(expr.xreplace(renamed), hint)
    return [sp.sympify(e).xreplace(renamed) for e in outputs]


def elimination_order(n: int, is_chain: bool) -> list[int]:
    """The order the factorisation eliminates the coordinates in: first to last on a chain,
    last to first on a tree (no fill-in, Featherstone (2008), ch. 6)."""
    return list(range(n)) if is_chain else list(reversed(range(n)))


def ldlt_factor(M: sp.Matrix, program: Program, hint: str = "iv") -> tuple[sp.Matrix, list[sp.Expr]]:
    """M = L D L^T, unrolled (unit lower L, diagonal D), exact zeros of L kept.

    D_j = M_jj - sum_{k<j} L_jk^2 D_k,  L_ij = (M_ij - sum_{k<j} L_ik L_jk D_k) / D_j.

    Returns:
        (L, D): L n x n with ones on the diagonal, D the n pivots (named intermediates).
    """
    n = M.rows
    L = sp.eye(n)
    D: list[sp.Expr] = [sp.S.Zero] * n
    for j in range(n):
        d = M[j, j] - sum((L[j, k] ** 2 * D[k] for k in range(j)), sp.S.Zero)
        D[j] = program.let(d, f"{hint}D")
        for i in range(j + 1, n):
            s = M[i, j] - sum((L[i, k] * L[j, k] * D[k] for k in range(j)), sp.S.Zero)
            L[i, j] = program.let(s / D[j], f"{hint}L") if s != 0 else sp.S.Zero
    return L, D


def ldlt_inverse(M: sp.Matrix, order: Sequence[int], program: Program, hint: str = "iv") -> sp.Matrix:
    """M^-1 of a symmetric positive definite M = X^T D^-1 X with X = L^-1 (module docstring),
    factorised in `order` (elimination_order); both triangles filled, entries named."""
    n = M.rows
    order = list(order)
    L, D = ldlt_factor(M.extract(order, order), program, hint)
    X = sp.eye(n)
    for j in range(n):
        for i in range(j + 1, n):
            s = L[i, j] + sum((L[i, k] * X[k, j] for k in range(j + 1, i)), sp.S.Zero)
            X[i, j] = program.let(-s, f"{hint}X") if s != 0 else sp.S.Zero
    Dinv = [program.let(1 / d, f"{hint}d") for d in D]
    Y = sp.Matrix(n, n, lambda k, a: program.let(X[k, a] * Dinv[k], f"{hint}Y") if X[k, a] != 0 else 0)
    inv = sp.zeros(n, n)
    for a in range(n):
        for b in range(a, n):
            s = sum((Y[k, a] * X[k, b] for k in range(b, n)), sp.S.Zero)
            inv[order[a], order[b]] = inv[order[b], order[a]] = program.let(s, f"{hint}M")
    return inv


def matmul(A: sp.Matrix, B: sp.Matrix, program: Program, hint: str) -> sp.Matrix:
    """A B entry by entry, skipping exact zeros of A and B; nonzero entries named."""
    out = sp.zeros(A.rows, B.cols)
    for i in range(A.rows):
        for j in range(B.cols):
            terms = [A[i, k] * B[k, j] for k in range(A.cols) if A[i, k] != 0 and B[k, j] != 0]
            out[i, j] = program.let(sp.Add(*terms), hint) if terms else sp.S.Zero
    return out
