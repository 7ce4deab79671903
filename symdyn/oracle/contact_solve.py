"""The oracle's contact solves, NumPy only: the checked arguments of the contact functions and
the KKT system of symdyn.oracle.contacts (its docstring states the equations) for batches of
states, one Schur complement each: (Jc M^-1 Jc^T + mu I) lambda = con - Jc M^-1 rhs over the
active contacts' rows, refused when that Delassus matrix is singular.

Shared by symdyn.oracle.contacts (the public functions) and symdyn.oracle.contact_derivatives
(the differences, which evaluate many states at once).
"""

from __future__ import annotations

import numpy as np

from ..errors import SymdynError, shown
from .contact_kinematics import ContactRows, contact_kinematics
from .floating import floating_inputs
from .inputs import checked_inputs
from .rnea import mass_matrix, rnea

__all__ = [
    "SINGULAR",
    "checked_state",
    "checked_mask",
    "checked_number",
    "float_array",
    "kkt_solve",
    "constrained",
    "impulse",
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


def float_array(robot, value, name: str, where: str) -> np.ndarray:
    """`value` as an array of floats, or SymdynError: `name` must hold numbers."""
    try:
        return np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        raise SymdynError(
            f"{where}: robot '{robot.name}': {name} must hold numbers, got {shown(value)}"
        ) from None


def checked_mask(robot, rows: ContactRows, active, where: str) -> np.ndarray:
    """The mask as NCONTACT booleans (None: every contact active)."""
    count = len(rows.frames)
    if active is None:
        return np.ones(count, dtype=bool)
    a = float_array(robot, active, "active", where)
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
