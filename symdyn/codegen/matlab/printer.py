"""SymPy expression -> MATLAB/Octave expression text (the MATLAB backend's printer).

A scalar MATLAB expression is written as C's with the same precedences (+ -, * /, unary
minus binding more loosely than ^), so the printer is the C printer's tree
(symdyn.codegen.c.printer: powers up to MAX_UNROLLED_POWER as products, numbers as
literals that round-trip a double) with MATLAB's calls: abs instead of fabs, sign(x) (0 at
0, as SymPy's), Heaviside(x, 0) as double(x > 0) (Heaviside(-x, 0) as double(x < 0)), and any
other power as x^y. Only double precision exists here.
"""

from __future__ import annotations

import sympy as sp

from ...errors import SymdynError
from ...symbolic.simplify import MAX_UNROLLED_POWER
from ..c.printer import ATOM, UNARY, CPrinter
from ..printing import step_comparison

__all__ = ["MatlabPrinter", "MATLAB_CALLS"]

#: SymPy functions of one argument and their MATLAB names.
MATLAB_CALLS = {sp.sin: "sin", sp.cos: "cos", sp.tan: "tan", sp.Abs: "abs", sp.sign: "sign"}


class MatlabPrinter(CPrinter):
    """SymPy expression -> MATLAB text; `names` maps every symbol to its MATLAB name."""

    def __init__(self, names: dict[sp.Symbol, str]):
        super().__init__(names, "double")

    def _call(self, e: sp.Expr) -> tuple[str, int]:
        if isinstance(e, sp.Heaviside):
            x, op = step_comparison(e)
            return f"double({self._print(x)[0]} {op} 0)", ATOM
        if isinstance(e, sp.atan2):  # the logarithm of a floating base's rotation (lie_group)
            y, x = (self._print(a)[0] for a in e.args)
            return f"atan2({y}, {x})", ATOM
        call = MATLAB_CALLS.get(type(e))
        if call is None:
            raise SymdynError(f"cannot print '{type(e).__name__}' as MATLAB: {e}")
        if not e.free_symbols and call != "sign":
            return self._number(e)
        return f"{call}({self._print(e.args[0])[0]})", ATOM

    def _pow(self, e: sp.Pow) -> tuple[str, int]:
        exp = e.exp
        small = exp.is_Integer and -MAX_UNROLLED_POWER <= exp <= MAX_UNROLLED_POWER and exp != 0
        if not e.free_symbols or small or exp in (sp.Rational(1, 2), sp.Rational(-1, 2)):
            return super()._pow(e)
        return (
            f"{self._wrap(e.base, ATOM)}^{self._wrap(exp, ATOM)}",
            UNARY,
        )  # binds tighter than *, looser than an atom
