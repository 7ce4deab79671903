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


def test_printed_expressions_compute_sympys_values_on_a_batch():
    printer = NumpyPrinter(NAMES)
    columns = np.array(POINTS).T
    env = {"np": np, "p_x": columns[0], "y": columns[1], "z": columns[2]}
    for e in EXPRESSIONS:
        text = printer.doprint(e)
        got = np.broadcast_to(eval(text, env), (len(POINTS),))  # our own printer's text
        want = [float(e.evalf(30, subs=dict(zip((x, y, z), point, strict=True)))) for point in POINTS]
        np.testing.assert_allclose(got, want, rtol=1e-13, atol=1e-13, err_msg=f"{e} printed as {text}")


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
    assert printer.doprint(sp.sign(y)) == "np.sign(y)"  # sign(0) = 0 as in SymPy
    assert printer.doprint(sp.Heaviside(y, 0)) == "np.heaviside(y, 0.0)"  # 0 at 0
    assert printer.doprint(sp.Heaviside(-y, 0)) == "np.heaviside(-y, 0.0)"


def test_parameter_names_that_clash_in_python(tmp_path):
    clashing = ["np", "p", "q", "qd", "tau", "x1", "NDOF", "p_np", "p_p", "p_x1_", "DTYPE"]
    robot = robot_with_parameters(clashing + ["m", "izz"])
    ctx = symdyn.codegen.context(robot)
    names = local_names(ctx)
    chosen = [names[s] for s in ctx.dynamics.params]
    assert len(set(chosen)) == len(chosen)
    generated = re.compile(r"(x|q|qd|qdd|tau)[0-9]+\Z")
    for s, name in names.items():
        assert name.isidentifier() and not keyword.iskeyword(name) and not generated.match(name), name
        assert name not in {"np", "q", "qd", "qdd", "tau", "p", "_vector", "_params", "_assemble", "_lead"}
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
