"""The NumPy backend's printer and names (symdyn.codegen.python.printer), judged by evaluation.

Printed expressions are evaluated with NumPy on a batch of points and compared
with SymPy's 30-digit values; literals must round-trip a double; parameters named
like Python keywords or the module's own names get other names, and the module
generated for such a robot agrees with the numeric oracle symdyn.rnea.
"""

from __future__ import annotations

import importlib
import importlib.util
import keyword
import re
from types import SimpleNamespace

import numpy as np
import pytest
import sympy as sp
from test_c_config import robot_with_parameters
from test_c_printer import EXPRESSIONS, POINTS, awkward_doubles

import symdyn.codegen
from symdyn.codegen import python as numpy_backend
from symdyn.codegen.python import NumpyPrinter, local_names
from symdyn.symbolic.simplify import MAX_UNROLLED_POWER

oracle = importlib.import_module("symdyn.rnea")
x, y, z = sp.symbols("x y z")
NAMES = {x: "p_x", y: "y", z: "z"}


#: functions and constants the generated modules may meet, with those of test_c_printer
MORE_EXPRESSIONS = [
    sp.Heaviside(y - z, 0),
    sp.Heaviside(-y, 0) * x,
    sp.sin(sp.pi / 7) * x,
    -sp.sqrt(2) * y,
    x * sp.cos(sp.pi / 5) - sp.sqrt(3),
]


@pytest.mark.parametrize("library", ["numpy", "array_api_strict", "jax.numpy"])
def test_printed_expressions_compute_sympys_values_on_a_batch(library):
    """The text evaluates to SymPy's 30-digit values with NumPy, with array-api-strict (which
    refuses anything outside the array API standard) and with jax.numpy (as `jnp`)."""
    xp = importlib.import_module(library)
    module = "jnp" if library == "jax.numpy" else "xp"
    printer = NumpyPrinter(NAMES, module=module)
    columns = np.array(POINTS).T
    env = {module: xp, **{name: xp.asarray(c) for name, c in zip(("p_x", "y", "z"), columns, strict=True)}}
    rtol = 1e-13 if np.asarray(env["y"]).dtype == np.float64 else 1e-5  # JAX without x64: float32
    for e in EXPRESSIONS + MORE_EXPRESSIONS:
        text = printer.doprint(e)
        got = np.broadcast_to(np.asarray(eval(text, env)), (len(POINTS),))  # our own printer's text
        want = [float(e.evalf(30, subs=dict(zip((x, y, z), point, strict=True)))) for point in POINTS]
        np.testing.assert_allclose(got, want, rtol=rtol, atol=rtol, err_msg=f"{e} printed as {text}")


def test_sign_and_heaviside_at_zero():
    """sign(0) = 0 as in SymPy; Heaviside(x, 0) is 0 at 0 (and 1 above, 0 below)."""
    printer = NumpyPrinter(NAMES)
    env = {"xp": np, "y": np.array([-2.0, -0.0, 0.0, 3.0])}
    assert list(eval(printer.doprint(sp.sign(y)), env)) == [-1, 0, 0, 1]
    assert list(eval(printer.doprint(sp.Heaviside(y, 0)), env)) == [0, 0, 0, 1]
    assert list(eval(printer.doprint(sp.Heaviside(-y, 0)), env)) == [1, 0, 0, 0]


def test_small_integer_powers_are_products():
    printer = NumpyPrinter(NAMES)
    for k in range(2, MAX_UNROLLED_POWER + 1):
        for e in (x**k, x**k * y, (x + y) ** k, x**-k):
            text = printer.doprint(e)
            assert "**" not in text and text.count("*") >= k - 1, text
    assert "**" in printer.doprint(x ** (MAX_UNROLLED_POWER + 1))


def test_literals_round_trip_a_double():
    printer = NumpyPrinter(NAMES)
    values = awkward_doubles()
    for v in values:
        assert float(printer.doprint(sp.Float(v))) == v
    assert float(printer.doprint(sp.Rational(2, 7))) == 2 / 7
    for constant in (sp.pi, sp.sqrt(2), sp.E, sp.sin(sp.pi / 7)):  # printed as the nearest double
        assert float(printer.doprint(constant)) == float(constant.evalf(30))


def test_parameter_names_that_clash_in_python(tmp_path):
    clashing = ["np", "p", "q", "qd", "tau", "x1", "NDOF", "p_np", "p_p", "p_x1_", "DTYPE", "xp", "jnp"]
    clashing += ["device", "jax"]
    robot = robot_with_parameters(clashing + ["m", "izz"])
    ctx = symdyn.codegen.context(robot)
    names = local_names(ctx)
    chosen = [names[s] for s in ctx.dynamics.params]
    assert len(set(chosen)) == len(chosen)
    generated = re.compile(r"(x|q|qd|qdd|tau)[0-9]+\Z")
    for s, name in names.items():
        assert name.isidentifier() and not keyword.iskeyword(name) and not generated.match(name), name
        assert name not in {"np", "xp", "jnp", "jax", "device", "q", "qd", "qdd", "tau", "p", "_vector"}
        assert name not in {"_params", "_assemble", "_lead", "_namespace", "_batch"}
        assert name == s.name or s.name in clashing
    ((fname, text),) = numpy_backend.render(ctx).items()
    (tmp_path / fname).write_text(text)
    spec = importlib.util.spec_from_file_location("_symdyn_clash_numpy", tmp_path / fname)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    rng = np.random.default_rng(9)
    p = rng.uniform(0.5, 1.5, len(ctx.dynamics.params))
    values = dict(zip(module.PARAM_NAMES, p, strict=True))
    q, qd = rng.uniform(-2, 2, (2, 4, 1))
    np.testing.assert_allclose(module.gravity(q, p), oracle.gravity_torque(robot, q, values), rtol=1e-12)
    np.testing.assert_allclose(module.friction(qd, p), oracle.friction_torque(robot, qd, values), rtol=1e-12)
    np.testing.assert_allclose(module.mass_matrix(q, p), oracle.mass_matrix(robot, q, values), rtol=1e-12)


def test_python_keywords_are_renamed():
    """Robot files cannot spell a keyword (expressions are Python syntax), but a Robot built in
    code can hold any SymPy symbol."""
    params = [sp.Symbol("lambda"), sp.Symbol("p_lambda"), sp.Symbol("def"), sp.Symbol("p_def")]
    ctx = SimpleNamespace(dynamics=SimpleNamespace(params=params))
    names = local_names(ctx)
    assert len(set(names.values())) == len(params)
    for name in names.values():
        assert name.isidentifier() and not keyword.iskeyword(name)
        # our own text, evaluated: the name can be assigned to and read back
        scope: dict = {}
        exec(f"{name} = 1.5", scope)
        assert scope[name] == 1.5


@pytest.mark.parametrize("precision", ["double", "float"])
def test_dtype_per_precision(precision):
    from symdyn.codegen.python.printer import dtype

    assert np.dtype(dtype(precision)) == (np.float64 if precision == "double" else np.float32)
