"""Dynamic conditioning of a manipulator (lecture slides 21-23).

At a state (q, qd), with M, V, G, F from the robot's generated NumPy module
and J the end-effector's geometric Jacobian (base frame; end-effector = origin
of the last convention frame, `kinematics.end_effector_jacobian`), restricted
to the chosen task axes (rows x, y, z, rx, ry, rz):

* Generalized inertia ellipsoid (slide 21): with qd = 0 and no gravity,
  tau = M qdd; the unit sphere of joint accelerations maps onto the ellipsoid
  {M qdd : |qdd| <= 1} in joint-torque space. Its principal axes are the
  eigenvectors of M M^T and its semi-axis *lengths* are the square roots of the
  eigenvalues of M M^T, i.e. the singular values of M (for the symmetric
  positive-definite M, its eigenvalues), sorted from largest to smallest.
* Task-space accelerations (slides 22-23):
      xdd = J qdd + Jdot qd = J M^-1 L tau_hat + v_bias,  L = diag(torque limits),
      v_bias = Jdot qd - J M^-1 (V + G + F) = v_vel + v_grav,
      v_vel = Jdot qd - J M^-1 (V + F),  v_grav = -J M^-1 G.
  Jdot qd is exact: the symbolic time derivative of J, sum_j dJ/dq_j qd_j, times qd.
  F(qd) (friction) is zero at qd = 0 and for frictionless robots.
* Dynamic manipulability ellipsoid: tau_hat^T tau_hat <= 1 gives
      (xdd - v_bias)^T (J M^-1 L^2 M^-T J^T)^-1 (xdd - v_bias) <= 1;
  "matrix" is J M^-1 L^2 M^-T J^T, its semi-axes the square roots of its
  eigenvalues (the singular values of J M^-1 L). The measure reported is
      kappa_d = sqrt(det[J (M^T M)^-1 J^T])    (square root taken; no L),
  while the lecture prints det[J (M^T M)^-1 J^T] without the root
  (`DynamicManipulability.measure_squared`).
* Acceleration polytope: the image {J M^-1 L tau_hat + v_bias : |tau_hat_i| <= 1}
  of the torque hypercube, a zonotope. For a 2-D task space its vertices are the
  convex hull (monotone chain) of the 2^n images of the cube's vertices, in
  counter-clockwise order; in 3 or more dimensions they are the extreme images
  found facet by facet (each facet is normal to a set of generators), sorted.
"""

from __future__ import annotations

import json
import math
import os
from collections.abc import Sequence
from dataclasses import dataclass
from functools import lru_cache
from itertools import combinations, product

import numpy as np
import sympy as sp

from ..algorithms.kinematics import end_effector_jacobian
from ..errors import SymdynError
from ..model.robot import Robot
from ..model.symbols import joint_symbols
from .compiled import CompiledDynamics, compiled_dynamics
from .output import figure, figure_bytes, plot_format, write_atomic

__all__ = [
    "TASK_AXES",
    "InertiaEllipsoid",
    "DynamicManipulability",
    "AccelerationPolytope",
    "Analysis",
    "parse_axes",
    "task_jacobian",
    "inertia_ellipsoid",
    "dynamic_manipulability",
    "acceleration_polytope",
    "convex_hull_2d",
    "zonotope_vertex_signs",
    "analyze",
    "plot_analysis",
    "plot_workspace",
    "ellipse_points",
]

TASK_AXES = ("x", "y", "z", "rx", "ry", "rz")
MAX_ENUMERATED_JOINTS = 16  # 2^n images enumerated for the 2-D hull up to this many joints
TOL = 1e-10
MEASURE_NOTE = "kappa_d = sqrt(det(J (M^T M)^-1 J^T)), square root taken (the lecture prints it without)"
LENGTHS_NOTE = (
    "lengths = sqrt(eigenvalues of M M^T) = singular values of M (semi-axes of {M qdd : |qdd| <= 1})"
)


# --------------------------------------------------------------------------- kinematics


def parse_axes(axes: str | Sequence[str] | None) -> tuple[str, ...] | None:
    """Task axes from "x,y" or a sequence of names among x, y, z, rx, ry, rz (None: default)."""
    if axes is None:
        return None
    names = [a.strip() for a in axes.split(",")] if isinstance(axes, str) else [str(a).strip() for a in axes]
    names = [a for a in names if a]
    if not names:
        raise SymdynError(f"--axes: no axis given (any of {', '.join(TASK_AXES)})")
    bad = [a for a in names if a not in TASK_AXES]
    if bad:
        raise SymdynError(f"--axes: unknown axis {', '.join(bad)} (any of {', '.join(TASK_AXES)})")
    if len(set(names)) != len(names):
        raise SymdynError(f"--axes: repeated axis in {','.join(names)}")
    return tuple(names)


@lru_cache(maxsize=32)
def _kinematics(robot: Robot):
    """(f(q, qd, p) -> (J 6xn, Jdot qd 6), the linear rows not identically zero, free params)."""
    r = robot.resolved()
    q, qd, _ = joint_symbols(r.n)
    J = end_effector_jacobian(r, list(q))
    Jdot = sp.zeros(*J.shape)
    for j in range(r.n):
        Jdot += J.diff(q[j]) * qd[j]
    bias = Jdot * qd
    f = sp.lambdify([list(q), list(qd), list(r.params)], [J, bias], modules="numpy", cse=True)
    live = tuple(TASK_AXES[i] for i in range(3) if any(x != 0 for x in J[i, :]))
    return f, live, r.params


def default_axes(robot: Robot) -> tuple[str, ...]:
    """The linear axes x, y, z whose Jacobian rows are not identically zero (x, y for a planar arm)."""
    live = _kinematics(robot)[1]
    return live or ("x", "y", "z")


def task_jacobian(robot: Robot, q, qd=None, axes=None, params=None) -> tuple[np.ndarray, np.ndarray]:
    """(J, Jdot qd) of the end-effector, rows `axes` (default `default_axes`), as numbers."""
    f, _, free = _kinematics(robot)
    names = parse_axes(axes) or default_axes(robot)
    n = robot.n
    q = _vector(q, n, "q")
    qd = np.zeros(n) if qd is None else _vector(qd, n, "qd")
    values = robot.param_values(params) if robot.params else {}
    by_name = {str(k): v for k, v in values.items()}
    p = [by_name[str(s)] for s in free]
    J, b = f(q, qd, p)
    J = np.asarray(J, dtype=float).reshape(6, n)
    b = np.asarray(b, dtype=float).reshape(6)
    rows = [TASK_AXES.index(a) for a in names]
    return J[rows], b[rows]


def _vector(x, n: int, name: str) -> np.ndarray:
    try:
        a = np.array(x, dtype=float).reshape(-1)
    except (TypeError, ValueError) as exc:
        raise SymdynError(f"{name}: expected numbers, got {x!r}") from exc
    if a.shape != (n,):
        raise SymdynError(f"{name} must have {n} entries (one per joint), got {a.size}")
    if not np.all(np.isfinite(a)):
        raise SymdynError(f"{name} must be finite")
    return a


# --------------------------------------------------------------------------- ellipsoids


def _normalise_signs(vectors: np.ndarray) -> np.ndarray:
    """Each row with its largest-magnitude entry positive (a deterministic sign for eigenvectors)."""
    out = vectors.copy()
    for k, v in enumerate(out):
        if v[np.argmax(np.abs(v))] < 0:
            out[k] = -v
    return out


def _principal(S: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(axes as rows, lengths = sqrt of eigenvalues) of a symmetric PSD matrix, largest first."""
    w, U = np.linalg.eigh((S + S.T) / 2)
    order = np.argsort(w)[::-1]
    lengths = np.sqrt(np.clip(w[order], 0.0, None))
    return _normalise_signs(U[:, order].T), lengths


@dataclass
class InertiaEllipsoid:
    """The generalized inertia ellipsoid {M qdd : |qdd| <= 1} (joint-torque space).

    axes: (n, n), row k the unit direction of axis k (eigenvectors of M M^T);
    lengths: (n,), sqrt(eigenvalues of M M^T) = singular values of M, largest first.
    """

    axes: np.ndarray
    lengths: np.ndarray


def inertia_ellipsoid(M) -> InertiaEllipsoid:
    M = np.asarray(M, dtype=float)
    axes, lengths = _principal(M @ M.T)
    return InertiaEllipsoid(axes, lengths)


@dataclass
class DynamicManipulability:
    """The dynamic manipulability ellipsoid and measure (slide 23).

    measure: kappa_d = sqrt(det[J (M^T M)^-1 J^T]) (square root taken);
    measure_squared: det[J (M^T M)^-1 J^T] as the lecture prints it;
    bias: v_bias (the ellipsoid's centre); matrix: J M^-1 L^2 M^-T J^T;
    axes (rows), lengths: its principal directions and semi-axes (sqrt of eigenvalues).
    """

    measure: float
    measure_squared: float
    bias: np.ndarray
    matrix: np.ndarray
    axes: np.ndarray
    lengths: np.ndarray


def dynamic_manipulability(J, M, torque_limits, bias) -> DynamicManipulability:
    J = np.atleast_2d(np.asarray(J, dtype=float))
    M = np.asarray(M, dtype=float)
    L = np.diag(np.asarray(torque_limits, dtype=float))
    Minv = np.linalg.inv(M)
    A = J @ Minv @ L
    matrix = A @ A.T
    det = float(np.linalg.det(J @ np.linalg.inv(M.T @ M) @ J.T))
    det = max(det, 0.0)  # rounding can make a singular configuration's det slightly negative
    axes, lengths = _principal(matrix)
    return DynamicManipulability(math.sqrt(det), det, np.asarray(bias, dtype=float), matrix, axes, lengths)


def ellipse_points(center, matrix, count: int = 200) -> np.ndarray:
    """Boundary of {c + S^(1/2) u : |u| = 1} for a 2 x 2 PSD shape matrix S: (count, 2)."""
    w, U = np.linalg.eigh(np.asarray(matrix, dtype=float))
    half = U @ np.diag(np.sqrt(np.clip(w, 0, None)))
    th = np.linspace(0, 2 * np.pi, count)
    return np.asarray(center, dtype=float) + (half @ np.vstack([np.cos(th), np.sin(th)])).T


# --------------------------------------------------------------------------- the polytope


def _cross(o, a, b) -> float:
    return (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])


def convex_hull_2d(points, tol: float = 0.0) -> list[int]:
    """Indices of the convex hull's vertices, counter-clockwise from the lowest-x (then y) point.

    Andrew's monotone chain; collinear and repeated points are dropped. `tol` is the
    cross-product magnitude below which three points count as collinear.
    """
    pts = np.asarray(points, dtype=float)
    if len(pts) == 0:
        return []
    order = sorted(range(len(pts)), key=lambda i: (pts[i][0], pts[i][1]))
    uniq: list[int] = []
    for i in order:
        if not uniq or np.any(np.abs(pts[i] - pts[uniq[-1]]) > 0):
            uniq.append(i)
    if len(uniq) <= 2:
        return uniq if len(uniq) < 2 or np.any(pts[uniq[0]] != pts[uniq[1]]) else uniq[:1]

    def chain(idx):
        out: list[int] = []
        for i in idx:
            while len(out) >= 2 and _cross(pts[out[-2]], pts[out[-1]], pts[i]) <= tol:
                out.pop()
            out.append(i)
        return out

    lower = chain(uniq)
    upper = chain(list(reversed(uniq)))
    hull = lower[:-1] + upper[:-1]
    return hull if len(hull) >= 2 else uniq[:1] + uniq[-1:]


def zonotope_vertex_signs(A, tol: float = TOL) -> np.ndarray:
    """Sign vectors s in {-1, 1}^n with A s an extreme point of the zonotope {A t : |t_i| <= 1}.

    A: (d, n). Works in the span of A's columns (rank r): r = 0 one point, r = 1 the
    two ends, r = 2 the monotone-chain hull of the 2^n images (n <= 16), r >= 3 facet
    by facet: every facet is normal to r-1 independent generators, and the facet
    (itself a zonotope of the generators lying in it) is solved one dimension lower.
    Generators that are zero get sign +1.
    """
    A = np.atleast_2d(np.asarray(A, dtype=float))
    n = A.shape[1]
    norms = np.linalg.norm(A, axis=0)
    scale = float(norms.max()) if n else 0.0
    active = norms > tol * max(scale, 1e-300) if scale > 0 else np.zeros(n, dtype=bool)
    if not active.any():
        return np.ones((1, n))
    U, s, _ = np.linalg.svd(A[:, active], full_matrices=False)
    r = int((s > tol * s[0]).sum())
    C = U[:, :r].T @ A  # coordinates in the column span, (r, n)
    idx = np.flatnonzero(active)
    if r == 1:
        sg = np.ones(n)
        sg[idx] = np.where(C[0, idx] >= 0, 1.0, -1.0)
        return np.array([sg, -sg + 2 * (~active)])  # inactive generators keep +1
    if r == 2 and len(idx) <= MAX_ENUMERATED_JOINTS:
        signs = np.array(list(product((-1.0, 1.0), repeat=len(idx))))
        images = signs @ C[:, idx].T
        hull = convex_hull_2d(images, tol * scale * scale)
        out = np.ones((len(hull), n))
        out[:, idx] = signs[hull]
        return out
    found: dict[tuple, None] = {}
    for S in combinations(idx, r - 1):
        CS = C[:, S]
        _, sv, Vt = np.linalg.svd(CS.T)
        if len(sv) < r - 1 or sv[-1] <= tol * scale:
            continue
        u = Vt[-1]  # unit normal to the span of the generators in S
        proj = u @ C
        on_facet = active & (np.abs(proj) <= tol * np.maximum(norms, 1e-300) * 1e3)
        facet = np.flatnonzero(on_facet)
        sub = zonotope_vertex_signs(C[:, facet], tol)
        for sgn_u in (1.0, -1.0):
            base = np.ones(n)
            base[active] = np.where(sgn_u * proj[active] > 0, 1.0, -1.0)
            for row in sub:
                full = base.copy()
                full[facet] = row
                found[tuple(full)] = None
    return np.array(sorted(found))


@dataclass
class AccelerationPolytope:
    """Vertices (k, d) of {J M^-1 L tau_hat + bias : |tau_hat_i| <= 1}, with signs (k, n) = tau_hat there.

    In 2-D counter-clockwise; otherwise sorted lexicographically.
    """

    vertices: np.ndarray
    signs: np.ndarray


def acceleration_polytope(A, bias) -> AccelerationPolytope:
    """The acceleration polytope of generator matrix A = J M^-1 L around `bias`."""
    A = np.atleast_2d(np.asarray(A, dtype=float))
    bias = np.asarray(bias, dtype=float)
    signs = zonotope_vertex_signs(A)
    vertices = signs @ A.T + bias
    if A.shape[0] == 2 and len(vertices) > 2:
        order = convex_hull_2d(vertices)
        if len(order) == len(vertices):
            vertices, signs = vertices[order], signs[order]
    elif A.shape[0] != 2:
        order = np.lexsort(vertices.T[::-1])
        vertices, signs = vertices[order], signs[order]
    return AccelerationPolytope(vertices, signs)


# --------------------------------------------------------------------------- the whole analysis


def _torque_limits(limits, n: int) -> np.ndarray:
    try:
        a = np.array(limits, dtype=float).reshape(-1)
    except (TypeError, ValueError) as exc:
        raise SymdynError(f"torque limits: expected numbers, got {limits!r}") from exc
    if a.size == 1:
        a = np.full(n, a[0])
    if a.shape != (n,):
        raise SymdynError(f"torque limits: expected 1 or {n} values, got {a.size}")
    if not np.all(np.isfinite(a)) or np.any(a <= 0):
        raise SymdynError("torque limits must be positive numbers")
    return a


@dataclass
class Analysis:
    """Everything `analyze` computes at one state (see the module docstring for the formulas).

    `polytope` is the biased acceleration polytope.
    """

    robot: str
    q: np.ndarray
    qd: np.ndarray
    axes: tuple[str, ...]
    torque_limits: np.ndarray
    M: np.ndarray
    V: np.ndarray
    G: np.ndarray
    F: np.ndarray
    J: np.ndarray
    Jdot_qd: np.ndarray
    v_vel: np.ndarray
    v_grav: np.ndarray
    inertia: InertiaEllipsoid
    manipulability: DynamicManipulability
    polytope: AccelerationPolytope

    @property
    def bias(self) -> np.ndarray:
        return self.manipulability.bias

    def to_dict(self) -> dict:
        """The JSON document: the three results under their fixed keys, plus context and notes."""

        def lst(a):
            return (np.asarray(a, dtype=float) + 0.0).tolist()  # + 0.0 turns -0.0 into 0.0

        return {
            "robot": self.robot,
            "q": lst(self.q),
            "qd": lst(self.qd),
            "task_axes": list(self.axes),
            "torque_limits": lst(self.torque_limits),
            "inertia_ellipsoid": {"axes": lst(self.inertia.axes), "lengths": lst(self.inertia.lengths)},
            "dynamic_manipulability": {
                "measure": float(self.manipulability.measure),
                "bias": lst(self.manipulability.bias),
                "matrix": lst(self.manipulability.matrix),
            },
            "acceleration_polytope": {"vertices": lst(self.polytope.vertices)},
            "notes": {
                "inertia_ellipsoid": "axes: unit eigenvectors of M M^T (rows, joint space); " + LENGTHS_NOTE,
                "measure": MEASURE_NOTE,
                "bias": "v_bias = Jdot qd - J M^-1 (V + G + F), task axes as listed",
                "matrix": "J M^-1 L^2 M^-T J^T, L = diag(torque_limits): the ellipsoid "
                "(xdd - bias)^T matrix^-1 (xdd - bias) <= 1",
                "vertices": "extreme points of {J M^-1 L tau_hat + bias : |tau_hat_i| <= 1}"
                + (", counter-clockwise" if len(self.axes) == 2 else ", sorted"),
            },
        }

    def to_json(self) -> str:
        return json.dumps(self.to_dict(), indent=2) + "\n"

    def to_text(self) -> str:
        def vec(a):
            return "(" + ", ".join(f"{x + 0.0:.6g}" for x in np.asarray(a, dtype=float)) + ")"

        dm = self.manipulability
        lines = [
            f"# {self.robot} at q = {vec(self.q)}, qd = {vec(self.qd)}",
            f"# task axes {', '.join(self.axes)} (end-effector, base frame); "
            f"torque limits |tau_i| <= {vec(self.torque_limits)}",
            "",
            "inertia ellipsoid {M qdd : |qdd| <= 1} (joint-torque space):",
            f"  {LENGTHS_NOTE}",
        ]
        for k, (a, length) in enumerate(zip(self.inertia.axes, self.inertia.lengths, strict=True), 1):
            lines.append(f"  axis {k}: length {length:.6g}  direction {vec(a)}")
        lines += [
            "",
            "dynamic manipulability:",
            f"  measure {MEASURE_NOTE}: {dm.measure:.6g}",
            f"  (without the square root, as the lecture prints it: {dm.measure_squared:.6g})",
            f"  bias v_bias = Jdot qd - J M^-1 (V + G + F) = {vec(dm.bias)}",
            f"    velocity part Jdot qd - J M^-1 (V + F) = {vec(self.v_vel)}, gravity part -J M^-1 G = "
            f"{vec(self.v_grav)}",
            "  matrix J M^-1 L^2 M^-T J^T =",
        ]
        lines += [f"    {vec(row)}" for row in dm.matrix]
        for k, (a, length) in enumerate(zip(dm.axes, dm.lengths, strict=True), 1):
            lines.append(f"  ellipsoid semi-axis {k}: {length:.6g} along {vec(a)}")
        order = "counter-clockwise" if len(self.axes) == 2 else "sorted"
        lines += [
            "",
            f"acceleration polytope {{J M^-1 L tau_hat + v_bias : |tau_hat_i| <= 1}}: "
            f"{len(self.polytope.vertices)} vertices ({order}; tau_hat at each vertex):",
        ]
        for v, s in zip(self.polytope.vertices, self.polytope.signs, strict=True):
            signs = " ".join("+" if x > 0 else "-" for x in s)
            lines.append(f"  {vec(v)}  [{signs}]")
        return "\n".join(lines) + "\n"


def analyze(
    robot: Robot,
    q,
    qd=None,
    torque_limits=1.0,
    axes=None,
    params=None,
    dynamics: CompiledDynamics | None = None,
) -> Analysis:
    """Inertia ellipsoid, dynamic manipulability and acceleration polytope at (q, qd).

    torque_limits: one bound for every joint or one per joint (N m or N); axes: task
    rows of the end-effector Jacobian (default: the linear axes that move, e.g. x, y
    for a planar arm). `dynamics` reuses a CompiledDynamics of the same robot.
    """
    n = robot.n
    q = _vector(q, n, "q")
    qd = np.zeros(n) if qd is None else _vector(qd, n, "qd")
    limits = _torque_limits(torque_limits, n)
    names = parse_axes(axes) or default_axes(robot)
    dyn = dynamics if dynamics is not None else compiled_dynamics(robot, params)
    M = np.asarray(dyn.mass_matrix(q), dtype=float)
    V = np.asarray(dyn.coriolis(q, qd), dtype=float)
    G = np.asarray(dyn.gravity(q), dtype=float)
    F = np.asarray(dyn.friction(qd), dtype=float)
    J, Jdq = task_jacobian(robot, q, qd, names, params)
    try:
        Minv = np.linalg.inv(M)
    except np.linalg.LinAlgError as exc:
        raise SymdynError(f"the mass matrix is singular at q = {q.tolist()}") from exc
    v_vel = Jdq - J @ Minv @ (V + F)
    v_grav = -J @ Minv @ G
    bias = v_vel + v_grav
    A = J @ Minv @ np.diag(limits)
    return Analysis(
        robot=robot.name,
        q=q,
        qd=qd,
        axes=names,
        torque_limits=limits,
        M=M,
        V=V,
        G=G,
        F=F,
        J=J,
        Jdot_qd=Jdq,
        v_vel=v_vel,
        v_grav=v_grav,
        inertia=inertia_ellipsoid(M),
        manipulability=dynamic_manipulability(J, M, limits, bias),
        polytope=acceleration_polytope(A, bias),
    )


# --------------------------------------------------------------------------- plots


def _unit(axis: str) -> str:
    return "rad/s²" if axis.startswith("r") else "m/s²"


def _closed(points: np.ndarray) -> np.ndarray:
    return np.vstack([points, points[:1]])


def _draw_shapes(ax, a: Analysis, origin=(0.0, 0.0), scale: float = 1.0, swap=False, labels=True) -> None:
    """Unbiased ellipse, biased ellipse, biased polytope and the bias arrow, scaled and shifted."""

    def tr(p):
        p = np.atleast_2d(p) * scale + np.asarray(origin)
        return (p[:, 1], p[:, 0]) if swap else (p[:, 0], p[:, 1])

    dm = a.manipulability
    zero = np.zeros(2)
    poly = a.polytope.vertices
    biased = "gravity-biased" if not np.any(a.qd) else "biased (gravity and velocity)"
    if len(poly) > 2:
        ax.fill(*tr(_closed(poly)), color="C2", alpha=0.18, lw=0)
    ax.plot(*tr(_closed(poly)), color="C2", lw=1.6, label=f"polytope, {biased}" if labels else None)
    ax.plot(
        *tr(ellipse_points(zero, dm.matrix)),
        color="C0",
        lw=1.4,
        ls="--",
        label="ellipse, unbiased" if labels else None,
    )
    ax.plot(
        *tr(ellipse_points(dm.bias, dm.matrix)),
        color="C3",
        lw=1.6,
        label=f"ellipse, {biased}" if labels else None,
    )
    (x0,), (y0,) = tr(zero)
    (x1,), (y1,) = tr(dm.bias)
    ax.annotate(
        "",
        xy=(x1, y1),
        xytext=(x0, y0),
        arrowprops={"arrowstyle": "-|>", "color": "k", "lw": 1.3, "mutation_scale": 9},
    )
    ax.plot([x0], [y0], "k.", ms=4, label="bias v_bias (arrow from zero)" if labels else None)


def _gravity_layout(robot: Robot, axes: tuple[str, ...], params=None) -> tuple[bool, bool, bool]:
    """(swap, invert vertical, invert horizontal) so that gravity points down on the page."""
    from ..rnea import numeric_model

    g = numeric_model(robot, robot.param_values(params) if robot.params else None).gravity
    idx = [TASK_AXES.index(a) for a in axes]
    g2 = np.array([g[i] if i < 3 else 0.0 for i in idx])
    if not np.any(g2):
        return False, False, False
    k = int(np.argmax(np.abs(g2)))
    if abs(g2[1 - k]) > 1e-9 * abs(g2[k]):
        return False, False, False  # gravity not along an axis: plain layout
    swap = k == 0  # the gravity axis goes vertical
    inv_v = g2[k] > 0  # positive gravity component points down
    # a swap is a reflection; inverting one axis makes the page a proper rotation again
    inv_h = swap != inv_v
    return swap, inv_v, inv_h


def plot_analysis(
    a: Analysis, path: str | os.PathLike | None = None, robot: Robot | None = None, params=None
) -> bytes:
    """Task-space acceleration plot (2 axes only): unbiased and biased ellipses, biased polytope."""
    if len(a.axes) != 2:
        raise SymdynError(f"--plot draws a 2-D task space: give two --axes (got {','.join(a.axes)})")
    fmt = plot_format(path) if path is not None else "png"
    fig = figure(1, width=6.4, height_per_row=6.0)
    ax = fig.subplots()
    swap, inv_v, inv_h = (
        _gravity_layout(robot, a.axes, params) if robot is not None else (False, False, False)
    )
    _draw_shapes(ax, a, swap=swap)
    h, v = (a.axes[1], a.axes[0]) if swap else a.axes
    ax.set_xlabel(f"acceleration {h} ({_unit(h)})")
    ax.set_ylabel(f"acceleration {v} ({_unit(v)})" + (", gravity down" if inv_v else ""))
    if inv_v:
        ax.invert_yaxis()
    if inv_h:
        ax.invert_xaxis()
    ax.set_aspect("equal", adjustable="datalim")
    ax.grid(True, alpha=0.3)
    ax.legend(loc="best", fontsize="small")
    q = ", ".join(f"{x:.3g}" for x in a.q)
    qd = f", qd = ({', '.join(f'{x:.3g}' for x in a.qd)})" if np.any(a.qd) else ""
    lim = ", ".join(f"{x:.3g}" for x in a.torque_limits)
    ax.set_title(
        f"{a.robot}: q = ({q}){qd}, |tau_i| <= ({lim})\n"
        f"kappa_d = sqrt(det J (M^T M)^-1 J^T) = {a.manipulability.measure:.4g}",
        fontsize="medium",
    )
    data = figure_bytes(fig, fmt)
    if path is not None:
        write_atomic(path, data)
    return data


def plot_workspace(
    robot: Robot,
    analyses: Sequence[Analysis],
    path: str | os.PathLike | None = None,
    scale: float | None = None,
    params=None,
    title: str | None = None,
) -> bytes:
    """The slide-24 picture: the arm at each analysed configuration, and at its hand the
    unbiased ellipse, the gravity-biased ellipse and the gravity-biased polytope, drawn
    to scale (`scale` metres per unit acceleration; automatic when None). Axes x, y only.
    """
    from ..algorithms.kinematics import numeric_pose

    if not analyses:
        raise SymdynError("plot_workspace needs at least one analysis")
    axes = analyses[0].axes
    if any(a.axes != axes for a in analyses) or len(axes) != 2 or any(x not in ("x", "y", "z") for x in axes):
        raise SymdynError("plot_workspace draws two linear task axes (e.g. x,y), the same for all analyses")
    fmt = plot_format(path) if path is not None else "png"
    rows = [TASK_AXES.index(x) for x in axes]
    frames = [lk.frame.p for lk in robot.resolved().links]  # points with the values substituted
    arms, hands = [], []
    for a in analyses:
        pts = [np.zeros(2)]
        for k in range(robot.n):
            T = numeric_pose(robot, a.q, link=k, point=list(frames[k]), params=params)
            pts.append(T[rows, 3])
        arms.append(np.array(pts))
        hands.append(pts[-1])
    hands_arr = np.array(hands)
    if scale is None:
        extent = max(
            float(np.max(np.linalg.norm(np.vstack([a.polytope.vertices, a.bias[None, :]]), axis=1)))
            for a in analyses
        )
        gaps = [
            np.linalg.norm(hands_arr[i] - hands_arr[j])
            for i in range(len(hands_arr))
            for j in range(i + 1, len(hands_arr))
        ]
        reach = float(np.max(np.linalg.norm(np.vstack(arms), axis=1)))
        room = 0.5 * min(gaps) if gaps else 0.3 * reach
        scale = room / extent if extent > 0 else 1.0
    swap, inv_v, inv_h = _gravity_layout(robot, axes, params)
    fig = figure(1, width=8.0, height_per_row=7.4)
    ax = fig.subplots()
    for k, (a, arm) in enumerate(zip(analyses, arms, strict=True)):
        xs, ys = (arm[:, 1], arm[:, 0]) if swap else (arm[:, 0], arm[:, 1])
        ax.plot(xs, ys, "-o", color="0.72", lw=1.6, ms=3, zorder=0, label="arm" if k == 0 else None)
        _draw_shapes(ax, a, origin=arm[-1], scale=scale, swap=swap, labels=k == 0)
    ax.plot([0], [0], "ks", ms=7, label="base (joint 1)")
    h, v = (axes[1], axes[0]) if swap else axes
    ax.set_xlabel(f"{h} (m)")
    ax.set_ylabel(f"{v} (m)" + (", gravity down" if inv_v else ""))
    if inv_v:
        ax.invert_yaxis()
    if inv_h:
        ax.invert_xaxis()
    ax.set_aspect("equal", adjustable="datalim")
    ax.grid(True, alpha=0.3)
    ax.legend(loc="upper left", fontsize="small", framealpha=0.9)
    lim = analyses[0].torque_limits
    lim_text = f"{lim[0]:g}" if np.all(lim == lim[0]) else ", ".join(f"{x:g}" for x in lim)
    head = title or f"{robot.name}: hand accelerations for |tau_i| <= {lim_text}"
    ax.set_title(
        f"{head}\nshapes drawn at the hand to scale: 1 m/s² = {scale * 1000:.3g} mm", fontsize="medium"
    )
    data = figure_bytes(fig, fmt)
    if path is not None:
        write_atomic(path, data)
    return data
