"""The C printer (symdyn.codegen.c.printer) judged by a C compiler.

Printed expressions are compiled into a small C function with the strict flags
(-Werror) and evaluated through ctypes against SymPy's own 30-digit value. In
float precision the source must also compile under -Wdouble-promotion and
-Wfloat-conversion, so no double literal or double function can hide in it.
Literals are read back by the compiler and compared bit for bit. Exact text is
asserted only where the text is the contract (docs/generated-code.md): the
unrolled powers the operation counts assume, 1.0/x, the sign idiom, sinf.
"""

from __future__ import annotations

import ctypes
import math

import numpy as np
import pytest
import sympy as sp
from cbuild import compile_shared

from symdyn.codegen.c import CPrinter
from symdyn.errors import SymdynError
from symdyn.symbolic.simplify import MAX_UNROLLED_POWER

x, y, z = sp.symbols("x y z")
NAMES = {x: "x", y: "y", z: "z"}
FLOAT_ONLY = ("-Wdouble-promotion", "-Wfloat-conversion")
CTYPE = {"double": ctypes.c_double, "float": ctypes.c_float}
DTYPE = {"double": np.float64, "float": np.float32}

EXPRESSIONS = [
    x**2,
    x**3 * y,
    x**MAX_UNROLLED_POWER,
    x ** (MAX_UNROLLED_POWER + 1),
    x**-1,
    y / x**2,
    x**-3 * z,
    x ** (-MAX_UNROLLED_POWER - 1),
    (x + y) ** 2,
    -x * (y + z),
    x - y,
    3 - x - (x + y) ** 2,
    sp.sqrt(x),
    1 / sp.sqrt(x + z * z),
    x ** sp.Rational(3, 2),
    x ** sp.Float(2.5),
    sp.Rational(1, 3) * y,
    sp.Rational(-5, 7) * x * y,
    -sp.Rational(1, 2) * x / (x + y) ** 2,
    2 * x,
    sp.pi * x,
    sp.pi**2 + y,
    sp.E * z,
    sp.sqrt(2) * x,
    sp.Float("0.1") * x + sp.Float("1e-30") * y,
    sp.sign(y - z),
    sp.sign(x) * y,
    sp.Abs(y) + sp.Abs(x - z),
    sp.sin(x + y) - sp.cos(x) * sp.tan(z),
    x / (y * z**2 * (x + y)),
    -(x + y) / (z * (x - y)),
    (x - y) ** 3 * (y + z) ** -2,
]
POINTS = [(0.7, -1.3, 2.9), (1.9, 0.4, -0.6), (1.1, 2.5, 0.3)]


def _library(body: list[str], precision: str, tmp_path, name: str) -> ctypes.CDLL:
    """Compile `body` (C statements) as `void evaluate(const real v[], real out[])`."""
    real = precision
    source = [
        "#include <math.h>",
        f"void evaluate(const {real} v[], {real} out[]);",
        f"void evaluate(const {real} v[], {real} out[])",
        "{",
        *(f"    const {real} {NAMES[s]} = v[{k}];" for k, s in enumerate((x, y, z))),
        *(f"    (void){NAMES[s]};" for s in (x, y, z)),
        *(f"    {line}" for line in body),
        "}",
    ]
    path = tmp_path / f"{name}_{precision}.c"
    path.write_text("\n".join(source) + "\n")
    extra = FLOAT_ONLY if precision == "float" else ()
    lib = ctypes.CDLL(str(compile_shared([path], tmp_path / f"lib{name}_{precision}.so", extra=extra)))
    pointer = ctypes.POINTER(CTYPE[precision])
    lib.evaluate.argtypes = [pointer, pointer]
    lib.evaluate.restype = None
    return lib


def _evaluate(lib: ctypes.CDLL, values, count: int, precision: str) -> np.ndarray:
    pointer = ctypes.POINTER(CTYPE[precision])
    v = np.ascontiguousarray(values, dtype=DTYPE[precision])
    out = np.full(count, np.nan, dtype=DTYPE[precision])
    lib.evaluate(v.ctypes.data_as(pointer), out.ctypes.data_as(pointer))
    return out.astype(float)


@pytest.mark.parametrize("precision", ["double", "float"])
def test_printed_expressions_compute_sympys_values(precision, tmp_path):
    printer = CPrinter(NAMES, precision)
    texts = [printer.doprint(e) for e in EXPRESSIONS]
    lib = _library([f"out[{k}] = {t};" for k, t in enumerate(texts)], precision, tmp_path, "exprs")
    rtol = 1e-13 if precision == "double" else 2e-6
    for point in POINTS:
        point = [float(DTYPE[precision](v)) for v in point]  # the inputs the C function really sees
        got = _evaluate(lib, point, len(EXPRESSIONS), precision)
        subs = dict(zip((x, y, z), point, strict=True))
        for e, text, value in zip(EXPRESSIONS, texts, got, strict=True):
            want = float(e.evalf(30, subs=subs))
            assert abs(value - want) <= rtol * max(1.0, abs(want)), (
                f"{e} printed as {text}: {value} != {want}"
            )


def test_small_integer_powers_are_unrolled():
    printer = CPrinter(NAMES)
    for k in range(2, MAX_UNROLLED_POWER + 1):
        assert printer.doprint(x**k) == "*".join(["x"] * k)
        assert printer.doprint(x**-k) == "1.0/(" + "*".join(["x"] * k) + ")"
        assert printer.doprint((x + y) ** k) == "*".join(["(x + y)"] * k)
    assert printer.doprint(x ** (MAX_UNROLLED_POWER + 1)) == f"pow(x, {MAX_UNROLLED_POWER + 1}.0)"


def test_reciprocals_are_divisions():
    double, single = CPrinter(NAMES, "double"), CPrinter(NAMES, "float")
    assert double.doprint(1 / x) == "1.0/x"
    assert single.doprint(1 / x) == "1.0f/x"
    assert double.doprint(y / x**2) == "y/(x*x)"
    assert double.doprint(1 / sp.sqrt(x)) == "1.0/sqrt(x)"
    assert single.doprint(1 / sp.sqrt(x)) == "1.0f/sqrtf(x)"


@pytest.mark.parametrize("precision", ["double", "float"])
def test_sign_idiom(precision, tmp_path):
    """sign(x) is ((real)((x > 0) - (x < 0))): no branch, no libm, and sign(0) = 0 as in SymPy."""
    printer = CPrinter(NAMES, precision)
    assert printer.doprint(sp.sign(x)) == f"(({precision})((x > 0) - (x < 0)))"
    text = printer.doprint(sp.sign(x - y))
    lib = _library([f"out[0] = {text};"], precision, tmp_path, "sign")
    for a, b in ((-2.0, 0.5), (0.0, 0.0), (3.0, -1.0), (1e-30, 0.0), (0.0, 1e-30)):
        (got,) = _evaluate(lib, [a, b, 0.0], 1, precision)
        assert got == float(sp.sign(sp.Float(a) - sp.Float(b))), (a, b)


def awkward_doubles() -> np.ndarray:
    """Awkward doubles: short and long decimals, extremes, subnormals, and random ones."""
    rng = np.random.default_rng(2024)
    random = rng.uniform(1.0, 2.0, 200) * np.exp2(rng.integers(-1020, 1020, 200).astype(float))
    special = [0.0, 1.0, 0.1, 1 / 3, 2 / 3, 1e22, 1e23, 2.0**53 + 2, 123456789.0, 5e-324]
    special += [2.2250738585072014e-308, 1.7976931348623157e308, math.pi, math.e, 9.999999999999999e-5]
    return np.concatenate([special, random])


def _read_back(literals: list[str], precision: str, tmp_path) -> np.ndarray:
    """The values the compiler makes of `literals`, in an array of the precision's type."""
    table = f"static const {precision} table[] = {{{', '.join(literals)}}};"
    copy = f"for (k = 0; k < {len(literals)}u; ++k) out[k] = table[k];"
    lib = _library([table, "unsigned k;", copy], precision, tmp_path, "literals")
    return _evaluate(lib, [0.0, 0.0, 0.0], len(literals), precision)


def test_literals_round_trip_a_double(tmp_path):
    printer = CPrinter(NAMES)
    values = awkward_doubles()
    literals = [printer.literal(v) for v in values]
    for v, text in zip(values, literals, strict=True):
        assert float(text) == v and any(c in text for c in ".eE"), text  # a floating literal
    np.testing.assert_array_equal(_read_back(literals, "double", tmp_path), values)  # every bit
    assert printer.doprint(sp.Rational(1, 3)) == repr(1 / 3)
    assert printer.doprint(-sp.Float(0.1) * x) == "-0.1*x"


def test_float_literals_carry_the_suffix(tmp_path):
    printer = CPrinter(NAMES, "float")
    rng = np.random.default_rng(7)
    scaled = rng.uniform(1, 2, 50) * np.exp2(rng.integers(-120, 120, 50))
    values = np.concatenate([[0.0, 0.1, 1 / 3, 1.0, 3.4e38], scaled])
    literals = [printer.literal(v) for v in values]
    assert all(text.endswith("f") and float(text[:-1]) == v for v, text in zip(values, literals, strict=True))
    got = _read_back(literals, "float", tmp_path)
    # the compiler rounds the decimal to a nearest float: within half a float spacing of the value
    assert np.all(np.abs(got - values) <= 0.5 * np.spacing(np.abs(values.astype(np.float32))) * (1 + 1e-6))


def test_float_precision_calls_float_functions():
    printer = CPrinter(NAMES, "float")
    text = printer.doprint(sp.sin(x) + sp.cos(y) * sp.tan(z) + sp.Abs(x) + sp.sqrt(y) + x ** sp.Float(2.5))
    for name in ("sinf(x)", "cosf(y)", "tanf(z)", "fabsf(x)", "sqrtf(y)", "powf(x, 2.5f)"):
        assert name in text, text
    assert printer.doprint(sp.Rational(1, 2) * x) == "0.5f*x"


def test_what_cannot_be_printed_is_a_clear_error():
    printer = CPrinter(NAMES)
    for constant in (sp.oo, -sp.oo, sp.nan, sp.zoo):
        with pytest.raises(SymdynError, match="cannot print"):
            printer.doprint(constant * x + 1)
    with pytest.raises(SymdynError, match="cannot print 'exp' as C"):
        printer.doprint(sp.exp(x))
    with pytest.raises(AssertionError, match="neither an input nor a temporary"):
        printer.doprint(sp.Symbol("w"))


@pytest.mark.parametrize("precision", ["double", "float"])
def test_heaviside_is_a_comparison(precision, tmp_path):
    """Heaviside(x, 0) (direction-dependent Coulomb friction) is ((real)(x > 0)) and Heaviside(-x, 0)
    is ((real)(x < 0)): no branch, 0 at 0."""
    printer = CPrinter(NAMES, precision)
    assert printer.doprint(sp.Heaviside(x, 0)) == f"(({precision})(x > 0))"
    assert printer.doprint(sp.Heaviside(-x, 0)) == f"(({precision})(x < 0))"
    plus, minus = printer.doprint(sp.Heaviside(x - y, 0)), printer.doprint(sp.Heaviside(y - x, 0))
    lib = _library([f"out[0] = {plus};", f"out[1] = {minus};"], precision, tmp_path, "heaviside")
    for a, b in ((-2.0, 0.5), (0.0, 0.0), (3.0, -1.0), (1e-30, 0.0), (0.0, 1e-30)):
        assert list(_evaluate(lib, [a, b, 0.0], 2, precision)) == [float(a > b), float(a < b)], (a, b)
