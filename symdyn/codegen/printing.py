"""The skeleton the C and CasADi printers share: a SymPy tree printed with precedences.

`TreePrinter._print` dispatches on the kind of node (symbol, constant, sum,
product, power, call) to a method of the target's printer, which returns the
text and its precedence (higher binds tighter). `_wrap` parenthesises an
operand only when it binds less tightly than its context needs. Each target's
rules (literals, powers, function names) stay in its own printer; the NumPy
and LaTeX targets subclass SymPy's own printers instead.
"""

from __future__ import annotations

import sympy as sp

__all__ = ["TreePrinter", "free_name", "step_comparison"]


def free_name(base: str, taken, temporary) -> str:
    """`base`, or `base_`, `base_1`, `base_2`, ... : the first that is not in `taken` and does
    not match `temporary` (the pattern of the eliminated temporaries' names), for a local of
    generated code named after a free parameter."""
    candidate, k = base, 0
    while candidate in taken or temporary.match(candidate):
        candidate = f"{base}_" if k == 0 else f"{base}_{k}"
        k += 1
    return candidate


def step_comparison(e: sp.Heaviside) -> tuple[sp.Expr, str]:
    """The Heaviside step H(x) with H(0) = 0 (direction-dependent Coulomb friction) as a strict
    comparison with zero, (x, ">"), or (y, "<") when x reads as -y: H(x) = [x > 0], H(-y) = [y < 0]."""
    assert isinstance(e, sp.Heaviside) and e.args[1:] == (sp.S.Zero,), e
    x = e.args[0]
    return (-x, "<") if x.could_extract_minus_sign() else (x, ">")


class TreePrinter:
    """SymPy expression -> (text, precedence) in some target language; subclasses print the nodes."""

    def doprint(self, expr) -> str:
        """The text of `expr` (anything sympify accepts)."""
        return self._print(sp.sympify(expr))[0]

    def _wrap(self, expr: sp.Expr, need: int) -> str:
        """Print `expr`, parenthesised unless it binds at least as tightly as `need`."""
        text, prec = self._print(expr)
        return f"({text})" if prec < need else text

    def _print(self, e: sp.Expr) -> tuple[str, int]:
        if e.is_Symbol:
            return self._symbol(e)
        if e.is_Number or e.is_NumberSymbol:
            return self._constant(e)
        if e.is_Add:
            return self._add(e)
        if e.is_Mul:
            return self._mul(e)
        if e.is_Pow:
            return self._pow(e)
        return self._call(e)

    def _symbol(self, e: sp.Symbol) -> tuple[str, int]:
        raise NotImplementedError

    def _constant(self, e: sp.Expr) -> tuple[str, int]:
        raise NotImplementedError

    def _add(self, e: sp.Add) -> tuple[str, int]:
        raise NotImplementedError

    def _mul(self, e: sp.Mul) -> tuple[str, int]:
        raise NotImplementedError

    def _pow(self, e: sp.Pow) -> tuple[str, int]:
        raise NotImplementedError

    def _call(self, e: sp.Expr) -> tuple[str, int]:
        raise NotImplementedError
