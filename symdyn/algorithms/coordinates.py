"""Body dynamics projected onto the independent coordinates (mimic joints), symbolically.

The recursions run on the nb bodies with one joint position, rate and acceleration per
body. When some joints mimic others (q_j = multiplier q_i + offset, symdyn.model.topology),
the body rates are qd_b = S qd with S the sparse nb x n selection matrix, and by virtual
work (the power tau^T qd equals tau_b^T qd_b for every qd) the dynamics on the n
independent coordinates are

    M = S^T M_b S,   C = S^T C_b S,   V = S^T V_b,   G = S^T G_b,   tau = S^T tau_b

(Featherstone, Rigid Body Dynamics Algorithms (2008), sec. 8.2, a joint-space constraint
qd_b = S qd with constant S). Each entry is formed directly as a sum over the nonzero
entries of S, M[a, b] = sum m_i m_k M_b[i, k] over the bodies i of coordinate a and k of
coordinate b, so exact zeros of M_b stay exact zeros; nothing multiplies dense matrices of
expressions. A robot without mimic joints has S = 1 and its body dynamics are returned as
they are.
"""

from __future__ import annotations

from collections.abc import Sequence

import sympy as sp

from ..model.robot import Robot
from ..spatial import vectors as v3
from ..symbolic.program import Program

__all__ = ["has_mimic", "coordinate_bodies", "project_vector", "project_matrix"]


def has_mimic(robot: Robot) -> bool:
    """Whether some joint mimics another (then n < nb and S is not the identity)."""
    return robot.n != robot.nb


def coordinate_bodies(robot: Robot) -> list[list[tuple[int, sp.Expr]]]:
    """Per independent coordinate a, the nonzero entries of column a of S.

    Returns:
        n lists of (body index i, multiplier S[i, a]), bodies in increasing order.
    """
    out: list[list[tuple[int, sp.Expr]]] = [[] for _ in range(robot.n)]
    for i, c in enumerate(robot.coordinates):
        out[c.index].append((i, sp.sympify(c.multiplier)))
    return out


def project_vector(robot: Robot, v_b: Sequence[sp.Expr], program: Program, hint: str) -> list[sp.Expr]:
    """S^T v_b: a body vector (efforts tau_b, V_b, G_b) on the independent coordinates.

    Args:
        robot: the model, nb bodies and n independent coordinates.
        v_b: nb entries, one per body (joint space of the bodies).
        program: receives the named entries.
        hint: the name hint of the entries.

    Returns:
        n entries; v_b itself (as a list) when the robot has no mimic joint.
    """
    assert len(v_b) == robot.nb, (len(v_b), robot.nb)
    if not has_mimic(robot):
        return list(v_b)
    return [
        program.let(v3.sum_terms(v3.product(m, v_b[i]) for i, m in bodies), hint)
        for bodies in coordinate_bodies(robot)
    ]


def project_matrix(robot: Robot, A_b: sp.Matrix, program: Program, hint: str) -> sp.Matrix:
    """S^T A_b S: a body matrix (M_b, C_b) on the independent coordinates.

    Args:
        robot: the model, nb bodies and n independent coordinates.
        A_b: nb x nb (joint space of the bodies).
        program: receives the named entries.
        hint: the name hint of the entries.

    Returns:
        n x n; A_b itself when the robot has no mimic joint. Entry (a, b) sums
        m_i m_k A_b[i, k] over the bodies i of coordinate a and k of coordinate b, skipping
        exact zeros of A_b.
    """
    assert A_b.shape == (robot.nb, robot.nb), (A_b.shape, robot.nb)
    if not has_mimic(robot):
        return A_b
    columns = coordinate_bodies(robot)
    n = robot.n
    A = sp.zeros(n, n)
    for a in range(n):
        for b in range(n):
            terms = (
                v3.product(v3.product(mi, mk), A_b[i, k]) for i, mi in columns[a] for k, mk in columns[b]
            )
            A[a, b] = program.let(v3.sum_terms(terms), hint)
    return A
