"""Ellipsoids and zonotopes of the dynamic conditioning analysis (lecture slides 21-23), in NumPy.

* Generalized inertia ellipsoid {M qdd : |qdd| <= 1} (joint-torque space): principal
  axes the eigenvectors of M M^T, semi-axis lengths the square roots of its
  eigenvalues (the singular values of M), largest first.
* Dynamic manipulability ellipsoid (task space): with A = J M^-1 L (L = diag of the
  torque limits), (xdd - v_bias)^T (A A^T)^-1 (xdd - v_bias) <= 1; its measure
  kappa_d = sqrt(det[J (M^T M)^-1 J^T]) (the lecture prints it without the root).
* Acceleration polytope {A tau_hat + v_bias : |tau_hat_i| <= 1}, a zonotope: in 2-D
  the convex hull (monotone chain) of the 2^n images of the torque cube's vertices,
  counter-clockwise; in 3 or more dimensions its extreme points found facet by facet.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from itertools import combinations, product

import numpy as np

__all__ = [
    "InertiaEllipsoid",
    "DynamicManipulability",
    "AccelerationPolytope",
    "inertia_ellipsoid",
    "dynamic_manipulability",
    "ellipse_points",
    "convex_hull_2d",
    "zonotope_vertex_signs",
    "acceleration_polytope",
]

MAX_ENUMERATED_JOINTS = 16  # 2^n images enumerated for the 2-D hull up to this many joints
TOL = 1e-10


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
    """The ellipsoid {M qdd : |qdd| <= 1} of a mass matrix M (slide 21), from the eigenpairs of M M^T."""
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
    """kappa_d = sqrt(det[J (M^T M)^-1 J^T]) and the ellipsoid of J M^-1 L around `bias` (slide 23)."""
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
