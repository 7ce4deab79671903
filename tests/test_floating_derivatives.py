"""The derivatives of a floating robot's dynamics (symdyn.algorithms.derivatives'
floating_effort_jacobians, the derivatives group of symdyn.codegen.derivative_functions) in the
tangent space, judged by independent routes.

dtau/dq . delta = d/de tau(q (+) e delta) at e = 0 with (+) Pinocchio's `integrate`, as
computeRNEADerivatives and computeABADerivatives define them: on Solo-12 the derivation equals
Pinocchio's computeRNEADerivatives; on the small floating arm of tests/data the generated C
(strict flags, -Werror) and NumPy functions equal central finite differences through
pinocchio.integrate of the numeric oracle's inverse and forward dynamics, and M^-1 its inverse.
"""

from __future__ import annotations

import ctypes
from pathlib import Path

import numpy as np
import pytest
from cbuild import load_c_and_numpy
from robots import floating_solo12

import symdyn
from symdyn.algorithms.base_parameters import evaluate
from symdyn.algorithms.derivatives import floating_effort_jacobians
from symdyn.codegen import render
from symdyn.rnea import forward_dynamics, mass_matrix

pin = pytest.importorskip("pinocchio", reason="the test extra installs pin (Pinocchio)")

ARM = Path(__file__).parent / "data" / "floating_arm.yaml"
STEP = 1e-6


def _flyer_model(n: int):
    """A Pinocchio model with a free flyer and n joints whose integration is addition: its
    `integrate` is the floating arm's q (+) v."""
    model = pin.Model()
    parent = model.addJoint(0, pin.JointModelFreeFlyer(), pin.SE3.Identity(), "base")
    for i in range(n):
        parent = model.addJoint(parent, pin.JointModelRZ(), pin.SE3.Identity(), f"j{i}")
    return model


def _tangent_differences(f, model, q: np.ndarray) -> np.ndarray:
    """d/de f(integrate(q, e delta_j)) at e = 0 for each tangent direction j, central differences."""
    columns = []
    for j in range(model.nv):
        d = np.zeros(model.nv)
        d[j] = STEP
        columns.append((f(pin.integrate(model, q, d)) - f(pin.integrate(model, q, -d))) / (2 * STEP))
    return np.array(columns).T


def _state(robot, rng):
    x = rng.normal(size=4)
    q = np.concatenate([rng.normal(size=3), x / np.linalg.norm(x), rng.uniform(-1, 1, robot.n)])
    return q, rng.normal(size=robot.nv), rng.normal(size=robot.nv)


def test_solo_derivatives_equal_pinocchio():
    if floating_solo12() is None:
        pytest.skip("example-robot-data is not installed")
    solo, dyn = floating_solo12()
    prog = dyn.program.copy("d")
    dq, dv = floating_effort_jacobians(prog, list(dyn.compact["tau"]), list(dyn.q), list(dyn.qd))
    out = [*dq, *dv]
    model = pin.buildModelFromUrdf(str(solo), pin.JointModelFreeFlyer())
    data = model.createData()
    rng = np.random.default_rng(12)
    nv = model.nv
    states = [pin.randomConfiguration(model, -np.ones(model.nq), np.ones(model.nq)) for _ in range(2)]
    states = [(q, rng.normal(size=nv), rng.normal(size=nv)) for q in states]
    symbols = (dyn.q, dyn.qd, dyn.qdd)
    values = {
        s: np.array([x[k][i] for x in states]) for k, syms in enumerate(symbols) for i, s in enumerate(syms)
    }
    all_got = evaluate(prog, out, values, len(states))  # (entries, states)
    for n_state, (q, v, a) in enumerate(states):
        got = all_got[:, n_state].reshape(2, nv, nv)
        expected = pin.computeRNEADerivatives(model, data, q, v, a)[:2]
        for g, e, name in zip(got, expected, ("dtau/dq", "dtau/dv"), strict=True):
            np.testing.assert_allclose(g, e, atol=1e-10 * max(1.0, np.abs(e).max()), err_msg=name)


def _rate_differences(f, v: np.ndarray) -> np.ndarray:
    """df/dv by central differences."""
    return np.array([(f(v + d) - f(v - d)) / (2 * STEP) for d in np.eye(len(v)) * STEP]).T


def _expected(robot, model, q, v, a) -> dict:
    """Per derivative function: its arguments, then its matrices by finite differences (and M^-1)."""
    tau = symdyn.rnea(robot, q, v, a)
    return {
        "inverse_dynamics_derivatives": (
            (q, v, a),
            _tangent_differences(lambda x: symdyn.rnea(robot, x, v, a), model, q),
            _rate_differences(lambda x: symdyn.rnea(robot, q, x, a), v),
        ),
        "forward_dynamics_derivatives": (
            (q, v, tau),
            _tangent_differences(lambda x: forward_dynamics(robot, x, v, tau), model, q),
            _rate_differences(lambda x: forward_dynamics(robot, q, x, tau), v),
            np.linalg.inv(mass_matrix(robot, q)),
        ),
    }


def test_generated_derivatives_equal_finite_differences(tmp_path):
    robot = symdyn.load_robot(ARM)
    name = robot.name
    files = render(robot, targets=("c", "python"), functions=["derivatives"])
    lib, numpy_module = load_c_and_numpy(files, tmp_path, name)
    ptr = ctypes.POINTER(ctypes.c_double)
    nv = robot.nv
    model = _flyer_model(robot.n)

    def c_call(fname, args, outputs):
        out = [np.full(nv * nv, np.nan) for _ in range(outputs)]
        fn = getattr(lib, f"{name}_{fname}")
        fn.argtypes = [ptr] * (len(args) + 1 + outputs)
        fn(
            *(np.ascontiguousarray(x).ctypes.data_as(ptr) for x in args),
            None,
            *(o.ctypes.data_as(ptr) for o in out),
        )
        return out

    def numpy_call(fname, args, outputs):
        return getattr(numpy_module, fname)(*args)

    rng = np.random.default_rng(5)
    for _ in range(2):
        q, v, a = _state(robot, rng)
        expected = _expected(robot, model, q, v, a)
        for target, call in (("C", c_call), ("NumPy", numpy_call)):
            for fname, (args, *matrices) in expected.items():
                got = call(fname, args, len(matrices))
                for k, (g, e) in enumerate(zip(got, matrices, strict=True)):
                    scale = max(1.0, np.abs(e).max())
                    np.testing.assert_allclose(
                        np.asarray(g).reshape(nv, nv), e, atol=1e-7 * scale, err_msg=f"{target} {fname} {k}"
                    )
