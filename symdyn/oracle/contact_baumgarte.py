"""The oracle's Baumgarte stabilisation, NumPy only: the contacts' position errors against anchors
and the stabilised constrained forward dynamics (docs/contacts.md, "Baumgarte stabilisation").

Independent of the symbolic code (symdyn.algorithms.contact_error): the contact frames' poses come
from symdyn.oracle.contact_kinematics' own walk of the bodies, the orientation error from the
unit quaternion of E = R_a^T R (Bar-Itzhack's: the eigenvector of the largest eigenvalue of
his symmetric 4 x 4 matrix), not from E's skew part. With (w, x, y, z) = (cos(theta/2),
sin(theta/2) u), sin(theta) u = 2 w (x, y, z), whatever the quaternion's sign. Per contact, its
rows' axes (anchor: its origin p_a, then R_a row-major, ANCHOR numbers):

    point: e = p - p_a (world);   6d: e = [R^T (p - p_a); sin(theta) u] (the frame's axes).

The stabilised dynamics solve the KKT system of symdyn.oracle.contacts with the active rows'
constraint Jc qdd + gamma = -Kd Jc qd - Kp e(q), gains = (Kp, Kd) >= 0:

    (Jc M^-1 Jc^T + mu I) lambda = -(gamma + Kd Jc qd + Kp e) - Jc M^-1 (tau - b - F).
"""

from __future__ import annotations

import numpy as np

from ..errors import SymdynError, shown
from .contact_kinematics import ContactRows, contact_kinematics, contact_poses, contact_rows
from .contact_solve import checked_mask, checked_number, checked_state, float_array, kkt_solve
from .rnea import mass_matrix, rnea

__all__ = ["ANCHOR", "contact_error", "contact_forward_dynamics_baumgarte"]

#: the numbers of one contact's anchor: its origin (3), then its rotation matrix row-major (9)
ANCHOR = 12


def _rows(robot, contacts, where: str) -> ContactRows:
    return contact_rows(robot, getattr(robot, "contacts", ()) if contacts is None else contacts, where)


def _anchors(robot, rows: ContactRows, anchor, where: str) -> np.ndarray:
    """The anchors as (NCONTACT, 12) finite numbers (given so or flat)."""
    count = len(rows.frames)
    a = float_array(robot, anchor, "anchor", where)
    if a.size != ANCHOR * count or a.ndim not in (1, 2) or (a.ndim == 2 and a.shape != (count, ANCHOR)):
        raise SymdynError(
            f"{where}: robot '{robot.name}': anchor must be {count} x {ANCHOR} numbers, got shape {a.shape}"
        )
    if not np.all(np.isfinite(a)):
        raise SymdynError(f"{where}: robot '{robot.name}': anchor has entries that are not finite")
    return a.reshape(count, ANCHOR)


def _sin_axis(E: np.ndarray) -> np.ndarray:
    """sin(theta) u of the rotation E by its unit quaternion (module docstring)."""
    (a, b, c), (d, e, f), (g, h, i) = E
    K = (
        np.array(
            [
                [a - e - i, d + b, g + c, h - f],
                [d + b, e - a - i, h + f, c - g],
                [g + c, h + f, i - a - e, d - b],
                [h - f, c - g, d - b, a + e + i],
            ]
        )
        / 3.0
    )
    quat = np.linalg.eigh(K)[1][:, -1]  # (x, y, z, w)
    return 2.0 * quat[3] * quat[:3]


def _error(robot, rows: ContactRows, q: np.ndarray, anchors: np.ndarray, params) -> np.ndarray:
    poses = contact_poses(robot, rows, q[None], params)[0]
    out = np.zeros(rows.nlambda)
    for T, kind, start, a in zip(poses, rows.kinds, rows.starts, anchors, strict=True):
        d = T[:3, 3] - a[:3]
        if kind == "point":
            out[start : start + 3] = d
            continue
        R, Ra = T[:3, :3], a[3:].reshape(3, 3)
        out[start : start + 3] = R.T @ d
        out[start + 3 : start + 6] = _sin_axis(Ra.T @ R)
    return out


def contact_error(robot, contacts, q, anchor, params=None) -> np.ndarray:
    """e(q) (NLAMBDA,) of the contacts (None: robot.contacts) against their anchors (module
    docstring; anchor (NCONTACT, 12) or flat).

    Raises:
        SymdynError: bad contacts, q, anchor or parameter values.
    """
    where = "contact_error"
    rows = _rows(robot, contacts, where)
    (q,) = checked_state(where, robot, params, q=q)
    return _error(robot, rows, q, _anchors(robot, rows, anchor, where), params)


def contact_forward_dynamics_baumgarte(
    robot, contacts, q, qd, tau, active=None, anchor=None, gains=(0.0, 0.0), params=None, damping=0.0
):
    """(qdd (NV,), lambda (NLAMBDA,)) of M qdd + b + F = tau + Jc^T lambda with the active rows'
    Jc qdd + gamma = -Kd Jc qd - Kp e(q) (module docstring), gains = (Kp, Kd); anchor None: the
    contacts' poses at q (e = 0).

    Raises:
        SymdynError: as symdyn.oracle.contacts.contact_forward_dynamics; bad anchor or gains.
    """
    where = "contact_forward_dynamics_baumgarte"
    rows = _rows(robot, contacts, where)
    q, qd, tau = checked_state(where, robot, params, q=q, qd=qd, tau=tau)
    mask = checked_mask(robot, rows, active, where)
    mu = checked_number(robot, damping, "damping", 0.0, np.inf, where)
    if np.ndim(gains) != 1 or len(gains) != 2:
        raise SymdynError(f"{where}: robot '{robot.name}': gains must be (Kp, Kd), got {shown(gains)}")
    kp, kd = (
        checked_number(robot, g, n, 0.0, np.inf, where) for g, n in zip(gains, ("Kp", "Kd"), strict=True)
    )
    if anchor is None:
        error = np.zeros(rows.nlambda)
    else:
        error = _error(robot, rows, q, _anchors(robot, rows, anchor, where), params)
    J, gamma = (x[0] for x in contact_kinematics(robot, rows, q[None], qd[None], params))
    M = mass_matrix(robot, q[None], params)[0]
    h = rnea(robot, q[None], qd[None], np.zeros((1, robot.nv)), params)[0]
    r = rows.rows(mask)
    con = -(gamma + kd * J @ qd + kp * error)[r]
    lam = np.zeros(rows.nlambda)
    qdd, lam[r] = kkt_solve(M, J[r], tau - h, con, mu, where)
    return qdd, lam
