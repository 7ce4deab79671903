"""Tests for symdyn.model.inertia, checked against values obtained another way.

Independent references: the lecture's printed matrices (slides 6-9), exact SymPy
integration of the defining integrals, and NumPy grid integration over the solids.
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest
import sympy as sp
from hypothesis import given, settings
from hypothesis import strategies as st
from timebound import refused

from symdyn.errors import SymdynError, SymdynWarning
from symdyn.model.inertia import (
    box,
    check_inertia,
    cylinder,
    parallel_axis,
    point_mass,
    principal_axes,
    rod,
    rotate,
    sphere,
)

m, w, l, h = sp.symbols("m w l h", positive=True)
x, y, z = sp.symbols("x y z", real=True)


def is_zero(M) -> bool:
    return sp.simplify(sp.Matrix(M)) == sp.zeros(*sp.Matrix(M).shape)


def integrated_box_tensor(mass, xr, yr, zr) -> sp.Matrix:
    """Tensor of a uniform box x in xr, y in yr, z in zr, from the slide-5 integrals."""
    rho = mass / ((xr[1] - xr[0]) * (yr[1] - yr[0]) * (zr[1] - zr[0]))

    def integral(f):
        return sp.integrate(f * rho, (x, *xr), (y, *yr), (z, *zr))

    ixx, iyy, izz = integral(y**2 + z**2), integral(x**2 + z**2), integral(x**2 + y**2)
    pxy, pxz, pyz = integral(x * y), integral(x * z), integral(y * z)
    return sp.Matrix([[ixx, -pxy, -pxz], [-pxy, iyy, -pyz], [-pxz, -pyz, izz]])


def grid_tensor(mass: float, pts: np.ndarray) -> np.ndarray:
    """Tensor of a uniform solid sampled at equally weighted points: m * mean(r'r 1 - r r')."""
    S = pts.T @ pts / len(pts)
    return mass * (np.trace(S) * np.eye(3) - S)


def midpoints(a: float, b: float, n: int) -> np.ndarray:
    edges = np.linspace(a, b, n + 1)
    return 0.5 * (edges[1:] + edges[:-1])


def grid_points(lo, hi, n: int) -> np.ndarray:
    axes = [midpoints(a, b, n) for a, b in zip(lo, hi, strict=True)]
    return np.stack(np.meshgrid(*axes, indexing="ij"), axis=-1).reshape(-1, 3)


def random_rotation(rng: np.random.Generator) -> np.ndarray:
    Q, R = np.linalg.qr(rng.normal(size=(3, 3)))
    Q = Q * np.sign(np.diag(R))
    if np.linalg.det(Q) < 0:
        Q[:, 0] = -Q[:, 0]
    return Q


# --- slides 6-9: the box, exactly -------------------------------------------------------

SLIDE_6_7 = sp.Matrix(
    [
        [m / 3 * (l**2 + h**2), -m / 4 * w * l, -m / 4 * h * w],
        [-m / 4 * w * l, m / 3 * (w**2 + h**2), -m / 4 * h * l],
        [-m / 4 * h * w, -m / 4 * h * l, m / 3 * (l**2 + w**2)],
    ]
)
SLIDE_9 = m / 12 * sp.diag(l**2 + h**2, w**2 + h**2, l**2 + w**2)


def test_box_corner_is_slide_6_7():
    I = box(m, w, l, h, about="corner")
    assert isinstance(I, sp.ImmutableMatrix)
    assert is_zero(I - SLIDE_6_7)
    assert is_zero(I - integrated_box_tensor(m, (0, w), (0, l), (0, h)))


def test_box_centre_is_slide_9():
    I = box(m, w, l, h)
    assert is_zero(I - SLIDE_9)
    ref = integrated_box_tensor(m, (-w / 2, w / 2), (-l / 2, l / 2), (-h / 2, h / 2))
    assert is_zero(I - ref)


def test_box_symbolic_with_integer_mass_stays_exact():
    I = box(2, w, l, h)
    assert I[2, 2] - sp.Rational(1, 6) * (l**2 + w**2) == 0


def test_box_bad_about_raises():
    with pytest.raises(SymdynError):
        box(1.0, 1.0, 1.0, 1.0, about="middle")


# --- slide 8: parallel axis ---------------------------------------------------------------


def test_parallel_axis_centre_to_corner_is_corner_box():
    I = parallel_axis(box(m, w, l, h), m, (w / 2, l / 2, h / 2))
    assert is_zero(I - SLIDE_6_7)


def test_parallel_axis_slide_8_scalar_statements():
    a, b, c, d, e, f = sp.symbols("a b c d e f", real=True)
    rx, ry, rz = sp.symbols("r_x r_y r_z", real=True)
    Ic = sp.Matrix([[a, d, e], [d, b, f], [e, f, c]])
    A = parallel_axis(Ic, m, (rx, ry, rz))
    assert sp.expand(A[2, 2] - (Ic[2, 2] + m * (rx**2 + ry**2))) == 0
    assert sp.expand(A[0, 0] - (Ic[0, 0] + m * (ry**2 + rz**2))) == 0
    # lecture: A Ixy = CM Ixy + m rx ry for the integral, so the tensor entry gains -m rx ry
    assert sp.expand(A[0, 1] - (Ic[0, 1] - m * rx * ry)) == 0
    assert sp.expand(A[1, 0] - (Ic[1, 0] - m * rx * ry)) == 0
    assert sp.expand(A[1, 2] - (Ic[1, 2] - m * ry * rz)) == 0


def test_parallel_axis_numeric():
    A = parallel_axis(np.zeros((3, 3)), 2.0, [1.0, 0.0, 0.0])
    assert isinstance(A, np.ndarray)
    np.testing.assert_allclose(A, np.diag([0.0, 2.0, 2.0]))


# --- slide 10: rotation ------------------------------------------------------------------


def test_rotate_corner_box_about_z_by_quarter_turn():
    # Rz(pi/2) sends (x, y, z) to (-y, x, z): the box [0,w]x[0,l]x[0,h] lands on
    # x in [-l, 0], y in [0, w], z in [0, h] (the octant x<0, y>0, z>0), i.e. a
    # corner box with w and l swapped, mirrored in x (xy and xz products change sign).
    Rz = sp.Matrix([[0, -1, 0], [1, 0, 0], [0, 0, 1]])
    I = rotate(box(m, w, l, h, about="corner"), Rz)
    expected = sp.Matrix(
        [
            [m / 3 * (w**2 + h**2), m / 4 * l * w, m / 4 * h * l],
            [m / 4 * l * w, m / 3 * (l**2 + h**2), -m / 4 * h * w],
            [m / 4 * h * l, -m / 4 * h * w, m / 3 * (w**2 + l**2)],
        ]
    )
    assert is_zero(I - expected)
    assert is_zero(I - integrated_box_tensor(m, (-l, 0), (0, w), (0, h)))


def test_rotate_preserves_trace_and_eigenvalues():
    rng = np.random.default_rng(1)
    I0 = box(1.3, 0.2, 0.5, 0.9, about="corner")
    for _ in range(5):
        R = random_rotation(rng)
        I1 = rotate(I0, R)
        assert np.isclose(np.trace(I1), np.trace(I0))
        np.testing.assert_allclose(np.linalg.eigvalsh(I1), np.linalg.eigvalsh(I0), atol=1e-12)
        np.testing.assert_allclose(rotate(I1, R.T), I0, atol=1e-12)


def test_rotate_back_symbolic_is_identity():
    t = sp.symbols("theta", real=True)
    R = sp.Matrix([[1, 0, 0], [0, sp.cos(t), -sp.sin(t)], [0, sp.sin(t), sp.cos(t)]])
    I0 = box(m, w, l, h, about="corner")
    assert is_zero(rotate(rotate(I0, R), R.T) - I0)


# --- numeric solids against grid integration (independent of the formulas) --------------


def test_box_numeric_against_grid():
    mass, dims = 2.5, (0.3, 0.7, 1.1)
    centre = grid_points([-d / 2 for d in dims], [d / 2 for d in dims], 60)
    np.testing.assert_allclose(box(mass, *dims), grid_tensor(mass, centre), rtol=1e-3, atol=1e-9)
    corner = grid_points([0, 0, 0], dims, 60)
    I = box(mass, *dims, about="corner")
    assert isinstance(I, np.ndarray) and I.dtype == float
    np.testing.assert_allclose(I, grid_tensor(mass, corner), rtol=1e-3)


@pytest.mark.parametrize("axis", ["x", "y", "z"])
def test_cylinder_numeric_against_grid(axis):
    mass, r, hh = 3.0, 0.4, 1.5
    pts = grid_points([-r, -r, -hh / 2], [r, r, hh / 2], 100)
    pts = pts[pts[:, 0] ** 2 + pts[:, 1] ** 2 <= r**2]
    k = "xyz".index(axis)
    order = {0: [2, 0, 1], 1: [1, 2, 0], 2: [0, 1, 2]}[k]  # the sampled z axis becomes `axis`
    pts = pts[:, order]
    ref = grid_tensor(mass, pts)
    np.testing.assert_allclose(cylinder(mass, r, hh, axis=axis), ref, rtol=3e-3, atol=1e-4)


def test_sphere_numeric_against_grid():
    mass, r = 1.7, 0.6
    pts = grid_points([-r] * 3, [r] * 3, 100)
    pts = pts[np.sum(pts**2, axis=1) <= r**2]
    np.testing.assert_allclose(sphere(mass, r), grid_tensor(mass, pts), rtol=3e-3, atol=1e-4)


@pytest.mark.parametrize("axis", ["x", "y", "z"])
def test_rod_numeric_against_line_integral(axis):
    mass, length = 0.8, 1.2
    s = midpoints(-length / 2, length / 2, 2000)
    pts = np.zeros((len(s), 3))
    pts[:, "xyz".index(axis)] = s
    np.testing.assert_allclose(rod(mass, length, axis=axis), grid_tensor(mass, pts), atol=1e-6)


def test_symbolic_solids_and_point_mass():
    r = sp.symbols("r", positive=True)
    assert is_zero(cylinder(m, r, h) - sp.diag(*([m * (3 * r**2 + h**2) / 12] * 2), m * r**2 / 2))
    assert is_zero(sphere(m, r) - sp.Rational(2, 5) * m * r**2 * sp.eye(3))
    assert is_zero(rod(m, l) - sp.diag(0, m * l**2 / 12, m * l**2 / 12))
    assert point_mass(m) == sp.zeros(3, 3) and isinstance(point_mass(m), sp.ImmutableMatrix)
    P = point_mass(2)
    assert isinstance(P, np.ndarray) and P.dtype == float and not P.any()
    with pytest.raises(SymdynError):
        cylinder(1.0, 1.0, 1.0, axis="w")


# --- principal axes ----------------------------------------------------------------------


def test_principal_axes_reconstructs():
    rng = np.random.default_rng(7)
    for _ in range(5):
        I = rotate(box(1.0, *rng.uniform(0.1, 2.0, 3), about="corner"), random_rotation(rng))
        moments, V = principal_axes(I)
        assert np.all(np.diff(moments) >= 0)
        assert np.isclose(np.linalg.det(V), 1.0)
        np.testing.assert_allclose(V.T @ V, np.eye(3), atol=1e-12)
        np.testing.assert_allclose(V @ np.diag(moments) @ V.T, I, atol=1e-12)


def test_principal_axes_symbolic_numbers_and_free_symbols():
    moments, V = principal_axes(box(12, sp.Integer(1), 2, 3))  # m/12 diag(13, 10, 5)
    np.testing.assert_allclose(moments, [5.0, 10.0, 13.0])
    assert np.isclose(np.linalg.det(V), 1.0)
    with pytest.raises(SymdynError):
        principal_axes(box(m, w, l, h))


# --- check_inertia -----------------------------------------------------------------------

WHERE = {"file": "arm.yaml", "link_index": 2, "link_name": "forearm"}


def test_check_negative_mass_raises():
    with pytest.raises(SymdynError) as err:
        check_inertia(-1.0, np.eye(3), **WHERE)
    assert err.value.field == "mass" and err.value.link_index == 2
    assert "arm.yaml" in str(err.value) and "forearm" in str(err.value)


def test_check_not_psd_raises():
    with pytest.raises(SymdynError) as err:
        check_inertia(1.0, [[1.0, 2.0, 0.0], [2.0, 1.0, 0.0], [0.0, 0.0, 1.0]], **WHERE)
    assert err.value.field == "inertia"


def test_check_asymmetric_raises():
    with pytest.raises(SymdynError) as err:
        check_inertia(1.0, [[1.0, 0.1, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]], **WHERE)
    assert err.value.field == "inertia" and "symmetric" in str(err.value)


def test_check_triangle_inequality_warns():
    with pytest.warns(SymdynWarning, match="triangle") as rec:
        check_inertia(1.0, np.diag([1.0, 1.0, 3.0]), **WHERE)
    assert "forearm" in str(rec[0].message)


def test_check_zero_mass_nonzero_inertia_warns():
    with pytest.warns(SymdynWarning, match="mass is zero"):
        check_inertia(0.0, np.diag([1.0, 1.0, 1.0]), **WHERE)


def test_check_valid_is_silent_and_symbolic_is_skipped():
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        check_inertia(2.0, box(2.0, 0.1, 0.2, 0.3), **WHERE)
        check_inertia(1.0, rod(1.0, 2.0))
        check_inertia(0.0, point_mass(0.0))
        check_inertia(sp.Integer(2), box(sp.Integer(2), 1, 2, 3))  # SymPy numbers are checked
        check_inertia(m, box(m, w, l, h))
        check_inertia(-m, sp.Matrix([[-m, 0, 0], [0, 1, 0], [0, 0, 1]]))
    with pytest.raises(SymdynError):
        check_inertia(sp.Integer(-1), sp.eye(3))


# --- properties ---------------------------------------------------------------------------

pos = st.floats(min_value=1e-2, max_value=10.0, allow_nan=False)
coord = st.floats(min_value=-5.0, max_value=5.0, allow_nan=False)


@settings(max_examples=60, deadline=None)
@given(mass=pos, a=pos, b=pos, c=pos, rx=coord, ry=coord, rz=coord)
def test_box_properties(mass, a, b, c, rx, ry, rz):
    for about in ("centre", "corner"):
        I = box(mass, a, b, c, about=about)
        scale = np.abs(I).max()
        ev = np.linalg.eigvalsh(I)
        assert ev[0] >= -1e-12 * scale
        assert ev[0] + ev[1] >= ev[2] * (1 - 1e-9)
        with warnings.catch_warnings():
            warnings.simplefilter("error")
            check_inertia(mass, I)
    Ic = box(mass, a, b, c)
    shift = parallel_axis(Ic, mass, (rx, ry, rz)) - Ic
    assert np.linalg.eigvalsh(shift)[0] >= -1e-12 * max(1.0, np.abs(shift).max())


# -- hostile numbers (issue 21): bounded before any eigenvalue is computed


@pytest.mark.parametrize("entry", [-1e308, 1e200, 1.7976931348623157e308])
def test_an_entry_beyond_1e150_is_refused_before_the_eigenvalues(entry):
    """-1e308 made LinAlgError('Eigenvalues did not converge') escape the loader."""
    with pytest.raises(
        SymdynError, match=r"f.yaml: link 1 \(a\): field 'inertia': inertia tensor has an entry of"
    ):
        check_inertia(1.0, np.diag([entry, 1.0, 1.0]), file="f.yaml", link_index=1, link_name="a")
    with pytest.raises(SymdynError, match="field 'mass': mass .* is too large"):
        check_inertia(abs(entry), np.eye(3), file="f.yaml", link_index=1, link_name="a")


def test_an_inertia_entry_of_minus_1e308_in_a_robot_file_exits_1_in_one_line(tmp_path, capsys):
    path = tmp_path / "huge.yaml"
    path.write_text(
        "name: t\nlinks:\n  - name: a\n    joint: revolute\n    mass: 1\n"
        "    inertia: {ixx: -1e308, iyy: 1, izz: 1}\n"
    )
    line = refused(capsys, "derive", path)
    assert line == (
        f"symdyn: error: {path}: link 1 (a): field 'inertia.ixx': number -1e+308 is too large "
        "(more than 1e+150 in absolute value)"
    )
