"""The Lagrange route: equal to Newton-Euler symbolically (small arms), to the numeric RNEA on
random robots, and consistent with the kinetic and potential energies of the numeric oracle."""

from __future__ import annotations

import zlib

import numpy as np
import pytest
import sympy as sp
from hypothesis import HealthCheck, event, given, settings
from robots import (
    EXAMPLE_NAMES,
    assert_close,
    assert_matrix_zero,
    build_robot,
    derived,
    derived_robot,
    ev,
    example,
    random_params,
    random_state,
    rational_example,
    robot_specs,
    sym3_data,
)

from symdyn.dynamics import QUANTITIES, derive
from symdyn.parsers.robot_file import robot_from_data
from symdyn.rnea import bias_torque, gravity_torque, kinetic_energy, mass_matrix, potential_energy, rnea

SMALL = {
    "roger_arm": lambda: example("roger_arm"),
    "planar_3r": lambda: rational_example("planar_3r"),
    "sym3_standard": lambda: robot_from_data(sym3_data("standard")),
    "sym3_modified": lambda: robot_from_data(sym3_data("modified")),
}


@pytest.mark.parametrize("name", list(SMALL))
def test_lagrange_equals_newton_euler_symbolically(name):
    """Exact equality of M, C, V, G, F, tau for arms of up to 3 joints.

    planar_3r is read with its decimals as exact rationals (floats would leave 1e-17
    residues); sym3 is an RPR arm with pi/2 twists and every parameter symbolic.
    """
    robot = SMALL[name]()
    assert robot.n <= 3
    ne, la = derived_robot(robot, "newton-euler"), derived_robot(robot, "lagrange")
    assert ne.params == la.params == robot.params
    for quantity in QUANTITIES:
        diff = la.closed_form(quantity) - ne.closed_form(quantity)
        assert_matrix_zero(diff, robot.n, f"{name} {quantity}: lagrange - newton-euler")


def test_lagrange_equals_newton_euler_roger_arm_simplified():
    """The default closed forms (trigonometrically simplified) of both methods agree."""
    ne = derived("roger_arm", "newton-euler", None)
    la = derived("roger_arm", "lagrange", None)
    for quantity in ("M", "C", "V", "G"):
        assert sp.simplify(la.closed_form(quantity) - ne.closed_form(quantity)) == sp.zeros(
            *ne.closed_form(quantity).shape
        )


@pytest.mark.parametrize("name", EXAMPLE_NAMES)
def test_energies_of_the_numeric_oracle(name):
    """1/2 qd^T M qd is the kinetic energy and G the gradient of the potential energy."""
    robot = example(name)
    dyn = derived(name, "lagrange")
    rng = np.random.default_rng(zlib.crc32(name.encode()))
    h = 1e-6
    for _ in range(5):
        q, qd, _ = random_state(robot, rng)
        p = random_params(robot, rng) if robot.params else None
        M = ev(dyn, "M", q, params=p)
        assert_close(0.5 * qd @ M @ qd, kinetic_energy(robot, q, qd, p))
        grad = [
            (potential_energy(robot, q + h * e, p) - potential_energy(robot, q - h * e, p)) / (2 * h)
            for e in np.eye(robot.n)
        ]
        assert_close(dyn.evaluate("G", q, params=p), grad, rtol=1e-6)


@settings(max_examples=25, deadline=None, database=None, suppress_health_check=[HealthCheck.too_slow])
@given(robot_specs(max_joints=4))
def test_lagrange_equals_rnea_on_random_robots(spec):
    event(f"{spec.kind}, {spec.n} joints")
    robot = build_robot(spec)
    dyn = derive(robot, method="lagrange", simplify=False)
    rng = np.random.default_rng(spec.seed)
    q, qd, qdd = random_state(robot, rng)
    what = f"{spec} at q={q}, qd={qd}, qdd={qdd}"
    assert_close(dyn.evaluate("tau", q, qd, qdd), rnea(robot, q, qd, qdd), what=what)
    assert_close(ev(dyn, "M", q), mass_matrix(robot, q), what=what)
    assert_close(dyn.evaluate("V", q, qd), bias_torque(robot, q, qd), what=what)
    assert_close(dyn.evaluate("G", q), gravity_torque(robot, q), what=what)
