"""The NumPy target: `NAME_numpy.py`, a standalone module (imports only numpy).

It holds the seven functions of docs/generated-code.md with the C target's names and
arguments (p optional when the robot has no free parameters), plus NDOF,
NPARAM and PARAM_NAMES. Every function evaluates the eliminated form of its
FunctionSpec, one statement per temporary, elementwise: it works for one
state (vectors of shape (n,)) or a batch with leading axes ((N, n); p either
(k,) or (N, k)). The outputs are assembled by broadcasting every entry to the
common leading shape, so constant entries (0) get the batch shape too.
Inputs and outputs are float64 (DTYPE), float32 with precision "float".
forward_dynamics is the unrolled LDL^T solve of the spec, elementwise as well.
"""

from __future__ import annotations

import keyword
import re

import sympy as sp
from sympy.printing.numpy import NumPyPrinter
from sympy.printing.precedence import PRECEDENCE

from ..symbolic.simplify import MAX_UNROLLED_POWER
from .functions import FunctionSpec
from .render import RenderContext, environment, header_lines

__all__ = ["render", "NumpyPrinter", "file_name"]

#: Names the generated function bodies use besides their locals.
_RESERVED = frozenset(
    {"np", "q", "qd", "qdd", "tau", "p", "NDOF", "NPARAM", "PARAM_NAMES"}
    | {"_vector", "_params", "_assemble", "_lead"}
)
_MATRICES = ("M", "C")
_GENERATED_NAME = re.compile(r"(x|q|qd|qdd|tau)[0-9]+\Z")


def file_name(name: str) -> str:
    return f"{name}_numpy.py"


def _small_power(expr: sp.Expr) -> bool:
    """x**k with 2 <= k <= MAX_UNROLLED_POWER, printed as a product x*x*..."""
    return bool(expr.is_Pow and expr.exp.is_Integer and 2 <= expr.exp <= MAX_UNROLLED_POWER)


class NumpyPrinter(NumPyPrinter):
    """NumPy code with `np.` functions, small integer powers as products, floats in full precision.

    `names` maps symbols to the Python names they have in the generated code.
    """

    def __init__(self, names: dict[sp.Symbol, str] | None = None) -> None:
        super().__init__({"fully_qualified_modules": True, "allow_unknown_functions": False})
        self._names = names or {}

    def _module_format(self, fqn: str, register: bool = True) -> str:
        return "np." + fqn[len("numpy.") :] if fqn.startswith("numpy.") else fqn

    def _print_Symbol(self, expr: sp.Symbol) -> str:
        return self._names.get(expr, expr.name)

    def _print_Rational(self, expr: sp.Rational) -> str:
        return repr(float(expr)) if expr.q != 1 else str(expr.p)

    def _print_Half(self, expr) -> str:
        return "0.5"

    def _print_Float(self, expr: sp.Float) -> str:
        return repr(float(expr))

    def _print_sign(self, expr) -> str:
        return f"np.sign({self._print(expr.args[0])})"

    def _print_Pow(self, expr: sp.Pow, rational: bool = False) -> str:
        base, exp = expr.base, expr.exp
        if _small_power(expr):
            b = self.parenthesize(base, PRECEDENCE["Mul"], strict=False)
            return "*".join([b] * int(exp))
        if exp.is_Integer and exp < 0:
            inverse = sp.Pow(base, -exp, evaluate=False) if exp != -1 else base
            return f"1/{self.parenthesize(inverse, PRECEDENCE['Mul'], strict=False)}"
        if exp == sp.S.Half:
            return f"np.sqrt({self._print(base)})"
        return f"{self.parenthesize(base, PRECEDENCE['Pow'])}**{self.parenthesize(exp, PRECEDENCE['Pow'])}"

    def parenthesize(self, item, level, strict=False) -> str:
        # a positive float literal is an atom in Python
        if isinstance(item, (sp.Rational, sp.Float)) and item.is_positive:
            return self._print(item)
        # an unrolled power is a product: always parenthesised inside another operation (the
        # callers judge by the precedence of a Pow, and Mul uses the precedence of a negative
        # product, an Add, for its denominator)
        if isinstance(item, sp.Basic) and _small_power(item):
            return f"({self._print(item)})"
        return super().parenthesize(item, level, strict)


def _local_names(ctx: RenderContext) -> dict[sp.Symbol, str]:
    """Python names of the free parameters: their own name when that is safe, else p_<name>."""
    taken = set(_RESERVED)
    names: dict[sp.Symbol, str] = {}
    for s in ctx.dynamics.params:
        name = s.name
        if keyword.iskeyword(name) or name in taken or _GENERATED_NAME.match(name):
            name = f"p_{name}"
            while name in taken or any(name == t.name for t in ctx.dynamics.params):
                name += "_"
        taken.add(name)
        names[s] = name
    return names


def _function(spec: FunctionSpec, printer: NumpyPrinter) -> dict:
    inputs = [inp for inp in spec.inputs if inp.name != "p"]
    params = next((inp for inp in spec.inputs if inp.name == "p"), None)
    free = spec.free_symbols
    unpack = []
    for inp in spec.inputs:
        for k, s in enumerate(inp.symbols):
            if s in free:
                unpack.append(f"{printer.doprint(s)} = {inp.name}[..., {k}]")
    body = [f"{printer.doprint(s)} = {printer.doprint(e)}" for s, e in spec.temporaries]
    rows, cols = spec.shape
    # vectors are (n, 1) specs; M and C stay matrices even for one joint (1, 1)
    shape = (rows, cols) if spec.output in _MATRICES else (rows,)
    entries = [printer.doprint(e) for e in spec.outputs]
    args = [inp.name for inp in inputs] + (["p=None"] if params is not None else [])
    return {
        "name": spec.name,
        "doc": spec.doc,
        "args": ", ".join(args),
        "inputs": [inp.name for inp in inputs],
        "has_p": params is not None,
        "lead": [inp.name for inp in spec.inputs],
        "unpack": unpack,
        "body": body,
        "output": spec.output,
        "shape": repr(shape),
        "batch_shape": "(N, " + ", ".join(str(d) for d in shape) + ")",
        "entries": entries,
    }


def _tuple_literal(items: list[str]) -> str:
    quoted = [f'"{x}"' for x in items]
    return "(" + ", ".join(quoted) + ("," if len(quoted) == 1 else "") + ")"


def render(ctx: RenderContext) -> dict[str, str]:
    """{NAME_numpy.py: module text} for the robot of `ctx`."""
    printer = NumpyPrinter(_local_names(ctx))
    functions = [_function(spec, printer) for spec in ctx.functions]
    text = (
        environment()
        .get_template("python/module.py.j2")
        .render(
            header=header_lines(ctx),
            name=ctx.name,
            ndof=ctx.robot.n,
            param_names=_tuple_literal([s.name for s in ctx.dynamics.params]),
            nparam=len(ctx.dynamics.params),
            dtype="float32" if ctx.precision == "float" else "float64",
            functions=functions,
        )
    )
    return {file_name(ctx.name): text}
