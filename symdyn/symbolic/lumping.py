"""Lumped constants: each distinct coefficient of a closed form named once, as Armstrong,
Khatib and Burdick printed the PUMA 560 (I1, I2, ... for inertial, g1, g2, ... for
gravitational constants).

A closed form in the configuration-space form is a sum of terms (coefficient) * (angle
part), the coefficient a number or a polynomial in the free parameters
(symdyn.symbolic.trig_polynomial). `Lumper` replaces every coefficient other than +-1 and a
bare parameter by a named constant, the same name for the same value up to sign (and
2 * name for twice a known value, as the Coriolis coefficients B = 2 Gamma have), in the
order the terms are printed.

The names are the seam for the identification of base parameters: a caller may pass
`known`, a map from coefficient to the symbol it should print as (a base parameter), and
only the coefficients not in it get fresh names.

Reference: B. Armstrong, O. Khatib, J. Burdick, "The explicit dynamic model and inertial
parameters of the PUMA 560 arm", Proc. IEEE ICRA 1986, tables of constants.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence

import sympy as sp

__all__ = ["Lumper"]

#: significant digits two float coefficients must share to get one name
DIGITS = 12


class Lumper:
    """Names the coefficients of closed forms; `definitions` lists (name, value) in order."""

    def __init__(
        self, q: Sequence[sp.Symbol], prefix: str = "I", known: Mapping[sp.Expr, sp.Symbol] | None = None
    ):
        self.q = tuple(q)
        self.prefix = prefix
        self._names: dict[object, sp.Symbol] = {}
        self._known = dict(known or {})
        self.definitions: list[tuple[sp.Symbol, sp.Expr]] = []

    @staticmethod
    def _key(c: sp.Expr) -> object:
        if c.is_Float:
            return ("f", float(f"{float(c):.{DIGITS}g}"))
        return c

    def _lookup(self, c: sp.Expr) -> sp.Expr | None:
        if c in self._known:
            return self._known[c]
        name = self._names.get(self._key(c))
        if name is not None:
            return name
        half = self._names.get(self._key(c / 2))
        return 2 * half if half is not None else None

    def name(self, c: sp.Expr) -> sp.Expr:
        """The printed form of coefficient c: c itself when trivial, else +-name."""
        if c.is_Symbol or (c.is_Number and abs(c) == 1):
            return c
        sign = -1 if c.could_extract_minus_sign() else 1
        c = sign * c
        found = self._lookup(c)
        if found is None:
            found = sp.Symbol(f"{self.prefix}{len(self.definitions) + 1}")
            self._names[self._key(c)] = found
            self.definitions.append((found, c))
        return sign * found

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
