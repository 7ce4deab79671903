"""The derivatives of the oracle's contact dynamics (symdyn.oracle.contacts) by differences,
NumPy only, as Pinocchio's computeConstraintDynamicsDerivatives and
computeImpulseDynamicsDerivatives define them: with respect to q in the tangent space (a floating
robot's q moved by q (+) dq, symdyn.oracle.derivatives.integrate, NV columns), qd and tau.

* d/dq, column j = d/de f(q (+) e e_j) at e = 0 by the five-point central difference of
  symdyn.oracle.derivatives (step STEP = 1e-3: truncation and rounding together about 1e-12 of
  the largest entry, a little more where the KKT matrix is ill-conditioned);
* d/dqd: qdd and lambda are quadratic in qd at a fixed q (b and gamma are, and the KKT solve is
  linear in them), qd+ and the impulse linear, so the central difference with a unit step has no
  truncation error (rounding only);
* d/dtau: linear, the same unit central difference.

Joint friction F(qd) enters with its Coulomb part frozen at qd (its derivative is zero away from
qd = 0, as in the symbolic derivatives): the viscous part's Jacobian D = F(2 e_j) - F(e_j) (the
Coulomb terms of two positive rates cancel) moves tau by -D dqd. Pinocchio has no friction.
"""

from __future__ import annotations

import numpy as np

from .contact_kinematics import contact_rows
from .contact_solve import checked_mask, checked_number, checked_state, constrained, impulse
from .derivatives import STEP, integrate
from .rnea import friction_torque

__all__ = ["contact_forward_dynamics_derivatives", "impulse_dynamics_derivatives"]


def _tangent_steps(robot, q: np.ndarray) -> np.ndarray:
    """q (+) s e_j for s in (h, -h, 2h, -2h) and every tangent direction j: (4 NV, NQ)."""
    E = np.eye(robot.nv)
    steps = np.concatenate([E * STEP, -E * STEP, E * 2 * STEP, -E * 2 * STEP])
    return integrate(robot, np.repeat(q[None], 4 * robot.nv, 0), steps)


def _five_point(values: np.ndarray) -> np.ndarray:
    """(8 (f(h) - f(-h)) - (f(2h) - f(-2h))) / (12 h) per tangent direction: values (4 NV, k),
    as _tangent_steps orders them -> (k, NV)."""
    p1, m1, p2, m2 = np.split(values, 4)
    return ((8 * (p1 - m1) - (p2 - m2)) / (12 * STEP)).T


def _viscous(robot, params) -> np.ndarray:
    """dF/dqd (NV, NV) with the Coulomb terms frozen (module docstring)."""
    E = np.eye(robot.nv)
    return (friction_torque(robot, 2 * E, params) - friction_torque(robot, E, params)).T


def _setup(where: str, robot, contacts, active, params, **vectors):
    rows = contact_rows(robot, getattr(robot, "contacts", ()) if contacts is None else contacts, where)
    state = checked_state(where, robot, params, **vectors)
    return rows, checked_mask(robot, rows, active, where), state


def contact_forward_dynamics_derivatives(
    robot, contacts, q, qd, tau, active=None, params=None, *, damping=0.0
) -> dict[str, np.ndarray]:
    """dqdd_dq, dqdd_dqd, dqdd_dtau (NV, NV) and dlambda_dq, dlambda_dqd, dlambda_dtau
    (NLAMBDA, NV) of symdyn.oracle.contacts.contact_forward_dynamics (module docstring).

    Raises:
        SymdynError: as contact_forward_dynamics.
    """
    where = "contact_forward_dynamics_derivatives"
    rows, mask, (q, qd, tau) = _setup(where, robot, contacts, active, params, q=q, qd=qd, tau=tau)
    mu = checked_number(robot, damping, "damping", 0.0, np.inf, where)
    tau0 = tau - friction_torque(robot, qd, params)  # the efforts less the friction at qd
    D = _viscous(robot, params)
    nv, E = robot.nv, np.eye(robot.nv)
    Q = np.concatenate([_tangent_steps(robot, q), np.repeat(q[None], 4 * nv, 0)])
    QD = np.concatenate([np.repeat(qd[None], 6 * nv, 0), qd + E, qd - E])
    TAU = np.concatenate(
        [np.repeat(tau0[None], 4 * nv, 0), tau0 + E, tau0 - E, tau0 - E @ D.T, tau0 + E @ D.T]
    )
    qdd, lam = constrained(robot, rows, mask, Q, QD, TAU, params, mu, where, friction=False)
    out = np.concatenate([qdd, lam], 1)
    dq = _five_point(out[: 4 * nv])
    dtau_p, dtau_m, dqd_p, dqd_m = np.split(out[4 * nv :], 4)
    dtau, ddqd = ((dtau_p - dtau_m) / 2).T, ((dqd_p - dqd_m) / 2).T
    return {
        "dqdd_dq": dq[:nv],
        "dqdd_dqd": ddqd[:nv],
        "dqdd_dtau": dtau[:nv],
        "dlambda_dq": dq[nv:],
        "dlambda_dqd": ddqd[nv:],
        "dlambda_dtau": dtau[nv:],
    }


def impulse_dynamics_derivatives(
    robot, contacts, q, qd, active=None, restitution=0.0, params=None, *, damping=0.0
) -> dict[str, np.ndarray]:
    """dqd_plus_dq, dqd_plus_dqd (NV, NV) and dimpulse_dq, dimpulse_dqd (NLAMBDA, NV) of
    symdyn.oracle.contacts.impulse_dynamics (module docstring).

    Raises:
        SymdynError: as impulse_dynamics.
    """
    where = "impulse_dynamics_derivatives"
    rows, mask, (q, qd) = _setup(where, robot, contacts, active, params, q=q, qd=qd)
    e = checked_number(robot, restitution, "restitution", 0.0, 1.0, where)
    mu = checked_number(robot, damping, "damping", 0.0, np.inf, where)
    nv, E = robot.nv, np.eye(robot.nv)
    Q = np.concatenate([_tangent_steps(robot, q), np.repeat(q[None], 2 * nv, 0)])
    QD = np.concatenate([np.repeat(qd[None], 4 * nv, 0), qd + E, qd - E])
    out = np.concatenate(impulse(robot, rows, mask, Q, QD, params, e, mu, where), 1)
    dq = _five_point(out[: 4 * nv])
    dqd = ((out[4 * nv : 5 * nv] - out[5 * nv :]) / 2).T
    return {
        "dqd_plus_dq": dq[:nv],
        "dqd_plus_dqd": dqd[:nv],
        "dimpulse_dq": dq[nv:],
        "dimpulse_dqd": dqd[nv:],
    }
