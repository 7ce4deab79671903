"""Product-of-exponentials data (Lynch and Park, "Modern Robotics" (2017), ch. 8) onto the
general joint model of `symdyn.model.robot`.

Modern Robotics describes a serial chain of n links by
  - M_{i-1,i} (i = 1 .. n+1): the home frame {i} of link i's centre of mass in frame {i-1}
    ({0} the space frame, {n+1} the end-effector frame, fixed to link n);
  - G_i = [[I_i, 0], [0, m_i 1]] (6x6, angular part first): link i's spatial inertia in {i};
  - S_i = [omega_i; v_i]: joint i's screw axis in the space frame at the home position,
    a revolute joint (|omega| = 1, pitch omega . v = 0, v = -omega x r for a point r on the
    axis) or a prismatic one (omega = 0, |v| = 1).

The model's joint turns (slides) about an axis through the origin of link i's body frame, so
the body frame of link i is its centre-of-mass frame {i} moved onto the joint axis: same
axes, origin the foot r_i = omega_i x v_i of the perpendicular from the space origin to the
axis (the centre of mass itself for a prismatic joint). At the home position

    e^[S_1] q_1 ... e^[S_i] q_i B_i = B_i(q) with B_i = (R_{0,i}, r_i),

so placement_i = B_{i-1}^-1 B_i and the joint axis in the body frame is R_{0,i}^T omega_i
(R_{0,i}^T v_i for a prismatic joint). `Link.frame` records frame {i} in the body frame for
i < n and the end-effector frame {n+1} for the last link: `symdyn.algorithms.tip_wrench`
takes the end-effector wrench F_tip of MR's InverseDynamics in that frame.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence

import sympy as sp

from ..errors import SymdynError
from ..model.bounded import check_bounded
from ..model.expressions import is_c_identifier
from ..model.frames import Frame
from ..model.inertia import check_inertia
from ..model.robot import Link, Robot
from ..spatial.transform import Transform

__all__ = ["PoeLink", "poe_links", "robot_from_poe", "TOLERANCE"]

#: A number within this of the required value passes (|omega| = 1, pitch 0, R^T R = 1, ...).
TOLERANCE = 1e-9

#: fail(message, link index (1-based) or None, field) -> the SymdynError to raise
Fail = Callable[[str, int | None, str], SymdynError]


class PoeLink:
    """One link as Modern Robotics lists it: M_{i-1,i}, G_i and S_i (SymPy entries)."""

    def __init__(self, name: str, M: Transform, G: sp.ImmutableMatrix, S: sp.ImmutableMatrix) -> None:
        self.name, self.M, self.G, self.S = name, M, G, S


def _vanishes(x: sp.Expr) -> bool:
    """x is zero: within TOLERANCE for a number, by simplification for an expression."""
    x = sp.sympify(x, strict=True)  # a number or an expression already parsed, never text
    if not x.free_symbols:
        return abs(complex(sp.N(x))) <= TOLERANCE
    return sp.simplify(x) == 0


def check_rotation(R: sp.ImmutableMatrix, fail: Fail, index: int | None, field: str) -> None:
    """Refuse a matrix that is not a rotation (R^T R = 1, det R = +1)."""
    E = R.T * R - sp.eye(3)
    if not all(_vanishes(e) for e in E):
        raise fail("the rotation is not orthonormal (R^T R != 1)", index, field)
    if not _vanishes(R.det() - 1):
        raise fail("the rotation has determinant -1 (a reflection, not a rotation)", index, field)


def _split_inertia(G: sp.ImmutableMatrix, fail: Fail, index: int, field: str):
    """mass and 3x3 rotational inertia of G = [[I, 0], [0, m 1]] (angular part first)."""
    if G.shape != (6, 6):
        raise fail(f"a spatial inertia is 6x6, got {G.shape[0]}x{G.shape[1]}", index, field)
    m = G[3, 3]
    off = [G[r, c] for r in range(3) for c in range(3, 6)] + [G[r, c] for r in range(3, 6) for c in range(3)]
    lower = [G[3 + r, 3 + c] - (m if r == c else 0) for r in range(3) for c in range(3)]
    if not all(_vanishes(x) for x in off + lower):
        raise fail(
            "G must be [[I, 0], [0, m*1]] (angular part first) in a frame at the centre of mass: "
            "its off-diagonal 3x3 blocks must be zero and its lower-right block m times the identity",
            index,
            field,
        )
    inertia = G[:3, :3]
    if not all(_vanishes(inertia[r, c] - inertia[c, r]) for r in range(3) for c in range(r + 1, 3)):
        raise fail("the rotational inertia (upper-left 3x3 block of G) is not symmetric", index, field)
    return m, sp.ImmutableMatrix(inertia)


def _joint(S: sp.ImmutableMatrix, fail: Fail, index: int, field: str):
    """(joint type, direction in the space frame, a point on the axis or None) of a screw [w; v]."""
    if S.shape != (6, 1):
        raise fail(f"a screw axis has 6 entries [omega; v], got {S.shape[0] * S.shape[1]}", index, field)
    w, v = S[:3, 0], S[3:, 0]
    if all(_vanishes(x) for x in w):
        if not _vanishes(v.dot(v) - 1):
            raise fail(f"a prismatic screw [0; v] needs a unit v, got |v|^2 = {v.dot(v)}", index, field)
        return "prismatic", v, None
    if not _vanishes(w.dot(w) - 1):
        raise fail(
            f"a revolute screw [omega; v] needs a unit omega, got |omega|^2 = {w.dot(w)}", index, field
        )
    pitch = w.dot(v)
    if not _vanishes(pitch):
        raise fail(
            f"screw axis with pitch omega.v = {pitch} (a helical joint): only revolute (pitch 0) and "
            "prismatic (omega = 0) joints are supported",
            index,
            field,
        )
    return "revolute", w, w.cross(v)


def poe_links(
    links: Sequence[PoeLink],
    end_effector: Transform,
    fail: Fail,
    subs: dict | None = None,
    file: str | None = None,
) -> list[Link]:
    """The `Link`s of a chain given as M_{i-1,i}, G_i, S_i (module docstring), in order.

    Args:
        links: the n links; M is the home centre-of-mass frame {i} in {i-1} ({0}: space).
        end_effector: M_{n,n+1}, the end-effector frame in link n's frame {n}.
        fail: builds the SymdynError for a message, a 1-based link index and a field.
        subs: parameter values, to check each mass and inertia (check_inertia) with.
        file: the file named in those checks' messages.
    """
    subs = subs or {}
    out: list[Link] = []
    C = Transform.identity()  # frame {i} at home, space frame
    B_prev = Transform.identity()  # body frame of link i-1 at home, space frame
    for i, link in enumerate(links, start=1):
        check_rotation(link.M.R, fail, i, "M.rotation")
        C = C @ link.M
        m, inertia = _split_inertia(link.G, fail, i, "G")
        check_inertia(m.xreplace(subs), inertia.xreplace(subs), file=file, link_index=i, link_name=link.name)
        joint, direction, point = _joint(link.S, fail, i, "S")
        origin = C.p if point is None else sp.ImmutableMatrix(point)
        B = Transform(C.R, origin)
        frame = B.inverse() @ C
        if i == len(links):
            check_rotation(end_effector.R, fail, None, "end_effector.rotation")
            frame = frame @ end_effector
        out.append(
            Link(
                name=link.name,
                joint=joint,
                placement=_clean(B_prev.inverse() @ B),
                axis=sp.ImmutableMatrix(C.R.T * direction).applyfunc(_tidy),
                mass=m,
                com=sp.ImmutableMatrix(C.R.T * (C.p - origin)).applyfunc(_tidy),
                inertia=inertia,
                frame=_clean(frame),
            )
        )
        B_prev = B
    return out


def _tidy(x: sp.Expr) -> sp.Expr:
    """Exact zeros and ones where float arithmetic left 1e-17 residues or 1.0."""
    x = sp.expand(x)
    if x.free_symbols:
        return x
    if abs(float(x)) <= 1e-15:
        return sp.S.Zero
    return sp.Integer(round(float(x))) if float(x) == round(float(x)) else x


def _clean(T: Transform) -> Transform:
    return Transform(T.R.applyfunc(_tidy), T.p.applyfunc(_tidy))


def _sympy(x) -> sp.Expr:
    """A number or SymPy expression (finite, within symdyn.model.bounded's bounds); integral floats
    become exact integers."""
    if isinstance(x, str):
        raise TypeError("strings are not accepted here; pass numbers or SymPy expressions")
    value = x if isinstance(x, sp.Basic) else sp.sympify(float(x) if hasattr(x, "dtype") else x, strict=True)
    if value.has(sp.oo, -sp.oo, sp.zoo, sp.nan):
        raise ValueError(f"{value} is not finite")
    check_bounded(value, SymdynError)  # finite, at most 1e150, exponents at most 64
    if value.is_Float and float(value) == round(float(value)):
        return sp.Integer(round(float(value)))
    return value


def _matrix(value, rows: int, cols: int, what: str) -> sp.ImmutableMatrix:
    try:
        m = sp.Matrix(value) if not isinstance(value, sp.MatrixBase) else value
        entries = [_sympy(x) for x in m]
    except (TypeError, ValueError, sp.SympifyError) as exc:
        raise SymdynError(f"robot_from_poe: {what} must hold numbers or SymPy expressions ({exc})") from None
    if m.shape != (rows, cols):
        raise SymdynError(f"robot_from_poe: {what} is {m.shape[0]}x{m.shape[1]}, expected {rows}x{cols}")
    return sp.ImmutableMatrix(rows, cols, entries)


def _transform(value, what: str) -> Transform:
    T = _matrix(value, 4, 4, what)
    if list(T[3, :]) != [0, 0, 0, 1]:
        raise SymdynError(f"robot_from_poe: {what} is not homogeneous (last row must be [0, 0, 0, 1])")
    return Transform(sp.ImmutableMatrix(T[:3, :3]), sp.ImmutableMatrix(T[:3, 3]))


def _poe_error(message: str, index: int | None, field: str) -> SymdynError:
    if index is None:
        return SymdynError(f"robot_from_poe: {field}: {message}")
    return SymdynError(f"robot_from_poe: link {index}: {field}: {message}")


def robot_from_poe(Mlist, Glist, Slist, gravity=(0, 0, -9.81), name: str = "poe_robot") -> Robot:
    """A `Robot` from Modern Robotics' lists, as its InverseDynamics takes them.

    Args:
        Mlist: n+1 homogeneous 4x4 matrices M_{i-1,i}: the home centre-of-mass frame {i} of
            link i in frame {i-1}; the last one is the end-effector frame {n+1} in {n}, which
            becomes the frame `end_effector` (symdyn.model.frames).
        Glist: n 6x6 spatial inertias G_i = [[I_i, 0], [0, m_i 1]] in frame {i} (angular first).
        Slist: a 6 x n matrix whose columns are the space-frame screw axes S_i = [omega; v].
        gravity: gravitational acceleration in the space frame (MR's g).
        name: the robot's name (a C identifier: it prefixes generated code).

    Entries may be numbers (NumPy arrays or lists) or SymPy expressions; the free symbols of
    the expressions become the robot's free parameters, in order of first appearance.

    Raises:
        SymdynError: wrong sizes, a non-rotation, a G not of that form, a screw of finite
            nonzero pitch or without a unit direction.
    """
    if not is_c_identifier(name):
        raise SymdynError(f"robot_from_poe: name {name!r} is not a C identifier")
    Ms, Gs = list(Mlist), list(Glist)
    S = _matrix(Slist, 6, len(Gs), f"Slist (6 x n with n = {len(Gs)} links, as Glist)")
    if len(Ms) != len(Gs) + 1:
        raise SymdynError(
            f"robot_from_poe: Mlist has {len(Ms)} frames, expected {len(Gs) + 1} (one per link in Glist "
            "and the end-effector frame)"
        )
    if not Gs:
        raise SymdynError("robot_from_poe: a robot needs at least one link")
    links = [
        PoeLink(
            f"link{i + 1}",
            _transform(Ms[i], f"Mlist[{i}]"),
            _matrix(Gs[i], 6, 6, f"Glist[{i}]"),
            sp.ImmutableMatrix(S[:, i]),
        )
        for i in range(len(Gs))
    ]
    g = _matrix(gravity, 3, 1, "gravity")
    end = _transform(Ms[-1], f"Mlist[{len(Gs)}]")
    built = poe_links(links, end, _poe_error)
    symbols: dict[sp.Symbol, None] = {}
    entries = [x for lk in links for x in (*lk.M.R, *lk.M.p, *lk.G, *lk.S)] + [*end.R, *end.p, *g]
    for x in entries:
        symbols.update(dict.fromkeys(sorted(x.free_symbols, key=str)))
    ee = Frame("end_effector", len(built) - 1, built[-1].frame)
    return Robot(
        name=name, links=tuple(built), gravity=g, params=tuple(symbols), convention="poe", frames=(ee,)
    )
