"""SymPy expression -> Python text over casadi SX values (the CasADi backend's printer and names).

A small tree printer: sin/cos/tan/sqrt/sign/Abs map to casadi (ca.sin, ...,
`CASADI_FUNCTIONS`), Heaviside(x, 0) becomes the comparison (x > 0) (Heaviside(-x, 0):
(x < 0)), integer powers up to simplify.MAX_UNROLLED_POWER become
multiplications (as the operation counts assume), rationals and floats become
float literals with full precision (repr), pi becomes math.pi. Inputs print as
indexed vector elements (q[0], p[2]): a parameter's name never becomes a Python
name, so no generated module can shadow one. The statements around the
expressions are spelled in templates/casadi/module.py.j2.
"""

from __future__ import annotations

import sympy as sp

from ...errors import SymdynError
from ...symbolic.simplify import MAX_UNROLLED_POWER
from ..printing import TreePrinter, step_comparison

__all__ = ["CasadiPrinter", "CASADI_FUNCTIONS", "input_names"]

# Precedences of printed Python expressions (higher binds tighter).
_ATOM = 100
_POW = 60
_MUL = 50
_NEG = 45  # unary minus: safe as an Add term, parenthesised as a factor or operand
_ADD = 40

#: SymPy functions and the casadi functions (module alias ca) they print as.
CASADI_FUNCTIONS = {
    sp.sin: "ca.sin",
    sp.cos: "ca.cos",
    sp.tan: "ca.tan",
    sp.asin: "ca.asin",
    sp.acos: "ca.acos",
    sp.atan: "ca.atan",
    sp.atan2: "ca.atan2",
    sp.sinh: "ca.sinh",
    sp.cosh: "ca.cosh",
    sp.tanh: "ca.tanh",
    sp.exp: "ca.exp",
    sp.log: "ca.log",
    sp.sign: "ca.sign",
    sp.Abs: "ca.fabs",
}


class CasadiPrinter(TreePrinter):
    """Print SymPy expressions as Python over casadi SX values.

    `names` maps every symbol that may appear (input elements, temporaries) to
    its Python spelling; any other symbol is an internal error. `uses_math`
    records whether a `math.` constant was printed.
    """

    def __init__(self, names: dict[sp.Symbol, str]) -> None:
        self.names = names
        self.uses_math = False

    # -- helpers -----------------------------------------------------------
    @staticmethod
    def _float(value) -> str:
        return repr(float(value))

    def _number(self, e: sp.Number) -> tuple[str, int]:
        if e.is_Integer:
            text = str(int(e))
        elif e.is_Rational or e.is_Float:
            text = self._float(e)
        else:
            raise SymdynError(f"casadi target: cannot print the number {e}")
        if text in ("inf", "-inf", "nan"):
            raise SymdynError(f"casadi target: non-finite number {e} in an expression")
        return text, (_NEG if text.startswith("-") else _ATOM)

    def _product(self, factors, coeff=None) -> tuple[str, int]:
        """The product of `factors` (after a numeric coefficient, if any), as one Python term."""
        printed = [] if coeff is None else [self._number(coeff)]
        printed += [self._print(f) for f in factors]
        if len(printed) == 1:
            return printed[0]
        return "*".join(t if p >= _MUL else f"({t})" for t, p in printed), _MUL

    def _power(self, base, k: int) -> tuple[str, int]:
        """base**k for a positive integer k (unrolled when small)."""
        if k == 1:
            return self._print(base)
        b = self._wrap(base, _POW + 1)
        if k <= MAX_UNROLLED_POWER:
            return "*".join([b] * k), _MUL
        return f"{b}**{k}", _POW

    # -- the nodes ---------------------------------------------------------
    def _symbol(self, e: sp.Symbol) -> tuple[str, int]:
        try:
            return self.names[e], _ATOM
        except KeyError:
            raise SymdynError(f"casadi target: unexpected symbol '{e}' in generated code") from None

    def _constant(self, e: sp.Expr) -> tuple[str, int]:
        if e is sp.pi:
            self.uses_math = True
            return "math.pi", _ATOM
        if e is sp.E:
            self.uses_math = True
            return "math.e", _ATOM
        if e.is_Number:
            return self._number(e)
        raise SymdynError(f"casadi target: cannot print {type(e).__name__} ({e})")

    def _call(self, e: sp.Expr) -> tuple[str, int]:
        if isinstance(e, sp.Heaviside):  # a 0/1 casadi expression, 0 at 0
            x, op = step_comparison(e)
            return f"({self._print(x)[0]} {op} 0)", _ATOM
        if e.is_Function and e.func in CASADI_FUNCTIONS:
            args = ", ".join(self._print(a)[0] for a in e.args)
            return f"{CASADI_FUNCTIONS[e.func]}({args})", _ATOM
        raise SymdynError(f"casadi target: cannot print {type(e).__name__} ({e})")

    def _add(self, e: sp.Add) -> tuple[str, int]:
        out = []
        for k, term in enumerate(e.args):
            negative = term.as_coeff_Mul()[0].is_negative
            if k == 0:
                out.append(self._wrap(term, _ADD) if not negative else self._print(term)[0])
            elif negative:
                out.append(" - " + self._wrap(-term, _ADD + 1))
            else:
                out.append(" + " + self._wrap(term, _ADD))
        return "".join(out), _ADD

    def _mul(self, e: sp.Mul) -> tuple[str, int]:
        coeff, factors = e.as_coeff_mul()
        if coeff.is_negative:
            text, prec = self._mul_positive(-coeff, factors)
            return "-" + (text if prec >= _MUL else f"({text})"), _NEG
        return self._mul_positive(coeff, factors)

    def _mul_positive(self, coeff: sp.Number, factors) -> tuple[str, int]:
        num, den = [], []
        for f in factors:
            if f.is_Pow and f.exp.is_Number and f.exp.is_negative:
                den.append(f.base if f.exp == -1 else sp.Pow(f.base, -f.exp, evaluate=False))
            else:
                num.append(f)
        if num or coeff != 1:
            numerator, prec = self._product(num, None if coeff == 1 else coeff)
        else:
            numerator, prec = "1", _ATOM
        if not den:
            return numerator, prec
        if prec < _MUL:
            numerator = f"({numerator})"
        text, prec = self._product(den)
        denominator = text if prec > _MUL else f"({text})"
        return f"{numerator}/{denominator}", _MUL

    def _pow(self, e: sp.Pow) -> tuple[str, int]:
        base, exp = e.base, e.exp
        if exp == sp.S.Half:
            return f"ca.sqrt({self._print(base)[0]})", _ATOM
        if exp == -sp.S.Half:
            return f"1/ca.sqrt({self._print(base)[0]})", _MUL
        if exp.is_Integer and exp > 0:
            return self._power(base, int(exp))
        if exp.is_Integer and exp < 0:
            text, prec = self._power(base, int(-exp))
            return f"1/{text if prec > _MUL else f'({text})'}", _MUL
        b = self._wrap(base, _POW + 1)
        x = self._wrap(exp, _POW + 1)
        return f"{b}**{x}", _POW


def input_names(inputs) -> dict[sp.Symbol, str]:
    """Every input symbol as an element of its argument vector: q2 -> q[1], the k-th parameter p[k]."""
    return {s: f"{inp.name}[{i}]" for inp in inputs for i, s in enumerate(inp.symbols)}
