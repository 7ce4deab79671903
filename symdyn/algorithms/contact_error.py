"""Baumgarte's stabilisation of contacts: the position error of each contact against its anchor and
the stabilised constraint, symbolic (docs/contacts.md, "Baumgarte stabilisation").

An anchor is the pose a contact should keep, 12 numbers per contact (ANCHOR_SIZE): its origin p_a
(world), then its rotation R_a (world_R_anchor) row-major. With p, R the contact frame's origin and
rotation at q (world_T_F), the error e(q) has the contact's rows (symdyn.algorithms.contacts):

* point (3 rows, world axes):       e = p - p_a;
* 6d (6 rows, the frame's axes):    e = [R^T (p - p_a);  vee(skew(R_a^T R))],

    vee(skew(E)) = 1/2 [E_32 - E_23, E_13 - E_31, E_21 - E_12] = sin(theta) u

for E = R_a^T R = exp(theta [u]x). The orientation error is the rotation vector log3(E) = theta u
to first order (sin(theta) = theta - theta^3/6), branch-free and smooth everywhere (no division, no
arccos), and zero only at E = I or at theta = pi: Baumgarte's term corrects small errors (the
drift of a held contact), for which it is log3's to within theta^3/6; log3 itself has no
branch-free form exact both near 0 and near pi. For both kinds de/dt = Jc qd at e = 0 (the rows'
velocities: a point's world-aligned velocity, a 6d frame's local twist), so that the stabilised
constraint of the held rows,

    Jc qdd + gamma = -Kd Jc qd - Kp e(q),

makes each error obey e'' + Kd e' + Kp e = 0 near the anchor (Kp in 1/s^2, Kd in 1/s; Kp = Kd = 0
is the exact constraint Jc qdd + gamma = 0). `stabilised_drift` gives its right-hand side as a
drift gamma + Kd Jc qd + Kp e, for symdyn.algorithms.contact_dynamics.KKT.forward_dynamics.
"""

from __future__ import annotations

from collections.abc import Sequence

import sympy as sp

from ..model.contacts import Contact
from ..symbolic.program import Program

__all__ = ["ANCHOR_SIZE", "anchor_symbols", "contact_error", "stabilised_drift"]

#: the numbers of one anchor: origin (3), then the rotation matrix row-major (9)
ANCHOR_SIZE = 12


def anchor_symbols(ncontact: int) -> tuple[sp.Symbol, ...]:
    """The anchors' NCONTACT * ANCHOR_SIZE symbols, contact by contact (names end in `_c`)."""
    return tuple(sp.Symbol(f"anchor{k + 1}_{i + 1}_c") for k in range(ncontact) for i in range(ANCHOR_SIZE))


def _vee_skew(E: sp.Matrix) -> list[sp.Expr]:
    """vee((E - E^T) / 2): sin(theta) u of the rotation E (module docstring)."""
    half = sp.Rational(1, 2)
    return [half * (E[2, 1] - E[1, 2]), half * (E[0, 2] - E[2, 0]), half * (E[1, 0] - E[0, 1])]


def contact_error(
    frames, contacts: Sequence[Contact], anchors: Sequence[sp.Expr], program: Program
) -> list[sp.Expr]:
    """e(q) (NLAMBDA entries, named) of `contacts` against `anchors` (module docstring).

    Args:
        frames: the robot's frame quantities (FrameKinematics or FloatingFrames) over `program`,
            whose pose(frame) is world_T_F.
        contacts: the contacts, rows in their order.
        anchors: NCONTACT * ANCHOR_SIZE entries (anchor_symbols).
        program: receives the named intermediates.
    """
    assert len(anchors) == ANCHOR_SIZE * len(contacts), "one anchor per contact"
    rows: list[sp.Expr] = []
    for k, c in enumerate(contacts):
        a = anchors[ANCHOR_SIZE * k : ANCHOR_SIZE * (k + 1)]
        T = frames.pose(c.frame)
        d = [T[i, 3] - a[i] for i in range(3)]
        if c.kind == "point":
            rows += d
            continue
        R, Ra = T[:3, :3], sp.Matrix(3, 3, list(a[3:]))
        rows += [sp.Add(*[R[j, i] * d[j] for j in range(3)]) for i in range(3)]
        E = Ra.T * sp.Matrix(R)
        rows += _vee_skew(E)
    return [program.let(e, "ce") for e in rows]


def stabilised_drift(
    Jc: sp.Matrix,
    gamma: Sequence[sp.Expr],
    qd: Sequence[sp.Expr],
    error: Sequence[sp.Expr],
    kp: sp.Expr,
    kd: sp.Expr,
    program: Program,
) -> list[sp.Expr]:
    """gamma + Kd Jc qd + Kp e: the drift whose constraint Jc qdd + (it) = 0 is Baumgarte's
    (module docstring), row by row, named."""
    out = []
    for r in range(Jc.rows):
        velocity = sp.Add(*[Jc[r, j] * qd[j] for j in range(Jc.cols) if Jc[r, j] != 0])
        out.append(program.let(gamma[r] + kd * program.let(velocity, "cv") + kp * error[r], "cb"))
    return out
