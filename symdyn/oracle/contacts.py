"""The oracle's contact dynamics, NumPy only: the constrained forward dynamics of a robot whose
named frames touch the world (a KKT system) and the impulse dynamics of a touchdown.

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

from ..errors import SymdynError
from .contact_kinematics import ContactRows, contact_kinematics, contact_rows, shown
from .floating import floating_inputs
from .inputs import checked_inputs
from .rnea import mass_matrix, rnea

__all__ = [
    "SINGULAR",
    "contact_jacobian",
    "contact_drift",
    "contact_forward_dynamics",
    "impulse_dynamics",
]

#: with no damping, a Delassus matrix whose eigenvalues' ratio is below this is singular
SINGULAR = 1e-12


def checked_state(where: str, robot, params, **vectors) -> list[np.ndarray]:
    """One state's vectors, checked: q (NQ entries), the others NV (floating) or n (fixed), finite."""
    named = list(vectors.items())
    if getattr(robot, "floating", False) is True:
        _, out, single = floating_inputs(
            where, robot, params, *((k, v, "q" if k == "q" else "v") for k, v in named)
        )
    else:
        _, out, single = checked_inputs(where, robot, params, *named)
    if not single:
        raise SymdynError(f"{where}: robot '{robot.name}': give one state (vectors, not rows of states)")
    for (name, _), a in zip(named, out, strict=True):
        if not np.all(np.isfinite(a)):
            raise SymdynError(f"{where}: robot '{robot.name}': {name} has entries that are not finite")
    return [a[0] for a in out]


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


def checked_mask(robot, rows: ContactRows, active, where: str) -> np.ndarray:
    """The mask as NCONTACT booleans (None: every contact active)."""
    count = len(rows.frames)
    if active is None:
        return np.ones(count, dtype=bool)
    try:
        a = np.asarray(active, dtype=float)
    except (TypeError, ValueError):
        raise SymdynError(
            f"{where}: robot '{robot.name}': active must hold numbers, got {shown(active)}"
        ) from None
    if a.shape != (count,) or not np.all((a == 0) | (a == 1)):
        raise SymdynError(
            f"{where}: robot '{robot.name}': active must be {count} entries of 0 or 1 (one per contact), "
            f"got {shown(np.asarray(active).tolist())}"
        )
    return a == 1


def checked_number(robot, value, name: str, low: float, high: float, where: str) -> float:
    """A finite number in [low, high] (damping, restitution)."""
    try:
        x = float(value)
    except (TypeError, ValueError):
        raise SymdynError(
            f"{where}: robot '{robot.name}': {name} must be a number, got {shown(value)}"
        ) from None
    if not low <= x <= high:
        raise SymdynError(f"{where}: robot '{robot.name}': {name} must be in [{low:g}, {high:g}], got {x!r}")
    return x


def kkt_solve(M: np.ndarray, J: np.ndarray, rhs: np.ndarray, con: np.ndarray, damping: float, where: str):
    """(x, lam) with M x = rhs + J^T lam and J x = con - damping lam: the Schur complement
    (J M^-1 J^T + damping I) lam = J M^-1 rhs - con, refused when singular (module docstring)."""
    try:
        np.linalg.cholesky(M)
    except np.linalg.LinAlgError:
        raise SymdynError(f"{where}: the mass matrix is not positive definite at this q") from None
    MinvJt = np.linalg.solve(M, J.T)
    Minv_rhs = np.linalg.solve(M, rhs)
    if not len(J):
        return Minv_rhs, np.zeros(0)
    A = J @ MinvJt + damping * np.eye(len(J))
    eig = np.linalg.eigvalsh(0.5 * (A + A.T))
    if not eig[0] > SINGULAR * eig[-1]:
        raise SymdynError(
            f"{where}: the active contacts' rows are dependent (Jc M^-1 Jc^T has eigenvalues "
            f"{eig[0]:.3g} .. {eig[-1]:.3g}): drop redundant contacts from the mask or give a damping "
            f"above {SINGULAR:g} times the largest"
        )
    lam = np.linalg.solve(A, con - J @ Minv_rhs)
    return Minv_rhs + MinvJt @ lam, lam


def constrained(robot, rows, mask, Q, QD, TAU, params, damping: float, where: str, *, friction: bool = True):
    """(qdd (N, NV), lambda (N, NLAMBDA)) of N checked states: the KKT system (module docstring)."""
    J, gamma = contact_kinematics(robot, rows, Q, QD, params)
    M = mass_matrix(robot, Q, params)
    h = rnea(robot, Q, QD, np.zeros_like(QD), params, friction=friction)
    r = rows.rows(mask)
    qdd, lam = np.zeros_like(QD), np.zeros((len(Q), rows.nlambda))
    for i in range(len(Q)):
        qdd[i], lam[i, r] = kkt_solve(M[i], J[i][r], TAU[i] - h[i], -gamma[i, r], damping, where)
    return qdd, lam


def impulse(robot, rows, mask, Q, QD, params, restitution: float, damping: float, where: str):
    """(qd_plus (N, NV), impulse (N, NLAMBDA)) of N checked states: M dqd = Jc^T P, Jc qd+ = -e Jc qd."""
    J = contact_kinematics(robot, rows, Q, np.zeros_like(QD), params)[0]
    M = mass_matrix(robot, Q, params)
    r = rows.rows(mask)
    jump, P = np.zeros_like(QD), np.zeros((len(Q), rows.nlambda))
    for i in range(len(Q)):
        Ji = J[i][r]
        jump[i], P[i, r] = kkt_solve(
            M[i], Ji, np.zeros(robot.nv), -(1 + restitution) * Ji @ QD[i], damping, where
        )
    return QD + jump, P


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
