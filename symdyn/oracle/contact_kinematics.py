"""The oracle's contact rows, NumPy only: the contacts of a robot checked (frames and kinds), their
Jacobian Jc and drift gamma = Jc_dot qd, for a batch of states.

Independent of the symbolic code (symdyn.algorithms.contacts): it reads only the numeric model
(symdyn.oracle.inputs) and walks the bodies outward in world axes over symdyn.oracle.spatial's
joint poses, each state with NV + 1 velocities at once (the unit vectors e_k, whose frame
velocities are Jc's columns, and qd, whose accelerations at qdd = 0 are the drift). Per body i
with parent p, d = o_i - o_p (world), z = R_i axis_i:

    v_i = v_p + w_p x d,  a_i = a_p + wd_p x d + w_p x (w_p x d)          (origins, classical)
    revolute:  w_i = w_p + z qd_i,  wd_i = wd_p + w_p x z qd_i
    prismatic: v_i += z qd_i,       a_i += 2 w_p x z qd_i

a floating base moving with its body twist constant (w_0 = R v[3:6], v_0 = R v[:3], a_0 = w_0 x
v_0, wd_0 = 0; Pinocchio's a = 0), a fixed base at rest.

Conventions (Pinocchio's, issue 36; q, qd as symdyn.model.free_flyer on a floating base):

* point (Pinocchio's CONTACT_3D, LOCAL_WORLD_ALIGNED): 3 rows, the linear velocity of the
  frame's origin in world axes, v_F = v_k + w_k x r (r the origin from link k's, world axes);
  its drift is the origin's classical acceleration at qdd = 0, a_F = a_k + wd_k x r + w_k x (w_k x r);
* 6d (CONTACT_6D, LOCAL): 6 rows, the frame's spatial velocity in its own axes, linear then
  angular, [R_F^T v_F; R_F^T w_k]; its drift the spatial acceleration in those axes at qdd = 0,
  [R_F^T (a_F - w_k x v_F); R_F^T wd_k] (Pinocchio's getFrameAcceleration(LOCAL), not the
  classical one).

Rows are stacked in the contacts' order: NLAMBDA = 3 a point + 6 a 6d contact.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Sequence

import numpy as np

from ..errors import SHOWN, SymdynError, shown
from .floating import base_rotation
from .inputs import body_positions, body_rates, numeric_model
from .spatial import joint_poses

__all__ = ["KINDS", "ContactRows", "contact_rows", "contact_kinematics", "contact_poses"]


#: the rows of each kind of contact
KINDS = {"point": 3, "6d": 6}


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
    raise SymdynError(
        f"{where}: robot '{robot.name}': contact {i} is not a (frame, kind) pair: {shown(contact)}"
    )


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
            raise SymdynError(
                f"{where}: robot '{robot.name}': contact {i}'s frame is not a name: {shown(frame)}"
            )
        if not isinstance(kind, str) or kind not in KINDS:
            raise SymdynError(
                f"{where}: robot '{robot.name}': contact {i} ({shown(frame)}) has kind {shown(kind)}, "
                "expected 'point' or '6d'"
            )
        if frame not in robot.frame_names:
            if len(frame) <= SHOWN:
                robot.frame(frame, where)  # raises, naming the near matches
            raise SymdynError(f"{where}: robot '{robot.name}': contact {i}: no frame is named {shown(frame)}")
        frames.append(frame)
        kinds.append(kind)
        starts.append(row)
        row += KINDS[kind]
    return ContactRows(tuple(frames), tuple(kinds), tuple(starts), row)


def _cross(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """a x b over the last axis (shapes broadcast)."""
    a, b = np.broadcast_arrays(a, b)
    return np.stack(
        [
            a[..., 1] * b[..., 2] - a[..., 2] * b[..., 1],
            a[..., 2] * b[..., 0] - a[..., 0] * b[..., 2],
            a[..., 0] * b[..., 1] - a[..., 1] * b[..., 0],
        ],
        -1,
    )


def _bodies(robot, mdl, Q: np.ndarray, V: np.ndarray):
    """Per body (the floating base last): (R (N,3,3), o (N,3), w, wd, v, a (N,K,3)), world axes,
    for the configurations Q (N, NQ) and velocities V (N, K, NV) (module docstring)."""
    N, K = V.shape[:2]
    if robot.floating:
        R0, p0, joints = base_rotation(Q[:, 3:7]), Q[:, :3], Q[:, 7:]
        w0 = np.einsum("nij,nkj->nki", R0, V[..., 3:6])
        v0 = np.einsum("nij,nkj->nki", R0, V[..., :3])
        root = (R0, p0, w0, np.zeros_like(w0), v0, _cross(w0, v0))
        rates = body_rates(mdl, V[..., 6:].reshape(N * K, -1)).reshape(N, K, -1)
    else:
        zero = np.zeros((N, K, 3))
        root = (
            np.broadcast_to(mdl.base_R, (N, 3, 3)),
            np.broadcast_to(mdl.base_p, (N, 3)),
            zero,
            zero,
            zero,
            zero,
        )
        joints, rates = Q, body_rates(mdl, V.reshape(N * K, -1)).reshape(N, K, -1)
    out: list[tuple] = []
    for i, (E, r) in enumerate(joint_poses(mdl, body_positions(mdl, joints))):
        p = mdl.parent[i]
        Rp, op, w, wd, v, a = out[p] if p >= 0 else root
        R = Rp @ E
        d = np.einsum("nij,nj->ni", Rp, r)[:, None]
        z = np.einsum("nij,j->ni", R, mdl.axis[i])[:, None] * rates[:, :, i, None]
        v, a = v + _cross(w, d), a + _cross(wd, d) + _cross(w, _cross(w, d))
        if mdl.revolute[i]:
            w, wd = w + z, wd + _cross(w, z)
        else:
            v, a = v + z, a + 2 * _cross(w, z)
        out.append((R, op + d[:, 0], w, wd, v, a))
    return out + [root]


def contact_kinematics(robot, rows: ContactRows, Q: np.ndarray, QD: np.ndarray, params=None):
    """(Jc (N, NLAMBDA, NV), gamma (N, NLAMBDA)) at N checked states Q (N, NQ), QD (N, NV)
    (module docstring). The fixed base's frames have zero rows."""
    mdl = numeric_model(robot, params)
    N, nv = len(Q), robot.nv
    V = np.concatenate([np.broadcast_to(np.eye(nv), (N, nv, nv)), QD[:, None]], 1)
    bodies = _bodies(robot, mdl, Q, V)
    J, gamma = np.zeros((N, rows.nlambda, nv)), np.zeros((N, rows.nlambda))
    for name, kind, start in zip(rows.frames, rows.kinds, rows.starts, strict=True):
        f = mdl.frame_names.index(name)
        k = int(mdl.frame_link[f])  # -1: the base, last in bodies
        if k < 0 and not robot.floating:
            continue
        R, o, w, wd, v, a = bodies[k]
        RF = R @ mdl.frame_R[f]
        r = np.einsum("nij,j->ni", R, mdl.frame_p[f])[:, None]
        vF = v + _cross(w, r)
        aF = a[:, nv] + _cross(wd[:, nv], r[:, 0]) + _cross(w[:, nv], _cross(w[:, nv], r[:, 0]))
        if kind == "point":
            J[:, start : start + 3] = np.swapaxes(vF[:, :nv], 1, 2)
            gamma[:, start : start + 3] = aF
            continue
        RT = np.swapaxes(RF, 1, 2)
        J[:, start : start + 3] = RT @ np.swapaxes(vF[:, :nv], 1, 2)
        J[:, start + 3 : start + 6] = RT @ np.swapaxes(w[:, :nv], 1, 2)
        spatial = aF - _cross(w[:, nv], vF[:, nv])
        gamma[:, start : start + 3] = np.einsum("nij,nj->ni", RT, spatial)
        gamma[:, start + 3 : start + 6] = np.einsum("nij,nj->ni", RT, wd[:, nv])
    return J, gamma


def contact_poses(robot, rows: ContactRows, Q: np.ndarray, params=None) -> np.ndarray:
    """(N, NCONTACT, 4, 4): the contact frames' world poses world_T_F at N checked states Q."""
    mdl = numeric_model(robot, params)
    bodies = _bodies(robot, mdl, Q, np.zeros((len(Q), 1, robot.nv)))
    out = np.zeros((len(Q), len(rows.frames), 4, 4))
    for j, name in enumerate(rows.frames):
        f = mdl.frame_names.index(name)
        R, o = bodies[int(mdl.frame_link[f])][:2]
        out[:, j, :3, :3] = R @ mdl.frame_R[f]
        out[:, j, :3, 3] = o + np.einsum("nij,j->ni", R, mdl.frame_p[f])
        out[:, j, 3, 3] = 1.0
    return out
