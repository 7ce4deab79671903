"""symdyn.symbolic.lumping.Lumper: names by value, names from `known` expressions, and the
names it must not take."""

from __future__ import annotations

import sympy as sp

from symdyn.symbolic.lumping import Lumper, split_sign

q1, a, b, m, x, y = sp.symbols("q1 a b m x y")


def test_by_value_up_to_sign_and_twice():
    lumper = Lumper([q1])
    assert lumper.name(a * b) == sp.Symbol("I1")
    assert lumper.name(-a * b) == -sp.Symbol("I1")
    assert lumper.name(2 * a * b) == 2 * sp.Symbol("I1")
    assert lumper.name(m) == m and lumper.name(sp.S.NegativeOne) == -1
    assert lumper.definitions == [(sp.Symbol("I1"), a * b)]


def test_known_expressions_print_as_one_symbol_or_a_named_combination():
    """x, 2 x print as they are; x + a y gets a name defined as the combination; a coefficient
    not in `known` is named by its value and listed in `missed`."""
    known = {a * m: x, 2 * b * m: 2 * x, a * b * m: x + a * y}
    lumper = Lumper([q1], known=known)
    assert lumper.name(-a * m) == -x
    assert lumper.name(2 * b * m) == 2 * x
    assert lumper.name(a * b * m) == sp.Symbol("I1")
    assert lumper.name(b**2) == sp.Symbol("I2")
    assert lumper.definitions == [(sp.Symbol("I1"), x + a * y), (sp.Symbol("I2"), b**2)]
    assert list(lumper.missed) == [b**2] and lumper.referenced == {x, y, a}


def test_reserved_names_are_skipped():
    lumper = Lumper([q1], reserved={"I1", "I3"})
    assert [lumper.name(e) for e in (a * b, a * m, b * m)] == list(sp.symbols("I2 I4 I5"))


def test_split_sign():
    assert split_sign(-2 * a) == (-1, 2 * a) and split_sign(a - b) == (1, a - b)
