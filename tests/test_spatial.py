"""The spatial algebra (symdyn.spatial) against its 6x6 matrix definitions.

Independent routes, in exact rational arithmetic:
- the cross products v x and v x* are the 6x6 matrices [[w x, 0], [u x, w x]] and
  -(v x)^T (Featherstone, Rigid Body Dynamics Algorithms (2008), sec. 2.9);
- a spatial inertia is the 6x6 [[I_c + m [c x][c x]^T, m [c x]], [m [c x]^T, m 1]]
  (Featherstone 2008, sec. 2.13), and I_o is the sum over point masses of
  m_k (r_k^T r_k 1 - r_k r_k^T), taken about the origin directly;
- the rate of change of an inertia moving with v is (v x*) I - I (v x);
- moving an inertia from a child frame into its parent is X^T I X, X the 6x6 motion
  transform from parent to child coordinates.
"""

from __future__ import annotations

import random

import pytest
import sympy as sp

from symdyn.algorithms.crba import shift_inertia
from symdyn.algorithms.frames import JointFrame
from symdyn.spatial import vectors as v3
from symdyn.spatial.inertia import (
    SpatialInertia,
    apply_inertia,
    body_inertia,
    inertia_rate,
    origin_inertia,
    scaled_inertia,
    shifted_rotational_inertia,
)
from symdyn.spatial.motion import (
    Force,
    Motion,
    cross_force,
    cross_motion,
    motion_subspace,
    project,
    spatial_add,
    spatial_sub,
)
from symdyn.spatial.transform import rot_axis
from symdyn.symbolic.program import Program


def _rand(rng: random.Random) -> sp.Rational:
    return sp.Rational(rng.randint(-9, 9), rng.randint(1, 5))


def _vec3(rng: random.Random) -> v3.Vec:
    return tuple(_rand(rng) for _ in range(3))  # type: ignore[return-value]


def _skew(a) -> sp.Matrix:
    return sp.Matrix([[0, -a[2], a[1]], [a[2], 0, -a[0]], [-a[1], a[0], 0]])


def _six(s) -> sp.Matrix:
    return sp.Matrix([*s.angular, *s.linear])


def _crm(v: Motion) -> sp.Matrix:
    """The 6x6 motion cross-product matrix v x."""
    W, U = _skew(v.angular), _skew(v.linear)
    return sp.Matrix(sp.BlockMatrix([[W, sp.zeros(3)], [U, W]]))


def _spatial6(m, c, Ic) -> sp.Matrix:
    """The 6x6 spatial inertia about the origin from mass, centre of mass and I_c."""
    C = _skew(c)
    return sp.Matrix(sp.BlockMatrix([[sp.Matrix(Ic) + m * C * C.T, m * C], [m * C.T, m * sp.eye(3)]]))


def _six_of(inertia: SpatialInertia) -> sp.Matrix:
    """The 6x6 matrix of a triple (m, h, I_o)."""
    m, h, I = inertia
    H = _skew(h)
    return sp.Matrix(sp.BlockMatrix([[sp.Matrix(I), H], [H.T, m * sp.eye(3)]]))


def _random_body(rng: random.Random, points: int = 4):
    """Point masses: (mass, centre of mass, I about the centre of mass, I about the origin)."""
    masses = [sp.Rational(rng.randint(1, 9), rng.randint(1, 3)) for _ in range(points)]
    places = [sp.Matrix(_vec3(rng)) for _ in range(points)]
    m = sum(masses)
    c = sum((mk * rk for mk, rk in zip(masses, places, strict=True)), sp.zeros(3, 1)) / m

    def about(o):
        rel = [r - o for r in places]
        terms = (mk * ((r.T * r)[0] * sp.eye(3) - r * r.T) for mk, r in zip(masses, rel, strict=True))
        return sum(terms, sp.zeros(3))

    return m, tuple(c), about(c), about(sp.zeros(3, 1))


SEEDS = range(4)


@pytest.mark.parametrize("seed", SEEDS)
def test_cross_products_are_the_6x6_operators(seed):
    rng = random.Random(seed)
    v, m = Motion(_vec3(rng), _vec3(rng)), Motion(_vec3(rng), _vec3(rng))
    f = Force(_vec3(rng), _vec3(rng))
    assert _six(cross_motion(v, m)) == _crm(v) * _six(m)
    assert _six(cross_force(v, f)) == -_crm(v).T * _six(f)
    assert project(m, f) == (_six(m).T * _six(f))[0]
    # <a, b x* f> = -<b, a x* f>, which coriolis.py uses for the lower triangle of C
    assert project(v, cross_force(m, f)) == -project(m, cross_force(v, f))


def test_kinds_and_sums_keep_their_type():
    a, b = Force((1, 2, 3), (4, 5, 6)), Force((1, 1, 1), (0, 0, 2))
    assert spatial_add(a, b, b) == Force((3, 4, 5), (4, 5, 10))
    assert spatial_sub(a, b) == Force((0, 1, 2), (4, 5, 4))
    assert type(spatial_add(Motion((1, 0, 0), (0, 0, 0)))) is Motion
    assert motion_subspace("revolute", [0, 0, 1]) == Motion((0, 0, 1), (0, 0, 0))
    assert motion_subspace("prismatic", [1, 0, 0]) == Motion((0, 0, 0), (1, 0, 0))
    with pytest.raises(AssertionError):
        motion_subspace("planar", [0, 0, 1])


def test_zero_aware_scalars_fold_before_sympy():
    x = sp.Symbol("x")
    assert v3.product(0, x) is sp.S.Zero and v3.product(x, 1) is x and v3.product(-1, x) == -x
    assert v3.sum_terms([0, sp.S.Zero]) is sp.S.Zero and v3.sum_terms([0, x]) is x


@pytest.mark.parametrize("seed", SEEDS)
def test_origin_inertia_is_the_point_mass_sum_about_the_origin(seed):
    m, c, Ic, Io = _random_body(random.Random(seed))
    assert sp.Matrix(origin_inertia(m, c, Ic)) == Io
    body = body_inertia(m, c, Ic)
    assert body.mass == m and sp.Matrix(body.first_moment) == m * sp.Matrix(c)
    assert _six_of(body) == _spatial6(m, c, Ic)


@pytest.mark.parametrize("seed", SEEDS)
def test_inertia_times_motion_is_the_6x6_product(seed):
    rng = random.Random(seed)
    m, c, Ic, _ = _random_body(rng)
    v = Motion(_vec3(rng), _vec3(rng))
    assert _six(apply_inertia(body_inertia(m, c, Ic), v)) == _spatial6(m, c, Ic) * _six(v)
    k = _rand(rng)
    assert _six_of(scaled_inertia(k, body_inertia(m, c, Ic))) == k * _spatial6(m, c, Ic)


@pytest.mark.parametrize("seed", SEEDS)
def test_inertia_rate_is_the_commutator_with_the_velocity(seed):
    rng = random.Random(seed)
    m, c, Ic, _ = _random_body(rng)
    v = Motion(_vec3(rng), _vec3(rng))
    I6 = _spatial6(m, c, Ic)
    want = -_crm(v).T * I6 - I6 * _crm(v)
    rate = inertia_rate(body_inertia(m, c, Ic), v)
    assert rate.mass == 0
    assert _six_of(rate) == want


def _motion_transform(R: sp.Matrix, p) -> sp.Matrix:
    """child_X_parent for the child frame at p with orientation R (parent axes)."""
    E = R.T
    return sp.Matrix(sp.BlockMatrix([[E, sp.zeros(3)], [-E * _skew(p), E]]))


@pytest.mark.parametrize("seed", SEEDS)
def test_moving_an_inertia_into_the_parent_is_XT_I_X(seed):
    rng = random.Random(seed)
    m, c, Ic, _ = _random_body(rng)
    p = _vec3(rng)
    R = sp.Matrix(rot_axis([0, 0, 1], sp.pi / 3) * rot_axis([1, 0, 0], -sp.pi / 2))
    child = body_inertia(m, c, Ic)
    want = _motion_transform(R, p).T * _spatial6(m, c, Ic) * _motion_transform(R, p)
    Rh = R * sp.Matrix(child.first_moment)
    J = R * sp.Matrix(child.inertia) * R.T
    zero = [[0] * 3] * 3
    rotational = shifted_rotational_inertia(zero, J.tolist(), tuple(Rh), m, p)
    assert sp.simplify(sp.Matrix(rotational) - want[:3, :3]) == sp.zeros(3)
    # the named version in algorithms.crba adds an inertia of the parent's own
    program = Program()
    frame = JointFrame(v3.mat(R), p, v3.mat(R))
    own = body_inertia(*_random_body(rng)[:3])
    moved = shift_inertia(frame, child, own, program, "s")
    expanded = SpatialInertia(
        program.expand([moved.mass])[0],
        tuple(program.expand(moved.first_moment)),
        sp.Matrix(3, 3, program.expand([x for row in moved.inertia for x in row])).tolist(),
    )
    assert sp.simplify(_six_of(expanded) - want - _six_of(own)) == sp.zeros(6)
