"""Straight-line programs (symdyn.symbolic.program): naming, sharing, differentiation, expansion."""

from __future__ import annotations

import random

import pytest
import sympy as sp
from sympy.core.parameters import distribute

from symdyn.symbolic.program import Program, derivative, is_trivial

x, y, z = sp.symbols("x y z")


def test_trivial_expressions_pass_through():
    p = Program()
    for e in (x, sp.Integer(3), sp.Rational(1, 2), sp.Float(0.25), 2 * x, -x, sp.Rational(-3, 4) * y, sp.pi):
        assert p.let(e) == e
        assert is_trivial(e)
    assert len(p) == 0
    for e in (x * y, x + 1, sp.sin(x), x**2, 2 * x * y):
        assert not is_trivial(e)


def test_let_names_and_dedups():
    p = Program()
    t = p.let(x * y + sp.sin(z), "a")
    assert isinstance(t, sp.Symbol) and t.name.startswith("_a")
    assert p.is_intermediate(t) and not p.is_intermediate(x)
    assert p.let(x * y + sp.sin(z)) == t  # same expression, same name (whatever the hint)
    assert p.let(sp.sin(z) + y * x, "b") == t  # SymPy's canonical order
    assert len(p) == 1
    assert p.assignments == [(t, x * y + sp.sin(z))]
    u = p.let(t * x)
    assert u != t and len(p) == 2


def test_name_names_what_let_finds_trivial():
    p = Program()
    t = p.name(2 * x, "c")
    assert isinstance(t, sp.Symbol) and p.assignments == [(t, 2 * x)]
    assert p.name(2 * x) == t and p.let(x * y) != t  # shared like let's names
    assert p.name(x) == x and p.name(sp.Float(0.5)) == sp.Float(0.5)  # atoms pass through
    assert p.expand([t + 1]) == [2 * x + 1]


def test_let_stores_the_positive_form_of_a_negation():
    p = Program()
    neg = p.let(-x * y)
    (sym, stored) = p.assignments[0]
    assert stored == x * y and neg == -sym
    assert p.let(x * y) == sym  # the positive expression shares the name
    neg3 = p.let(-3 * x * y)
    assert p.assignments[-1][1] == 3 * x * y and neg3 == -p.assignments[-1][0]
    # a negated sum as the recursions build it (distribution of -1 switched off)
    with distribute(False):
        neg_sum = -(x + sp.sin(y))
        assert neg_sum.is_Mul
        s = p.let(neg_sum)
    (sym2, stored2) = p.assignments[-1]
    assert stored2 == x + sp.sin(y) and s == -sym2
    assert p.let(x + sp.sin(y)) == sym2
    for sym_k, expr_k in p.assignments:
        assert not (expr_k.is_Mul and expr_k.as_coeff_Mul()[0].is_negative), (sym_k, expr_k)
    # whatever form a sum is stored in, it expands back to its value
    t = p.let(-x - sp.sin(y) * z)
    assert sp.expand(p.expand([t])[0] - (-x - sp.sin(y) * z)) == 0


def _same(a: sp.Expr, b: sp.Expr, seed: int = 0) -> bool:
    """a == b as functions of x, y, z: structurally after expansion, else at 5 random points to 30 digits."""
    d = sp.expand(a - b)
    if d == 0:
        return True
    rng = random.Random(seed)
    for _ in range(5):
        point = {s: sp.Rational(rng.randint(-90, 90), 97) for s in (x, y, z)}
        va, vb = sp.N(a.subs(point), 30), sp.N(b.subs(point), 30)
        if abs(va - vb) > 1e-22 * (1 + abs(vb)):
            return False
    return True


def _random_program(seed: int, size: int = 12):
    """A random program over x, y, z with its fully nested closed forms built alongside."""
    rng = random.Random(seed)
    p = Program()
    named = [x, y, z]  # what the program sees
    closed = [x, y, z]  # the same values written out
    ops = [
        lambda a, b: a * b,
        lambda a, b: a + b,
        lambda a, b: a - 2 * b,
        lambda a, b: sp.sin(a) * b,
        lambda a, b: sp.cos(a + b),
        lambda a, b: a**2 - b,
        lambda a, b: -a * b,
        lambda a, b: sp.sqrt(a**2 + 1) + b,
        lambda a, b: sp.exp(a) / (b**2 + 2),
        lambda a, b: sp.tan(a) - b**3,
    ]
    for _ in range(size):
        i, j = rng.randrange(len(named)), rng.randrange(len(named))
        op = rng.choice(ops)
        named.append(p.let(op(named[i], named[j]), "t"))
        closed.append(op(closed[i], closed[j]))
    return p, named, closed


@pytest.mark.parametrize("seed", range(8))
def test_expand_substitutes_back(seed):
    p, named, closed = _random_program(seed)
    outputs = named[-3:] + [named[-1] * named[-2] + x]
    want = closed[-3:] + [closed[-1] * closed[-2] + x]
    got = p.expand(outputs)
    for g_, w_ in zip(got, want, strict=True):
        assert not any(p.is_intermediate(s) for s in g_.free_symbols)
        assert g_ == w_ or _same(g_, w_, seed)


@pytest.mark.parametrize("seed", range(8))
def test_diff_equals_sympy_diff_of_the_expansion(seed):
    p, named, closed = _random_program(seed)
    outputs = [named[-1], named[-2] * y, named[-3] + named[-1]]
    want_closed = [closed[-1], closed[-2] * y, closed[-3] + closed[-1]]
    for var in (x, y, z):
        derivs = p.diff(outputs, var)
        got = p.expand(derivs)
        for g_, w_ in zip(got, want_closed, strict=True):
            assert _same(g_, sp.diff(w_, var), seed), (seed, var)
    w = sp.Symbol("w")
    assert p.diff(outputs, w) == [0, 0, 0]


def test_diff_on_a_known_program():
    p = Program()
    s = p.let(sp.sin(x) * y)
    t = p.let(s**2 + x * s)
    (d,) = p.expand(p.diff([t * z], x))
    closed = ((sp.sin(x) * y) ** 2 + x * sp.sin(x) * y) * z
    assert sp.simplify(d - sp.diff(closed, x)) == 0
    assert sp.simplify(d - z * (2 * y**2 * sp.sin(x) * sp.cos(x) + y * sp.sin(x) + x * y * sp.cos(x))) == 0


def test_diff_of_sign_is_zero_almost_everywhere():
    p = Program()
    t = p.let(sp.sign(x) * y + x * y)
    (d,) = p.expand(p.diff([t], x))
    assert d == y  # d/dx sign(x) = 0 for x != 0 (Coulomb friction)


def test_needed_lists_dependencies_in_order():
    p = Program()
    a = p.let(x * y)
    b = p.let(sp.sin(z) + z)  # unrelated to c
    c = p.let(a * z + a)
    d = p.let(c * c + x)
    assert [s for s, _ in p.needed([d])] == [a, c, d]
    assert [s for s, _ in p.needed([b])] == [b]
    assert p.needed([x + y]) == []


def test_copy_takes_new_intermediates_alone():
    x, y = sp.symbols("x y")
    prog = Program()
    a = prog.let(sp.sin(x) * y)
    twin = prog.copy("c")
    assert twin.let(sp.sin(x) * y) == a  # shares what was there
    b = twin.let(sp.cos(x) * y)
    assert len(twin) == 2 and len(prog) == 1 and not prog.is_intermediate(b)
    c = prog.let(x * y + 1)
    assert c != b  # numbered on, so the two never give one name two meanings
    assert twin.expand([b]) == [sp.cos(x) * y]


def test_derivative_of_abs_is_the_sign_times_the_inner_derivative():
    """|x y - 2| by x: sign(x y - 2) y, against a central difference at points on both sides of the
    kink (SymPy's own diff of Abs, for symbols not declared real, is written with re and im)."""
    x, y = sp.symbols("x y")
    e = sp.Abs(x * y - 2)
    d = derivative(e, {x: sp.S.One}, {})
    assert not d.has(sp.re, sp.im)
    f, df = sp.lambdify((x, y), e), sp.lambdify((x, y), d)
    h = 1e-6
    for px, py in ((0.3, 1.5), (3.0, 1.5), (-2.0, 0.7)):
        assert df(px, py) == pytest.approx((f(px + h, py) - f(px - h, py)) / (2 * h), rel=1e-8)
