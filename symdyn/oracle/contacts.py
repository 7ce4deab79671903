"""The oracle's contact dynamics, NumPy only, its public functions: the contact Jacobian and drift
of named frames, the constrained forward dynamics of a robot whose frames touch the world (a KKT
system), the impulse dynamics of a touchdown, and (from symdyn.oracle.contact_derivatives) the
derivatives of both. The solves live in symdyn.oracle.contact_solve.

Independent of the symbolic code (symdyn.algorithms.contacts): it reads only the model. Jc and
gamma come from symdyn.oracle.contact_kinematics (the conventions: Pinocchio's CONTACT_3D
LOCAL_WORLD_ALIGNED rows for a point, CONTACT_6D LOCAL rows for a 6d contact), M from the CRBA
and b + F = rnea(q, qd, 0) from the RNEA (symdyn.oracle.rnea). With the mask `active` (1 in
contact, 0 free) only the active contacts' rows enter:

    [ M   Jc^T ] [ qdd     ]   [ tau - b - F ]
    [ Jc  0    ] [ -lambda ] = [ -gamma      ]

solved by the Schur complement: (Jc M^-1 Jc^T + mu I) lambda = -gamma - Jc M^-1 (tau - b - F),
qdd = M^-1 (tau - b - F + Jc^T lambda); lambda is the force (and moment) on the robot in the rows'
axes, zero on the free contacts' rows. mu >= 0 (`damping`, default 0) regularises redundant sets
as Pinocchio's forwardDynamics(..., damping) does (then Jc qdd + gamma = -mu lambda): a Delassus
matrix Jc M^-1 Jc^T + mu I whose smallest eigenvalue is not above SINGULAR times its largest is
refused (SymdynError), never a NaN. Impulse dynamics (restitution e in [0, 1]):
M (qd+ - qd) = Jc^T P, Jc qd+ = -e Jc qd, so (Jc M^-1 Jc^T + mu I) P = -(1 + e) Jc qd and
qd+ = qd + M^-1 Jc^T P.
"""

from __future__ import annotations

import numpy as np

from .contact_derivatives import contact_forward_dynamics_derivatives, impulse_dynamics_derivatives
from .contact_kinematics import ContactRows, contact_kinematics, contact_rows
from .contact_solve import SINGULAR, checked_mask, checked_number, checked_state, constrained, impulse

__all__ = [
    "SINGULAR",
    "contact_jacobian",
    "contact_drift",
    "contact_forward_dynamics",
    "impulse_dynamics",
    "contact_forward_dynamics_derivatives",
    "impulse_dynamics_derivatives",
]


def _contacts(robot, contacts, where: str) -> ContactRows:
    return contact_rows(robot, getattr(robot, "contacts", ()) if contacts is None else contacts, where)


def contact_jacobian(robot, contacts, q, params=None) -> np.ndarray:
    """Jc (NLAMBDA, NV) of the contacts (None: robot.contacts) at q (module docstring).

    Raises:
        SymdynError: bad contacts, vectors or parameter values.
    """
    rows = _contacts(robot, contacts, "contact_jacobian")
    (q,) = checked_state("contact_jacobian", robot, params, q=q)
    return contact_kinematics(robot, rows, q[None], np.zeros((1, robot.nv)), params)[0][0]


def contact_drift(robot, contacts, q, qd, params=None) -> np.ndarray:
    """gamma = Jc_dot qd (NLAMBDA,) at (q, qd): the points' classical accelerations (world axes),
    the 6d frames' spatial accelerations (their own axes), at qdd = 0.

    Raises:
        SymdynError: bad contacts, vectors or parameter values.
    """
    rows = _contacts(robot, contacts, "contact_drift")
    q, qd = checked_state("contact_drift", robot, params, q=q, qd=qd)
    return contact_kinematics(robot, rows, q[None], qd[None], params)[1][0]


def contact_forward_dynamics(robot, contacts, q, qd, tau, active=None, params=None, damping=0.0):
    """(qdd (NV,), lambda (NLAMBDA,)) of M qdd + b + F = tau + Jc^T lambda, Jc qdd + gamma = 0 for
    the active contacts (module docstring; lambda zero on the free contacts' rows).

    Raises:
        SymdynError: bad contacts, mask, vectors, damping or parameter values; M not positive
            definite; dependent active rows with too small a damping.
    """
    where = "contact_forward_dynamics"
    rows = _contacts(robot, contacts, where)
    q, qd, tau = checked_state(where, robot, params, q=q, qd=qd, tau=tau)
    mask = checked_mask(robot, rows, active, where)
    mu = checked_number(robot, damping, "damping", 0.0, np.inf, where)
    qdd, lam = constrained(robot, rows, mask, q[None], qd[None], tau[None], params, mu, where)
    return qdd[0], lam[0]


def impulse_dynamics(robot, contacts, q, qd, active=None, restitution=0.0, params=None, damping=0.0):
    """(qd_plus (NV,), impulse (NLAMBDA,)) of a touchdown: M (qd+ - qd) = Jc^T P and
    Jc qd+ = -e Jc qd for the active contacts (module docstring; P zero on the free rows).

    Raises:
        SymdynError: as contact_forward_dynamics; a restitution outside [0, 1].
    """
    where = "impulse_dynamics"
    rows = _contacts(robot, contacts, where)
    q, qd = checked_state(where, robot, params, q=q, qd=qd)
    mask = checked_mask(robot, rows, active, where)
    e = checked_number(robot, restitution, "restitution", 0.0, 1.0, where)
    mu = checked_number(robot, damping, "damping", 0.0, np.inf, where)
    qd_plus, P = impulse(robot, rows, mask, q[None], qd[None], params, e, mu, where)
    return qd_plus[0], P[0]
