"""Joint friction (symdyn.model.friction), symmetric and direction-dependent.

Expected values are written out by hand: F = b qd + c sign(qd) (symmetric), and for the
Robotics Toolbox's PUMA 560 joint 1 (B = 1.48e-3, Tc+ = 0.395, Tc- = -0.435, written in a robot
file as the magnitudes [0.395, 0.435]) F = 1.48e-3 qd + 0.395 at qd > 0, 1.48e-3 qd - 0.435 at
qd < 0, 0 at rest; the whole inverse dynamics differs from the frictionless one by exactly F,
in the derivation (both routes) and in the numeric oracle symdyn.rnea.
"""

from __future__ import annotations

import importlib

import numpy as np
import pytest
import sympy as sp
from robots import (
    ASYMMETRIC_PARAMS,
    asymmetric_friction,
    derived_robot,
    friction_closed_form,
    friction_states,
)

from symdyn.model.friction import Friction
from symdyn.parsers import robot_from_data

rn = importlib.import_module("symdyn.rnea")  # the module (symdyn.rnea is also the function)
x = sp.Symbol("x", real=True)


def _at(expr: sp.Expr, value) -> sp.Expr:
    return sp.sympify(expr).subs(x, value)


def test_symmetric_friction_is_viscous_plus_coulomb_sign():
    f = Friction(sp.Rational(1, 10), sp.Rational(3, 10))
    assert not f.asymmetric and f.coefficients() == (sp.Rational(1, 10), sp.Rational(3, 10))
    assert [_at(f.effort(x), v) for v in (2, -2, 0)] == [sp.Rational(1, 2), -sp.Rational(1, 2), 0]
    assert f.coulomb_columns(x) == [sp.sign(x)]


def test_direction_dependent_friction_takes_each_magnitude_on_its_side_and_zero_at_rest():
    b, cp, cm = sp.symbols("b cp cm", nonnegative=True)
    f = Friction(b, cp, cm)
    assert f.asymmetric and f.coefficients() == (b, cp, cm)
    assert _at(f.effort(x), 2) == 2 * b + cp
    assert _at(f.effort(x), -2) == -2 * b - cm
    assert _at(f.effort(x), 0) == 0
    plus, minus = f.coulomb_columns(x)
    assert [(_at(plus, v), _at(minus, v)) for v in (3, -3, 0)] == [(1, 0), (0, -1), (0, 0)]
    assert f.subs({cm: 2}).coulomb_minus == 2 and Friction(b, cp).subs({cp: 1}).coulomb_minus is None


@pytest.mark.parametrize("method", ["newton-euler", "lagrange"])
def test_puma560_joint1_toolbox_friction(method):
    """The toolbox's joint-1 values give tau - tau(no friction) = 1.48e-3 + 0.395 at qd1 = +1,
    -1.48e-3 - 0.435 at qd1 = -1 and 0 at rest (hand-computed: 0.39648, -0.43648, 0)."""
    robot = asymmetric_friction()
    dyn = derived_robot(robot, method)
    F1 = dyn.F[0]
    qd1 = sp.Symbol("qd1")
    assert [float(F1.subs(qd1, v)) for v in (1, -1, 0)] == pytest.approx([0.39648, -0.43648, 0.0], abs=1e-15)
    q, qdd = np.array([0.3, -0.7, 1.1]), np.array([0.5, -0.2, 0.4])
    for v, want in ((1.0, 0.39648), (-1.0, -0.43648), (0.0, 0.0)):
        qd = np.array([v, 0.0, 0.0])
        diff = rn.rnea(robot, q, qd, qdd, ASYMMETRIC_PARAMS) - rn.rnea(
            robot, q, qd, qdd, ASYMMETRIC_PARAMS, friction=False
        )
        np.testing.assert_allclose(diff, [want, 0.0, 0.0], rtol=0, atol=1e-12)


@pytest.mark.parametrize("method", ["newton-euler", "lagrange"])
def test_both_routes_match_the_oracle_at_rates_of_both_signs_and_at_rest(method):
    robot = asymmetric_friction()
    dyn = derived_robot(robot, method)
    for q, qd, qdd, _ in zip(*friction_states(), strict=True):
        np.testing.assert_allclose(
            dyn.evaluate("F", q, qd, qdd, ASYMMETRIC_PARAMS), friction_closed_form(qd), atol=1e-14
        )
        want = rn.rnea(robot, q, qd, qdd, ASYMMETRIC_PARAMS)
        np.testing.assert_allclose(
            dyn.evaluate("tau", q, qd, qdd, ASYMMETRIC_PARAMS), want, rtol=1e-10, atol=1e-12
        )


def test_a_mimic_joint_takes_the_magnitude_of_its_own_direction():
    """Link b follows link a with multiplier -2, so it moves backwards when a moves forwards:
    F_1 = (0.1 qd + c_a) - 2 (0.2 (-2 qd) - c-_b) at qd > 0, by hand 0.4 + 1.02 = 1.42 at qd = 1,
    and -0.6 - 2.2 = -2.8 at qd = -1 (b's rate +2: 0.4 + 0.7); 0 at rest. Both routes and the
    oracle agree, tau included."""
    link = {"joint": "revolute", "a": 0.5, "mass": 1, "com": [-0.25, 0, 0]}
    link["inertia"] = {"ixx": 0.01, "iyy": 0.02, "izz": 0.02}
    data = {
        "name": "mimic_friction",
        "links": [
            dict(link, name="a", friction={"viscous": 0.1, "coulomb": [0.3, 0.5]}),
            dict(
                link,
                name="b",
                friction={"viscous": 0.2, "coulomb": [0.7, 0.11]},
                mimic={"joint": "a", "multiplier": -2},
            ),
        ],
    }
    robot = robot_from_data(data)
    q, qdd = np.array([0.3]), np.array([0.2])
    for method in ("newton-euler", "lagrange"):
        dyn = derived_robot(robot, method)
        for qd, want in ((1.0, 1.42), (-1.0, -2.8), (0.0, 0.0)):
            assert dyn.evaluate("F", q, [qd], qdd)[0] == pytest.approx(want, abs=1e-14)
            assert rn.friction_torque(robot, [qd])[0] == pytest.approx(want, abs=1e-14)
            np.testing.assert_allclose(
                dyn.evaluate("tau", q, [qd], qdd), rn.rnea(robot, q, [qd], qdd), atol=1e-13
            )
