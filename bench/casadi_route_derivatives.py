"""The CasADi route's derivatives: what a CasADi user writes for dtau/dx, dqdd/dx and M^-1.

The traced RNEA and CRBA of bench/casadi_route.py (casadi.SX, numeric parameters), then
CasADi's automatic differentiation, code-generated and compiled like the route's other
functions:

* ``rnea_derivatives(q, qd, qdd) -> (dtau_dq, dtau_dqd)``: ``casadi.jacobian`` of the traced
  RNEA (friction included, as in symdyn's inverse_dynamics_derivatives);
* ``aba_derivatives(q, qd, tau) -> (dqdd_dq, dqdd_dqd, Minv)``: the Jacobians of
  qdd = ``casadi.solve(M, tau - bias)`` (CasADi's symbolic factorisation of the traced CRBA)
  by q, qd and tau;
* ``minverse(q) -> Minv``: ``casadi.solve(M, I)``.

Every output is dense and column-major (CasADi's layout): the harness compares and times them
as they are.
"""

from __future__ import annotations

import casadi as cs
from casadi_route import crba, rnea, robot_arrays

__all__ = ["derivative_functions", "DERIVATIVE_FUNCTIONS"]

DERIVATIVE_FUNCTIONS = ("rnea_derivatives", "aba_derivatives", "minverse")


def derivative_functions(robot, prefix: str = "crd") -> dict[str, cs.Function]:
    """The traced SX derivative functions of `robot` (numeric parameters), by name."""
    m = robot_arrays(robot)
    n = m.n
    q, qd, qdd, tau = (cs.SX.sym(s, n) for s in ("q", "qd", "qdd", "tau"))
    name = f"{prefix}_{robot.name}"
    t = rnea(m, q, qd, qdd)
    M = crba(m, q)
    acc = cs.solve(M, tau - rnea(m, q, qd, cs.SX.zeros(n, 1)))
    dense = cs.densify
    return {
        "rnea_derivatives": cs.Function(
            f"{name}_rnea_derivatives",
            [q, qd, qdd],
            [dense(cs.jacobian(t, q)), dense(cs.jacobian(t, qd))],
            ["q", "qd", "qdd"],
            ["dtau_dq", "dtau_dqd"],
        ),
        "aba_derivatives": cs.Function(
            f"{name}_aba_derivatives",
            [q, qd, tau],
            [dense(cs.jacobian(acc, q)), dense(cs.jacobian(acc, qd)), dense(cs.jacobian(acc, tau))],
            ["q", "qd", "tau"],
            ["dqdd_dq", "dqdd_dqd", "Minv"],
        ),
        "minverse": cs.Function(f"{name}_minverse", [q], [dense(cs.solve(M, cs.SX.eye(n)))], ["q"], ["Minv"]),
    }
