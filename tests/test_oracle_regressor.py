"""The oracle's regressor (symdyn.oracle.regressor): tau = Y(q, qd, qdd) pi, judged by independent routes.

Y @ pi, with pi the standard parameters of symdyn.standard_parameters (read from the model's
fields), must equal the numeric RNEA symdyn.rnea (which builds each body's spatial inertia from
mass, centre of mass and tensor, never from pi) with friction and rotor inertia, at random states,
to 1e-10 relative: every example robot (standard and modified DH, prismatic joints, free
parameters), random DH and general robots, URDF files, trees and mimic joints, and the real
Solo-12 and Panda-with-gripper of example-robot-data. The inertial columns are also compared with
Pinocchio's `computeJointTorqueRegressor` (a peer library) on URDF files.
"""

from __future__ import annotations

import ast
import importlib
import importlib.metadata
import warnings
from pathlib import Path

import numpy as np
import pytest
import sympy as sp
from hypothesis import given, settings
from robots import (
    ASYMMETRIC_PARAMS,
    EXAMPLE_NAMES,
    assert_close,
    asymmetric_friction,
    build_robot,
    example,
    friction_states,
    random_params,
    random_state,
    robot_specs,
    solo_robot,
    tree_robot,
    y_robot,
)
from test_parameters import pinocchio_order

import symdyn
from symdyn.errors import SymdynError
from symdyn.model.parameters import numeric_parameters, standard_parameters
from symdyn.model.robot import Mimic
from symdyn.oracle.regressor import regressor

rr = importlib.import_module("symdyn.oracle.regressor")
URDF_DIR = Path(__file__).resolve().parent / "data" / "urdf"
URDFS = ("axes", "branch", "cartesian", "fixed_offset", "rpy_chain", "tree", "two_link")
ROBOT_DATA = {
    "solo12": "solo_description/robots/solo12.urdf",
    "panda_gripper": "panda_description/urdf/panda.urdf",
}
RTOL = 1e-10
STATES = 4


def check(robot, seed: int, states: int = STATES) -> None:
    """Y @ pi == symdyn.rnea (friction and rotor inertia included) at random states, one by one."""
    rng = np.random.default_rng(seed)
    params = random_params(robot, rng) if robot.params else None
    pi = numeric_parameters(robot, params)
    for _ in range(states):
        q, qd, qdd = random_state(robot, rng)
        Y = regressor(robot, q, qd, qdd, params)
        assert Y.shape == (robot.n, 13 * robot.nb)
        assert_close(Y @ pi, symdyn.rnea(robot, q, qd, qdd, params), RTOL, robot.name)


@pytest.mark.parametrize("name", EXAMPLE_NAMES)
def test_every_example_robot(name):
    check(example(name), seed=len(name))


@settings(max_examples=25, deadline=None)
@given(robot_specs())
def test_random_dh_and_general_robots(spec):
    """Standard DH, modified DH and general links; revolute and prismatic; friction and motors."""
    check(build_robot(spec), seed=spec.seed % 1000, states=2)


def test_trees_and_mimic_joints():
    check(y_robot(), seed=1)
    check(solo_robot(), seed=2)
    mimic = {3: Mimic(1, sp.Float(1.5), sp.Float(-0.2))}  # link 4 follows link 2 across a fork
    joints = ("revolute", "prismatic", "revolute", "revolute", "prismatic", "revolute")
    robot = tree_robot("tree6", (-1, 0, 0, 2, -1, 4), joints, seed=7, mimic=mimic)
    assert (robot.n, robot.nb) == (5, 6)
    check(robot, seed=3)


@pytest.mark.parametrize("name", URDFS)
def test_urdf_robots(name):
    check(symdyn.load_urdf(URDF_DIR / f"{name}.urdf"), seed=len(name))


def _robot_data(name: str):
    try:
        dist = importlib.metadata.distribution("example-robot-data")
    except importlib.metadata.PackageNotFoundError:
        pytest.skip("example-robot-data is not installed")
    path = dist.locate_file(f"cmeel.prefix/share/example-robot-data/robots/{ROBOT_DATA[name]}")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return symdyn.load_urdf(path)


@pytest.mark.parametrize("name", sorted(ROBOT_DATA))
def test_solo12_tree_and_panda_mimic_finger(name):
    robot = _robot_data(name)
    assert robot.n < robot.nb if name == "panda_gripper" else not robot.is_chain
    check(robot, seed=5, states=2)


def test_batch_shape_and_batch_equals_loop():
    robot = y_robot()
    rng = np.random.default_rng(11)
    q, qd, qdd = (rng.uniform(-2, 2, (5, robot.n)) for _ in range(3))
    Y = regressor(robot, q, qd, qdd)
    assert Y.shape == (5, robot.n, 13 * robot.nb)
    for k in range(5):
        np.testing.assert_array_equal(Y[k], regressor(robot, q[k], qd[k], qdd[k]))
    pi = numeric_parameters(robot)
    assert_close(Y @ pi, symdyn.rnea(robot, q, qd, qdd), RTOL)


def test_joint_columns_are_the_rates_on_the_joints_own_row():
    """Columns Ia, fv, fc of body i: qdd_i, qd_i, sign(qd_i) on row i, zero elsewhere (a chain)."""
    robot = example("puma560")
    q, qd, qdd = np.linspace(-1, 1, 6), np.array([1.0, -2.0, 0.0, 0.5, -0.1, 3.0]), np.arange(6.0)
    Y = regressor(robot, q, qd, qdd)
    for i in range(6):
        expected = np.zeros((6, 3))
        expected[i] = qdd[i], qd[i], np.sign(qd[i])
        np.testing.assert_array_equal(Y[:, 13 * i + 10 : 13 * i + 13], expected)


def test_bad_arguments_are_one_clear_message():
    robot = example("planar_3r")
    with pytest.raises(SymdynError, match=r"^regressor: qd has 2 entries, expected 3"):
        regressor(robot, np.zeros(3), np.zeros(2), np.zeros(3))
    with pytest.raises(SymdynError, match="has free parameters"):
        regressor(example("roger_arm"), np.zeros(2), np.zeros(2), np.zeros(2))


def test_regressor_is_independent_of_the_symbolic_code():
    """Like symdyn.rnea: NumPy, the oracle's own modules, no SymPy and no symbolic derivation."""
    source = Path(rr.__file__).read_text()
    nodes = list(ast.walk(ast.parse(source)))
    modules = {n.module for n in nodes if isinstance(n, ast.ImportFrom)}
    modules |= {a.name for n in nodes if isinstance(n, ast.Import) for a in n.names}
    assert modules <= {"__future__", "numpy", "inputs", "spatial"}
    assert "sympy" not in source


# --- Pinocchio's regressor -------------------------------------------------------------------------


@pytest.mark.parametrize("name", URDFS)
def test_inertial_columns_against_pinocchio(name):
    """pinocchio.computeJointTorqueRegressor: 10 columns per joint in toDynamicParameters order.

    Pinocchio's model is built with every joint free (mimic joints too: nv = nb) and run at the
    bodies' rates q_b = S q + o, qd_b = S qd, qdd_b = S qdd; its rows are projected, S^T Y_b."""
    pin = pytest.importorskip("pinocchio")
    path = URDF_DIR / f"{name}.urdf"
    robot = symdyn.load_urdf(path)
    model = pin.buildModelFromUrdf(str(path))
    data = model.createData()
    order = pinocchio_order(path, robot, model)
    assert robot.nb == model.nv
    S = np.array(robot.selection().tolist(), dtype=float)
    rng = np.random.default_rng(len(name))
    for _ in range(STATES):
        q, qd, qdd = random_state(robot, rng)
        q_b = np.array(robot.body_positions(list(q)), dtype=float)
        qp, v, a = pin.neutral(model), np.zeros(model.nv), np.zeros(model.nv)
        rows = []
        for i, j in enumerate(order):
            joint = model.joints[j]
            if joint.nq == 2:  # a continuous joint: (cos q, sin q)
                qp[joint.idx_q : joint.idx_q + 2] = np.cos(q_b[i]), np.sin(q_b[i])
            else:
                qp[joint.idx_q] = q_b[i]
            v[joint.idx_v], a[joint.idx_v] = S[i] @ qd, S[i] @ qdd
            rows.append(joint.idx_v)
        theirs = pin.computeJointTorqueRegressor(model, data, qp, v, a)[rows]
        theirs = S.T @ np.concatenate([theirs[:, 10 * (j - 1) : 10 * j] for j in order], axis=1)
        ours = regressor(robot, q, qd, qdd).reshape(robot.n, robot.nb, 13)[:, :, :10].reshape(robot.n, -1)
        assert_close(ours, theirs, RTOL, name)


def test_direction_dependent_coulomb_columns():
    """Links 1 and 3 of the arm have c+ and c-: their fc column holds [qd > 0] (fcp) and a column
    after the 13 nb others holds -[qd < 0] (fcn, link order); link 2 keeps sign(qd). Y pi is the
    oracle's tau at rates of both signs and exactly 0."""
    robot = asymmetric_friction()
    names = standard_parameters(robot)[0]
    assert (names[12], names[25], names[38], names[39:]) == ("fcp1", "fc2", "fcp3", ("fcn1", "fcn3"))
    pi = numeric_parameters(robot, ASYMMETRIC_PARAMS)
    assert (pi[12], pi[25], pi[38], *pi[39:]) == (0.395, 0.3, 0.2, 0.435, 0.25)
    for q, qd, qdd, _ in zip(*friction_states(), strict=True):
        Y = regressor(robot, q, qd, qdd, ASYMMETRIC_PARAMS)
        assert Y.shape == (3, 41)
        expected = np.zeros((3, 5))
        expected[0, 0], expected[1, 1], expected[2, 2] = qd[0] > 0, np.sign(qd[1]), qd[2] > 0
        expected[0, 3], expected[2, 4] = -1.0 * (qd[0] < 0), -1.0 * (qd[2] < 0)
        np.testing.assert_array_equal(Y[:, [12, 25, 38, 39, 40]], expected)
        assert_close(Y @ pi, symdyn.rnea(robot, q, qd, qdd, ASYMMETRIC_PARAMS), RTOL, robot.name)
