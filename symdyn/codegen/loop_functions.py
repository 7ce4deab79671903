"""The generated functions of a robot with closed loops (docs/closed-loops.md), in the
`dynamics` group: the closure and the dynamics in the actuated coordinates (Khalil and Dombre
(2002), ch. 14; symdyn.algorithms.closed_loops for the notation):

    loop_residual(q, p, phi)                       phi(q), the kept closure rows (npas)
    loop_jacobian(q, p, K)                         K = dphi/dq, npas x n
    loop_newton_step(q, p, phi, dqp, pivots)       phi, the Newton step dq_p = -K_p^-1 phi, its pivots
    loop_motion(q, qda, qdda, p, qd, qdd)          qd = W qd_a, qdd = W qdd_a - [0; K_p^-1 Kdot qd]
    actuated_inverse_dynamics(q, qda, qdda, p, tau_a)      tau_a = W^T tau(q, qd, qdd)
    actuated_mass_matrix(q, p, Ma)                 M_a = W^T M W
    actuated_forward_dynamics(q, qda, tau_a, p, qdda)      M_a qdd_a = tau_a - W^T tau(q, qd, qdd|qdd_a=0)
    loop_forces(q, qda, qdda, p, lam)              lambda = K_p^-T tau_p(q, qd, qdd) (lam: Python keyword)

q is the whole tree's configuration (closed: phi(q) = 0), qda, qdda and tau_a the actuated
coordinates' rates, accelerations and efforts in coordinate order. tau(q, qd, qdd) is the
tree's inverse dynamics (friction and rotor inertia included), its intermediates rewritten at
qd = W qd_a (symdyn.algorithms.derivatives.substitute). K_p^-1 is applied through the normal
equations with the unrolled L D L^T, M_a^-1 by the same factorisation: straight-line code,
no branch. lambda are the closure forces (world axes, on the loop's `link` side): the tree's
joints feel K^T lambda from them. NAME_solve_loops, the Newton loop over loop_newton_step,
is written by each target's template (a fixed maximum of iterations).
"""

from __future__ import annotations

import sympy as sp

from ..algorithms.closed_loops import check_loops, closure, solve_columns, spd_solve
from ..algorithms.derivatives import substitute
from ..algorithms.frame_kinematics import FrameKinematics
from ..dynamics import Dynamics
from .function_rows import FunctionRow, Input, Inputs, Output, with_steps

__all__ = ["loop_rows", "LOOP_FUNCTION_NAMES", "loop_inputs"]

LOOP_FUNCTION_NAMES = (
    "loop_residual",
    "loop_jacobian",
    "loop_newton_step",
    "loop_motion",
    "actuated_inverse_dynamics",
    "actuated_mass_matrix",
    "actuated_forward_dynamics",
    "loop_forces",
)


def loop_inputs(nact: int) -> tuple[Input, Input, Input]:
    """The inputs qda, qdda and tau_a (nact symbols each)."""
    return tuple(Input(name, tuple(sp.symbols(f"{name}1:{nact + 1}"))) for name in ("qda", "qdda", "tau_a"))


def _entries(*matrices: sp.Matrix) -> tuple[sp.Expr, ...]:
    return tuple(m[i, j] for m in matrices for i in range(m.rows) for j in range(m.cols))


def _project(v: list, X: sp.Matrix, act, pas, prog, hint: str) -> sp.Matrix:
    """W^T v = v_a - X^T v_p (v over every coordinate, X = K_p^-1 K_a)."""
    out = [v[a] - sum((X[i, k] * v[p] for i, p in enumerate(pas)), sp.S.Zero) for k, a in enumerate(act)]
    return sp.Matrix([prog.let(e, hint) for e in out])


def loop_rows(dyn: Dynamics, x: Inputs) -> list[FunctionRow]:
    """The functions of the module docstring for a robot with loops (none for a tree); warns
    with the closure rows dropped as dependent."""
    robot = dyn.robot
    if not robot.loops:
        return []
    an = check_loops(robot)
    n, act, pas = dyn.n, list(an.actuated), list(an.passive)
    na, npas = len(act), len(pas)
    qda, qdda, tau_a = loop_inputs(na)
    c = dyn.compact
    prog = dyn.program.copy("L")
    first = len(prog.assignments)
    fk = FrameKinematics(robot, list(dyn.q), list(dyn.qd), prog)
    phi_all, K_all, _ = closure(fk, robot, drift=False)
    phi = sp.Matrix([prog.let(phi_all[r], "phi") for r in an.rows])
    K = sp.Matrix([[prog.let(e, "K") for e in K_all[r]] for r in an.rows])
    Kp, Ka = K.extract(list(range(npas)), pas), K.extract(list(range(npas)), act)
    X = solve_columns(Kp, Ka, prog, "Lw")[0]
    step, pivots = solve_columns(Kp, phi, prog, "Lw")
    dqp = -step

    qd = [sp.S.Zero] * n
    for k, a in enumerate(act):
        qd[a] = qda.symbols[k]
    for i, p in enumerate(pas):
        qd[p] = prog.let(-sum((X[i, k] * qda.symbols[k] for k in range(na)), sp.S.Zero), "vqd")
    moving = FrameKinematics(robot, list(dyn.q), qd, prog)
    drift_all = closure(moving, robot)[2]
    gamma = solve_columns(Kp, sp.Matrix([prog.let(drift_all[r], "Kd") for r in an.rows]), prog, "Lw")[0]

    def accelerations(qdd_a) -> list:
        out = [sp.S.Zero] * n
        for k, a in enumerate(act):
            out[a] = qdd_a[k]
        for i, p in enumerate(pas):
            s = -sum((X[i, k] * qdd_a[k] for k in range(na)), sp.S.Zero) - gamma[i]
            out[p] = prog.let(s, "vqdd")
        return out

    qdd = accelerations(qdda.symbols)
    replaced = {**dict(zip(dyn.qd, qd, strict=True)), **dict(zip(dyn.qdd, qdd, strict=True))}
    tau = substitute(prog, list(c["tau"]), replaced, "Lt")
    tau_act = _project(tau, X, act, pas, prog, "ta")
    lam = solve_columns(Kp.T, sp.Matrix([tau[p] for p in pas]), prog, "Ll")[0]
    M = c["M"]
    W = sp.zeros(n, na)
    for k, a in enumerate(act):
        W[a, k] = 1
    for i, p in enumerate(pas):
        for k in range(na):
            W[p, k] = -X[i, k]
    MW = sp.Matrix(n, na, lambda i, k: prog.let(sum((M[i, j] * W[j, k] for j in range(n)), sp.S.Zero), "MW"))
    Ma = sp.Matrix(
        na, na, lambda k, m: prog.let(sum((W[j, k] * MW[j, m] for j in range(n)), sp.S.Zero), "Ma")
    )
    zero = {**dict(zip(dyn.qd, qd, strict=True)), **dict(zip(dyn.qdd, accelerations([0] * na), strict=True))}
    bias = _project(substitute(prog, list(c["tau"]), zero, "Lb"), X, act, pas, prog, "ba")
    rhs = sp.Matrix([prog.let(tau_a.symbols[k] - bias[k], "fb") for k in range(na)])
    qdda_out = spd_solve(Ma, rhs, prog, "La")[0]

    def out(name, rows, cols, doc, dims):
        return Output(name, rows, cols, doc, dims)

    rows = [
        (
            "loop_residual",
            "phi(q), the independent closure equations (position rows in m, rotation rows in rad)",
            (x.q, x.p),
            (out("phi", npas, 1, "closure residual phi(q), zero on a closed configuration", ("npas", "1")),),
            _entries(phi),
        ),
        (
            "loop_jacobian",
            "K(q) = dphi/dq, the closure Jacobian (difference of the loop frames' Jacobians)",
            (x.q, x.p),
            (out("K", npas, n, "closure Jacobian, row-major npas x n", ("npas", "n")),),
            _entries(K),
        ),
        (
            "loop_newton_step",
            "phi(q), the Newton step dq_p = -K_p^-1 phi on the passive coordinates, and the relative "
            "pivots D_j / N_jj of its solve (N = K_p^T K_p; near 0: K_p near singular)",
            (x.q, x.p),
            (
                out("phi", npas, 1, "closure residual phi(q)", ("npas", "1")),
                out("dqp", npas, 1, "Newton step of the passive coordinates", ("npas", "1")),
                out("pivots", npas, 1, "relative pivots of the step's solve, in (0, 1]", ("npas", "1")),
            ),
            _entries(phi, dqp, sp.Matrix(pivots)),
        ),
        (
            "loop_motion",
            "qd = W qd_a and qdd = W qdd_a - [0; K_p^-1 Kdot qd]: every joint's rate and acceleration",
            (x.q, qda, qdda, x.p),
            (
                out("qd", n, 1, "every joint's rate on the closure", ("n", "1")),
                out("qdd", n, 1, "every joint's acceleration on the closure", ("n", "1")),
            ),
            tuple(qd) + tuple(qdd),
        ),
        (
            "actuated_inverse_dynamics",
            "tau_a = W^T tau(q, W qd_a, W qdd_a - [0; K_p^-1 Kdot qd]), the actuated joints' efforts",
            (x.q, qda, qdda, x.p),
            (out("tau_a", na, 1, "actuated joint efforts", ("nact", "1")),),
            _entries(tau_act),
        ),
        (
            "actuated_mass_matrix",
            "M_a = W^T M W, the mass matrix in the actuated coordinates",
            (x.q, x.p),
            (out("Ma", na, na, "actuated mass matrix, row-major nact x nact", ("nact", "nact")),),
            _entries(Ma),
        ),
        (
            "actuated_forward_dynamics",
            "qdd_a solving M_a qdd_a = tau_a - W^T tau(q, qd, qdd at qdd_a = 0) (unrolled LDL^T)",
            (x.q, qda, tau_a, x.p),
            (out("qdda", na, 1, "actuated joint accelerations", ("nact", "1")),),
            _entries(qdda_out),
        ),
        (
            "loop_forces",
            "lambda = K_p^-T tau_p, the closure forces (world axes, on the loop's link side)",
            (x.q, qda, qdda, x.p),
            (out("lam", npas, 1, "closure forces; K^T lambda are their joint efforts", ("npas", "1")),),
            _entries(lam),
        ),
    ]
    return with_steps(rows, prog, first, "loops")
