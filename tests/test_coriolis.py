"""The composite-body Coriolis matrix (algorithms.coriolis) against routes that do not share its algebra.

- exactly: C = 1/2 dV/dqd, with dV/dqd from Program.diff (forward-mode differentiation of the
  Newton-Euler pass for V) for arms of up to 3 joints, both DH conventions and a prismatic joint;
- numerically: C[:, j] = (V(qd + e_j) - V(qd - e_j)) / 4 with V from the independent numeric
  RNEA (V is quadratic in qd, so this central difference is exact), for every example and for
  random chains with arbitrary joint axes;
- its cost: at most 3 times the operations of V for the 6- and 7-joint arms (issue 4).
"""

from __future__ import annotations

import zlib

import numpy as np
import pytest
import sympy as sp
from hypothesis import HealthCheck, given, settings
from robots import (
    EXAMPLE_NAMES,
    assert_close,
    assert_matrix_zero,
    build_robot,
    derived,
    derived_robot,
    ev,
    example,
    example_context,
    random_params,
    random_state,
    rational_example,
    robot_specs,
    roger_arm_robot,
    sym3_data,
)

from symdyn.parsers.robot_file import robot_from_data
from symdyn.rnea import bias_torque

SMALL = {
    "roger_arm": roger_arm_robot,
    "planar_3r": lambda: rational_example("planar_3r"),
    "sym3_standard": lambda: robot_from_data(sym3_data("standard")),
    "sym3_modified": lambda: robot_from_data(sym3_data("modified")),
}


@pytest.mark.parametrize("name", list(SMALL))
def test_half_derivative_of_V_exactly(name):
    robot = SMALL[name]()
    dyn = derived_robot(robot, "newton-euler")
    program, n = dyn.program, robot.n
    V = list(dyn.compact["V"])
    dV = sp.Matrix.hstack(*(sp.Matrix(program.diff(V, dyn.qd[j], "check")) for j in range(n)))
    C = sp.Matrix(n, n, program.expand(list(dyn.compact["C"])))
    half = sp.Matrix(n, n, program.expand(list(dV))) / 2
    assert_matrix_zero(C - half, n, f"{name}: C - 1/2 dV/dqd")


def _check_columns(robot, C_of, params, rng, states: int = 4) -> None:
    n = robot.n
    for _ in range(states):
        q, qd, _ = random_state(robot, rng)
        C = C_of(q, qd)
        for j in range(n):
            e = np.eye(n)[j]
            want = (bias_torque(robot, q, qd + e, params) - bias_torque(robot, q, qd - e, params)) / 4
            assert_close(C[:, j], want, what=f"{robot.name} column {j + 1} at q={q} qd={qd}")


@pytest.mark.parametrize("name", EXAMPLE_NAMES)
def test_columns_from_the_numeric_rnea(name):
    robot = example(name)
    dyn = derived(name, "newton-euler")
    rng = np.random.default_rng(11 + zlib.crc32(name.encode()))
    params = random_params(robot, rng) if robot.params else None
    _check_columns(robot, lambda q, qd: ev(dyn, "C", q, qd, params=params), params, rng)


@settings(max_examples=15, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(robot_specs(min_joints=1, max_joints=5))
def test_columns_on_random_chains(spec):
    """Arbitrary placements and joint axes (the general rotation path), prismatic joints."""
    robot = build_robot(spec)
    dyn = derived_robot(robot, "newton-euler")
    rng = np.random.default_rng(spec.seed)
    _check_columns(robot, lambda q, qd: ev(dyn, "C", q, qd), None, rng, states=2)


@pytest.mark.parametrize("name", ["puma560", "stanford", "panda"])
def test_at_most_three_times_the_operations_of_V(name):
    ops = {f.name: f.ops.total for f in example_context(name).functions}  # session-cached
    assert ops["coriolis_matrix"] <= 3 * ops["coriolis"], ops
