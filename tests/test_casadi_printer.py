"""The CasADi printer (symdyn.codegen.casadi.printer): printed text evaluated against SymPy.

Every printed expression is evaluated twice, with casadi on plain floats and as
an SX graph turned into a casadi.Function, and compared with SymPy's 30-digit
value. Exact text is asserted only where it is the contract: inputs as vector
elements (q[0], p[1]), unrolled small powers, math.pi recorded for the import.
"""

from __future__ import annotations

import math

import casadi as ca
import numpy as np
import pytest
import sympy as sp
from test_c_printer import EXPRESSIONS, POINTS, awkward_doubles

from symdyn.codegen.casadi import CasadiPrinter
from symdyn.errors import SymdynError
from symdyn.symbolic.simplify import MAX_UNROLLED_POWER

x, y, z = sp.symbols("x y z")
NAMES = {x: "q[0]", y: "p[1]", z: "x3"}  # an input element, a parameter element, a temporary

MORE = [
    sp.exp(x) - sp.log(z * z),
    sp.atan2(y, x) + sp.asin(x / 3) + sp.acos(-x / 4) + sp.atan(z),
    sp.sinh(y) * sp.cosh(z) - sp.tanh(x),
    sp.sin(x + sp.pi / 3),
]


def _env(point) -> dict:
    a, b, c = point
    return {"ca": ca, "math": math, "q": [a], "p": [0.0, b], "x3": c}


def test_printed_expressions_compute_sympys_values():
    printer = CasadiPrinter(NAMES)
    exprs = EXPRESSIONS + MORE
    texts = [printer.doprint(e) for e in exprs]
    q, p, x3 = ca.SX.sym("q", 1), ca.SX.sym("p", 2), ca.SX.sym("x3")
    symbolic = {"ca": ca, "math": math, "q": q, "p": p, "x3": x3}
    graph = ca.Function("f", [q, p, x3], [ca.vertcat(*[eval(t, symbolic) for t in texts])])  # our own text
    for point in POINTS:
        subs = dict(zip((x, y, z), point, strict=True))
        on_floats = [float(eval(t, _env(point))) for t in texts]
        on_graph = np.asarray(graph([point[0]], [0.0, point[1]], point[2]).full()).ravel()
        for e, text, a, b in zip(exprs, texts, on_floats, on_graph, strict=True):
            want = float(e.evalf(30, subs=subs))
            assert a == pytest.approx(want, rel=1e-13, abs=1e-13), f"{e} printed as {text}"
            assert b == pytest.approx(want, rel=1e-13, abs=1e-13), f"{e} printed as {text} (SX)"


def test_inputs_are_vector_elements_and_small_powers_products():
    printer = CasadiPrinter(NAMES)
    for k in range(2, MAX_UNROLLED_POWER + 1):
        assert printer.doprint(x**k) == "*".join(["q[0]"] * k)
        assert printer.doprint(x**-k) == "1/(" + "*".join(["q[0]"] * k) + ")"
    assert printer.doprint(x ** (MAX_UNROLLED_POWER + 1)) == f"q[0]**{MAX_UNROLLED_POWER + 1}"
    assert printer.doprint(sp.sign(y)) == "ca.sign(p[1])"
    assert printer.doprint(sp.Heaviside(y, 0)) == "(p[1] > 0)"  # 0 at 0, as casadi 0/1
    assert printer.doprint(-3 * sp.Heaviside(-y, 0)) == "-3*(p[1] < 0)"


def test_literals_round_trip_a_double():
    printer = CasadiPrinter(NAMES)
    values = awkward_doubles()
    for v in values:
        assert float(printer.doprint(sp.Float(v))) == v
    assert float(printer.doprint(sp.Rational(2, 7))) == 2 / 7


def test_math_constants_are_recorded():
    printer = CasadiPrinter(NAMES)
    printer.doprint(x + 2)
    assert not printer.uses_math
    assert "math.pi" in printer.doprint(sp.pi * x)
    assert printer.uses_math


def test_what_cannot_be_printed_is_a_clear_error():
    printer = CasadiPrinter(NAMES)
    with pytest.raises(SymdynError, match="unexpected symbol 'w'"):
        printer.doprint(sp.Symbol("w") + x)
    with pytest.raises(SymdynError, match="cannot print"):
        printer.doprint(sp.gamma(x))
    for constant in (sp.oo, sp.nan, sp.zoo):
        with pytest.raises(SymdynError, match="casadi target: cannot print"):
            printer.doprint(constant * x + 1)
