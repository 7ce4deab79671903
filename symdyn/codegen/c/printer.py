"""SymPy expression -> C99 expression text (the C backend's printer).

A small tree printer rather than SymPy's C99CodePrinter, whose output differs in
every case the contract fixes (it prints pow(x, 2), 0.10000000000000001, (1.0/3.0),
M_PI and an F suffix). The rules, docs/generated-code.md:
* integer powers up to simplify.MAX_UNROLLED_POWER as repeated multiplication
  (x*x*x), negative ones as a division (1.0/(x*x)), the operation counts assume so;
* 1/x as a division, x**(1/2) as sqrt(x), any other power as pow(x, y);
* sign(x) as ((double)((x > 0) - (x < 0))), so sign(0) = 0 as in SymPy;
* Heaviside(x, 0) (direction-dependent Coulomb friction) as ((double)(x > 0)), and
  Heaviside(-x, 0) as ((double)(x < 0)): 0 at 0, branch-free;
* every number as a floating literal that round-trips a double (repr, up to 17
  digits); pi and other constants by their value;
* under --precision float the literal suffix f and the float functions sinf, cosf, ...

Each node prints as its text and its precedence (ADD < MUL < UNARY < ATOM), and an
operand is parenthesised only when it binds less tightly than its context needs
(symdyn.codegen.printing).
"""

from __future__ import annotations

import math

import sympy as sp

from ...errors import SymdynError
from ...symbolic.simplify import MAX_UNROLLED_POWER
from ..printing import TreePrinter, step_comparison
from .config import MATH_CALLS, CConfig

__all__ = ["CPrinter", "ADD", "MUL", "UNARY", "ATOM"]

ADD, MUL, UNARY, ATOM = 1, 3, 4, 5


class CPrinter(TreePrinter):
    """SymPy expression -> C99 expression text for one floating type ("double" or "float").

    `names` maps every symbol that may appear (input locals, temporaries) to its C name;
    `calls` maps calls computed beforehand (sin(a), cos(a): symdyn.codegen.c.sincos) to the C
    text that reads their value.
    """

    def __init__(
        self,
        names: dict[sp.Symbol, str],
        precision: str = "double",
        calls: dict[sp.Expr, str] | None = None,
        freestanding: bool = False,
    ):
        self.names = names
        self.config = CConfig(precision, freestanding)
        self.calls = calls or {}

    # numbers
    def literal(self, value: float) -> str:
        """A floating literal that round-trips the double `value` (repr: up to 17 digits)."""
        if not math.isfinite(value):
            raise SymdynError(f"cannot print the non-finite constant {value} as C")
        text = repr(float(value))
        if not any(c in text for c in ".eE"):
            text += ".0"
        return text + self.config.literal_suffix

    def _number(self, e: sp.Expr) -> tuple[str, int]:
        if e.is_Rational:
            value = float(int(e.p)) if e.q == 1 else int(e.p) / int(e.q)
        else:
            try:
                value = float(e.evalf(30))
            except (TypeError, ValueError) as exc:
                raise SymdynError(f"cannot print the constant {e} as C") from exc
        if value < 0:
            return "-" + self.literal(-value), UNARY
        return self.literal(value), ATOM

    # the nodes
    def _symbol(self, e: sp.Symbol) -> tuple[str, int]:
        assert e in self.names, f"symbol '{e}' is neither an input nor a temporary"
        return self.names[e], ATOM

    def _constant(self, e: sp.Expr) -> tuple[str, int]:
        return self._number(e)

    def _call(self, e: sp.Expr) -> tuple[str, int]:
        if e in self.calls:
            return self.calls[e], ATOM
        if isinstance(e, sp.sign):
            x = self._print(e.args[0])[0]
            return f"(({self.config.real})(({x} > 0) - ({x} < 0)))", ATOM
        if isinstance(e, sp.Heaviside):
            x, op = step_comparison(e)
            return f"(({self.config.real})({self._print(x)[0]} {op} 0))", ATOM
        if isinstance(e, sp.atan2):  # the logarithm of a floating base's rotation (lie_group)
            y, x = (self._print(a)[0] for a in e.args)
            return f"{self.config.math('atan2')}({y}, {x})", ATOM
        call = MATH_CALLS.get(type(e))
        if call is not None:
            if not e.free_symbols:
                return self._number(e)
            return f"{self.config.math(call)}({self._print(e.args[0])[0]})", ATOM
        raise SymdynError(f"cannot print '{type(e).__name__}' as C: {e}")

    def _add(self, e: sp.Add) -> tuple[str, int]:
        parts: list[str] = []
        for term in e.args:
            coeff, _ = term.as_coeff_Mul()
            negative = coeff.is_Number and coeff < 0
            positive = -term if negative else term
            text = self._wrap(positive, MUL)
            if not parts:
                parts.append(f"-{text}" if negative else text)
            else:
                parts.append(f" - {text}" if negative else f" + {text}")
        return "".join(parts), ADD

    def _mul(self, e: sp.Mul) -> tuple[str, int]:
        coeff, rest = e.as_coeff_Mul()
        if coeff.is_Number and coeff < 0:
            text, prec = self._print_product(-coeff, rest)
            return f"-{text}", (UNARY if prec == ATOM else MUL)
        return self._print_product(coeff, rest)

    def _print_product(self, coeff: sp.Expr, rest: sp.Expr) -> tuple[str, int]:
        num: list[tuple[str, int]] = []
        den: list[sp.Expr] = []
        if coeff != 1:
            num.append(self._print(coeff))
        for f in sp.Mul.make_args(rest):
            if f == 1:
                continue
            if f.is_Pow and f.exp.is_Rational and f.exp < 0 and f.free_symbols:
                den.append(f.base if f.exp == -1 else sp.Pow(f.base, -f.exp, evaluate=False))
            else:
                text, prec = self._print(f)
                num.append((f"({text})" if prec < MUL else text, max(prec, MUL)))
        if not den:
            if not num:
                return self.literal(1.0), ATOM
            if len(num) == 1:
                return num[0]
            return "*".join(t for t, _ in num), MUL
        top = "*".join(t for t, _ in num) if num else self.literal(1.0)
        if len(den) == 1:
            bottom = self._wrap(den[0], ATOM)
        else:
            bottom = "(" + "*".join(self._wrap(d, MUL) for d in den) + ")"
        return f"{top}/{bottom}", MUL

    def _pow(self, e: sp.Pow) -> tuple[str, int]:
        if not e.free_symbols:
            return self._number(e)
        base, exp = e.base, e.exp
        if exp.is_Integer and 0 < exp <= MAX_UNROLLED_POWER:
            b = self._wrap(base, ATOM)
            return ("*".join([b] * int(exp)), ATOM if exp == 1 else MUL)
        if exp.is_Integer and -MAX_UNROLLED_POWER <= exp < 0:
            k = int(-exp)
            b = self._wrap(base, ATOM)
            bottom = b if k == 1 else "(" + "*".join([b] * k) + ")"
            return f"{self.literal(1.0)}/{bottom}", MUL
        sqrt = self.config.math("sqrt")
        if exp == sp.Rational(1, 2):
            return f"{sqrt}({self._print(base)[0]})", ATOM
        if exp == sp.Rational(-1, 2):
            return f"{self.literal(1.0)}/{sqrt}({self._print(base)[0]})", MUL
        return f"{self.config.math('pow')}({self._print(base)[0]}, {self._print(exp)[0]})", ATOM
