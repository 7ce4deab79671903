"""The NumPy target (NAME_numpy.py) against the independent numeric oracle symdyn.rnea.

Every example robot is derived once per session (tests/robots.py), its module rendered in
memory, written to a temporary folder and imported. At 50 random states (free
parameters random and positive, in dyn.params order) all seven functions must
match the RNEA/CRBA oracle to a relative 1e-9, a batch must equal the loop over
single states, and rendering must be byte-for-byte deterministic. The module follows the
array API standard: every function gives NumPy's values on JAX arrays and on
array-api-strict's (which refuses anything outside the standard), as arrays of that library.
"""

from __future__ import annotations

import ast
import dataclasses
import importlib
import importlib.util
from functools import cache
from pathlib import Path

import numpy as np
import pytest
from robots import example, example_context, spec_arguments

from symdyn.codegen import python as numpy_backend
from symdyn.codegen import render as render_targets
from symdyn.codegen.render import RenderContext

rn = importlib.import_module("symdyn.rnea")  # the module (symdyn.rnea is also the function)
EXAMPLES = Path(__file__).resolve().parent.parent / "examples"
ROBOT_FILES = sorted(EXAMPLES.glob("*.yaml"))
N_STATES = 50
RTOL = 1e-9


def _robot(path: Path):
    return example(path.stem)


def _context(path: Path) -> RenderContext:
    """What symdyn.codegen.context builds, over the session-wide cached derivation."""
    return example_context(path.stem)


@cache
def _source(path: Path) -> tuple[str, str]:
    files = numpy_backend.render(_context(path))
    assert len(files) == 1
    ((name, text),) = files.items()
    return name, text


@pytest.fixture(scope="module")
def generated(tmp_path_factory):
    """path -> imported generated module (written once per robot)."""
    folder = tmp_path_factory.mktemp("numpy_target")
    modules = {}

    def load(path: Path):
        if path not in modules:
            name, text = _source(path)
            file = folder / name
            file.write_text(text)
            spec = importlib.util.spec_from_file_location(f"_symdyn_gen_{file.stem}", file)
            module = importlib.util.module_from_spec(spec)
            spec.loader.exec_module(module)
            modules[path] = module
        return modules[path]

    return load


def _close(actual, expected, rtol=RTOL):
    """Relative agreement, measured against the size of the expected array."""
    actual, expected = np.asarray(actual), np.asarray(expected)
    assert actual.shape == expected.shape
    scale = max(1.0, float(np.max(np.abs(expected))))
    np.testing.assert_allclose(actual, expected, rtol=rtol, atol=rtol * scale)


def _states(n: int, k: int, seed: int):
    rng = np.random.default_rng(seed)
    q = rng.uniform(-np.pi, np.pi, (N_STATES, n))
    qd = rng.normal(0.0, 1.5, (N_STATES, n))
    qdd = rng.normal(0.0, 2.0, (N_STATES, n))
    tau = rng.normal(0.0, 5.0, (N_STATES, n))
    p = rng.uniform(0.5, 2.0, k)
    return q, qd, qdd, tau, p


def _oracle(robot, params, q, qd, qdd, tau):
    return {
        "inverse_dynamics": rn.rnea(robot, q, qd, qdd, params),
        "mass_matrix": rn.mass_matrix(robot, q, params),
        "coriolis": rn.bias_torque(robot, q, qd, params),
        "gravity": rn.gravity_torque(robot, q, params),
        "friction": rn.friction_torque(robot, qd, params),
        "forward_dynamics": rn.forward_dynamics(robot, q, qd, tau, params),
    }


def _call_all(mod, q, qd, qdd, tau, p):
    return {
        "inverse_dynamics": mod.inverse_dynamics(q, qd, qdd, p),
        "mass_matrix": mod.mass_matrix(q, p),
        "coriolis_matrix": mod.coriolis_matrix(q, qd, p),
        "coriolis": mod.coriolis(q, qd, p),
        "gravity": mod.gravity(q, p),
        "friction": mod.friction(qd, p),
        "forward_dynamics": mod.forward_dynamics(q, qd, tau, p),
    }


@pytest.mark.parametrize("path", ROBOT_FILES, ids=lambda p: p.stem)
def test_matches_rnea_and_batches_equal_single_states(path, generated):
    mod = generated(path)
    robot, dyn = _robot(path), _context(path).dynamics
    n, k = robot.n, len(dyn.params)
    assert (n, k, tuple(s.name for s in dyn.params)) == (mod.NDOF, mod.NPARAM, mod.PARAM_NAMES)
    q, qd, qdd, tau, p = _states(n, k, seed=len(path.stem) * 1009 + n)
    params = {s.name: v for s, v in zip(dyn.params, p, strict=True)} if k else None
    p_arg = p if k else None

    batch = _call_all(mod, q, qd, qdd, tau, p_arg)
    for name, expected in _oracle(robot, params, q, qd, qdd, tau).items():
        _close(batch[name], expected)
    # C is the Christoffel matrix: C qd = V, and dM/dt - 2C is skew-symmetric
    C = batch["coriolis_matrix"]
    assert C.shape == (N_STATES, n, n)
    _close(np.einsum("nij,nj->ni", C, qd), batch["coriolis"])
    h = 1e-6
    dM = (mod.mass_matrix(q + h * qd, p_arg) - mod.mass_matrix(q - h * qd, p_arg)) / (2 * h)
    S = dM - 2 * C
    _close(S + np.swapaxes(S, 1, 2), np.zeros_like(S), rtol=1e-5)

    for i in range(N_STATES):
        single = _call_all(mod, q[i], qd[i], qdd[i], tau[i], p_arg)
        for name, value in single.items():
            assert value.shape == batch[name].shape[1:], name
            _close(value, batch[name][i], rtol=1e-12)


@pytest.mark.parametrize("path", [p for p in ROBOT_FILES if p.stem in ("roger_arm", "roger_eye")], ids=str)
def test_parameters_per_state(path, generated):
    """p of shape (N, k) gives one parameter set per state; (k,) is broadcast."""
    mod = generated(path)
    robot, dyn = _robot(path), _context(path).dynamics
    n, k = robot.n, len(dyn.params)
    q, qd, qdd, tau, _ = _states(n, k, seed=7)
    P = np.random.default_rng(8).uniform(0.5, 2.0, (N_STATES, k))
    tau_batch = mod.inverse_dynamics(q, qd, qdd, P)
    M_batch = mod.mass_matrix(q, P)
    F_batch = mod.friction(qd[0], P)  # one state, many parameter sets
    assert F_batch.shape == (N_STATES, n)
    for i in (0, 17, N_STATES - 1):
        params = dict(zip(mod.PARAM_NAMES, P[i], strict=True))
        _close(tau_batch[i], rn.rnea(robot, q[i], qd[i], qdd[i], params))
        _close(M_batch[i], rn.mass_matrix(robot, q[i], params))
        _close(mod.gravity(q, P[i])[i], rn.gravity_torque(robot, q[i], params))


def test_constant_entries_get_the_batch_shape(generated):
    mod = generated(EXAMPLES / "planar_3r.yaml")
    qd = np.ones((4, 3))
    assert mod.friction(qd).shape == (4, 3)
    assert mod.coriolis_matrix(np.zeros((4, 3)), qd).shape == (4, 3, 3)
    assert mod.mass_matrix(np.zeros(3)).shape == (3, 3)
    assert mod.gravity([0.1, 0.2, 0.3]).shape == (3,)
    # an array-like that is no array of the standard is read by NumPy, as np.asarray reads it
    import array

    assert type(mod.gravity(array.array("d", [0.1, 0.2, 0.3]))) is np.ndarray


def test_bad_input_is_a_clear_error(generated):
    mod = generated(EXAMPLES / "roger_arm.yaml")
    with pytest.raises(ValueError, match="p is required"):
        mod.mass_matrix(np.zeros(2))
    with pytest.raises(ValueError, match=r"q must have shape \(2,\)"):
        mod.mass_matrix(np.zeros(3), np.ones(5))
    with pytest.raises(ValueError, match="p must have shape"):
        mod.gravity(np.zeros(2), np.ones(4))


@pytest.mark.parametrize("path", ROBOT_FILES, ids=lambda p: p.stem)
def test_module_is_standalone_and_deterministic(path):
    name, text = _source(path)
    assert name == f"{_robot(path).name}_numpy.py"
    assert numpy_backend.render(_context(path)) == {name: text}
    tree = ast.parse(text)
    imports = [a.name for node in ast.walk(tree) if isinstance(node, ast.Import) for a in node.names]
    assert imports == ["numpy"]
    modules = {node.module for node in ast.walk(tree) if isinstance(node, ast.ImportFrom)}
    assert modules == {"array_api_compat"}
    assert text.startswith("# Generated by symdyn")
    functions = [node.name for node in tree.body if isinstance(node, ast.FunctionDef)]
    assert [f for f in functions if not f.startswith("_")] == [
        "inverse_dynamics",
        "mass_matrix",
        "coriolis_matrix",
        "coriolis",
        "gravity",
        "friction",
        "forward_dynamics",
        "regressor",
        "base_regressor",
    ] + (["tip_wrench_torque"] if _robot(path).convention == "poe" else []) + [
        "inverse_dynamics_derivatives",
        "forward_dynamics_derivatives",
        "mass_matrix_inverse",
        "linearize",
    ]
    assert "**" not in text  # small integer powers are products


def test_public_render_is_deterministic_across_derivations():
    robot = _robot(EXAMPLES / "roger_arm.yaml")
    first = render_targets(robot, targets=("python",))
    second = render_targets(robot, targets=("python",))
    assert first == second == dict([_source(EXAMPLES / "roger_arm.yaml")])


def test_float_precision(tmp_path):
    ctx = dataclasses.replace(_context(EXAMPLES / "roger_arm.yaml"), precision="float")
    ((name, text),) = numpy_backend.render(ctx).items()
    assert "DTYPE = np.float32" in text and "float precision" in text
    (tmp_path / name).write_text(text)
    spec = importlib.util.spec_from_file_location("_symdyn_gen_float32", tmp_path / name)
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    q, qd, qdd, tau, p = _states(2, 5, seed=3)
    tau_ = mod.inverse_dynamics(q, qd, qdd, p)
    assert tau_.dtype == np.float32
    params = dict(zip(mod.PARAM_NAMES, p, strict=True))
    _close(tau_, rn.rnea(_robot(EXAMPLES / "roger_arm.yaml"), q, qd, qdd, params), rtol=1e-4)


@pytest.mark.parametrize(
    ("library", "stem"),
    [
        ("array_api_strict", "roger_arm"),
        ("array_api_strict", "planar_prismatic_modified"),
        ("jax.numpy", "roger_arm"),
    ],
)
def test_array_api_libraries(library, stem, generated):
    """Every function of the module (friction's sign and Heaviside included) on arrays of another
    library: that library's arrays back, NumPy's values (one state and a batch of 5). JAX runs
    op by op here, so it gets the smaller robot (its sign and Heaviside: test_python_printer)."""
    if library == "jax.numpy":
        import jax

        jax.config.update("jax_enable_x64", True)  # float64, as the module asks
    xp = importlib.import_module(library)
    path = EXAMPLES / f"{stem}.yaml"
    mod = generated(path)
    rng = np.random.default_rng(11)
    p = rng.uniform(0.5, 2.0, mod.NPARAM) if mod.NPARAM else None
    for spec in _context(path).functions:
        for batch in ((), (5,)):
            args = spec_arguments(spec, rng, batch)
            expected = getattr(mod, spec.name)(*args.values(), p)
            got = getattr(mod, spec.name)(
                *(xp.asarray(a) for a in args.values()), None if p is None else xp.asarray(p)
            )
            for g, e in zip(
                got if isinstance(got, tuple) else (got,),
                expected if isinstance(expected, tuple) else (expected,),
                strict=True,
            ):
                assert type(g) is type(xp.asarray(1.0)), (spec.name, type(g))
                assert g.dtype == xp.float64, spec.name
                _close(np.asarray(g), e, rtol=1e-12)
