"""The derivatives of a floating robot's dynamics (symdyn.algorithms.derivatives'
floating_effort_jacobians, the derivatives group of symdyn.codegen.derivative_functions) in the
tangent space, judged by independent routes.

dtau/dq . delta = d/de tau(q (+) e delta) at e = 0 with (+) Pinocchio's `integrate`, as
computeRNEADerivatives and computeABADerivatives define them: on Solo-12 the derivation equals
Pinocchio's computeRNEADerivatives; on the small floating arm of tests/data the generated C
(strict flags, -Werror) and NumPy functions equal central finite differences through
pinocchio.integrate of the numeric oracle's inverse and forward dynamics, and M^-1 its inverse.

linearize on the tangent space: on the arm, A and B equal the mixed central differences of the
deviation dx(t) = (difference(qr, q), v - vr) between two solutions one step apart (the generated
integrate and difference, the oracle's forward dynamics); on a small floating URDF its dqdd
blocks and M^-1 equal Pinocchio's computeABADerivatives.
"""

from __future__ import annotations

import ctypes
from pathlib import Path

import numpy as np
import pytest
from cbuild import load_c_and_numpy
from robots import floating_solo12
from test_floating_frames import small_floating

import symdyn
from symdyn.algorithms.base_parameters import evaluate
from symdyn.algorithms.derivatives import floating_effort_jacobians
from symdyn.codegen import render
from symdyn.codegen.derivative_functions import derivative_rows
from symdyn.codegen.function_rows import Inputs
from symdyn.oracle.inputs import skew
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


@pytest.fixture(scope="module")
def arm(tmp_path_factory):
    """(robot, compiled C, NumPy module) of the floating arm's derivatives and configuration
    groups, rendered and compiled once."""
    robot = symdyn.load_robot(ARM)
    files = render(robot, targets=("c", "python"), functions=["derivatives", "configuration"])
    lib, numpy_module = load_c_and_numpy(files, tmp_path_factory.mktemp("arm"), robot.name)
    return robot, lib, numpy_module


def _c_function(robot, lib, fname: str, shapes):
    """The generated C function NAME_fname as a Python callable returning its outputs (shapes)."""
    ptr = ctypes.POINTER(ctypes.c_double)
    fn = getattr(lib, f"{robot.name}_{fname}")

    def call(*args):
        out = [np.full(shape, np.nan) for shape in shapes]
        fn.argtypes = [ptr] * (len(args) + 1 + len(out))
        fn(
            *(np.ascontiguousarray(x).ctypes.data_as(ptr) for x in args),
            None,
            *(o.ctypes.data_as(ptr) for o in out),
        )
        return out

    return call


def test_generated_derivatives_equal_finite_differences(arm):
    robot, lib, numpy_module = arm
    nv = robot.nv
    model = _flyer_model(robot.n)

    def c_call(fname, args, outputs):
        return _c_function(robot, lib, fname, [(nv, nv)] * outputs)(*args)

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


EPS = H = 1e-4  # the perturbation and the time step of the mixed differences


def _linearisation_differences(robot, gen, q, v, tau) -> tuple[np.ndarray, np.ndarray]:
    """A and B by mixed central differences: d^2/(de dh) of the deviation
    (difference(qr(h), q(h)), v(h) - vr(h)) between the solution from (q, v, tau) and the one from
    (q (+) e dq, v + e dv, tau + e dtau), each advanced by one explicit Euler step of h (exact to
    first order in h, which is all the derivative at h = 0 sees)."""
    nv = robot.nv

    def step(q0, v0, t0, h):
        qdd = forward_dynamics(robot, q0, v0, t0)
        return gen.integrate(q0, v0, np.array([h])), v0 + h * qdd

    def deviation(d, e, h):
        q1, v1 = gen.integrate(q, d[:nv], np.array([e])), v + e * d[nv : 2 * nv]
        qr, vr = step(q, v, tau, h)
        qp, vp = step(q1, v1, tau + e * d[2 * nv :], h)
        return np.r_[gen.difference(qr, qp), vp - vr]

    columns = []
    for d in np.eye(3 * nv):
        mixed = deviation(d, EPS, H) - deviation(d, -EPS, H) - deviation(d, EPS, -H) + deviation(d, -EPS, -H)
        columns.append(mixed / (4 * EPS * H))
    F = np.array(columns).T
    return F[:, : 2 * nv], F[:, 2 * nv :]


def test_linearize_on_the_tangent_space_equals_finite_differences(arm):
    robot, lib, gen = arm
    nv = robot.nv
    c_linearize = _c_function(robot, lib, "linearize", [(2 * nv, 2 * nv), (2 * nv, nv)])
    rng = np.random.default_rng(8)
    for _ in range(2):
        q, v, tau = _state(robot, rng)
        A_fd, B_fd = _linearisation_differences(robot, gen, q, v, tau)
        for target, (A, B) in (("NumPy", gen.linearize(q, v, tau)), ("C", c_linearize(q, v, tau))):
            for got, want, what in ((A, A_fd, "A"), (B, B_fd, "B")):
                scale = max(1.0, np.abs(want).max())
                np.testing.assert_allclose(got, want, atol=1e-6 * scale, err_msg=f"{target} {what}")
            np.testing.assert_allclose(B[nv:], np.linalg.inv(mass_matrix(robot, q)), rtol=1e-9, atol=1e-12)


class _Walk:
    """The derivation's assignments, then a family's steps, in program order: what
    symdyn.algorithms.base_parameters.evaluate walks (its `needed`) to evaluate the rows' outputs."""

    def __init__(self, dyn, steps) -> None:
        self.assignments = [*dyn.program.assignments, *steps]

    def needed(self, outputs):
        return self.assignments


def test_linearize_equals_pinocchio_aba_derivatives(tmp_path):
    robot, model = small_floating(tmp_path)
    dyn = symdyn.derive(robot, simplify=False)
    rows = derivative_rows(dyn, Inputs.of(dyn))
    (linearize,) = (row for row in rows if row.name == "linearize")
    walk = _Walk(dyn, rows[0].steps)  # the first row carries the family's steps
    data = model.createData()
    nv = model.nv
    pin.seed(4)
    rng = np.random.default_rng(4)
    for _ in range(2):
        q = pin.randomConfiguration(model, -np.ones(model.nq), np.ones(model.nq))
        v, tau = rng.normal(size=nv), rng.normal(size=nv)
        # qdd (which linearize does not read: it takes FD(q, v, tau)) is zero for the other rows' steps
        inputs = (*dyn.q, *dyn.qd, *Inputs.of(dyn).tau.symbols, *dyn.qdd)
        values = dict(zip(inputs, np.r_[q, v, tau, np.zeros(nv)][:, None], strict=True))
        A, B = np.split(evaluate(walk, list(linearize.exprs), values, 1)[:, 0], [4 * nv * nv])
        A, B = A.reshape(2 * nv, 2 * nv), B.reshape(2 * nv, nv)
        ddq_dq, ddq_dv, Minv = (np.array(m) for m in pin.computeABADerivatives(model, data, q, v, tau))
        Minv = np.triu(Minv) + np.triu(Minv, 1).T  # Pinocchio may fill the upper triangle only
        w, nu = v[3:6], v[:3]
        ad = np.block([[skew(w), skew(nu)], [np.zeros((3, 3)), skew(w)]])
        want_A = np.block([[np.zeros((nv, nv)), np.eye(nv)], [ddq_dq, ddq_dv]])
        want_A[:6, :6] = -ad
        for got, want, what in (
            (A, want_A, "A"),
            (B, np.vstack([np.zeros((nv, nv)), Minv]), "B"),
        ):
            scale = max(1.0, np.abs(want).max())
            np.testing.assert_allclose(got, want, atol=1e-10 * scale, err_msg=what)
