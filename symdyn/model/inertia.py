"""Inertia tensors of simple solids, the parallel-axis theorem, rotation and checks.

Convention (URDF, lecture slide 5): the tensor is

    I = [[Ixx, -Pxy, -Pxz], [-Pxy, Iyy, -Pyz], [-Pxz, -Pyz, Izz]]

with the moments Ixx = ∫(y²+z²)ρdV, ... and the lecture's products of inertia
Pxy = ∫xyρdV, ...; the off-diagonal entries returned here are the tensor
entries, i.e. minus those integrals.

Every function works in two modes, chosen by its arguments: if any argument
is a SymPy object (or holds one) the result is an exact 3x3
``sympy.ImmutableMatrix``; otherwise (Python or NumPy numbers) it is a 3x3
NumPy ``float`` array.
"""

from __future__ import annotations

import warnings
from collections.abc import Iterable
from typing import Any

import numpy as np
import sympy as sp

from symdyn.errors import SymdynError, SymdynWarning, location
from symdyn.model.bounded import MAX_MAGNITUDE

__all__ = [
    "box",
    "cylinder",
    "sphere",
    "rod",
    "point_mass",
    "parallel_axis",
    "rotate",
    "principal_axes",
    "check_inertia",
    "tensor_from_components",
]

Tensor = sp.ImmutableMatrix | np.ndarray

_AXES = {"x": 0, "y": 1, "z": 2}


#: Below this (kg m^2) a tensor entry is numerically zero: published URDFs write 1e-35 for none.
ABSOLUTE_TOLERANCE = 1e-15


def _is_symbolic(*args: Any) -> bool:
    """True if any argument is, or (as a sequence/array) contains, a SymPy object."""
    for a in args:
        if isinstance(a, (sp.Basic, sp.MatrixBase)):
            return True
        if isinstance(a, np.ndarray):
            if a.dtype == object and any(_is_symbolic(x) for x in a.flat):
                return True
        elif isinstance(a, Iterable) and not isinstance(a, (str, bytes)) and any(_is_symbolic(x) for x in a):
            return True
    return False


def _diag(symbolic: bool, a: Any, b: Any, c: Any) -> Tensor:
    if symbolic:
        return sp.ImmutableMatrix(sp.diag(a, b, c))
    return np.diag([float(a), float(b), float(c)])


def _scalars(symbolic: bool, *args: Any) -> list[Any]:
    """SymPy-ify (so that m/12 stays exact) or float-ify scalar arguments."""
    return [sp.sympify(a) if symbolic else float(a) for a in args]


def _axis_index(axis: str) -> int:
    try:
        return _AXES[axis]
    except (KeyError, TypeError):
        raise SymdynError(f"axis must be 'x', 'y' or 'z', not {axis!r}") from None


def box(m: Any, w: Any, l: Any, h: Any, about: str = "centre") -> Tensor:
    """Solid box of mass m, sides w (along x), l (along y), h (along z); frame axes along the sides.

    about="centre": about the centre of mass (slide 9),
        CM I = m/12 diag(l²+h², w²+h², l²+w²).
    about="corner": about the corner A at the origin, box in the positive octant (slides 6-7),
        A I = [[m/3 (l²+h²), -m/4 wl, -m/4 hw],
               [-m/4 wl, m/3 (w²+h²), -m/4 hl],
               [-m/4 hw, -m/4 hl, m/3 (l²+w²)]].
    """
    sym = _is_symbolic(m, w, l, h)
    m, w, l, h = _scalars(sym, m, w, l, h)
    if about == "centre":
        k = m / 12
        return _diag(sym, k * (l**2 + h**2), k * (w**2 + h**2), k * (l**2 + w**2))
    if about == "corner":
        a, b = m / 3, m / 4
        rows = [
            [a * (l**2 + h**2), -b * w * l, -b * h * w],
            [-b * w * l, a * (w**2 + h**2), -b * h * l],
            [-b * h * w, -b * h * l, a * (l**2 + w**2)],
        ]
        return sp.ImmutableMatrix(rows) if sym else np.array(rows, dtype=float)
    raise SymdynError(f"box: about must be 'centre' or 'corner', not {about!r}")


def cylinder(m: Any, r: Any, h: Any, axis: str = "z") -> Tensor:
    """Solid cylinder of mass m, radius r, height h, about its centre of mass.

    Frame: origin at the centre of mass, the cylinder's axis along `axis`. About
    the axis I = m r²/2; about any perpendicular axis I = m (3 r² + h²)/12.
    """
    k = _axis_index(axis)
    sym = _is_symbolic(m, r, h)
    m, r, h = _scalars(sym, m, r, h)
    moments = [m * (3 * r**2 + h**2) / 12] * 3
    moments[k] = m * r**2 / 2
    return _diag(sym, *moments)


def sphere(m: Any, r: Any) -> Tensor:
    """Solid sphere of mass m and radius r about its centre: I = 2/5 m r² 1 (any axes)."""
    sym = _is_symbolic(m, r)
    m, r = _scalars(sym, m, r)
    i = 2 * m * r**2 / 5
    return _diag(sym, i, i, i)


def rod(m: Any, length: Any, axis: str = "x") -> Tensor:
    """Thin rod of mass m and given length about its centre, lying along `axis`.

    I = m length²/12 about both perpendicular axes, 0 about the rod's own axis.
    """
    k = _axis_index(axis)
    sym = _is_symbolic(m, length)
    m, length = _scalars(sym, m, length)
    moments = [m * length**2 / 12] * 3
    moments[k] = 0 * m
    return _diag(sym, *moments)


def point_mass(m: Any) -> Tensor:
    """A point mass about itself: the zero tensor (SymPy zeros if m is symbolic)."""
    if _is_symbolic(m):
        return sp.ImmutableMatrix(sp.zeros(3, 3))
    return np.zeros((3, 3))


def parallel_axis(I_com: Any, m: Any, r: Any) -> Tensor:
    """Parallel-axis theorem (slide 8): the tensor about a point A, the centre of mass being at r.

    A I = CM I + m (rᵀr 1 − r rᵀ), all in the same axes. E.g. A Izz = CM Izz + m (rx² + ry²)
    and the tensor's xy entry changes by −m rx ry.
    """
    if _is_symbolic(I_com, m, r):
        Ic = sp.Matrix(I_com)
        rv = sp.Matrix([sp.sympify(x) for x in r])
        if Ic.shape != (3, 3) or rv.shape != (3, 1):
            raise SymdynError("parallel_axis: need a 3x3 tensor and a 3-vector r")
        m = sp.sympify(m)
        return sp.ImmutableMatrix(Ic + m * ((rv.T * rv)[0, 0] * sp.eye(3) - rv * rv.T))
    Ic = np.asarray(I_com, dtype=float)
    rv = np.asarray(r, dtype=float).reshape(-1)
    if Ic.shape != (3, 3) or rv.shape != (3,):
        raise SymdynError("parallel_axis: need a 3x3 tensor and a 3-vector r")
    return Ic + float(m) * (rv @ rv * np.eye(3) - np.outer(rv, rv))


def rotate(I: Any, R: Any) -> Tensor:
    """Re-express a tensor in rotated axes (slide 10): I₁ = R I₀ Rᵀ.

    R maps coordinates in frame 0 (where I₀ is given) to frame 1, e.g. R = 1_R_0;
    equivalently, rotate(I_body, A_R_B) gives the body tensor in A's axes.
    """
    if _is_symbolic(I, R):
        Rm = sp.Matrix(R)
        return sp.ImmutableMatrix(Rm * sp.Matrix(I) * Rm.T)
    Rm = np.asarray(R, dtype=float)
    return Rm @ np.asarray(I, dtype=float) @ Rm.T


def tensor_from_components(entries: dict[str, Any]) -> sp.ImmutableMatrix:
    """The symmetric SymPy tensor from the entries ixx, iyy, izz, ixy, ixz, iyz (a missing one is 0).

    The entries are the tensor's own (as in URDF and the robot file), placed unchanged.
    """
    e = {k: entries.get(k, sp.S.Zero) for k in ("ixx", "iyy", "izz", "ixy", "ixz", "iyz")}
    return sp.ImmutableMatrix(
        [
            [e["ixx"], e["ixy"], e["ixz"]],
            [e["ixy"], e["iyy"], e["iyz"]],
            [e["ixz"], e["iyz"], e["izz"]],
        ]
    )


def _numeric_matrix(I: Any) -> np.ndarray | None:
    """3x3 float array, or None if the entries have free symbols."""
    if _is_symbolic(I):
        M = sp.Matrix(I)
        if M.free_symbols:
            return None
        M = M.evalf()
        try:
            return np.array([[float(x) for x in row] for row in M.tolist()], dtype=float)
        except TypeError:  # e.g. complex entries
            return None
    return np.asarray(I, dtype=float)


def principal_axes(I: Any) -> tuple[np.ndarray, np.ndarray]:
    """Principal moments (ascending) and axes of a numeric tensor: I = V diag(moments) Vᵀ.

    The columns of V are the unit principal axes expressed in the tensor's frame, made
    right-handed (det V = +1); each of the first two columns has its largest-magnitude
    component positive. SymPy input without free symbols is evaluated; with free symbols
    it raises SymdynError.
    """
    A = _numeric_matrix(I)
    if A is None:
        raise SymdynError("principal_axes needs a numeric tensor (this one has free symbols)")
    if A.shape != (3, 3):
        raise SymdynError(f"principal_axes needs a 3x3 tensor, not shape {A.shape}")
    moments, V = np.linalg.eigh(0.5 * (A + A.T))
    for j in range(2):
        if V[np.argmax(np.abs(V[:, j])), j] < 0:
            V[:, j] = -V[:, j]
    V[:, 2] = np.cross(V[:, 0], V[:, 1])
    return moments, V


def check_inertia(
    mass: Any,
    inertia: Any,
    *,
    file: str | None = None,
    link_index: int | None = None,
    link_name: str | None = None,
) -> None:
    """Check a link's mass and centre-of-mass tensor, as the robot loader does.

    Only numeric values are checked (SymPy numbers are evaluated; anything with free symbols
    is skipped). Errors (SymdynError, field "mass" or "inertia"): mass negative or not
    finite or more than 1e150; tensor not 3x3, not finite, an entry of more than 1e150 in absolute
    value (checked before any eigenvalue is computed), not symmetric, or not positive semi-definite
    (smallest eigenvalue < -1e-12 * scale). Warnings (SymdynWarning): principal moments
    breaking the triangle inequality I1 + I2 >= I3 (relative tolerance 1e-9), zero mass with
    a non-zero tensor.
    """
    where = {"file": file, "link_index": link_index, "link_name": link_name}
    m = None
    if not (_is_symbolic(mass) and sp.sympify(mass).free_symbols):
        try:
            m = float(mass)
        except TypeError:
            raise SymdynError(f"mass {mass} is not a real number", field="mass", **where) from None
        if not np.isfinite(m):
            raise SymdynError(f"mass {mass} is not finite", field="mass", **where)
        if abs(m) > MAX_MAGNITUDE:
            raise SymdynError(f"mass {m:g} is too large (more than {MAX_MAGNITUDE:g})", field="mass", **where)
        if m < 0:
            raise SymdynError(f"mass {mass} is negative", field="mass", **where)
    A = _numeric_matrix(inertia)
    if A is None:
        return
    if A.shape != (3, 3):
        raise SymdynError(f"inertia must be 3x3, not shape {A.shape}", field="inertia", **where)
    if not np.all(np.isfinite(A)):
        raise SymdynError("inertia tensor has non-finite entries", field="inertia", **where)
    scale = float(np.max(np.abs(A)))
    if scale > MAX_MAGNITUDE:
        raise SymdynError(
            f"inertia tensor has an entry of {scale:g} in absolute value (more than {MAX_MAGNITUDE:g})",
            field="inertia",
            **where,
        )
    if np.max(np.abs(A - A.T)) > 1e-9 * scale:
        raise SymdynError("inertia tensor is not symmetric", field="inertia", **where)
    moments = np.linalg.eigvalsh(0.5 * (A + A.T))  # entries <= 1e150: their squares stay finite
    if moments[0] < -(1e-12 * scale + ABSOLUTE_TOLERANCE):
        raise SymdynError(
            f"inertia tensor is not positive semi-definite (principal moments {moments.tolist()})",
            field="inertia",
            **where,
        )
    loc = location(file, link_index, link_name, "inertia")
    prefix = f"{loc}: " if loc else ""
    i1, i2, i3 = moments
    if i1 + i2 < i3 - (1e-9 * scale + ABSOLUTE_TOLERANCE):
        warnings.warn(
            f"{prefix}principal moments {moments.tolist()} break the triangle inequality "
            "I1 + I2 >= I3 (no real body has them)",
            SymdynWarning,
            stacklevel=2,
        )
    if m == 0 and scale > 0:
        warnings.warn(f"{prefix}mass is zero but the inertia tensor is not zero", SymdynWarning, stacklevel=2)
