"""The oracle's check that M(q) can be inverted before forward dynamics solves M qdd = b.

M (joint space, N states) is factorised M = L D L^T, coordinates first to last, pivots

    D_j = M_jj - sum_{k<j} L_jk^2 D_k    (the diagonal of the Schur complements).

M is positive semi-definite, so a pivot that vanishes (at most TOL times the largest diagonal
entry of that state's M: rounding leaves a true zero at a few ulps of it) makes M singular.
The message names the joint as the robot file does (the joint of link 'X') and the cause,
found from the numeric model: the bodies the coordinate moves have no mass or inertia
("massless"), or they have mass but M_jj vanishes, all of it on the joint's axis ("on_axis"),
or the joint moves them only as the joints before it do ("dependent").
"""

from __future__ import annotations

import numpy as np

from ..errors import SINGULAR_REASONS, SymdynError
from .inputs import NumericModel

__all__ = ["TOL", "check_invertible"]

#: A pivot at most TOL times the largest diagonal entry of M counts as zero.
TOL = 64 * np.finfo(float).eps


def _pivots(M: np.ndarray) -> np.ndarray:
    """The pivots D (N, n) of M = L D L^T (N, n, n), a pivot that vanishes (see TOL) set to
    exactly zero and its column of L taken as zero (M positive semi-definite)."""
    A = np.array(M, dtype=float)
    n = A.shape[-1]
    scale = np.max(np.abs(np.diagonal(A, axis1=-2, axis2=-1)), axis=-1)
    D = np.zeros(A.shape[:-1])
    for j in range(n):
        d = A[:, j, j]
        zero = d <= TOL * scale
        D[:, j] = np.where(zero, 0.0, d)
        safe = np.where(zero, 1.0, d)
        lj = np.where(zero[:, None], 0.0, A[:, j + 1 :, j] / safe[:, None])
        A[:, j + 1 :, j + 1 :] -= lj[:, :, None] * A[:, j, None, j + 1 :]
    return D


def _subtree(mdl: NumericModel, c: int) -> list[int]:
    """The bodies that coordinate c moves: those whose joint follows it, and their subtrees."""
    moved = [mdl.coordinate[i] == c for i in range(mdl.nb)]
    for i in range(mdl.nb):  # parents come before children
        if mdl.parent[i] >= 0 and moved[mdl.parent[i]]:
            moved[i] = True
    return [i for i in range(mdl.nb) if moved[i]]


def _reason(mdl: NumericModel, M: np.ndarray, c: int) -> str:
    """Why the pivot of coordinate c vanishes in M (n, n): a key of SINGULAR_REASONS."""
    bodies = _subtree(mdl, c)
    own = [i for i in range(mdl.nb) if mdl.coordinate[i] == c]
    turns = any(mdl.revolute[i] for i in own)
    rotor = any(mdl.reflected[i] != 0 for i in own)
    mass = any(mdl.mass[i] != 0 for i in bodies)
    inertia = any(np.any(mdl.inertia[i] != 0) for i in bodies)
    if not rotor and not mass and (not turns or not inertia):
        return "massless"
    if M[c, c] <= TOL * np.max(np.abs(np.diagonal(M))):
        return "on_axis"
    return "dependent"


def check_invertible(mdl: NumericModel, M: np.ndarray, where: str) -> None:
    """Raise SymdynError when M (N, n, n) is singular at a state: which joints, and why
    (module docstring); the first such state is reported, by its index in a batch."""
    D = _pivots(M)
    bad = np.flatnonzero(np.any(D == 0.0, axis=1))
    if not bad.size:
        return
    k = int(bad[0])
    joints = []
    for c in np.flatnonzero(D[k] == 0.0).tolist():
        i = int(mdl.own[c])
        joints.append(
            f"the joint of link '{mdl.names[i]}' (link {i + 1}) {SINGULAR_REASONS[_reason(mdl, M[k], c)]}"
        )
    at = f" at state {k} of the batch" if len(M) > 1 else ""
    raise SymdynError(f"{where}: robot '{mdl.name}': M(q) is singular{at}: {'; '.join(joints)}")
