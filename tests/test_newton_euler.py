"""The symbolic recursive Newton-Euler route against the numeric spatial RNEA and hand closed forms."""

from __future__ import annotations

import numpy as np
import pytest
import sympy as sp
from hypothesis import HealthCheck, event, given, settings
from robots import (
    EXAMPLE_NAMES,
    ZERO3,
    Z,
    assert_close,
    build_robot,
    ev,
    example,
    random_params,
    random_state,
    robot_specs,
    vec,
    without_motors,
)

from symdyn.algorithms.newton_euler import newton_euler
from symdyn.dynamics import METHODS, derive
from symdyn.model.robot import Link, Robot
from symdyn.model.symbols import joint_symbols
from symdyn.rnea import bias_torque, gravity_torque, mass_matrix, rnea
from symdyn.spatial.transform import Transform
from symdyn.symbolic.program import Program


@settings(max_examples=25, deadline=None, database=None, suppress_health_check=[HealthCheck.too_slow])
@given(robot_specs(max_joints=5))
def test_newton_euler_equals_rnea_on_random_robots(spec):
    """Random chains: DH (both conventions, through robot_from_data) or general placements/axes.

    Up to five joints: every kind, joint type and twist is drawn at any length, and a link's
    recursion step is the same however many follow; a 7-joint example cost four times a 4-joint
    one. Six and seven joints against the oracle: the PUMA, UR5, Stanford arm and Panda in
    test_dynamics.py::test_derive_equals_rnea_on_examples."""
    event(f"{spec.kind}, {spec.n} joints")
    robot = build_robot(spec)
    dyn = derive(robot, method="newton-euler", simplify=False)
    rng = np.random.default_rng(spec.seed)
    q, qd, qdd = random_state(robot, rng)
    what = f"{spec} at q={q}, qd={qd}, qdd={qdd}"
    assert_close(dyn.evaluate("tau", q, qd, qdd), rnea(robot, q, qd, qdd), what=what)
    assert_close(ev(dyn, "M", q), mass_matrix(robot, q), what=what)
    assert_close(dyn.evaluate("V", q, qd), bias_torque(robot, q, qd), what=what)
    assert_close(dyn.evaluate("G", q), gravity_torque(robot, q), what=what)


@pytest.mark.parametrize("name", EXAMPLE_NAMES)
def test_recursion_with_numeric_inputs(name):
    """newton_euler() on numbers folds to numbers: the rigid-body part of the RNEA."""
    robot = example(name)
    rng = np.random.default_rng(2)
    p = random_params(robot, rng) if robot.params else None
    numeric = robot.numeric(p)
    bare = without_motors(robot)
    for _ in range(3):
        q, qd, qdd = random_state(robot, rng)
        tau = newton_euler(numeric, list(q), list(qd), list(qdd), Program())
        assert all(sp.sympify(t).is_number for t in tau)
        want = rnea(bare, q, qd, qdd, p, friction=False)
        assert_close([float(t) for t in tau], want)
        tau_g = newton_euler(numeric, list(q), [0] * robot.n, [0] * robot.n, Program())
        assert_close([float(t) for t in tau_g], gravity_torque(bare, q, p))


@pytest.mark.parametrize("name", ["roger_arm", "planar_3r", "scara", "stanford"])
def test_zero_inputs_fold_away(name):
    """No gravity, no velocity, no acceleration: every effort is exactly zero, no program."""
    robot = example(name).resolved()
    q, _, _ = joint_symbols(robot.n)
    program = Program()
    zeros = [0] * robot.n
    tau = newton_euler(robot, list(q), zeros, zeros, program, gravity=False)
    assert all(t == 0 for t in tau)
    assert len(program) == 0


def polar_arm() -> tuple[Robot, tuple]:
    """A turntable (inertia I1 about the vertical z) carrying a point mass m on a radial slide.

    The slide runs along body 1's x axis; the mass sits at r = c + q2. Hand-derived
    (Lagrange, T = 1/2 (I1 + m r^2) qd1^2 + 1/2 m qd2^2, gravity along -z does no work):
        tau1 = (I1 + m r^2) qdd1 + 2 m r qd1 qd2
        tau2 = m qdd2 - m r qd1^2
    """
    I1, m, c, g = sp.symbols("I1 m c g", positive=True)
    table_inertia = sp.ImmutableMatrix(sp.diag(0, 0, I1))
    table = Link("table", "revolute", Transform.identity(), Z, sp.S.Zero, vec([0, 0, 0]), table_inertia)
    slide = Link("slide", "prismatic", Transform.tx(c), vec([1, 0, 0]), m, vec([0, 0, 0]), ZERO3)
    robot = Robot("polar", (table, slide), vec([0, 0, -g]), params=(I1, m, c, g))
    return robot, (I1, m, c, g)


@pytest.mark.parametrize("method", METHODS)
def test_prismatic_coriolis_closed_form(method):
    """The 2 w x d' term of the prismatic recursion (slide 15), against a hand-derived arm."""
    robot, (I1, m, c, g) = polar_arm()
    dyn = derive(robot, method=method, simplify=False)
    q, qd, qdd = dyn.q, dyn.qd, dyn.qdd
    r = c + q[1]
    want = sp.Matrix([(I1 + m * r**2) * qdd[0] + 2 * m * r * qd[0] * qd[1], m * qdd[1] - m * r * qd[0] ** 2])
    assert sp.simplify(dyn.tau - want) == sp.zeros(2, 1)
    assert sp.simplify(dyn.M - sp.diag(I1 + m * r**2, m)) == sp.zeros(2, 2)
    assert sp.zeros(2, 1) == dyn.G
