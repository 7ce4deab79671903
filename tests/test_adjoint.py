"""symdyn.symbolic.adjoint: the adjoint program w^T dy/dx of a straight-line program, evaluated
numerically, against central differences of the program (a hand-written one with every form
the partial derivatives know, and one they leave to SymPy), and against the derivative
functions symdyn derives by forward propagation (Roger's arm: the rows of d tau / d q, d qdd /
d tau = M^-1, ... for unit weights, read from the committed generated/ NumPy module)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import sympy as sp
from robots import example

from symdyn.codegen import context
from symdyn.codegen.python.printer import NumpyPrinter
from symdyn.generated_modules import load_module
from symdyn.symbolic.adjoint import adjoint_program, partial

ROOT = Path(__file__).resolve().parents[1]
a, b, c = sp.symbols("a b c")
t1, t2, t3 = sp.symbols("t1 t2 t3")


def _run(temporaries, outputs, values: dict) -> np.ndarray:
    """The program's outputs at `values` (symbol: number, or arrays of one shape: one state a
    column), as one function of Python statements printed by SymPy."""
    printer = NumpyPrinter(module="np")  # the NumPy target's: sign and Heaviside as generated code has them
    args = list(values)
    lines = [f"def program({', '.join(printer.doprint(x) for x in args)}):"]
    lines += [f"    {printer.doprint(s)} = {printer.doprint(e)}" for s, e in temporaries]
    outs = ", ".join(printer.doprint(sp.sympify(e)) for e in outputs)
    lines.append(f"    return np.broadcast_arrays({outs}, {printer.doprint(args[0])})[:-1]")
    scope = {"np": np}
    exec("\n".join(lines), scope)
    return np.array(scope["program"](*values.values()))


def _names():
    return sp.numbered_symbols("u")


#: sums, products, numeric powers (a quotient), sin, cos, Abs, sign and Heaviside, and exp (SymPy's diff)
PROGRAM = (
    (t1, sp.sin(a) * b + c**2),
    (t2, t1 / (1 + a**2) - sp.cos(t1 * b) + sp.Abs(c) * sp.sign(b) + 3 * sp.Heaviside(a, 0)),
    (t3, t1 * t2 * sp.exp(b)),
)
OUTPUTS = (t3 - 2 * a * t2, t1 + t2 * c, sp.Integer(4))


def test_the_adjoint_of_a_program_equals_central_differences():
    rng = np.random.default_rng(41)
    x, w = rng.uniform(0.3, 1.2, 3), rng.uniform(-1.0, 1.0, 3)
    weights = sp.symbols("w0:3")
    program = adjoint_program(PROGRAM, OUTPUTS, weights, (a, b, c), _names())
    got = _run(
        program.temporaries,
        program.outputs,
        {**dict(zip((a, b, c), x, strict=True)), **dict(zip(weights, w, strict=True))},
    )
    h = 1e-6

    def loss(x):
        return w @ _run(PROGRAM, OUTPUTS, dict(zip((a, b, c), x, strict=True)))

    want = [(loss(x + h * e) - loss(x - h * e)) / (2 * h) for e in np.eye(3)]
    np.testing.assert_allclose(got, want, rtol=1e-7)
    # no weight at all leaves every cotangent 0
    assert adjoint_program(PROGRAM, OUTPUTS, (0, 0, 0), (a, b, c), _names()).outputs == (0, 0, 0)


def test_partial_derivatives_of_each_form():
    assert partial(a * b * sp.sin(a), a) == b * sp.sin(a) + a * b * sp.cos(a)
    assert partial(sp.sign(a) + sp.Heaviside(a, 0), a) == 0
    assert partial(sp.Abs(a - b), b) == -sp.sign(a - b)
    assert partial(sp.atan2(a, b), c) == 0
    assert sp.simplify(partial(sp.atan2(a, b), a) - b / (a**2 + b**2)) == 0


@pytest.fixture(scope="module")
def roger():
    """Roger's arm's context (the dynamics and their derivatives) and its committed NumPy module."""
    ctx = context(example("roger_arm"), functions=["dynamics"])
    mod = load_module(ROOT / "generated" / "roger_arm" / "roger_arm_numpy.py", "_symdyn_test_adjoint_roger")
    return ctx, mod


def test_adjoints_of_the_dynamics_are_the_rows_of_their_derivatives(roger):
    """For the unit weights e_i, the adjoint program of inverse_dynamics gives row i of
    d tau/dq, d tau/dqd and M; that of forward_dynamics row i of d qdd/dq, d qdd/dqd, M^-1, as
    the derivative functions symdyn generates by forward propagation (their own equations)."""
    ctx, mod = roger
    rng = np.random.default_rng(42)
    n = mod.NDOF
    state = dict(zip(("q", "qd", "qdd", "tau"), rng.uniform(-1.5, 1.5, (4, n)), strict=True))
    p = np.array([9.81, 0.25, 0.2, 0.25, 0.2])
    wants = {
        "inverse_dynamics": (*mod.inverse_dynamics_derivatives(state["q"], state["qd"], state["qdd"], p),),
        "forward_dynamics": mod.forward_dynamics_derivatives(state["q"], state["qd"], state["tau"], p),
    }
    wants["inverse_dynamics"] += (mod.mass_matrix(state["q"], p),)
    for name, want in wants.items():
        spec = ctx.function(name)
        weights = sp.symbols(f"w0:{n}")
        inputs = [s for inp in spec.inputs for s in inp.symbols]
        program = adjoint_program(spec.temporaries, spec.outputs, weights, inputs, _names())
        # one column per unit weight e_i: the cotangents' entries by rows, the weights' index by columns
        values = {
            s: np.full(n, v)
            for inp in spec.inputs
            for s, v in zip(inp.symbols, state.get(inp.name, p), strict=True)
        }
        got = _run(
            program.temporaries, program.outputs, {**values, **dict(zip(weights, np.eye(n), strict=True))}
        )
        for k, jacobian in enumerate(want):
            np.testing.assert_allclose(got[k * n : (k + 1) * n].T, jacobian, rtol=1e-10, atol=1e-12)
