"""The Coriolis matrix C of a floating robot, Christoffel-consistent: dM/dt = C + C^T, C qd = V.

With body i's spatial inertia I_i, its velocity v_i and its Jacobian J_i (v_i = J_i qd; the free
flyer's six columns included), all in body i's coordinates, and J'_i the time derivative of J_i
taken in an inertial frame and expressed in body i's coordinates,

    C = sum_i J_i^T (I_i J'_i + B(I_i, v_i) J_i),
    B(I, v) c = 1/2 (v x* (I c) - I (v x c) + c x* (I v))

(Echeandia and Wensing, "Numerical methods to compute the Coriolis matrix and Christoffel symbols
for rigid-body systems", J. Comput. Nonlinear Dynam. 16 (2021), eq. 20; the matrix Pinocchio's
computeCoriolisMatrix returns). B + B^T = v x* I - I v x = the rate of I_i, so C + C^T = dM/dt;
B(I, v) v = v x* I v, so C qd is Newton-Euler's V. A column of J_i is the subspace S_k of a joint
k supporting body i, carried into body i's coordinates, S_ik = iX_k S_k, and its inertial rate is
iX_k (v_k x S_k); for the free flyer S_0 is the identity (the base twist in the base frame) and
its rate v_0 x. Motion transforms: iX_p m = (R^T w, R^T (u + w x p)) for the joint frame (R, p).
Columns come in Pinocchio's order: the base's linear then angular velocity, then the joints'.
"""

from __future__ import annotations

from collections.abc import Sequence

import sympy as sp

from ..model.robot import Robot
from ..spatial import vectors as v3
from ..spatial.inertia import SpatialInertia, apply_inertia, body_inertia
from ..spatial.motion import Force, Motion, cross_force, cross_motion, motion_subspace, project
from ..symbolic.program import Program
from .coordinates import project_matrix
from .frames import JointFrame

__all__ = ["floating_coriolis_matrix"]

_UNIT = tuple(tuple(sp.S.One if r == c else sp.S.Zero for r in range(3)) for c in range(3))
#: the free flyer's subspace, Pinocchio's order: unit linear velocities, then unit angular ones
_BASE = tuple(Motion(v3.ZERO3, e) for e in _UNIT) + tuple(Motion(e, v3.ZERO3) for e in _UNIT)


def _to_child(frame: JointFrame, m: Motion, program: Program, hint: str) -> Motion:
    """iX_p m: a motion in the parent's coordinates carried into child i's (frame (R, p))."""
    w, u = m
    if w == v3.ZERO3 and u == v3.ZERO3:
        return m
    return Motion(
        program.let_vector(v3.mul_t(frame.R, w), hint),
        program.let_vector(v3.mul_t(frame.R, v3.add(u, v3.cross(w, frame.p))), hint),
    )


def _named(m: Motion, program: Program, hint: str) -> Motion:
    return Motion(program.let_vector(m.angular, hint), program.let_vector(m.linear, hint))


def _b_times(inertia: SpatialInertia, v: Motion, Iv: Force, c: Motion) -> Force:
    """B(I, v) c = 1/2 (v x* (I c) - I (v x c) + c x* (I v))."""
    first = cross_force(v, apply_inertia(inertia, c))
    second = apply_inertia(inertia, cross_motion(v, c))
    third = cross_force(c, Iv)
    half = sp.Rational(1, 2)
    return Force(
        v3.scale(half, v3.add(first.angular, v3.neg(second.angular), third.angular)),
        v3.scale(half, v3.add(first.linear, v3.neg(second.linear), third.linear)),
    )


def floating_coriolis_matrix(
    robot: Robot, frames: list[JointFrame], base_twist: Sequence, qd_b: Sequence, program: Program
) -> sp.Matrix:
    """C (NV x NV) of a floating robot over the base twist (v, w) (base frame) and the bodies' joint
    rates qd_b (module documentation); projected onto the independent coordinates."""
    nb = robot.nb
    parents = robot.parents
    v0 = _named(Motion(v3.vec(base_twist[3:]), v3.vec(base_twist[:3])), program, "Cv0_")
    # per body: its velocity, and its Jacobian's columns (index, S_ik, rate) in its coordinates
    velocities: list[Motion] = []
    columns: list[list[tuple[int, Motion, Motion]]] = []
    base_columns = [(k, s, cross_motion(v0, s)) for k, s in enumerate(_BASE)]
    for i, link in enumerate(robot.links):
        k = f"C{i + 1}_"
        p = parents[i]
        v_p, cols_p = (v0, base_columns) if p < 0 else (velocities[p], columns[p])
        S = motion_subspace(link.joint, link.axis)
        carried = _to_child(frames[i], v_p, program, k)
        v = _named(
            Motion(
                v3.add(carried.angular, v3.scale(qd_b[i], S.angular)),
                v3.add(carried.linear, v3.scale(qd_b[i], S.linear)),
            ),
            program,
            k,
        )
        velocities.append(v)
        cols = [
            (j, _to_child(frames[i], s, program, k), _to_child(frames[i], r, program, k))
            for j, s, r in cols_p
        ]
        cols.append((6 + i, S, cross_motion(v, S)))
        columns.append(cols)
    C = sp.zeros(nb + 6, nb + 6)
    bodies = [
        (body_inertia(robot.base_body.mass, robot.base_body.com, robot.base_body.inertia), v0, base_columns)
    ]
    bodies += [
        (body_inertia(lk.mass, lk.com, lk.inertia), velocities[i], columns[i])
        for i, lk in enumerate(robot.links)
    ]
    for index, (inertia, v, cols) in enumerate(bodies):
        if inertia.mass == 0 and all(x == 0 for row in inertia.inertia for x in row):
            continue
        Iv = apply_inertia(inertia, v)
        hint = f"CF{index}_"
        forces = []
        for _, s, rate in cols:
            a = apply_inertia(inertia, rate)
            b = _b_times(inertia, v, Iv, s)
            forces.append(
                Force(
                    program.let_vector(v3.add(a.angular, b.angular), hint),
                    program.let_vector(v3.add(a.linear, b.linear), hint),
                )
            )
        for r, s, _ in cols:
            for (c, _, _), f in zip(cols, forces, strict=True):
                C[r, c] += project(s, f)
    C = C.applyfunc(lambda e: program.let(e, "C") if e != 0 else e)
    out = sp.zeros(robot.n + 6, robot.n + 6)
    out[:6, :6] = C[:6, :6]
    S = robot.selection()
    out[:6, 6:] = C[:6, 6:] * S
    out[6:, :6] = S.T * C[6:, :6]
    out[6:, 6:] = project_matrix(robot, C[6:, 6:], program, "C")
    return out
