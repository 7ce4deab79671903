"""SymPy expression -> array-API text, and the Python names of the NumPy and JAX backends.

`NumpyPrinter` is SymPy's NumPyPrinter (terms in the expression's own order, as the C target
prints them) with the functions of the Python array API standard
taken from a namespace variable (`xp.sin`: the NumPy module's namespace, picked from its
inputs by array-api-compat; `jnp.sin` in the JAX module), small integer powers as products
(as the operation counts assume), floats and rationals in full precision (repr), every
constant number (pi, sqrt(2), sin(pi/7)) as its double literal, sign as xp.sign and
Heaviside(x, 0) as (xp.sign(x) + abs(xp.sign(x)))*0.5 (0 at 0; the standard has no
heaviside). `local_names` gives every free parameter a Python name that shadows nothing the
generated module defines. The statements around the expressions are spelled in
templates/python/module.py.j2 and templates/jax/module.py.j2.
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
    {"np", "xp", "jnp", "jax", "torch"}
    | {"q", "qd", "qdd", "tau", "p", "NDOF", "NQ", "NV", "NPARAM", "PARAM_NAMES"}
    | {"DTYPE"}
    | {"array_namespace", "is_array_api_obj", "device", "_array_device", "_NUMPY", "_NUMPY_INPUTS"}
    | {"_namespace", "_batch", "functools"}
    | {"_vector", "_params", "_assemble", "_lead", "_check_x64", "_device", "_leading"}
)
_GENERATED_NAME = re.compile(r"(x|q|qd|qdd|tau)[0-9]+\Z")


def _small_power(expr: sp.Expr) -> bool:
    """x**k with 2 <= k <= MAX_UNROLLED_POWER, printed as a product x*x*..."""
    return bool(expr.is_Pow and expr.exp.is_Integer and 2 <= expr.exp <= MAX_UNROLLED_POWER)


class NumpyPrinter(NumPyPrinter):
    """Array-API code with `xp.` functions (`module`), small integer powers as products, numbers
    in full precision.

    `names` maps symbols to the Python names they have in the generated code; `module` is the
    name of the array namespace there ("xp" in the NumPy module, "jnp" in the JAX module).
    """

    def __init__(self, names: dict[sp.Symbol, str] | None = None, module: str = "xp") -> None:
        # order "none": terms and factors in the expression's own (canonical, deterministic)
        # order, as the C printer writes them; SymPy's default sorts every Add and Mul again by
        # sort_key, which was half of the time of printing a module
        super().__init__({"fully_qualified_modules": True, "allow_unknown_functions": False, "order": "none"})
        self._names = names or {}
        self._xp = module

    def _module_format(self, fqn: str, register: bool = True) -> str:
        return f"{self._xp}." + fqn[len("numpy.") :] if fqn.startswith("numpy.") else fqn

    def _print(self, expr, **kwargs) -> str:
        # a constant that is not a literal (pi, sqrt(2), sin(pi/7)) is its double: an array
        # function of a Python number is outside the standard, and a literal keeps its dtype weak
        if isinstance(expr, sp.Expr) and expr.is_number and not expr.is_Rational and not expr.is_Float:
            value = float(expr)
            return repr(value) if value >= 0 else f"({value!r})"
        return super()._print(expr, **kwargs)

    def _print_Symbol(self, expr: sp.Symbol) -> str:
        return self._names.get(expr, expr.name)

    def _print_Rational(self, expr: sp.Rational) -> str:
        return repr(float(expr)) if expr.q != 1 else str(expr.p)

    def _print_Half(self, expr) -> str:
        return "0.5"

    def _print_Float(self, expr: sp.Float) -> str:
        return repr(float(expr))

    def _print_sign(self, expr) -> str:
        return f"{self._xp}.sign({self._print(expr.args[0])})"

    def _print_Heaviside(self, expr) -> str:
        assert expr.args[1:] == (sp.S.Zero,), expr
        sign = f"{self._xp}.sign({self._print(expr.args[0])})"
        return f"(({sign} + abs({sign}))*0.5)"

    def _print_Pow(self, expr: sp.Pow, rational: bool = False) -> str:
        base, exp = expr.base, expr.exp
        if _small_power(expr):
            b = self.parenthesize(base, PRECEDENCE["Mul"], strict=False)
            return "*".join([b] * int(exp))
        if exp.is_Integer and exp < 0:
            inverse = sp.Pow(base, -exp, evaluate=False) if exp != -1 else base
            return f"1/{self.parenthesize(inverse, PRECEDENCE['Mul'], strict=False)}"
        if exp == sp.S.Half:
            return f"{self._xp}.sqrt({self._print(base)})"
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
