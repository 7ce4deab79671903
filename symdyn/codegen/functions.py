"""The seven generated functions (docs/generated-code.md), as target-independent straight-line code.

Each `FunctionSpec` names its inputs (q, qd, qdd or tau, p: vectors of SymPy
symbols), one output (tau, M, C, V, G, F or qdd, row-major), and the
eliminated temporaries (symdyn.symbolic.simplify) that compute it. Printers for C,
CasADi, NumPy and LaTeX render these specs; nothing here is target-specific.

forward_dynamics solves M qdd = tau - (V + G + F) with an LDL^T factorisation
unrolled symbolically (no square roots):
    D_j = M_jj - sum_{k<j} L_jk^2 D_k,  L_ij = (M_ij - sum_{k<j} L_ik L_jk D_k) / D_j,
then L y = b, z = D^-1 y, L^T qdd = z. Structural zeros of M fold away.

A generated function cannot raise, so forward_dynamics is not generated for a robot whose
M is singular by construction: a joint that moves no mass or inertia (a massless subtree
and no rotor inertia, symdyn.model.robot.Robot.idle_joints) would make some D_j an exact
zero. `build_functions` then leaves it out with a SymdynWarning naming the joints, and the
other six functions are generated as usual. This is decided on numbers only: with symbolic
masses M cannot be known to be singular, and forward_dynamics is generated.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass

import sympy as sp

from ..dynamics import QUANTITIES, Dynamics
from ..errors import SymdynWarning
from ..symbolic.program import Program
from ..symbolic.simplify import Eliminated, OpCount, eliminate_many

__all__ = ["FunctionSpec", "Input", "build_functions", "FUNCTION_NAMES"]

FUNCTION_NAMES = (
    "inverse_dynamics",
    "mass_matrix",
    "coriolis_matrix",
    "coriolis",
    "gravity",
    "friction",
    "forward_dynamics",
)


@dataclass(frozen=True)
class Input:
    """A vector argument: its name in the generated code and its symbols."""

    name: str
    symbols: tuple[sp.Symbol, ...]


@dataclass(frozen=True)
class FunctionSpec:
    """One generated function: inputs, one output array, and the code computing it."""

    name: str
    doc: str
    inputs: tuple[Input, ...]
    output: str
    shape: tuple[int, int]
    code: Eliminated

    @property
    def ops(self) -> OpCount:
        return self.code.ops

    @property
    def temporaries(self):
        return self.code.temporaries

    @property
    def outputs(self):
        return self.code.outputs

    @property
    def free_symbols(self) -> set[sp.Symbol]:
        """Every symbol the temporaries and outputs read (input symbols and temporaries)."""
        return set().union(
            *(e.free_symbols for _, e in self.code.temporaries),
            *(sp.sympify(e).free_symbols for e in self.code.outputs),
        )


def _ldlt_solve(M: sp.Matrix, b: list[sp.Expr], prog: Program) -> list[sp.Expr]:
    n = M.rows
    L = sp.zeros(n, n)
    D: list[sp.Expr] = [sp.S.Zero] * n
    for j in range(n):
        d = M[j, j] - sum((L[j, k] ** 2 * D[k] for k in range(j)), sp.S.Zero)
        D[j] = prog.let(d, "fdD")
        for i in range(j + 1, n):
            s = M[i, j] - sum((L[i, k] * L[j, k] * D[k] for k in range(j)), sp.S.Zero)
            L[i, j] = prog.let(s / D[j], "fdL") if s != 0 else sp.S.Zero
    y: list[sp.Expr] = []
    for i in range(n):
        y.append(prog.let(b[i] - sum((L[i, k] * y[k] for k in range(i)), sp.S.Zero), "fdy"))
    x: list[sp.Expr] = [sp.S.Zero] * n
    for i in reversed(range(n)):
        zi = y[i] / D[i]
        x[i] = prog.let(zi - sum((L[k, i] * x[k] for k in range(i + 1, n)), sp.S.Zero), "fdx")
    return x


def _solvable(dyn: Dynamics) -> bool:
    """Whether M can be inverted as far as the numbers tell; warn naming the joints if not."""
    robot = dyn.robot
    idle = robot.idle_joints()
    if idle:
        names = ", ".join(f"'{robot.links[i].name}' (link {i + 1})" for i in idle)
        warnings.warn(
            f"robot '{robot.name}': forward_dynamics is not generated: joint(s) {names} move no mass "
            "or inertia, so M(q) is singular; the other functions are",
            SymdynWarning,
            stacklevel=3,
        )
    return not idle


def build_functions(dyn: Dynamics) -> list[FunctionSpec]:
    """The generated functions for a derived robot, with CSE applied per function.

    All seven, or the six without forward_dynamics (and a SymdynWarning) when a joint moves
    no mass or inertia (see the module docstring).
    """
    n = dyn.n
    q = Input("q", tuple(dyn.q))
    qd = Input("qd", tuple(dyn.qd))
    qdd = Input("qdd", tuple(dyn.qdd))
    tau = Input("tau", tuple(sp.Symbol(f"tau{i + 1}") for i in range(n)))
    p = Input("p", tuple(dyn.params))
    c = dyn.compact
    table = [
        ("inverse_dynamics", "tau = M(q) qdd + V(q, qd) + G(q) + F(qd)", (q, qd, qdd, p), "tau", c["tau"]),
        ("mass_matrix", "M(q), row-major n x n", (q, p), "M", c["M"]),
        (
            "coriolis_matrix",
            "C(q, qd) from Christoffel symbols, row-major; C qd = V",
            (q, qd, p),
            "C",
            c["C"],
        ),
        ("coriolis", "V(q, qd) = C(q, qd) qd", (q, qd, p), "V", c["V"]),
        ("gravity", "G(q)", (q, p), "G", c["G"]),
        ("friction", "F(qd) = viscous qd + coulomb sign(qd)", (qd, p), "F", c["F"]),
    ]
    program_outputs = [e for name in QUANTITIES for e in c[name]] + list(c["bias"])
    steps = dyn.program.needed(program_outputs)
    if _solvable(dyn):
        fd = Program()
        b = [fd.let(tau.symbols[i] - c["bias"][i], "fdb") for i in range(n)]
        qdd_out = _ldlt_solve(sp.Matrix(c["M"]), b, fd)
        table.append(
            (
                "forward_dynamics",
                "qdd solving M(q) qdd = tau - V(q, qd) - G(q) - F(qd) (unrolled LDL^T)",
                (q, qd, tau, p),
                "qdd",
                sp.Matrix(qdd_out),
            )
        )
        steps += fd.needed(qdd_out)
    outputs = {name: list(exprs) for name, _, _, _, exprs in table}
    inputs = (*q.symbols, *qd.symbols, *qdd.symbols, *tau.symbols, *p.symbols)
    code = eliminate_many(steps, outputs, reserved=inputs)
    return [
        FunctionSpec(name, doc, inputs, out, (exprs.rows, exprs.cols), code[name])
        for name, doc, inputs, out, exprs in table
    ]
