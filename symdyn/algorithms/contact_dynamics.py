"""Constrained (contact) and impulse dynamics, and their derivatives, as straight-line programs.

With M the NV x NV mass matrix, b = V + G + F the bias, Jc (NLAMBDA x NV) and gamma the
contact Jacobian and drift (symdyn.algorithms.contacts), the constrained forward dynamics solve
the KKT system (Pinocchio's constraintDynamics; lambda the force on the robot):

    M qdd + b = tau + Jc^T lambda,    Jc qdd + gamma = 0.

No branch: with a_r in {0, 1} the activity of row r's contact (the run-time mask) and A0 =
Jc M^-1 Jc^T the Delassus matrix, the solve is

    A lambda = -a * (gamma + Jc M^-1 (tau - b)),  A_rs = a_r a_s A0_rs + (1 - a_r + mu) delta_rs,
    qdd = M^-1 (tau - b + Jc^T lambda),

so an inactive row decouples (A's row and column are those of (1 + mu) I, its right-hand side 0)
and its lambda is exactly 0. mu = DAMPING (1e-10) regularises a redundant or singular set of
active rows (more rows than the robot can satisfy independently: two point contacts on one
frame, a point and a 6d contact there): the solve is then the damped (proximal) one, finite,
with lambda of the minimum-norm kind; on a regular set it changes lambda by about mu |A0^-1|
relative. Both solves use M's unrolled L D L^T factorisation M = P^T L D L^T P (P the
elimination order of forward dynamics, symdyn.algorithms.derivatives.elimination_order):
W = L^-1 P Jc^T, A0 = W^T D^-1 W, Jc M^-1 x = W^T D^-1 L^-1 P x, M^-1 (x + Jc^T lambda) =
P^T L^-T D^-1 (L^-1 P x + W lambda); A by the same unrolled L D L^T.

Impulse dynamics (Pinocchio's impulseDynamics, restitution e):

    M (qd_plus - qd) = Jc^T impulse,   Jc qd_plus = -e Jc qd  (active rows),
    A impulse = -(1 + e) a * (Jc qd),   qd_plus = qd + M^-1 Jc^T impulse.

Derivatives (Carpentier and Mansard, RSS 2018, for the contact case as Pinocchio's
computeConstraintDynamicsDerivatives): differentiating the KKT system at the solution,

    M dqdd - Jc^T dlambda = -r1,   Jc dqdd = -r2,
    r1 = d/dx (ID(q, qd, qdd) - Jc^T lambda),  r2 = d/dx (Jc qdd + gamma)   (qdd, lambda held),

    dlambda = A^-1 a * (Jc M^-1 r1 - r2),   dqdd = M^-1 (Jc^T a * dlambda - r1),

and for tau, r1 = -I, r2 = 0: dqdd/dtau = M^-1 - M^-1 Jc^T A^-1 a* Jc M^-1 is symmetric, and
KKT.tau_sensitivities computes the half its back substitutions reach first. W's rows are kept
scaled as D^-1 W too (KKT.WD), so that each product W^T D^-1 u costs one multiplication a term.
For the impulse, with qd_plus and the impulse held,
r1 = -d/dx (Jc^T impulse) (M's own derivative times qd_plus - qd enters through
d/dx (M (qd_plus - qd)), computed as d/dx ID(q, 0, qd_plus - qd) without gravity: the
inertia part of the RNEA, symdyn.algorithms.floating.inertia_efforts, one recursion to
differentiate instead of M's NV^2 entries), r2 = d/dx (Jc (qd_plus + e qd)). By qd, M and Jc are constant:
r1 = -M, r2 = e Jc, and the sensitivities reduce to dimpulse/dqd = -(1 + e) A^-1 a * Jc,
dqd_plus/dqd = I + M^-1 Jc^T dimpulse/dqd (KKT.jump_sensitivities: no solves of M's dense columns,
a third of Talos' impulse derivatives before). The derivatives by q are taken in
the tangent space on a floating base (symdyn.algorithms.derivatives.floating_effort_jacobians).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import sympy as sp

from ..symbolic.program import Program
from .derivatives import ldlt_factor

__all__ = ["DAMPING", "FactoredMass", "KKT", "masked_delassus"]

#: mu, the damping added to the Delassus matrix's diagonal (module docstring)
DAMPING = sp.Float("1e-10")


def _sum(terms) -> sp.Expr:
    return sp.Add(*[t for t in terms if t != 0])


@dataclass
class FactoredMass:
    """M = P^T L D L^T P, unrolled (module docstring), with the solves that reuse it."""

    L: sp.Matrix
    D: list[sp.Expr]
    Dinv: list[sp.Expr]
    order: list[int]
    program: Program

    @classmethod
    def of(cls, M: sp.Matrix, order: Sequence[int], program: Program, hint: str) -> FactoredMass:
        order = list(order)
        L, D = ldlt_factor(M.extract(order, order), program, hint)
        return cls(L, D, [program.let(1 / d, f"{hint}r") for d in D], order, program)

    def forward(self, x: Sequence[sp.Expr], hint: str) -> list[sp.Expr]:
        """y = L^-1 P x (x in the natural order)."""
        n, L = len(self.order), self.L
        y: list[sp.Expr] = []
        for i in range(n):
            s = x[self.order[i]] - _sum(L[i, k] * y[k] for k in range(i) if L[i, k] != 0 and y[k] != 0)
            y.append(self.program.let(s, hint) if s != 0 else sp.S.Zero)
        return y

    def backward(self, y: Sequence[sp.Expr], hint: str, last: int = 0) -> list[sp.Expr]:
        """P^T L^-T D^-1 y: M^-1 x for y = forward(x), in the natural order. The solve runs from the
        last eliminated coordinate down to position `last` of the order: entry order[i] of the result
        reads only positions above i, so stopping there leaves exactly the positions below `last`
        out (their entries are None)."""
        n, L = len(self.order), self.L
        z: list = [None] * n
        for i in range(n - 1, last - 1, -1):
            s = y[i] * self.Dinv[i] - _sum(L[k, i] * z[k] for k in range(i + 1, n) if L[k, i] != 0)
            z[i] = self.program.let(s, hint) if s != 0 else sp.S.Zero
        out: list[sp.Expr] = [sp.S.Zero] * n
        for i, j in enumerate(self.order):
            out[j] = z[i]
        return out

    def scaled(self, w: Sequence[sp.Expr], hint: str) -> list[sp.Expr]:
        """D^-1 w of a forward() result, nonzero entries named (for `dot` with many vectors)."""
        return [
            self.program.let(a * d, hint) if a != 0 else sp.S.Zero for a, d in zip(w, self.Dinv, strict=True)
        ]


def _dot(u: Sequence[sp.Expr], w: Sequence[sp.Expr]) -> sp.Expr:
    """u^T w over the entries that are not exact zeros."""
    return _sum(a * b for a, b in zip(u, w, strict=True) if a != 0 and b != 0)


def masked_delassus(A0: sp.Matrix, active: Sequence[sp.Expr], program: Program, hint: str) -> sp.Matrix:
    """A_rs = a_r a_s A0_rs + (1 - a_r + mu) delta_rs (module docstring), entries named."""
    m = A0.rows
    A = sp.zeros(m, m)
    for r in range(m):
        for s in range(r, m):
            e = active[r] * active[s] * A0[r, s] if r != s else active[r] * A0[r, r] + 1 - active[r] + DAMPING
            A[r, s] = A[s, r] = program.let(e, hint) if A0[r, s] != 0 or r == s else sp.S.Zero
    return A


def spd_solve(A: sp.Matrix, b: Sequence[sp.Expr], program: Program, hint: str) -> list[sp.Expr]:
    """x solving A x = b by A's unrolled L D L^T (A symmetric positive definite, small and dense)."""
    F = FactoredMass.of(A, range(A.rows), program, hint)
    return F.backward(F.forward(list(b), hint), hint)


@dataclass
class KKT:
    """The masked contact system of one robot state (module docstring), over one Program.

    Args:
        M: the NV x NV mass matrix; Jc: NLAMBDA x NV; active: per row, its contact's activity a_r.
        order: M's elimination order; program: receives the intermediates.
    """

    M: sp.Matrix
    Jc: sp.Matrix
    active: list[sp.Expr]
    order: list[int]
    program: Program

    def __post_init__(self) -> None:
        prog = self.program
        self.mass = FactoredMass.of(self.M, self.order, prog, "kD")
        m = self.Jc.rows
        self.W = [self.mass.forward(list(self.Jc[r, :]), "kW") for r in range(m)]  # L^-1 P Jc_r^T
        self.WD = [self.mass.scaled(w, "kV") for w in self.W]  # D^-1 L^-1 P Jc_r^T
        A0 = sp.zeros(m, m)
        for r in range(m):
            for s in range(r, m):
                A0[r, s] = A0[s, r] = _dot(self.WD[r], self.W[s])
        self.A = masked_delassus(A0, self.active, prog, "kA")
        self.factor = FactoredMass.of(self.A, range(m), prog, "kL")

    def solve_rows(self, rhs: Sequence[sp.Expr], hint: str) -> list[sp.Expr]:
        """x solving A x = a * rhs (an inactive row's x is 0)."""
        b = [
            self.program.let(a * r, hint) if r != 0 else sp.S.Zero
            for a, r in zip(self.active, rhs, strict=True)
        ]
        return self.factor.backward(self.factor.forward(b, hint), hint)

    def forward_dynamics(self, force: Sequence[sp.Expr], gamma: Sequence[sp.Expr]) -> tuple[list, list]:
        """(qdd, lambda) solving M qdd = force + Jc^T lambda, Jc qdd + gamma = 0 (force = tau - b)."""
        u = self.mass.forward(list(force), "ku")
        rhs = [-(g + _dot(w, u)) for g, w in zip(gamma, self.WD, strict=True)]
        lam = self.solve_rows(rhs, "kl")
        return self._accelerate(u, lam, "kq"), lam

    def impulse(self, qd: Sequence[sp.Expr], restitution: sp.Expr) -> tuple[list, list]:
        """(qd_plus, impulse): M (qd_plus - qd) = Jc^T impulse, Jc qd_plus = -e Jc qd."""
        vel = [
            _sum(self.Jc[r, j] * qd[j] for j in range(self.Jc.cols) if self.Jc[r, j] != 0)
            for r in range(self.Jc.rows)
        ]
        rhs = [-(1 + restitution) * self.program.let(v, "kv") for v in vel]
        imp = self.solve_rows(rhs, "ki")
        dv = self._accelerate([sp.S.Zero] * len(self.order), imp, "kp")
        return [self.program.let(q + d, "kp") for q, d in zip(qd, dv, strict=True)], imp

    def _accelerate(self, u: Sequence[sp.Expr], lam: Sequence[sp.Expr], hint: str, last: int = 0) -> list:
        """M^-1 (x + Jc^T lam) for u = L^-1 P x (down to position `last` of the order:
        FactoredMass.backward)."""
        y = [
            _sum([u[i], *(self.W[r][i] * lam[r] for r in range(len(lam)) if self.W[r][i] != 0)])
            for i in range(len(u))
        ]
        return self.mass.backward(y, hint, last)

    def sensitivities(self, r1: sp.Matrix, r2: sp.Matrix, hint: str) -> tuple[sp.Matrix, sp.Matrix]:
        """(dqdd, dlambda) = (M^-1 (Jc^T dlambda - r1), A^-1 a * (Jc M^-1 r1 - r2)) column by column
        (module docstring); r1 NV x k, r2 NLAMBDA x k. Jc^T dlambda needs no mask: an inactive
        row's dlambda is 0."""
        cols_q, cols_l = [], []
        for j in range(r1.cols):
            u = self.mass.forward([-x for x in r1[:, j]], f"{hint}u")  # L^-1 P (-r1)
            rhs = [-(_dot(w, u) + r2[r, j]) for r, w in enumerate(self.WD)]
            dl = self.solve_rows(rhs, f"{hint}l")
            cols_q.append(self._accelerate(u, dl, f"{hint}q"))
            cols_l.append(dl)
        dq = sp.Matrix(r1.rows, r1.cols, lambda i, j: cols_q[j][i])
        dl = sp.Matrix(r2.rows, r1.cols, lambda i, j: cols_l[j][i])
        return dq, dl

    def tau_sensitivities(self, hint: str) -> tuple[sp.Matrix, sp.Matrix]:
        """(dqdd/dtau, dlambda/dtau): `sensitivities` with r1 = -I, r2 = 0, using the symmetry of
        dqdd/dtau = M^-1 - M^-1 Jc^T A^-1 a* Jc M^-1 (the top-left block of the KKT matrix's inverse:
        A^-1 a* = a* A^-1 a* when every a_r is 0 or 1, as A then has no entry between an active and an
        inactive row). Column j's back substitution stops at j's position in M's elimination order,
        so each column computes the entries eliminated at or after j (M^-1's column j reads those
        only) and the rest are mirrored: half the back substitutions' work. dlambda/dtau =
        -A^-1 a* Jc M^-1 column by column, as before."""
        n, m = self.Jc.cols, self.Jc.rows
        position = {j: i for i, j in enumerate(self.order)}
        cols_q, cols_l = [], []
        for j in range(n):
            u = self.mass.forward([sp.S.One if i == j else sp.S.Zero for i in range(n)], f"{hint}u")
            dl = self.solve_rows([-_dot(w, u) for w in self.WD], f"{hint}l")
            cols_q.append(self._accelerate(u, dl, f"{hint}q", position[j]))
            cols_l.append(dl)

        def entry(i: int, j: int) -> sp.Expr:
            return cols_q[j][i] if position[i] >= position[j] else cols_q[i][j]

        return sp.Matrix(n, n, entry), sp.Matrix(m, n, lambda i, j: cols_l[j][i])

    def jump_sensitivities(self, restitution: sp.Expr, hint: str) -> tuple[sp.Matrix, sp.Matrix]:
        """(dqd_plus/dqd, dimpulse/dqd) of `impulse` in closed form (module docstring): M and Jc do
        not depend on qd, so r1 = -M and r2 = e Jc, and `sensitivities` reduces to

            dimpulse/dqd = -(1 + e) A^-1 a * Jc,   dqd_plus/dqd = I + M^-1 Jc^T dimpulse/dqd,

        column by column, without the forward solves of M's dense columns (L^-1 P M = D L^T P) that
        the general form spends; a column of Jc that is zero gives the unit column and no impulse."""
        n, m = self.Jc.cols, self.Jc.rows
        scale = self.program.let(-(1 + restitution), f"{hint}e")
        none = [sp.S.Zero] * n
        cols_q, cols_l = [], []
        for j in range(n):
            rhs = [scale * self.Jc[r, j] for r in range(m)]
            if all(x == 0 for x in rhs):
                cols_l.append([sp.S.Zero] * m)
                cols_q.append([sp.S.One if i == j else sp.S.Zero for i in range(n)])
                continue
            dl = self.solve_rows(rhs, f"{hint}l")
            dv = self._accelerate(none, dl, f"{hint}q")
            cols_q.append([d + 1 if i == j else d for i, d in enumerate(dv)])
            cols_l.append(dl)
        dq = sp.Matrix(n, n, lambda i, j: cols_q[j][i])
        dl = sp.Matrix(m, n, lambda i, j: cols_l[j][i])
        return dq, dl
