"""The regressor and base parameters of a floating robot (symdyn.algorithms.regressor's
floating_regressor, symdyn.algorithms.base_parameters), judged by independent routes.

At random states with random unit quaternions: Y pi equals the numeric oracle's inverse dynamics
(symdyn.rnea, friction and rotor inertia included) on the small floating arm of tests/data and on
Solo-12, and Y's inertial columns equal Pinocchio's computeJointTorqueRegressor with a free flyer;
the base regressor has full column rank, the rank of Y, and Y_b pi_b = tau. The generated C
(strict flags, -Werror) and NumPy regressor functions give the oracle's tau too.
"""

from __future__ import annotations

import ctypes
from pathlib import Path

import numpy as np
import pytest
import sympy as sp
from cbuild import load_c_and_numpy
from robots import floating_solo12

import symdyn
from symdyn import SymdynError
from symdyn.codegen import render
from symdyn.model.parameters import INERTIAL_NAMES, numeric_parameters, standard_parameters

ARM = Path(__file__).parent / "data" / "floating_arm.yaml"


def _state(robot, rng):
    x = rng.normal(size=4)
    q = np.concatenate([rng.normal(size=3), x / np.linalg.norm(x), rng.uniform(-1, 1, robot.n)])
    return q, rng.normal(size=robot.nv), rng.normal(size=robot.nv)


def _compact(dyn):
    Y = dyn.regressor_compact()
    steps = dyn.program.needed(list(Y))
    return sp.lambdify(
        [list(dyn.q), list(dyn.qd), list(dyn.qdd)], Y, modules="numpy", cse=lambda e: (steps, e)
    )


@pytest.fixture(scope="module")
def arm():
    robot = symdyn.load_robot(ARM)
    return symdyn.derive(robot, simplify=False)


@pytest.fixture(scope="module")
def solo():
    if floating_solo12() is None:
        pytest.skip("example-robot-data is not installed")
    return floating_solo12()


def _check(dyn, seed: int, states: int = 12) -> None:
    """Y pi = tau (oracle); the base regressor: full rank = rank(Y), Y_b pi_b = tau."""
    robot = dyn.robot
    f = _compact(dyn)
    Y, base = dyn.linear_compact()
    names = standard_parameters(robot)[0]
    assert Y.shape == (robot.nv, 13 * robot.nb + 10)
    assert names[-10:] == tuple(f"{p}0" for p in INERTIAL_NAMES)  # the base body's, last
    pi = numeric_parameters(robot)
    pi_b = base.matrix() @ pi
    rng = np.random.default_rng(seed)
    stacked = []
    for _ in range(states):
        q, v, a = _state(robot, rng)
        Ys = np.asarray(f(q, v, a), dtype=float)
        tau = symdyn.rnea(robot, q, v, a)
        scale = max(1.0, np.abs(tau).max())
        np.testing.assert_allclose(Ys @ pi, tau, atol=1e-10 * scale)
        np.testing.assert_allclose(Ys[:, list(base.columns)] @ pi_b, tau, atol=1e-9 * scale)
        assert not Ys[6:, -10:].any()  # the base body's columns: base rows only
        stacked.append(Ys)
    W = np.concatenate(stacked)
    r = len(base.names)
    assert np.linalg.matrix_rank(W) == r == np.linalg.matrix_rank(W[:, list(base.columns)])


def test_arm_regressor_and_base_parameters(arm):
    _check(arm, 3)
    names = [n for n, _ in arm.base_parameters]
    # the total mass of the base and the links it carries whatever the joints do: one parameter
    assert names[0] == "m0R" and str(arm.base_parameters[0][1]) == "m0 + m1 + m2"


def test_solo_regressor_equals_pinocchio(solo):
    pin = pytest.importorskip("pinocchio", reason="the test extra installs pin (Pinocchio)")
    path, solo = solo
    _check(solo, 5, states=10)
    model = pin.buildModelFromUrdf(str(path), pin.JointModelFreeFlyer())
    data = model.createData()
    f = _compact(solo)
    rng = np.random.default_rng(7)
    nb = solo.robot.nb
    for _ in range(3):
        q, v, a = _state(solo.robot, rng)
        Ys = np.asarray(f(q, v, a), dtype=float)
        ours = np.concatenate([Ys[:, -10:], *(Ys[:, 13 * i : 13 * i + 10] for i in range(nb))], 1)
        np.testing.assert_allclose(ours, pin.computeJointTorqueRegressor(model, data, q, v, a), atol=1e-12)


def test_generated_regressor_functions_equal_the_oracle(arm, tmp_path):
    robot = arm.robot
    name = robot.name
    files = render(robot, targets=("c", "python"), functions=["regressor"])
    lib, numpy_module = load_c_and_numpy(files, tmp_path, name)
    pi = numeric_parameters(robot)
    K = arm.linear_compact()[1].matrix()
    ptr = ctypes.POINTER(ctypes.c_double)
    rng = np.random.default_rng(4)
    for _ in range(2):
        q, v, a = _state(robot, rng)
        tau = symdyn.rnea(robot, q, v, a)
        for fname, width, coeffs in (("regressor", len(pi), pi), ("base_regressor", K.shape[0], K @ pi)):
            out = np.full(robot.nv * width, np.nan)
            fn = getattr(lib, f"{name}_{fname}")
            fn.argtypes = [ptr] * 5
            fn(
                *(np.ascontiguousarray(x).ctypes.data_as(ptr) for x in (q, v, a)),
                None,
                out.ctypes.data_as(ptr),
            )
            np.testing.assert_allclose(out.reshape(robot.nv, width) @ coeffs, tau, atol=1e-10, err_msg=fname)
            got = np.asarray(getattr(numpy_module, fname)(q, v, a)) @ coeffs
            np.testing.assert_allclose(got, tau, atol=1e-10, err_msg=f"NumPy {fname}")


def test_identification_checks_the_floating_sizes(arm):
    """identify takes a floating robot (tests/test_identify.py identifies this arm) but not
    measurements of a fixed base's sizes."""
    from symdyn.apps.identification.identify import identify
    from symdyn.apps.identification.measurements import Measurements

    z = np.zeros((50, 3))
    with pytest.raises(SymdynError, match=r"^identify: robot 'floating_arm' has NQ = 10 positions and NV = "):
        identify(arm.robot, Measurements(z[:, 0], z, z, z, z), arm.base_parameters)
