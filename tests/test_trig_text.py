"""The text of trigonometric polynomials (symdyn.symbolic.trig_text): every entry parses with
sympy.sympify back to the same polynomial (exactly for exact data, to 15 digits for floats),
and the text is the same for equal polynomials built in different orders."""

from __future__ import annotations

import math
from fractions import Fraction

import pytest
import sympy as sp
from robots import example, rational_example

from symdyn.dynamics import derive
from symdyn.symbolic.trig_polynomial import TrigRing
from symdyn.symbolic.trig_text import TrigText, number_text

NAMES = ("M", "B", "Csq", "G")


def _entries(cs):
    for name in NAMES:
        rows, cols = cs.shape(name)
        for r in range(rows):
            for c in range(cols):
                yield name, r, c


def _assert_parses_back(cs, entry) -> None:
    """Fractions and symbolic coefficients exactly; floats (also inside SymPy numbers such as
    0.12*pi**2) to the 15 digits they print with."""
    want = cs.poly(*entry)
    got = cs.ring.convert(sp.sympify(cs.text(*entry)))
    assert got.keys() == want.keys(), entry
    for key, c in want.items():
        if isinstance(c, Fraction) or not sp.sympify(c).is_number:
            assert got[key] == c, (entry, key)
        else:
            assert math.isclose(float(got[key]), float(c), rel_tol=1e-14), (entry, key)


@pytest.mark.parametrize("name", ["roger_arm", "stanford", "scara", "puma560"])
def test_exact_text_parses_back_to_the_same_polynomial(name):
    robot = example(name) if name == "roger_arm" else rational_example(name)
    cs = derive(robot, simplify=False).configuration_space
    for entry in _entries(cs):
        _assert_parses_back(cs, entry)


@pytest.mark.parametrize("name", ["puma560", "scara"])
def test_float_text_parses_back_within_15_digits(name):
    cs = derive(example(name), simplify=False).configuration_space
    for entry in _entries(cs):
        _assert_parses_back(cs, entry)


def test_numbers_signs_and_sums_of_angles():
    q1, q2, m = sp.symbols("q1 q2 m")
    ring = TrigRing([q1, q2])
    e = -sp.Rational(3, 2) * sp.cos(q1 - q2) + m * sp.sin(2 * q2) - 2 - m * sp.cos(q1)
    e += sp.sqrt(2) * sp.sin(q1 + q2)
    text = TrigText(ring).text(ring.convert(e))
    assert text == "-2 - m*cos(q1) + m*sin(2*q2) - 3/2*cos(q1 - q2) + sqrt(2)*sin(q1 + q2)"
    assert sp.expand(sp.sympify(text) - e) == 0
    assert TrigText(ring).text({}) == "0"


def test_order_does_not_depend_on_how_the_polynomial_was_built():
    q1, q2, a = sp.symbols("q1 q2 a")
    ring = TrigRing([q1, q2])
    one = ring.convert(sp.cos(q1) * sp.cos(q2) + a * sp.sin(q2))
    other = dict(reversed(list(one.items())))
    assert TrigText(ring).text(one) == TrigText(ring).text(other)


def test_number_text():
    assert number_text(Fraction(3, 4)) == "3/4" and number_text(Fraction(-5)) == "-5"
    assert number_text(0.38487629400000006) == "0.384876294"
    assert float(number_text(1 / 3)) == pytest.approx(1 / 3, rel=1e-15)
    assert number_text(1e-5) == "1e-05" and math.isclose(float(sp.sympify(number_text(1e-5))), 1e-5)
