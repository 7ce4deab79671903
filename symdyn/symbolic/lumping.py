"""Lumped constants: each distinct coefficient of a closed form named once, as Armstrong,
Khatib and Burdick printed the PUMA 560 (I1, I2, ... for inertial, g1, g2, ... for
gravitational constants).

A closed form in the configuration-space form is a sum of terms (coefficient) * (angle
part), the coefficient a number or a polynomial in the free parameters
(symdyn.symbolic.trig_polynomial). `Lumper` replaces every coefficient other than +-1 and a
bare parameter by a named constant, the same name for the same value up to sign (and
2 * name for twice a known value, as the Coriolis coefficients B = 2 Gamma have), in the
order the terms are printed.

With `known`, a map from coefficient (sign split off: `split_sign`) to its expression over
named parameters (symdyn.lumped: a combination of base parameters), a coefficient found there
prints as that expression when it is +-(a number times) one symbol, else as a fresh name defined
as the expression (the same name for the same expression, up to sign and a factor 2); the
coefficients not found get names defined by their value, as without `known`, and are listed in
`missed`. Names in `reserved` (the robot's own symbols) are skipped.

Reference: B. Armstrong, O. Khatib, J. Burdick, "The explicit dynamic model and inertial
parameters of the PUMA 560 arm", Proc. IEEE ICRA 1986, tables of constants.
"""

from __future__ import annotations

from collections.abc import Collection, Mapping, Sequence

import sympy as sp

__all__ = ["Lumper", "split_sign"]

#: significant digits two float coefficients must share to get one name
DIGITS = 12


def split_sign(c: sp.Expr) -> tuple[int, sp.Expr]:
    """(sign, |c|) with c = sign * |c|, the sign SymPy can extract (-2*x -> (-1, 2*x))."""
    return (-1, -c) if c.could_extract_minus_sign() else (1, c)


class Lumper:
    """Names the coefficients of closed forms; `definitions` lists (name, definition) in order."""

    def __init__(
        self,
        q: Sequence[sp.Symbol],
        prefix: str = "I",
        known: Mapping[sp.Expr, sp.Expr] | None = None,
        reserved: Collection[str] = (),
    ):
        self.q = tuple(q)
        self.prefix = prefix
        self._reserved = set(reserved)
        self._count = 0
        self._names: dict[object, sp.Symbol] = {}
        self._known = dict(known or {})
        self.definitions: list[tuple[sp.Symbol, sp.Expr]] = []
        #: the symbols of the `known` expressions printed, directly or in a definition
        self.referenced: set[sp.Symbol] = set()
        #: with `known`: the coefficients not in it, named by value
        self.missed: dict[sp.Expr, None] = {}

    @staticmethod
    def _key(c: sp.Expr) -> object:
        if c.is_Float:
            return ("f", float(f"{float(c):.{DIGITS}g}"))
        return c

    def _lookup(self, key: object, half: object) -> sp.Expr | None:
        name = self._names.get(key)
        if name is not None:
            return name
        name = self._names.get(half)
        return 2 * name if name is not None else None

    def _fresh(self, key: object, definition: sp.Expr) -> sp.Symbol:
        self._count += 1
        while f"{self.prefix}{self._count}" in self._reserved:
            self._count += 1
        found = sp.Symbol(f"{self.prefix}{self._count}")
        self._names[key] = found
        self.definitions.append((found, definition))
        return found

    def _combination(self, e: sp.Expr) -> sp.Expr:
        """A known expression as printed: itself when +-(number times) one symbol, else a name."""
        self.referenced |= e.free_symbols
        sign, e = split_sign(e)
        if e.as_coeff_Mul()[1].is_Symbol:
            return sign * e
        found = self._lookup(("b", e), ("b", e / 2))
        return sign * (found if found is not None else self._fresh(("b", e), e))

    def name(self, c: sp.Expr) -> sp.Expr:
        """The printed form of coefficient c: c itself when trivial, else +-name."""
        sign, a = split_sign(c)
        if self._known:
            e = self._known.get(a)
            if e is not None:
                return sign * self._combination(e)
            if not (c.is_Number and abs(c) == 1):
                self.missed[a] = None
        if c.is_Symbol or (c.is_Number and abs(c) == 1):
            return c
        found = self._lookup(self._key(a), self._key(a / 2))
        return sign * (found if found is not None else self._fresh(self._key(a), a))

    def lump(self, expr: sp.Expr) -> sp.Expr:
        """expr with each term's coefficient (the part free of q) named, terms in printed order."""
        expr = sp.sympify(expr)
        if expr == 0:
            return expr
        out = []
        for term in sp.Add.make_args(expr) if not expr.is_Add else expr.as_ordered_terms():
            coef, angle = term.as_independent(*self.q, as_Add=False)
            out.append(self.name(coef) * angle)
        return sp.Add(*out)
