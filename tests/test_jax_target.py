"""The JAX target (NAME_jax.py) against the NumPy target and the numeric oracle symdyn.rnea.

generated/ holds NAME_jax.py beside NAME_numpy.py for roger_arm, puma560, panda (with its frame
functions) and the legs of solo12 (a kinematic tree), kept up to date by tests/test_generated.py,
so no robot is derived here. At a random state every function of each JAX module must equal the
NumPy module's (itself checked against the oracle by tests/test_numpy_target.py) to 1e-12, and
the dynamics the oracle's; jax.jacrev of the JAX inverse dynamics (its adjoint program) and
jax.jacfwd of the forward dynamics must equal the generated derivative functions, jax.jacrev in
p central differences;
jit and vmap (the f_batch twins) and jax.lax.scan (a simulation) give the NumPy module's
values; a float32 module is checked with a float32 tolerance, and a double one refuses to
import without JAX's x64 mode.
"""

from __future__ import annotations

import dataclasses
import functools
import importlib
import inspect
import warnings
from pathlib import Path

import numpy as np
import pytest
import sympy as sp
from robots import example

from symdyn import load_robot
from symdyn.algorithms.closed_loops import analyse
from symdyn.cli import main
from symdyn.codegen import context, render
from symdyn.codegen.jax import stages as jax_stages
from symdyn.codegen.jax import target as jax_target
from symdyn.codegen.python.printer import NumpyPrinter
from symdyn.errors import SymdynWarning
from symdyn.generated_modules import load_module
from symdyn.oracle import closed_loops as oc
from symdyn.regenerate import example_robot

jax = pytest.importorskip("jax")
jnp = pytest.importorskip("jax.numpy")

rn = importlib.import_module("symdyn.rnea")  # the module (symdyn.rnea is also the function)
ROOT = Path(__file__).resolve().parents[1]
GENERATED = ROOT / "generated"
ROBOTS = ("roger_arm", "puma560", "panda", "solo12")
#: sizes of the inputs that are not one value per joint (the tip wrench of tip_wrench_torque)
SIZES = {"F": 6}


@pytest.fixture(scope="module", autouse=True)
def x64():
    """The generated double modules need JAX's 64-bit mode (restored afterwards)."""
    before = jax.config.jax_enable_x64
    jax.config.update("jax_enable_x64", True)
    yield
    jax.config.update("jax_enable_x64", before)


@pytest.fixture(scope="module")
def modules(x64):
    """robot -> (its JAX module, its NumPy module, its Robot), from generated/."""
    with warnings.catch_warnings():
        return _modules()


def _modules():
    out = {}
    warnings.simplefilter("ignore", SymdynWarning)  # the published data of puma560.yaml
    for name in ROBOTS:
        jax_mod = load_module(GENERATED / name / f"{name}_jax.py", f"_symdyn_test_{name}_jax")
        numpy_mod = load_module(GENERATED / name / f"{name}_numpy.py", f"_symdyn_test_{name}_numpy")
        out[name] = (jax_mod, numpy_mod, example_robot(ROOT, name))
    return out


def _functions(mod) -> list[str]:
    """The module's one-state functions (not their f_batch twins)."""
    return [
        n
        for n, f in vars(mod).items()
        if inspect.isfunction(f)
        and f.__module__ == mod.__name__
        and not n.startswith("_")
        and not n.endswith("_batch")
    ]


def _inputs(mod, name: str, rng, batch=()) -> list[np.ndarray]:
    names = [a for a in inspect.signature(getattr(mod, name)).parameters if a != "p"]
    return [rng.uniform(-2.0, 2.0, (*batch, SIZES.get(a, mod.NDOF))) for a in names]


def _params(mod, rng, batch=()):
    return rng.uniform(0.5, 2.0, (*batch, mod.NPARAM)) if mod.NPARAM else None


def _tuple(x):
    return x if isinstance(x, tuple) else (x,)


def _close(actual, expected, rtol=1e-12):
    """Relative agreement, measured against the size of the expected array."""
    actual, expected = np.asarray(actual), np.asarray(expected)
    assert actual.shape == expected.shape
    scale = max(1.0, float(np.max(np.abs(expected), initial=0.0)))
    np.testing.assert_allclose(actual, expected, rtol=rtol, atol=rtol * scale)


@pytest.mark.parametrize("robot", ROBOTS)
def test_every_function_matches_numpy_and_the_oracle(robot, modules):
    jax_mod, numpy_mod, model = modules[robot]
    assert (jax_mod.NDOF, jax_mod.NPARAM, jax_mod.PARAM_NAMES) == (
        numpy_mod.NDOF,
        numpy_mod.NPARAM,
        numpy_mod.PARAM_NAMES,
    )
    names = _functions(jax_mod)
    assert names == _functions(numpy_mod)
    assert all(callable(getattr(jax_mod, f"{n}_batch")) for n in names)
    rng = np.random.default_rng(len(robot))
    p = _params(jax_mod, rng)
    for name in names:
        args = _inputs(jax_mod, name, rng)
        got, want = _tuple(getattr(jax_mod, name)(*args, p)), _tuple(getattr(numpy_mod, name)(*args, p))
        assert len(got) == len(want), name
        for g, w in zip(got, want, strict=True):
            assert isinstance(g, jax.Array) and g.dtype == jnp.float64, name
            _close(g, w)
    q, qd, qdd = rng.uniform(-2.0, 2.0, (3, model.n))
    params = dict(zip(jax_mod.PARAM_NAMES, p, strict=True)) if p is not None else None
    tau = rn.rnea(model, q, qd, qdd, params)
    _close(jax_mod.inverse_dynamics(q, qd, qdd, p), tau, rtol=1e-9)
    _close(jax_mod.mass_matrix(q, p), rn.mass_matrix(model, q, params), rtol=1e-9)
    _close(jax_mod.coriolis(q, qd, p), rn.bias_torque(model, q, qd, params), rtol=1e-9)
    _close(jax_mod.gravity(q, p), rn.gravity_torque(model, q, params), rtol=1e-9)
    _close(jax_mod.forward_dynamics(q, qd, tau, p), qdd, rtol=1e-9)


def test_jacobians_equal_the_generated_derivatives(modules):
    """jax.jit of jax.jacrev (the adjoint program) and of jax.jacfwd (forward mode of the body)
    through the JAX inverse dynamics and of jax.jacfwd through the forward dynamics (forward mode
    of its body) = the derivative functions symdyn derived symbolically (and M^-1 =
    d qdd / d tau), for Roger's arm."""
    jax_mod, _, _ = modules["roger_arm"]
    rng = np.random.default_rng(3)
    q, qd, qdd, tau = rng.uniform(-2.0, 2.0, (4, jax_mod.NDOF))
    p = _params(jax_mod, rng)
    want_dq, want_dqd = jax_mod.inverse_dynamics_derivatives(q, qd, qdd, p)
    for jacobian in (jax.jacrev, jax.jacfwd):
        dq, dqd = jax.jit(jacobian(jax_mod.inverse_dynamics, argnums=(0, 1)))(q, qd, qdd, p)
        _close(dq, want_dq, rtol=1e-10)
        _close(dqd, want_dqd, rtol=1e-10)
    dq, dqd, dtau = jax.jit(jax.jacfwd(jax_mod.forward_dynamics, argnums=(0, 1, 2)))(q, qd, tau, p)
    want_dq, want_dqd, minv = jax_mod.forward_dynamics_derivatives(q, qd, tau, p)
    _close(dq, want_dq, rtol=1e-10)
    _close(dqd, want_dqd, rtol=1e-10)
    _close(dtau, minv, rtol=1e-10)


def _every_mode(f, plain, args, batch=None, hessian=True):
    """[(got, want)]: jax.jvp, jax.jacfwd, jax.jacrev, a Hessian-vector product (jax.jvp of
    jax.grad of a weighted sum of the output: jax.hessian's forward-over-reverse, one direction),
    jax.hessian itself if `hessian`, and given the states `batch` (of the first argument) both
    Jacobians vmapped over them, a jax.lax.scan of jax.jvp over them and jax.grad through that
    scan, all under one jax.jit, of f (a ruled function) and of plain (its body: XLA's autodiff,
    forward mode for both Jacobians), as pairs of arrays; the last len(args) pairs are jax.jacrev
    of f by each argument."""
    every = tuple(range(len(args)))
    tangents = tuple(np.cos(np.arange(np.size(a)) + k) for k, a in enumerate(args))
    weights = np.linspace(-1.0, 2.0, len(plain(*args)))
    rest = (None,) * (len(args) - 1)

    def modes(g, jacobians):
        def along(x):
            return jax.jvp(lambda x: g(x, *args[1:]), (x,), (tangents[0],))[1]

        def scanned(states):
            return jax.lax.scan(lambda c, x: (c + jnp.sum(g(x, *args[1:]) ** 2), along(x)), 0.0, states)

        def weighted(*a):
            return jnp.sum(g(*a) * weights)

        out = [jax.jvp(g, args, tangents)[1], jax.jvp(jax.grad(weighted, argnums=every), args, tangents)[1]]
        out += [jax.hessian(weighted, argnums=every)(*args)] if hessian else []
        if batch is not None:
            out += [scanned(batch)[1], jax.grad(lambda states: scanned(states)[0])(batch)]
            out += [jax.vmap(jacobian(g), in_axes=(0, *rest))(batch, *args[1:]) for jacobian in jacobians]
        return out + [jacobian(g, argnums=every)(*args) for jacobian in jacobians]

    # both Jacobians against forward mode of the body (XLA merges its two copies)
    got, want = jax.jit(
        lambda: [modes(f, (jax.jacfwd, jax.jacrev)), modes(plain, (jax.jacfwd, jax.jacfwd))]
    )()
    return list(zip(jax.tree.leaves(got), jax.tree.leaves(want), strict=True))


def test_every_mode_of_the_ruled_functions_equals_autodiff(modules):
    """Forward and reverse mode, second order, vmap and lax.scan of the inverse dynamics (a
    linear primitive: forward mode of the body, transposed by the adjoint program) and of the
    forward dynamics (the same, transposed through the inverse dynamics' adjoint program by the
    identity of IDENTITIES) by every argument, p included, equal XLA's autodiff of
    the bodies as written (_NAME_plain), for Roger's arm (a fixed base, 5 free parameters)."""
    jax_mod, _, _ = modules["roger_arm"]
    rng = np.random.default_rng(41)
    args = tuple(rng.uniform(-2.0, 2.0, (3, jax_mod.NDOF))) + (_params(jax_mod, rng),)
    batch = rng.uniform(-2.0, 2.0, (3, jax_mod.NDOF))
    for name in ("inverse_dynamics", "forward_dynamics"):
        f, plain = getattr(jax_mod, name), getattr(jax_mod, f"_{name}_plain")
        # the forward dynamics' rule under vmap and lax.scan: test_adjoints_equal_autodiff_and_differences,
        # test_grad_through_a_lax_scan_equals_differences
        for got, want in _every_mode(f, plain, args, batch if name == "inverse_dynamics" else None):
            _close(got, want, rtol=1e-10)


def test_adjoints_equal_autodiff_and_differences(modules):
    """The forward dynamics' reverse mode (the inverse dynamics' adjoint program at weight
    M^-1 w): jacrev vmapped over states equals the generated derivatives state by state; grad of
    a vmapped loss equals central differences of the NumPy module's loss (Roger's arm: 5 free
    parameters); every mode of both dynamics against XLA's autodiff:
    test_every_mode_of_the_ruled_functions_equals_autodiff. All in one jit: one compilation
    costs less than running the transformations op by op."""
    jax_mod, numpy_mod, _ = modules["roger_arm"]
    fd = jax_mod.forward_dynamics
    rng = np.random.default_rng(31)
    rng.uniform(-2.0, 2.0, (3, jax_mod.NDOF))  # the state the Jacobians took before (same draws after)
    p = _params(jax_mod, rng)
    Q, QD, TAU = rng.uniform(-2.0, 2.0, (3, 4, jax_mod.NDOF))
    vmapped = jax.vmap(fd, in_axes=(0, 0, 0, None))

    @jax.jit
    def transformed(Q):
        return (
            jax.vmap(jax.jacrev(fd, argnums=(0, 1, 2)), in_axes=(0, 0, 0, None))(Q, QD, TAU, p),
            jax.grad(lambda q, p: jnp.sum(vmapped(q, QD, TAU, p) ** 2), argnums=(0, 1))(Q, p),
        )

    per_state, (got_q, got_p) = transformed(Q)
    for k in range(len(Q)):
        derivatives = jax_mod.forward_dynamics_derivatives(Q[k], QD[k], TAU[k], p)
        for g, w in zip(per_state, derivatives, strict=True):
            _close(g[k], w, rtol=1e-10)

    def loss(q, p):
        return float(np.sum(numpy_mod.forward_dynamics(q, QD, TAU, p) ** 2))

    h = 1e-6
    want_q = np.zeros_like(Q)
    for index in np.ndindex(Q.shape):
        e = np.zeros_like(Q)
        e[index] = h
        want_q[index] = (loss(Q + e, p) - loss(Q - e, p)) / (2 * h)
    want_p = np.array([(loss(Q, p + h * e) - loss(Q, p - h * e)) / (2 * h) for e in np.eye(len(p))])
    _close(got_q, want_q, rtol=1e-7)
    _close(got_p, want_p, rtol=1e-7)


def test_grad_through_a_lax_scan_equals_differences(modules):
    """jit(grad) of the end of a jax.lax.scan simulation (reverse mode through the scan and the
    forward dynamics' rule) by the initial rates = central differences of the same loop
    written with the NumPy module."""
    jax_mod, numpy_mod, _ = modules["roger_arm"]
    p = np.array([9.81, 1.0, 1.2, 0.8, 0.7])
    dt, steps, q0, tau = 1e-2, 20, np.array([0.4, -0.3]), np.array([0.3, -0.1])

    def end(qd0, forward, scan):
        def step(state, _):
            q, qd = state
            qd = qd + dt * forward(q, qd, tau, p)
            return (q + dt * qd, qd), None

        if scan:
            return jax.lax.scan(step, (q0, qd0), None, length=steps)[0]
        state = (q0, qd0)
        for _ in range(steps):
            state = step(state, None)[0]
        return state

    got = jax.jit(jax.grad(lambda v: jnp.sum(end(v, jax_mod.forward_dynamics, True)[0] ** 2)))(
        np.array([0.0, 0.5])
    )
    h = 1e-6

    def loss(v):
        return float(np.sum(end(v, numpy_mod.forward_dynamics, False)[0] ** 2))

    want = np.array(
        [
            (loss(np.array([0.0, 0.5]) + h * e) - loss(np.array([0.0, 0.5]) - h * e)) / (2 * h)
            for e in np.eye(2)
        ]
    )
    _close(got, want, rtol=1e-7)


#: A floating base with one revolute joint: the smallest robot whose rule maps a quaternion
FLYER = """
name: flyer
base: {floating: true, mass: 2, com: [0.05, -0.02, 0.1], inertia: {ixx: 0.1, iyy: 0.12, izz: 0.2, ixy: 0.01}}
links:
  - {joint: revolute, a: 0.5, alpha: 1.5707963267948966, d: 0.1, theta: 0, mass: 1, com: [-0.25, 0, 0.02],
     inertia: {ixx: 0.01, iyy: 0.02, izz: 0.02, ixz: 0.002}, friction: {viscous: 0.3}}
"""


def test_forward_dynamics_rule_by_the_quaternion_entries(x64, tmp_path):
    """On a floating base the rule maps q's NQ entries (a quaternion of any norm) to the tangent
    space of the generated Jacobians: jax.jacrev of the
    forward dynamics by q equals central differences of the numeric oracle in q's entries (the
    base position's columns 0, a change along the quaternion none), and so does jax.jacrev of the
    forward dynamics through the inverse dynamics' adjoint (a module with the inverse dynamics too,
    without its derivative function). Only these functions are rendered (the groups' other
    functions dropped before printing)."""
    (tmp_path / "flyer.yaml").write_text(FLYER)
    robot = load_robot(tmp_path / "flyer.yaml")
    full = context(robot, functions=["dynamics", "derivatives"])
    # the forward dynamics with its derivative function: the rule (RULES); with the inverse
    # dynamics: the identity (IDENTITIES, taken over the rule when a module holds all three)
    kinds = {
        "rule": ("forward_dynamics", "forward_dynamics_derivatives"),
        "identity": ("inverse_dynamics", "forward_dynamics"),
    }
    modules = {}
    for kind, kept in kinds.items():
        ctx = dataclasses.replace(full, functions=tuple(f for f in full.functions if f.name in kept))
        (text,) = jax_target.render(ctx).values()
        assert ("_forward_dynamics_jvp" in text) == (kind == "rule"), kind
        (tmp_path / f"flyer_{kind}_jax.py").write_text(text)
        modules[kind] = load_module(tmp_path / f"flyer_{kind}_jax.py", f"_symdyn_test_flyer_{kind}_jax")
    identity = modules["identity"]
    rng = np.random.default_rng(37)
    q = np.concatenate([rng.normal(size=3), 1.7 * rng.normal(size=4), rng.uniform(-1, 1, robot.n)])
    qd, tau = rng.normal(size=(2, robot.nv))
    qdd = rng.normal(size=robot.nv)
    pairs = {}
    for name, args in (("inverse_dynamics", (q, qd, qdd)), ("forward_dynamics", (q, qd, tau))):
        mod = modules["identity" if name == "inverse_dynamics" else "rule"]
        f, plain = getattr(mod, name), getattr(mod, f"_{name}_plain")
        # vmap and lax.scan of both: test_every_mode_of_the_ruled_functions_equals_autodiff; the
        # forward dynamics' hessian took 30 s to compile here: its Hessian-vector product
        pairs[name] = _every_mode(
            f, lambda *a, plain=plain: plain(*a, jnp.zeros(0)), args, None, name == "inverse_dynamics"
        )
        for got, want in pairs[name]:
            _close(got, want, rtol=1e-9)
    got = pairs["forward_dynamics"][-3][0]  # jax.jacrev of the rule by q, compiled with the modes
    h = 1e-6
    want = np.array(
        [
            (rn.forward_dynamics(robot, q + h * e, qd, tau) - rn.forward_dynamics(robot, q - h * e, qd, tau))
            / (2 * h)
            for e in np.eye(robot.nq)
        ]
    ).T
    _close(got, want, rtol=1e-7)
    np.testing.assert_allclose(np.asarray(got)[:, :3], 0.0, atol=1e-12)
    np.testing.assert_allclose(np.asarray(got)[:, 3:7] @ q[3:7], 0.0, atol=1e-9)
    # the identity's reverse mode in q's entries, jitted (1.5 CPU s; op by op 2.9 s)
    _close(jax.jit(jax.jacrev(identity.forward_dynamics))(q, qd, tau), want, rtol=1e-7)


def test_jacrev_of_inverse_dynamics_on_a_tree(modules):
    """jax.jacrev (op by op: compiling would cost more) of the inverse dynamics of the Solo-12
    legs, a kinematic tree of 12 joints = the generated inverse_dynamics_derivatives."""
    jax_mod, _, _ = modules["solo12"]
    rng = np.random.default_rng(4)
    q, qd, qdd = rng.uniform(-2.0, 2.0, (3, jax_mod.NDOF))
    dq, dqd = jax.jacrev(jax_mod.inverse_dynamics, argnums=(0, 1))(q, qd, qdd, None)
    want_dq, want_dqd = jax_mod.inverse_dynamics_derivatives(q, qd, qdd, None)
    _close(dq, want_dq, rtol=1e-10)
    _close(dqd, want_dqd, rtol=1e-10)


def test_gradient_in_the_parameters(modules):
    """jax.jacrev of tau in p (the adjoint program's cotangent of p) = central differences of
    the NumPy module in p."""
    jax_mod, numpy_mod, _ = modules["roger_arm"]
    rng = np.random.default_rng(5)
    q, qd, qdd = rng.uniform(-2.0, 2.0, (3, 2))
    p = _params(jax_mod, rng)
    # jitted: 0.25 CPU s, where op by op its first call took 2 s (every operation compiled alone)
    got = jax.jit(jax.jacrev(jax_mod.inverse_dynamics, argnums=3))(q, qd, qdd, p)
    h = 1e-6
    want = np.stack(
        [
            (
                numpy_mod.inverse_dynamics(q, qd, qdd, p + h * e)
                - numpy_mod.inverse_dynamics(q, qd, qdd, p - h * e)
            )
            / (2 * h)
            for e in np.eye(len(p))
        ],
        axis=-1,
    )
    _close(got, want, rtol=1e-7)


def test_jit_vmap_and_batches(modules):
    """f_batch (vmap + jit) and jax.jit(jax.vmap(f)) equal the NumPy module over a batch, with
    one parameter set for all states or one per state."""
    jax_mod, numpy_mod, _ = modules["roger_arm"]
    rng = np.random.default_rng(7)
    q, qd, qdd = rng.uniform(-2.0, 2.0, (3, 64, 2))
    p, P = _params(jax_mod, rng), _params(jax_mod, rng, (64,))
    _close(jax_mod.inverse_dynamics_batch(q, qd, qdd, p), numpy_mod.inverse_dynamics(q, qd, qdd, p))
    _close(jax_mod.inverse_dynamics_batch(q, qd, qdd, P), numpy_mod.inverse_dynamics(q, qd, qdd, P))
    _close(jax_mod.mass_matrix_batch(q, p), numpy_mod.mass_matrix(q, p))
    forward = jax.jit(jax.vmap(jax_mod.forward_dynamics, in_axes=(0, 0, 0, None)))
    tau = numpy_mod.inverse_dynamics(q, qd, qdd, p)
    _close(forward(q, qd, tau, p), qdd, rtol=1e-10)
    # one state through the batch twin is the function itself
    _close(jax_mod.gravity_batch(q[0], p), numpy_mod.gravity(q[0], p))


def test_vmapped_vectors_are_selected_not_concatenated(modules):
    """The fast path under XLA's defaults: jax.jit(jax.vmap(f)) of a vector function holds no
    concatenate (XLA's CPU fusion emitters recomputed the statements shared by the entries of
    one, once per path: the Panda's inverse dynamics ran 250 times slower than f_batch), and
    equals the NumPy module over a batch; the matrices are concatenated selected blocks
    (test_matrices_are_selected_or_concatenated_blocks)."""
    jax_mod, numpy_mod, _ = modules["panda"]
    rng = np.random.default_rng(13)
    q, qd, qdd = rng.uniform(-2.0, 2.0, (3, 32, jax_mod.NDOF))
    for name, args in (("inverse_dynamics", (q, qd, qdd)), ("forward_dynamics", (q, qd, qdd))):
        text = jax.jit(jax.vmap(getattr(jax_mod, name))).lower(*args).as_text()
        assert "concatenate" not in text, name
    vmapped = jax.jit(jax.vmap(jax_mod.inverse_dynamics))
    _close(vmapped(q, qd, qdd), numpy_mod.inverse_dynamics(q, qd, qdd))
    one = jax_mod._vector_of(1)
    assert one.shape == (1,) and one.dtype == jnp.float64 and float(one[0]) == 1.0
    np.testing.assert_array_equal(jax_mod._vector_of(2, jnp.float64(3.5), -1), [2.0, 3.5, -1.0])


def test_matrices_are_selected_or_concatenated_blocks(modules):
    """The three ways a matrix is built (symdyn.codegen.jax.target.matrix_builders), entry by entry
    in row order: _selection_of (one selection: the Panda's M, 49 entries of a short body),
    _matrix_of (one selection up to _FUSED_CONCATENATE entries, above it a concatenate of more
    than _FUSED_CONCATENATE selected blocks of at most _BLOCK entries, which XLA's CPU compiler
    computes apart: coriolis_matrix, 49 entries of 648 statements, 10 blocks of 5, and the
    regressor), _array_of (one concatenate of every entry: the derivative functions' long
    bodies); jax.jit(jax.vmap(...)) of a selected and of a blocked matrix equal the NumPy module's."""
    jax_mod, numpy_mod, _ = modules["panda"]
    ways = {
        "_array_of": ("inverse_dynamics_derivatives", "forward_dynamics_derivatives", "linearize"),
        "_selection_of": ("mass_matrix", "link7_jacobian", "mass_matrix_inverse"),
        "_matrix_of": ("coriolis_matrix", "regressor", "base_regressor"),
    }
    source = Path(jax_mod.__file__).read_text()
    for way, names in ways.items():
        for name in names:
            body = source.split(f"\ndef {name}(")[1].split("\ndef ")[0]
            assert [w for w in ways if f"{w}(" in body] == [way], name
    fused, block = jax_mod._FUSED_CONCATENATE, jax_mod._BLOCK
    for rows, cols in ((1, 1), (1, fused), (1, fused + 1), (3, 7), (7, 7), (7, 91), (3, 20 * block + 1)):
        entries = [float(k) for k in range(rows * cols)]
        entries[-1] = jnp.float64(entries[-1])  # an array among numbers
        want = np.arange(rows * cols, dtype=float).reshape(rows, cols)
        for way in ways if rows * cols <= 64 else ("_matrix_of",):  # the others: one op each
            got = getattr(jax_mod, way)((rows, cols), *entries)
            assert got.shape == (rows, cols) and got.dtype == jnp.float64
            np.testing.assert_array_equal(got, want)
    rng = np.random.default_rng(17)
    q, qd = rng.uniform(-2.0, 2.0, (2, 16, jax_mod.NDOF))
    selected = jax.jit(jax.vmap(jax_mod.mass_matrix))
    assert "stablehlo.concatenate" not in selected.lower(q).as_text()
    _close(selected(q), numpy_mod.mass_matrix(q))
    blocked = jax.jit(jax.vmap(jax_mod.coriolis_matrix))
    lines = [x for x in blocked.lower(q, qd).as_text().splitlines() if "stablehlo.concatenate" in x]
    assert len(lines) == 1 and lines[0].count("%") == 10 + 1, lines
    _close(blocked(q, qd), numpy_mod.coriolis_matrix(q, qd))


def test_jit_grad_of_a_vmapped_loss_equals_differences(modules):
    """jax.jit(jax.grad(sum of squares of jax.vmap(f)(...))) with respect to the states and to
    the shared parameters = central differences of the NumPy module's loss."""
    jax_mod, numpy_mod, _ = modules["roger_arm"]
    rng = np.random.default_rng(17)
    q, qd, qdd = rng.uniform(-2.0, 2.0, (3, 8, 2))
    p = _params(jax_mod, rng)
    vmapped = jax.vmap(jax_mod.inverse_dynamics, in_axes=(0, 0, 0, None))
    grad = jax.jit(jax.grad(lambda q, p: jnp.sum(vmapped(q, qd, qdd, p) ** 2), argnums=(0, 1)))
    got_q, got_p = grad(q, p)

    def loss(q, p):
        return float(np.sum(numpy_mod.inverse_dynamics(q, qd, qdd, p) ** 2))

    h = 1e-6
    want_q = np.zeros_like(q)
    for index in np.ndindex(q.shape):
        e = np.zeros_like(q)
        e[index] = h
        want_q[index] = (loss(q + e, p) - loss(q - e, p)) / (2 * h)
    want_p = np.array([(loss(q, p + h * e) - loss(q, p - h * e)) / (2 * h) for e in np.eye(len(p))])
    _close(got_q, want_q, rtol=1e-7)
    _close(got_p, want_p, rtol=1e-7)


def test_batches_compile_without_the_cpu_fusion_emitters(modules, monkeypatch):
    """f_batch compiles with XLA's CPU fusion emitters off under the pinned jax (the option
    exists); with an option this XLA does not know (as an older jax), f_batch compiles without
    options and still equals the NumPy module."""
    jax_mod, numpy_mod, _ = modules["roger_arm"]
    assert jax_mod._batch_options() == {"xla_cpu_use_fusion_emitters": False}
    rng = np.random.default_rng(11)
    q, qd, qdd = rng.uniform(-2.0, 2.0, (3, 16, 2))
    p = _params(jax_mod, rng)
    want = numpy_mod.inverse_dynamics(q, qd, qdd, p)
    _close(jax_mod.inverse_dynamics_batch(q, qd, qdd, p), want)
    # inside another transformation the twin jits plainly (options are for a top-level jit only):
    # traced arguments, and constant ones closed over by the outer function
    _close(jax.jit(jax_mod.inverse_dynamics_batch)(q, qd, qdd, p), want)
    _close(jax.jit(lambda: jax_mod.inverse_dynamics_batch(q, qd, qdd, p))(), want)
    scanned = jax.lax.scan(
        lambda c, _: (c, jax_mod.inverse_dynamics_batch(q, qd, qdd, p)), 0.0, None, length=2
    )
    _close(scanned[1][1], want)
    monkeypatch.setattr(jax_mod, "_BATCH_OPTIONS", {"xla_cpu_no_such_option_of_symdyn": True})
    jax_mod._batch_options.cache_clear()
    try:
        assert jax_mod._batch_options() == {}
        fresh = jax_mod._batch(jax_mod.inverse_dynamics)
        _close(fresh(q, qd, qdd, p), want)
    finally:
        jax_mod._batch_options.cache_clear()


def test_lax_scan_simulation(modules):
    """A semi-implicit Euler simulation under jax.lax.scan (jitted) follows the same loop
    written with the NumPy module."""
    jax_mod, numpy_mod, _ = modules["roger_arm"]
    p = np.array([9.81, 1.0, 1.2, 0.8, 0.7])  # g, l1, m1, l2, m2
    dt, steps = 1e-3, 300
    x0 = (np.array([0.4, -0.3]), np.array([0.0, 0.5]))
    tau = np.array([0.3, -0.1])

    def step(state, _):
        q, qd = state
        qd = qd + dt * jax_mod.forward_dynamics(q, qd, tau, p)
        return (q + dt * qd, qd), q

    (q_end, qd_end), path = jax.jit(lambda x: jax.lax.scan(step, x, None, length=steps))(x0)
    q, qd = x0
    for _ in range(steps):
        qd = qd + dt * numpy_mod.forward_dynamics(q, qd, tau, p)
        q = q + dt * qd
    assert path.shape == (steps, 2)
    _close(q_end, q, rtol=1e-10)
    _close(qd_end, qd, rtol=1e-10)


def test_a_stage_carries_only_what_it_reads_and_defines():
    """cut_into_stages: a stage's loop takes the values its statements read and returns its own
    values read later; a value read two stages on passes the stage between outside its loop."""
    a, b, t0, t1, t2 = sp.symbols("a b t0 t1 t2")
    body = [(t0, a * b), (t1, a + 1), (t2, t0 + b)]
    got = jax_stages.cut_into_stages(body, [t1, t2], {a, b}, NumpyPrinter(module="jnp"), 1)
    assert [(s["start"], s["stop"], s["inputs"], s["outputs"]) for s in got] == [
        (0, 1, ["a", "b"], ["t0"]),
        (1, 2, ["a"], ["t1"]),
        (2, 3, ["b", "t0"], ["t2"]),
    ]


def test_a_staged_body_equals_the_plain_one(modules, tmp_path, monkeypatch):
    """A long body cut into stages (symdyn.codegen.jax.stages: the true branches of jax.lax.conds
    that XLA does not fuse across, conds still under jax.vmap: their predicate is not batched;
    Roger's arm staged by 12 statements, as the Talos' functions are by 300: the inverse dynamics
    and its adjoint program, the forward dynamics differentiated through it, the mass matrix,
    which JAX differentiates through the stages) gives the committed module's values, forward
    and reverse derivatives (jacfwd through the stages, the gradient of a vmapped loss),
    under jit and vmap, and the forward dynamics' jacrev. Stages of 12 (3 for the inverse
    dynamics, 4 for its adjoint and the forward dynamics, the mass matrix's one) carry values
    between stages as stages of 4 do, and compile in two thirds of their time."""
    monkeypatch.setattr(jax_stages, "STAGE_ABOVE", 0)
    monkeypatch.setattr(jax_stages, "STAGE_SIZE", 12)
    text = render(example("roger_arm"), targets=("jax",))["roger_arm_jax.py"]
    (tmp_path / "roger_arm_jax.py").write_text(text)
    staged = load_module(tmp_path / "roger_arm_jax.py", "_symdyn_test_staged_roger_arm_jax")
    plain, _, _ = modules["roger_arm"]
    rng = np.random.default_rng(17)
    Q, QD, QDD = rng.uniform(-2.0, 2.0, (3, 5, 2))
    p = _params(plain, rng)
    for f, args in [
        (staged.inverse_dynamics, (Q[0], QD[0], QDD[0], p)),
        (staged._inverse_dynamics_adjoint, (Q[0], QD[0], QDD[0], p, QDD[1])),
        (staged.forward_dynamics, (Q[0], QD[0], QDD[0], p)),
        (staged.mass_matrix, (Q[0], p)),
    ]:
        batched = [np.stack([a, a]) for a in args]
        assert "cond[" in str(jax.make_jaxpr(jax.vmap(f))(*batched)), f.__name__

    @functools.partial(jax.jit, static_argnums=(2, 3))
    def every(states, p, f, forward):
        n = len(states)
        vmapped = jax.vmap(f, in_axes=(0,) * n + (None,))
        jacobians = jax.vmap(jax.jacfwd(f, argnums=tuple(range(n + 1))), in_axes=(0,) * n + (None,))
        return (
            vmapped(*states, p),
            jacobians(*states, p) if forward else (),
            jax.grad(lambda q, p: jnp.sum(vmapped(q, *states[1:], p) ** 2), argnums=(0, 1))(states[0], p),
        )

    for name, states, forward in [
        ("inverse_dynamics", (Q, QD, QDD), True),
        ("forward_dynamics", (Q, QD, QDD), False),
        ("mass_matrix", (Q,), True),
    ]:
        got = jax.tree.leaves(every(states, p, getattr(staged, name), forward))
        want = jax.tree.leaves(every(states, p, getattr(plain, name), forward))
        for g, w in zip(got, want, strict=True):
            _close(g, w, rtol=1e-12)
    # the staged forward dynamics' adjoint reads its value (_adjoint_ruled's valued): jax.jacrev
    # by every argument, op by op, transposes it once per output entry
    assert "valued=True" in text
    args = (Q[0], QD[0], QDD[0], p)
    got = jax.jacrev(staged.forward_dynamics, argnums=(0, 1, 2, 3))(*args)
    want = jax.jacrev(plain.forward_dynamics, argnums=(0, 1, 2, 3))(*args)
    for g, w in zip(got, want, strict=True):
        _close(g, w, rtol=1e-12)


def test_float32_module(tmp_path):
    """--precision float: float32 in and out (also with x64 on), jittable, equal to the oracle
    within float32's precision."""
    robot = example("roger_arm")
    files = render(robot, targets=("jax",), precision="float")
    assert list(files) == ["roger_arm_jax.py"]
    (tmp_path / "roger_arm_jax.py").write_text(files["roger_arm_jax.py"])
    mod = load_module(tmp_path / "roger_arm_jax.py", "_symdyn_test_roger_arm_jax32")
    assert mod.DTYPE is jnp.float32
    rng = np.random.default_rng(9)
    q, qd, qdd = rng.uniform(-2.0, 2.0, (3, 16, 2))
    p = rng.uniform(0.5, 2.0, 5)
    tau = mod.inverse_dynamics_batch(q, qd, qdd, p)
    assert tau.dtype == jnp.float32
    params = dict(zip(mod.PARAM_NAMES, p, strict=True))
    _close(tau, rn.rnea(robot, q, qd, qdd, params), rtol=2e-5)
    _close(mod.forward_dynamics_batch(q, qd, tau, p), qdd, rtol=1e-3)


def test_double_needs_x64_and_bad_input_is_a_clear_error(modules):
    jax_mod, _, _ = modules["roger_arm"]
    jax.config.update("jax_enable_x64", False)
    try:
        with pytest.raises(ImportError, match="jax_enable_x64"):
            load_module(GENERATED / "roger_arm" / "roger_arm_jax.py", "_symdyn_test_no_x64")
    finally:
        jax.config.update("jax_enable_x64", True)
    with pytest.raises(ValueError, match="p is required"):
        jax_mod.mass_matrix(np.zeros(2))
    with pytest.raises(ValueError, match=r"q must have shape \(2,\)"):
        jax_mod.mass_matrix(np.zeros((4, 2)), np.ones(5))


def test_cli_writes_the_jax_module(tmp_path):
    robot = str(ROOT / "examples" / "roger_eye.yaml")
    assert main(["generate", robot, "--target", "jax", "--out", str(tmp_path)]) == 0
    assert sorted(p.name for p in tmp_path.iterdir()) == ["roger_eye_jax.py"]
    text = (tmp_path / "roger_eye_jax.py").read_text()
    again = render(example("roger_eye"), targets=("jax",), functions=("dynamics",))
    assert text == again["roger_eye_jax.py"]  # deterministic
    assert "numpy" not in text.replace("jax.numpy", "") and " np." not in text


def test_identification_example(tmp_path):
    """examples/jax_identification: gradient descent through jax.grad recovers Roger's arm."""
    script = load_module(ROOT / "examples" / "jax_identification" / "identify.py", "_symdyn_jax_identify")
    arm = script.generated_module(tmp_path)
    found = script.identify(arm, *script.samples(200, seed=1))
    for name, value in script.TRUE.items():
        assert found[name] == pytest.approx(value, rel=1e-6), name
    np.testing.assert_allclose(
        script.base_parameters(**found), script.base_parameters(**script.TRUE), rtol=1e-6
    )


# -- closed loops: solve_loops, and a floating base


@pytest.fixture(scope="module")
def loop_modules(x64, tmp_path_factory):
    """name -> (Robot, its JAX module, its NumPy module) of examples/closed_loops/NAME.yaml, one
    render of both targets each, on first use."""
    folder, out = tmp_path_factory.mktemp("loops_jax"), {}

    def get(name: str):
        if name not in out:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                robot = load_robot(ROOT / "examples" / "closed_loops" / f"{name}.yaml")
                files = render(robot, targets=("python", "jax"))
            mods = []
            for kind in ("jax", "numpy"):
                (folder / f"{name}_{kind}.py").write_text(files[f"{name}_{kind}.py"])
                mods.append(load_module(folder / f"{name}_{kind}.py", f"_symdyn_test_{name}_{kind}_loops"))
            out[name] = (robot, *mods)
        return out[name]

    return get


@pytest.mark.parametrize("name", ["fourbar", "fivebar"])
def test_solve_loops_under_jit_and_vmap_equals_numpy_and_closes_the_oracles_loops(name, loop_modules):
    """solve_loops (a bounded lax.while_loop of Newton steps) vmapped over actuated positions and
    jitted (solve_loops_batch) takes the NumPy module's steps to
    the same q, which closes the loops by the oracle's closure (one state at a time under jit on
    the four-bar); the states where Newton fails
    (a singular K_p, a NaN guess) give -1 in their own lane without disturbing the others."""
    robot, jm, nm = loop_modules(name)
    assert (jm.NACT, jm.ACTUATED, jm.PASSIVE) == (nm.NACT, nm.ACTUATED, nm.PASSIVE)
    assert (jm.LOOP_TOL, jm.LOOP_MAX_ITERATIONS, jm.LOOP_PIVOT) == (1e-12, 50, 1e-14)
    q0 = np.array(analyse(robot.resolved()).assembled[0])
    rng = np.random.default_rng(11)
    qa = q0[nm.ACTUATED] + rng.uniform(-0.6, 0.6, (8, nm.NACT))
    guesses = np.tile(q0, (len(qa), 1))
    guesses[-1, nm.PASSIVE[0]] = np.nan  # a hopeless guess among good ones
    if name == "fourbar":  # coupler and rocker aligned: K_p singular
        qa[-2], guesses[-2] = [0.0], [0.0, 1.0, 1.0]
    want = [nm.solve_loops(a, g) for a, g in zip(qa, guesses, strict=True)]
    assert want[-1][0] == -1 and all(i > 0 for i, _ in want[:-2]) and (name != "fourbar" or want[-2][0] == -1)
    results = {"batch (jit of vmap)": jm.solve_loops_batch(qa, guesses)}
    if name == "fourbar":  # one state at a time: the while_loop without a batched predicate
        single = jax.jit(jm.solve_loops)
        results["jit"] = [single(a, g) for a, g in zip(qa, guesses, strict=True)]
    for how, got in results.items():
        its, qs = zip(*got, strict=True) if how == "jit" else got
        its, qs = np.array(its), np.array(qs)
        assert its.dtype == np.int32, how
        np.testing.assert_array_equal(its, [i for i, _ in want], err_msg=how)
        for it, q, (_, q_numpy), a in zip(its, qs, want, qa, strict=True):
            if it >= 0:
                np.testing.assert_allclose(q, q_numpy, rtol=0, atol=1e-12, err_msg=how)
                assert np.array_equal(q[nm.ACTUATED], a) and np.abs(oc.closure(robot, q)[0]).max() < 1e-12


def test_jacfwd_through_solve_loops_gives_the_loop_motion(loop_modules):
    """d q / d qa through the jitted Newton loop (jax.jacfwd) is W, the rates of every joint per
    unit rate of the crank (loop_motion of the NumPy module)."""
    _, jm, nm = loop_modules("fourbar")
    guess = np.array([0.7, -0.2, 1.6])
    it, q = nm.solve_loops([0.7], guess)
    W = jax.jit(jax.jacfwd(lambda qa: jm.solve_loops(qa, guess)[1]))(np.array([0.7]))
    np.testing.assert_allclose(np.asarray(W)[:, 0], nm.loop_motion(q, [1.0], [0.0])[0], atol=1e-8)


def test_a_floating_robot_takes_q_of_nq_and_equals_the_oracle(tmp_path):
    """The JAX module of a floating robot (Roger's arm on a free flyer): NQ = NDOF + 1, q of shape
    (NQ,) with a quaternion of any norm; its inverse dynamics, vmapped and jitted, equals the
    oracle's (the NumPy module's floating case: tests/test_floating.py)."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", SymdynWarning)
        robot = load_robot(ROOT / "examples" / "roger_arm.yaml", floating=True)
    # a massless base under a planar arm: M is singular (the base slides and turns in the plane
    # while the links stand still), so forward dynamics is left out with this warning
    with pytest.warns(SymdynWarning, match=r"M\(q\) is singular: the base's coordinate vx_b"):
        files = render(robot, targets=("jax",))
    (tmp_path / "roger_arm_jax.py").write_text(files["roger_arm_jax.py"])
    mod = load_module(tmp_path / "roger_arm_jax.py", "_symdyn_test_floating_roger_arm_jax")
    assert (mod.NQ, mod.NV, mod.NDOF) == (robot.nq, robot.nv, robot.nv) == (9, 8, 8)
    rng = np.random.default_rng(12)
    q = np.concatenate([rng.normal(size=(6, 3)), rng.normal(size=(6, 4)), rng.uniform(-1, 1, (6, 2))], axis=1)
    qd, qdd = rng.normal(size=(2, 6, robot.nv))
    p = rng.uniform(0.5, 2.0, mod.NPARAM)
    params = dict(zip(mod.PARAM_NAMES, p, strict=True))
    want = [rn.rnea(robot, *x, params) for x in zip(q, qd, qdd, strict=True)]
    _close(mod.inverse_dynamics_batch(q, qd, qdd, p), np.array(want), rtol=1e-10)
    with pytest.raises(ValueError, match=r"q must have shape \(9,\)"):
        mod.mass_matrix(q[0, 1:], p)


def _accelerator():
    """JAX's first device that is not the CPU (a GPU or TPU), else None."""
    try:
        return next((d for d in jax.devices() if d.platform != "cpu"), None)
    except RuntimeError:  # no backend but the CPU's
        return None


@pytest.mark.accelerator
@pytest.mark.skipif(_accelerator() is None, reason="no accelerator (GPU or TPU) for JAX")
def test_an_accelerator_gives_the_cpus_values(modules):
    """On a GPU or TPU: jax.jit(jax.vmap(f)), f_batch and jax.grad through the adjoint program run
    there (their outputs stay on the device) and equal the NumPy module's values and the CPU's
    gradient in float64."""
    device, cpu = _accelerator(), jax.devices("cpu")[0]
    jax_mod, numpy_mod, _ = modules["panda"]
    rng = np.random.default_rng(41)
    host = rng.uniform(-2.0, 2.0, (3, 256, jax_mod.NDOF))
    args = jax.device_put(tuple(host), device)
    want = numpy_mod.inverse_dynamics(*host)
    for got in (jax.jit(jax.vmap(jax_mod.inverse_dynamics))(*args), jax_mod.inverse_dynamics_batch(*args)):
        assert got.devices() == {device}
        _close(got, want)
    _close(jax_mod.mass_matrix_batch(args[0]), numpy_mod.mass_matrix(host[0]))

    def loss(q, qd, qdd):
        return jnp.sum(jax.vmap(jax_mod.inverse_dynamics)(q, qd, qdd) ** 2)

    grad = jax.jit(jax.grad(loss))
    there = grad(*args)
    assert there.devices() == {device}
    _close(there, grad(*jax.device_put(tuple(host), cpu)), rtol=1e-10)
