"""Trajectory optimisation of the Franka Panda with CasADi's Opti, IPOPT and symdyn's derivatives.

The generated CasADi module (symdyn generate examples/panda.yaml --target casadi --functions all) gives
forward_dynamics and forward_dynamics_derivatives. `with_derivatives` wraps the first as a
casadi.Function whose Jacobian is the second (CasADi's `custom_jacobian`): IPOPT then takes
dqdd/dq, dqdd/dqd and M^-1 from symdyn's code instead of differentiating the expression graph,
and a limited-memory Hessian keeps the problem first order.

The problem (docs/tutorials/ilqr.md): move the arm from rest at q_start to rest at q_goal in T
seconds, N intervals of constant torque, multiple shooting with one RK4 step per interval,
minimising the integral of |tau|^2 within the torque limits.

    python examples/derivatives_control/panda_opti.py generated/panda/panda_casadi.py
"""

from __future__ import annotations

import importlib.util
import sys

import casadi as ca
import numpy as np

TAU_MAX = np.array([87.0, 87.0, 87.0, 87.0, 12.0, 12.0, 12.0])  # the Panda's torque limits, N m


def load_functions(path: str) -> dict[str, ca.Function]:
    """functions() of a generated NAME_casadi.py."""
    spec = importlib.util.spec_from_file_location("generated_casadi", path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module.functions()


def with_derivatives(functions: dict[str, ca.Function]) -> ca.Function:
    """qdd = fd(q, qd, tau) whose Jacobian is symdyn's forward_dynamics_derivatives."""
    fd, fdd = functions["forward_dynamics"], functions["forward_dynamics_derivatives"]
    n = fd.size1_in(0)
    q, qd, tau, qdd = (ca.SX.sym(s, n) for s in ("q", "qd", "tau", "qdd"))
    p = ca.SX.sym("p", 0)
    dq, dqd, minv = fdd(q, qd, tau, p)
    jac = ca.Function(
        "jac_fd_symdyn",
        [q, qd, tau, qdd],
        [dq, dqd, minv],
        ["q", "qd", "tau", "out_qdd"],
        ["jac_qdd_q", "jac_qdd_qd", "jac_qdd_tau"],
    )
    return ca.Function(
        "fd_symdyn",
        [q, qd, tau],
        [fd(q, qd, tau, p)],
        ["q", "qd", "tau"],
        ["qdd"],
        {"custom_jacobian": jac, "jac_penalty": 0, "never_inline": True},
    )


def rk4(f, x, u, h: float, n: int):
    """One RK4 step of xd = (qd, f(q, qd, u))."""

    def xdot(z):
        return ca.vertcat(z[n:], f(z[:n], z[n:], u))

    k1 = xdot(x)
    k2 = xdot(x + h / 2 * k1)
    k3 = xdot(x + h / 2 * k2)
    k4 = xdot(x + h * k3)
    return x + h / 6 * (k1 + 2 * k2 + 2 * k3 + k4)


def solve(functions: dict[str, ca.Function], q_start, q_goal, T: float = 0.6, N: int = 15, verbose=False):
    """The minimum-effort motion; returns (X (2n x N+1), U (n x N), IPOPT's stats)."""
    f = with_derivatives(functions)
    n = len(q_start)
    h = T / N
    opti = ca.Opti()
    X = opti.variable(2 * n, N + 1)
    U = opti.variable(n, N)
    opti.minimize(h * ca.sumsqr(U))
    for k in range(N):
        opti.subject_to(X[:, k + 1] == rk4(f, X[:, k], U[:, k], h, n))
        opti.subject_to(opti.bounded(-TAU_MAX, U[:, k], TAU_MAX))
    opti.subject_to(X[:, 0] == np.concatenate([q_start, np.zeros(n)]))
    opti.subject_to(X[:, N] == np.concatenate([q_goal, np.zeros(n)]))
    for k in range(N + 1):  # a straight line in joint space as the initial guess
        opti.set_initial(X[:n, k], q_start + (q_goal - q_start) * k / N)
    options = {"ipopt.hessian_approximation": "limited-memory", "ipopt.tol": 1e-8}
    if not verbose:
        options |= {"ipopt.print_level": 0, "print_time": False, "ipopt.sb": "yes"}
    opti.solver("ipopt", options)
    sol = opti.solve()
    return np.asarray(sol.value(X)), np.asarray(sol.value(U)), sol.stats()


def main(path: str) -> None:
    q_start = np.array([0.0, -0.3, 0.0, -2.2, 0.0, 2.0, 0.8])
    q_goal = np.array([0.5, 0.0, -0.3, -1.8, 0.2, 1.8, 0.5])
    X, U, stats = solve(load_functions(path), q_start, q_goal, verbose=True)
    print(f"{stats['return_status']} after {stats['iter_count']} iterations, effort {np.sum(U**2):.4f}")


if __name__ == "__main__":
    main(sys.argv[1] if len(sys.argv) > 1 else "generated/panda/panda_casadi.py")
