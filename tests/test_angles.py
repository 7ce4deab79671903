"""Decimal angles near multiples of pi/2 (symdyn.model.angles): snapped within 1e-9 rad, warned within 1e-3.

Expected values come from elsewhere: the multiples are written as k*pi/2 by hand,
and the distance of a double from the nearest multiple is computed exactly (the
double's binary value as a rational, minus k*pi/2 evaluated to 50 digits).
"""

from __future__ import annotations

import math
import warnings

import pytest
import sympy as sp
from hypothesis import assume, given
from hypothesis import strategies as st
from robots import raw_example
from timebound import within

from symdyn.errors import SymdynError, SymdynWarning
from symdyn.model.angles import LARGEST, SNAP_TOLERANCE, WARN_TOLERANCE, snap_angle
from symdyn.model.expressions import parse_expression
from symdyn.parsers import robot_from_data

HALF_PI = math.pi / 2


def snap(value, **where):
    """snap_angle(value) and the messages of the SymdynWarnings it gave."""
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        out = snap_angle(value if isinstance(value, sp.Basic) else sp.Float(value), **where)
    assert all(issubclass(w.category, SymdynWarning) for w in caught)
    return out, [str(w.message) for w in caught]


@pytest.mark.parametrize("k", [*range(-9, 10), 40, -63])
def test_every_multiple_of_a_right_angle_becomes_exact(k):
    """k pi/2 as a double (negative, and beyond 2 pi too) becomes SymPy's exact k*pi/2."""
    out, warned = snap(k * HALF_PI)
    assert out == k * sp.pi / 2 and not warned
    assert sp.cos(out) in (-1, 0, 1) and sp.sin(out) in (-1, 0, 1)


@pytest.mark.parametrize(
    "text, exact",
    [
        ("1.5707963267948966", sp.pi / 2),
        ("-1.5707963267948966", -sp.pi / 2),
        ("3.14159265359", sp.pi),  # 2.1e-13 from pi
        ("-4.71238898038", -3 * sp.pi / 2),  # 4.7e-12 from -3 pi/2
        ("7.853981633974483", 5 * sp.pi / 2),
        ("-6.283185307179586", -2 * sp.pi),
        ("2 * 1.5707963267948966", sp.pi),  # an expression of decimals, no symbol
        ("1.57079632679489661923132169", sp.pi / 2),  # more digits than a double holds
    ],
)
def test_decimals_as_written_in_files_snap(text, exact):
    out, warned = snap(parse_expression(text))
    assert out == exact and not warned


def test_the_1e9_boundary_on_both_sides():
    for k in (1, -1, 2, -3, 5, 12):
        for sign in (1, -1):
            inside = k * HALF_PI + sign * 0.99 * SNAP_TOLERANCE
            out, warned = snap(inside)
            assert out == k * sp.pi / 2 and not warned, (k, sign)
            outside = k * HALF_PI + sign * 1.01 * SNAP_TOLERANCE
            out, warned = snap(outside)
            assert out == sp.Float(outside) and len(warned) == 1, (k, sign)


def test_the_1e3_boundary_of_the_warning():
    for sign in (1, -1):
        out, warned = snap(HALF_PI + sign * 0.99 * WARN_TOLERANCE)
        assert len(warned) == 1 and out == sp.Float(HALF_PI + sign * 0.99 * WARN_TOLERANCE)
        out, warned = snap(HALF_PI + sign * 1.01 * WARN_TOLERANCE)
        assert not warned and out == sp.Float(HALF_PI + sign * 1.01 * WARN_TOLERANCE)


@pytest.mark.parametrize(
    "value, multiple, spelled, as_double",
    [
        (1.5708, "pi/2", "write pi/2 if pi/2 is meant", "write 1.5707963267948966 if pi/2 is meant"),
        (-1.5708, "-pi/2", "write -pi/2 if -pi/2", "write -1.5707963267948966 if -pi/2"),
        (3.1416, "pi", "write pi if pi", "write 3.141592653589793 if pi"),
        (-3.14159, "-pi", "write -pi if -pi", "write -3.141592653589793 if -pi"),
        (4.7124, "3*pi/2", "write 3*pi/2 if 3*pi/2", "write 4.71238898038469 if 3*pi/2"),
        (-7.854, "-5*pi/2", "write -5*pi/2 if -5*pi/2", "write -7.853981633974483 if -5*pi/2"),
        (6.2832, "2*pi", "write 2*pi if 2*pi", "write 6.283185307179586 if 2*pi"),
    ],
)
def test_a_printed_right_angle_is_kept_with_one_warning_naming_the_multiple(
    value, multiple, spelled, as_double
):
    where = {"file": "arm.yaml", "link_index": 3, "link_name": "elbow", "field": "alpha"}
    out, warned = snap(value, **where)
    assert out == sp.Float(value)  # kept as written
    (message,) = warned
    assert message.startswith(f"arm.yaml: link 3 (elbow): field 'alpha': {value!r} rad is ")
    assert f"rad from {multiple}, so it is kept as written" in message and spelled in message
    exact = sp.Integer(round(value / HALF_PI)) * sp.pi / 2
    assert f"is {abs(value - float(exact)):.2g} rad from" in message
    (message,) = snap(value, expressions=False, angle="pitch", line=12, **where)[1]
    assert f"field 'alpha': pitch {value!r} rad" in message
    assert as_double in message and message.endswith("is meant (line 12)")


@pytest.mark.parametrize("value", [5e-4, -9.9e-4, 0.01, 1.0, 0.7853981633974483, 2.0, 1.55, -3.16])
def test_angles_near_zero_or_far_from_a_right_angle_are_left_alone(value):
    out, warned = snap(value)
    assert out == sp.Float(value) and not warned


@pytest.mark.parametrize("value", [0.0, -0.0, 6.123233995736766e-17, 1e-10, -0.99e-9])
def test_rounding_noise_around_zero_becomes_exact_zero(value):
    out, warned = snap(value)
    assert out == 0 and out.is_Integer and not warned


@pytest.mark.parametrize(
    "value",
    [
        sp.pi / 2,
        -sp.pi,
        sp.Integer(0),
        sp.Integer(2),
        sp.Rational(1, 3),
        sp.pi / 3,
        sp.Symbol("q") + sp.Float(1.5707963267948966),  # a symbol: not a number
        sp.Symbol("alpha1"),
        sp.Float(LARGEST * 1.5),  # beyond any plausible angle
    ],
)
def test_exact_values_symbols_and_huge_numbers_pass_unchanged(value):
    out, warned = snap(value)
    assert out is value and not warned


def _exact_distance(x: float) -> tuple[int, float]:
    """(k, |x - k pi/2|) with x's binary value taken exactly and pi to 50 digits."""
    k = round(x / HALF_PI)
    return k, abs(float((sp.Rational(x) - k * sp.pi / 2).evalf(50)))


@given(
    k=st.integers(-200, 200),
    offset=st.one_of(
        st.floats(-3e-9, 3e-9), st.floats(-2e-3, 2e-3), st.sampled_from([0.0, 1e-12, -1e-12, 5e-10])
    ),
)
def test_the_rule_against_exact_arithmetic(k, offset):
    x = k * HALF_PI + offset
    kk, distance = _exact_distance(x)
    # the helper works in doubles: stay clear of the thresholds by more than their rounding
    assume(abs(distance - SNAP_TOLERANCE) > 1e-13 and abs(distance - WARN_TOLERANCE) > 1e-13)
    out, warned = snap(x)
    if distance <= SNAP_TOLERANCE:
        assert out == kk * sp.pi / 2 and not warned
    else:
        assert out == sp.Float(x)
        assert len(warned) == (1 if kk != 0 and distance <= WARN_TOLERANCE else 0)


@pytest.mark.parametrize(
    "text, double",
    [
        ("pi/2*pi/2", math.pi**2 / 4),
        ("sqrt(2)", math.sqrt(2)),
        ("sin(1)", math.sin(1)),
        ("0.3*pi", 0.3 * math.pi),
        ("pi + 0.25", math.pi + 0.25),
    ],
)
def test_constants_that_sympy_cannot_simplify_become_doubles(text, double):
    """cos(pi**2/4) would stay a symbol in every product of the derivation; the double does not."""
    out, warned = snap(parse_expression(text))
    assert out.is_Float and float(out) == pytest.approx(double, rel=1e-15) and not warned


def test_a_constant_near_a_right_angle_snaps_like_a_decimal():
    assert snap(parse_expression("0.5*pi"))[0] == sp.pi / 2
    assert snap(parse_expression("pi*(1/2 + 1e-12)"))[0] == sp.pi / 2


def test_a_constant_angle_that_is_not_a_finite_real_number_is_refused():
    with pytest.raises(
        SymdynError, match=r"f.yaml: link 2 \(a\): field 'alpha': angle .* not a finite real number"
    ):
        snap_angle(sp.sqrt(-2) + 1, file="f.yaml", link_index=2, link_name="a", field="alpha")


def test_the_panda_with_a_twist_of_pi_squared_over_4_is_the_panda_with_its_double():
    """examples/panda.yaml with link 4's alpha written "pi/2*pi/2" ran past 120 s; now it is the
    robot with that twist written as the double pi**2/4 (2.4674011002723395)."""
    data = raw_example("panda")
    data["links"][3]["alpha"] = "pi/2*pi/2"
    with within(20):
        robot = robot_from_data(data, "panda")
    data["links"][3]["alpha"] = math.pi**2 / 4
    assert robot.links[3].frame == robot_from_data(data, "panda").links[3].frame
    assert not any(link.frame.R.has(sp.pi**2) for link in robot.links)
