"""The text of a trigonometric polynomial (symdyn.symbolic.trig_polynomial), written directly.

`derive` prints the configuration-space form term by term. Going through SymPy (building
each entry's Add, then sstr sorting its terms) costs about a millisecond per term, minutes
for a 7-joint arm with full inertia tensors (the Panda's 228,647 terms); writing the terms
from the polynomial's keys costs microseconds. The text is SymPy's syntax (it parses with
sympy.sympify to the same expression as TrigRing.to_sympy), in a fixed order of our own:

- terms grouped by their angle part, as to_sympy groups them: the constant first, then the
  angles of one joint (q1, 2*q1, q2, ...), then of two (q1 + q2, q1 - q2, ...), and so on,
  cos before sin,
  powers of prismatic coordinates last within one angle;
- a number coefficient: a Fraction exactly as p/q, a float to 15 significant digits (as
  SymPy prints a Float, without its trailing zeros: the digits past the 15th are rounding
  noise of the derivation, 0.38487629400000006 prints as 0.384876294), other numbers
  (sqrt(2), pi) by sstr;
- a coefficient with parameters as to_sympy forms it (common factors pulled out), written by
  sstr and parenthesised when it is a sum.

The order depends only on the keys, so two equal polynomials (the two derivation routes)
print the same text.
"""

from __future__ import annotations

from collections.abc import Callable
from fractions import Fraction

import sympy as sp

from .trig_polynomial import TrigPoly, TrigRing

__all__ = ["TrigText", "number_text"]


def number_text(c) -> str:
    """A coefficient as text: Fraction p/q, float repr, else SymPy's str."""
    if isinstance(c, Fraction):
        return str(c.numerator) if c.denominator == 1 else f"{c.numerator}/{c.denominator}"
    if isinstance(c, float):
        return f"{c:.15g}"
    return sp.sstr(c)


def _negative(c) -> bool:
    if isinstance(c, (Fraction, float)):
        return c < 0
    return bool(sp.sympify(c).could_extract_minus_sign())


def _atom_text(e: sp.Expr) -> str:
    text = sp.sstr(e)
    return text if (e.is_Symbol or e.is_Function) else f"({text})"


class TrigText:
    """Writes the TrigPolys of one TrigRing as text; caches the strings of angles and monomials.

    coefficient: maps a group's coefficient (a SymPy number or polynomial in the parameters)
    to the expression to print instead (lumped constants, symdyn.symbolic.lumping); it is
    called in printed order.
    """

    def __init__(self, ring: TrigRing, coefficient: Callable[[sp.Expr], sp.Expr] | None = None) -> None:
        self.ring = ring
        self.coefficient = coefficient
        self._angles: dict[tuple, str] = {}
        self._monos: dict[tuple, str] = {}
        self._names = [sp.sstr(q) for q in ring.q]

    def angle(self, k: tuple, kind: int) -> str:
        """cos(k . q) or sin(k . q) as text ("" for the constant cos(0))."""
        hit = self._angles.get((k, kind))
        if hit is None:
            n = self.ring.n
            if not any(k):
                hit = ""
            else:
                parts = []
                for x, name in zip(k, (*self._names, None), strict=True):
                    if x == 0:
                        continue
                    sign = "-" if x < 0 else "+"
                    size = abs(x)
                    if name is None:
                        body = number_text(Fraction(size) if not isinstance(size, float) else size)
                    else:
                        body = name if size == 1 else f"{number_text(_exact(size))}*{name}"
                    parts.append((sign, body))
                text = ("-" if parts[0][0] == "-" else "") + parts[0][1]
                text += "".join(f" {s} {b}" for s, b in parts[1:])
                hit = f"{'cos' if kind == 0 else 'sin'}({text})"
                if not any(k[:n]):  # cos(1/5): a number, as SymPy writes it
                    hit = sp.sstr(self.ring.trig_expr(k, kind))
            self._angles[(k, kind)] = hit
        return hit

    def monomial(self, mono: tuple) -> str:
        """A product of generators (coordinates or parameters) with powers, as text."""
        hit = self._monos.get(mono)
        if hit is None:
            parts = []
            for g, e in mono:
                atom = self.ring.gens[g]
                base = self._names[g] if g < self.ring.n else _atom_text(atom)
                parts.append(base if e == 1 else f"{base}**{e}")
            hit = self._monos[mono] = "*".join(parts)
        return hit

    def text(self, p: TrigPoly) -> str:
        """The polynomial as one SymPy-syntax string ("0" when empty)."""
        out: list[str] = []
        for (qpart, k, kind), items in self.ring.groups(p):
            factors = [f for f in (self.monomial(qpart), self.angle(k, kind)) if f]
            negative, coef = self._coefficient(items, bool(factors))
            body = "*".join(factors if coef == "1" and factors else [coef, *factors])
            if not out:
                out.append(f"-{body}" if negative else body)
            else:
                out.append(f" - {body}" if negative else f" + {body}")
        return "".join(out) or "0"

    def _coefficient(self, items: list, factors: bool) -> tuple[bool, str]:
        """(negative, text of |coefficient|) of one angle group, a sum parenthesised when
        factors follow or a minus sign precedes it."""
        if self.coefficient is None and len(items) == 1 and not items[0][1]:
            c = items[0][0]
            negative = _negative(c)
            text = number_text(-c if negative else c)
            if (factors or negative) and not isinstance(c, (Fraction, float)) and sp.sympify(c).is_Add:
                text = f"({text})"
            return negative, text
        coef = self.ring.group_coefficient(items)
        if self.coefficient is not None:
            coef = self.coefficient(coef)
        negative = coef.could_extract_minus_sign()
        if negative:
            coef = -coef
        text = sp.sstr(coef)
        if coef.is_Add and (factors or negative):
            text = f"({text})"
        return negative, text


def _exact(x):
    return Fraction(x) if isinstance(x, int) else x
