"""SymPy expression -> NumPy text, and the Python names of the NumPy backend.

`NumpyPrinter` is SymPy's NumPyPrinter with `np.` functions, small integer
powers as products (as the operation counts assume), floats and rationals in
full precision (repr), sign as np.sign and Heaviside(x, 0) as
np.heaviside(x, 0.0) (0 at 0). `local_names` gives every free
parameter a Python name that shadows nothing the generated module defines.
The statements around the expressions are spelled in templates/python/module.py.j2.
"""

from __future__ import annotations

import keyword
import re

import sympy as sp
from sympy.printing.numpy import NumPyPrinter
from sympy.printing.precedence import PRECEDENCE

from ...symbolic.simplify import MAX_UNROLLED_POWER
from ..render import RenderContext

__all__ = ["NumpyPrinter", "local_names", "dtype"]

#: Names the generated function bodies use besides their locals.
_RESERVED = frozenset(
    {"np", "q", "qd", "qdd", "tau", "p", "NDOF", "NQ", "NV", "NPARAM", "PARAM_NAMES"}
    | {"_vector", "_params", "_assemble", "_lead"}
)
_GENERATED_NAME = re.compile(r"(x|q|qd|qdd|tau)[0-9]+\Z")


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

    def _print_Heaviside(self, expr) -> str:
        assert expr.args[1:] == (sp.S.Zero,), expr
        return f"np.heaviside({self._print(expr.args[0])}, 0.0)"

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


def local_names(ctx: RenderContext) -> dict[sp.Symbol, str]:
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


def dtype(precision: str) -> str:
    """The NumPy dtype of every input and output for --precision double or float."""
    return "float32" if precision == "float" else "float64"
