"""Bounds on powers and numbers (symdyn.model.bounded), at parse time and after substitution.

Each hostile case must be refused with a SymdynError naming the field, within a time bound
(tests/timebound.py); the values that pass are compared with Python's integers and floats.
"""

from __future__ import annotations

import pytest
import sympy as sp
from timebound import within

from symdyn.errors import SymdynError
from symdyn.model.bounded import MAX_EXPONENT, MAX_MAGNITUDE, bounded_subs, check_bounded
from symdyn.model.expressions import parse_expression

x, y, b, e = sp.symbols("x y b e")


def fail(message: str) -> SymdynError:
    return SymdynError(message, file="f.yaml", field="mass")


@pytest.mark.parametrize(
    "text",
    [
        "((((x+1)**64)**64)**64)",  # SymPy merges it into (x+1)**262144
        "(((((x**64)**64)**64)**64)**64)",
        "(x**64)**2",
        "x**40*x**40",  # merged into x**80 by multiplication
        "sqrt(x)**200",
    ],
)
def test_towers_are_refused_once_sympy_merges_them(text):
    with within(2), pytest.raises(SymdynError, match=r"field 'mass'.*exponent .* larger than 64"):
        parse_expression(text, file="f.yaml", field="mass")


@pytest.mark.parametrize(
    "text", ["1e200", "-1e151", "10**30*10**30*10**30*10**30*10**30*10**30", "2**64*1e140"]
)
def test_numbers_beyond_the_magnitude_bound_are_refused(text):
    with within(2), pytest.raises(SymdynError, match=r"too large \(more than 1e\+150"):
        parse_expression(text, field="mass")


def test_numbers_within_the_bounds_pass_as_python_computes_them():
    assert parse_expression("x**64") == x**64
    assert parse_expression("(x**8)**8") == x**64
    assert parse_expression("1e150") == sp.Float(1e150)
    assert parse_expression("3**64*5") == sp.Integer(3**64 * 5)
    assert parse_expression(1e-300) == sp.Float(1e-300)


def test_an_exponent_filled_in_by_a_value_is_checked_before_sympy_evaluates_it():
    """m*b**e with e = 9**9 would compute b**387420489 once b has a value."""
    with within(2), pytest.raises(SymdynError, match=r"exponent 387420489 in 'b\*\*e' is larger than 64"):
        bounded_subs(sp.Symbol("m") * b**e, {e: sp.Integer(9**9)}, fail)
    with within(2), pytest.raises(SymdynError, match="exponent 4096"):
        bounded_subs(x**64, {x: y**64}, fail)  # (y**64)**64 merges into y**4096


def test_a_numeric_power_is_refused_before_it_is_computed():
    with within(2), pytest.raises(SymdynError, match="too large"):
        bounded_subs(x**64, {x: sp.Integer(3**64)}, fail)  # 3**4096: 6,500 bits


def test_substitution_within_the_bounds_equals_xreplace():
    expr = sp.sin(x) * y**3 + x**64 / (y + 1)
    values = {x: sp.Integer(3), y: sp.Rational(1, 2)}
    assert bounded_subs(expr, values, fail) == expr.xreplace(values)
    assert bounded_subs(expr, values, fail).equals(sp.sin(3) / 8 + sp.Integer(3**64) * sp.Rational(2, 3))


def test_check_bounded_names_the_field():
    with pytest.raises(SymdynError, match=f"f.yaml: field 'mass': exponent {MAX_EXPONENT + 1}"):
        check_bounded(x ** (MAX_EXPONENT + 1), fail)
    with pytest.raises(SymdynError, match="not finite as a double"):
        check_bounded(sp.Float("1e400"), fail)
    check_bounded(sp.Float(MAX_MAGNITUDE) * x**MAX_EXPONENT, fail)
