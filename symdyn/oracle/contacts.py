"""The oracle's contact dynamics, NumPy only: the contact Jacobian Jc and drift gamma of named
frames, the constrained forward dynamics (a KKT system) and the impulse dynamics of a touchdown.

Independent of the symbolic code (symdyn.algorithms.contacts): it reads only the model. The
bodies' world motions come from the oracle's own spatial kinematics (symdyn.oracle.centroidal's
walk over symdyn.oracle.spatial's joint poses, a floating base's twist constant in its body
frame), M from the CRBA and b + F = rnea(q, qd, 0) from the RNEA (symdyn.oracle.rnea).

Conventions (Pinocchio's, issue 36; q, qd as symdyn.model.free_flyer on a floating base):

* point (Pinocchio's CONTACT_3D, LOCAL_WORLD_ALIGNED): 3 rows, the linear velocity of the
  frame's origin in world axes; its drift is the origin's classical acceleration at qdd = 0,
  a_F = a_O + wd x r + w x (w x r) (r: the origin from the link's, world axes);
* 6d (CONTACT_6D, LOCAL): 6 rows, the frame's spatial velocity in its own axes, linear then
  angular, [R^T v_F; R^T w]; its drift is the spatial acceleration in those axes at qdd = 0,
  [R^T (a_F - w x v_F); R^T wd] (Pinocchio's getFrameAcceleration(LOCAL), not the classical one).

Rows are stacked in the contacts' order (NLAMBDA = 3 a point + 6 a 6d contact). With the mask
`active` (1 in contact, 0 free) only the active contacts' rows enter:

    [ M   Jc^T ] [ qdd     ]   [ tau - b - F ]
    [ Jc  0    ] [ -lambda ] = [ -gamma      ]

solved by the Schur complement: (Jc M^-1 Jc^T + mu I) lambda = -gamma - Jc M^-1 (tau - b - F),
qdd = M^-1 (tau - b - F + Jc^T lambda); lambda is the force (and moment) on the robot in the rows'
axes, zero on the free contacts' rows. mu >= 0 (`damping`, default 0) regularises redundant sets
(Pinocchio's forwardDynamics(..., damping)): with mu = 0 a Delassus matrix whose smallest
eigenvalue is below SINGULAR times its largest is refused (SymdynError), never a NaN.
Impulse dynamics (restitution e in [0, 1]): M (qd+ - qd) = Jc^T P, Jc qd+ = -e Jc qd, so
(Jc M^-1 Jc^T + mu I) P = -(1 + e) Jc qd and qd+ = qd + M^-1 Jc^T P.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Sequence
from typing import NamedTuple

import numpy as np

from ..errors import SymdynError
from .centroidal import _Bodies
from .floating import floating_inputs
from .inputs import checked_inputs, numeric_model
from .rnea import mass_matrix, rnea

__all__ = [
    "KINDS",
    "SINGULAR",
    "ContactRows",
    "contact_rows",
    "contact_jacobian",
    "contact_drift",
    "contact_forward_dynamics",
    "impulse_dynamics",
]

#: the rows of each kind of contact
KINDS = {"point": 3, "6d": 6}
#: with no damping, a Delassus matrix whose eigenvalues' ratio is below this is singular
SINGULAR = 1e-12


@dataclasses.dataclass(frozen=True)
class ContactRows:
    """The checked contacts of a robot: per contact its frame's name, its kind and its first row;
    nlambda the total number of rows."""

    frames: tuple[str, ...]
    kinds: tuple[str, ...]
    starts: tuple[int, ...]
    nlambda: int

    def rows(self, active: np.ndarray) -> np.ndarray:
        """The row indices of the active contacts (active: NCONTACT booleans)."""
        spans = [range(s, s + KINDS[k]) for s, k, a in zip(self.starts, self.kinds, active, strict=True) if a]
        return np.array([r for span in spans for r in span], dtype=int)


def _pair(robot, contact, i: int, where: str) -> tuple[object, object]:
    """(frame, kind) of a Contact-like object or of a pair."""
    if hasattr(contact, "frame") and hasattr(contact, "kind"):
        return contact.frame, contact.kind
    if isinstance(contact, Sequence) and not isinstance(contact, (str, bytes)) and len(contact) == 2:
        return contact[0], contact[1]
    raise SymdynError(f"{where}: robot '{robot.name}': contact {i} is not a (frame, kind) pair: {contact!r}")


def contact_rows(robot, contacts, where: str = "contacts") -> ContactRows:
    """The contacts, (frame_name, kind) pairs or objects with `.frame` and `.kind`, checked.

    Raises:
        SymdynError: not a sequence, an unknown frame or kind.
    """
    if isinstance(contacts, (str, bytes)) or not isinstance(contacts, Sequence):
        raise SymdynError(f"{where}: robot '{robot.name}': contacts must be a list of (frame, kind) pairs")
    frames, kinds, starts, row = [], [], [], 0
    for i, contact in enumerate(contacts):
        frame, kind = _pair(robot, contact, i, where)
        if not isinstance(frame, str):
            raise SymdynError(f"{where}: robot '{robot.name}': contact {i}'s frame is not a name: {frame!r}")
        if not isinstance(kind, str) or kind not in KINDS:
            raise SymdynError(
                f"{where}: robot '{robot.name}': contact {i} ({frame!r}) has kind {kind!r}, "
                "expected 'point' or '6d'"
            )
        robot.frame(frame, where)  # raises for an unknown name, naming the near matches
        frames.append(frame)
        kinds.append(kind)
        starts.append(row)
        row += KINDS[kind]
    return ContactRows(tuple(frames), tuple(kinds), tuple(starts), row)


class Kinematics(NamedTuple):
    """Contact rows at one q: Jc (NLAMBDA, NV) and the drifts gamma = Jc_dot qd (K, NLAMBDA) of K
    velocities qd."""

    jacobian: np.ndarray
    drift: np.ndarray


def contact_kinematics(robot, rows: ContactRows, q: np.ndarray, qd: np.ndarray, params=None) -> Kinematics:
    """Jc at a checked q and the drifts of the checked velocities qd (K, NV) (module docstring).

    The bodies' world motions (symdyn.oracle.centroidal) are computed column by column: Jc's
    columns are the frames' velocities at qd = e_k, each drift is the acceleration at one qd.
    """
    mdl = numeric_model(robot, params)
    bodies = _Bodies(robot, q, params)
    nv, K = robot.nv, len(qd)
    motions = bodies.motions(robot, np.concatenate([np.eye(nv), qd.T], 1))
    J, gamma = np.zeros((rows.nlambda, nv)), np.zeros((rows.nlambda, K))
    for name, kind, start in zip(rows.frames, rows.kinds, rows.starts, strict=True):
        f = mdl.frame_names.index(name)
        k = int(mdl.frame_link[f])
        if k < 0 and not robot.floating:  # the fixed base: no motion, zero rows
            continue
        R_k = bodies.R[k] if k >= 0 else bodies.R0
        R_F, r = R_k @ mdl.frame_R[f], (R_k @ mdl.frame_p[f])[:, None]
        w, wd, v_o, a_o = motions[k]  # k = -1 on a floating base: the base body, last
        v_F = v_o + np.cross(w, r, axis=0)
        a_F = a_o + np.cross(wd, r, axis=0) + np.cross(w, np.cross(w, r, axis=0), axis=0)  # classical, world
        if kind == "point":
            J[start : start + 3], gamma[start : start + 3] = v_F[:, :nv], a_F[:, nv:]
        else:
            J[start : start + 6] = np.vstack([R_F.T @ v_F[:, :nv], R_F.T @ w[:, :nv]])
            spatial = a_F[:, nv:] - np.cross(w[:, nv:], v_F[:, nv:], axis=0)
            gamma[start : start + 6] = np.vstack([R_F.T @ spatial, R_F.T @ wd[:, nv:]])
    return Kinematics(J, gamma.T)


def checked_state(where: str, robot, params, **vectors) -> list[np.ndarray]:
    """One state's vectors, checked: q (NQ entries), the others NV (floating) or n (fixed)."""
    named = [(k, v) for k, v in vectors.items()]
    if getattr(robot, "floating", False) is True:
        _, out, single = floating_inputs(
            where, robot, params, *((k, v, "q" if k == "q" else "v") for k, v in named)
        )
    else:
        _, out, single = checked_inputs(where, robot, params, *named)
    if not single:
        raise SymdynError(f"{where}: robot '{robot.name}': give one state (vectors, not rows of states)")
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
    return contact_kinematics(robot, rows, q, np.zeros((0, robot.nv)), params).jacobian


def contact_drift(robot, contacts, q, qd, params=None) -> np.ndarray:
    """gamma = Jc_dot qd (NLAMBDA,) at (q, qd): the points' classical accelerations (world axes),
    the 6d frames' spatial accelerations (their own axes), at qdd = 0.

    Raises:
        SymdynError: bad contacts, vectors or parameter values.
    """
    rows = _contacts(robot, contacts, "contact_drift")
    q, qd = checked_state("contact_drift", robot, params, q=q, qd=qd)
    return contact_kinematics(robot, rows, q, qd[None], params).drift[0]


def checked_mask(robot, rows: ContactRows, active, where: str) -> np.ndarray:
    """The mask as NCONTACT booleans (None: every contact active)."""
    count = len(rows.frames)
    if active is None:
        return np.ones(count, dtype=bool)
    try:
        a = np.asarray(active, dtype=float)
    except (TypeError, ValueError):
        raise SymdynError(
            f"{where}: robot '{robot.name}': active must hold numbers, got {active!r}"
        ) from None
    if a.shape != (count,) or not np.all((a == 0) | (a == 1)):
        raise SymdynError(
            f"{where}: robot '{robot.name}': active must be {count} entries of 0 or 1 (one per contact), "
            f"got {np.asarray(active).tolist()!r}"
        )
    return a == 1


def checked_number(robot, value, name: str, low: float, high: float, where: str) -> float:
    """A finite number in [low, high] (damping, restitution)."""
    try:
        x = float(value)
    except (TypeError, ValueError):
        raise SymdynError(f"{where}: robot '{robot.name}': {name} must be a number, got {value!r}") from None
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


def _unique(Q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The distinct rows of Q (in first-seen order) and, per row of Q, its index among them."""
    keys = [x.tobytes() for x in Q]
    first: dict[bytes, int] = {}
    for i, key in enumerate(keys):
        first.setdefault(key, i)
    position = {key: u for u, key in enumerate(first)}
    return Q[list(first.values())], np.array([position[key] for key in keys], dtype=int)


def constrained(robot, rows, mask, Q, QD, TAU, params, damping: float, where: str, *, friction: bool = True):
    """(qdd (N, NV), lambda (N, NLAMBDA)) of N checked states: the KKT system (module docstring),
    one Jc, M and kinematic pass per distinct q."""
    distinct, index = _unique(Q)
    M = mass_matrix(robot, distinct, params)
    h = rnea(robot, Q, QD, np.zeros_like(QD), params, friction=friction)
    r = rows.rows(mask)
    qdd, lam = np.zeros_like(QD), np.zeros((len(Q), rows.nlambda))
    for u in range(len(distinct)):
        which = np.flatnonzero(index == u)
        kin = contact_kinematics(robot, rows, distinct[u], QD[which], params)
        for k, i in enumerate(which):
            qdd[i], lam[i, r] = kkt_solve(
                M[u], kin.jacobian[r], TAU[i] - h[i], -kin.drift[k, r], damping, where
            )
    return qdd, lam


def impulse(robot, rows, mask, Q, QD, params, restitution: float, damping: float, where: str):
    """(qd_plus (N, NV), impulse (N, NLAMBDA)) of N checked states: M dqd = Jc^T P, Jc qd+ = -e Jc qd."""
    distinct, index = _unique(Q)
    M = mass_matrix(robot, distinct, params)
    r = rows.rows(mask)
    jump, P = np.zeros_like(QD), np.zeros((len(Q), rows.nlambda))
    for u in range(len(distinct)):
        J = contact_kinematics(robot, rows, distinct[u], np.zeros((0, robot.nv)), params).jacobian[r]
        for i in np.flatnonzero(index == u):
            con = -(1 + restitution) * J @ QD[i]
            jump[i], P[i, r] = kkt_solve(M[u], J, np.zeros(robot.nv), con, damping, where)
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
