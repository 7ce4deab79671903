"""Factoring polynomials Horner-like, and sharing equal or opposite pieces under names.

`Factoring` turns AtomPolys (symdyn.symbolic.atom_polynomial) into SymPy expressions:

- Horner's scheme, greedily: of a polynomial of several terms, the variable that appears
  in most terms (ties: the smaller name) is factored out, P = v Q + R, and Q and R are
  factored in turn; a variable in no two terms ends the recursion (a plain sum);
- sharing: each factored piece is keyed by its terms up to sign (the first term's
  coefficient made positive; floats to 13 significant digits, below the rounding of the
  derivation), so a piece that occurs more than once, in one entry or across
  entries (equal or opposite entries; the Christoffel symbols repeat), is defined once as a
  named quantity x1, x2, ... and referred to by name (a negated one as -x1). Names are
  given in order of first appearance, a quantity's pieces before it.

Everything depends only on the polynomials and the variables' names: deterministic.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from fractions import Fraction

import sympy as sp
from sympy.printing.str import StrPrinter

from .atom_polynomial import AtomPoly
from .trig_polynomial import fast_add, fast_mul, to_sympy_number
from .trig_text import number_text

__all__ = ["Factoring", "product_text"]


def _negative(c) -> bool:
    if isinstance(c, (Fraction, float)):
        return c < 0
    return bool(sp.sympify(c).could_extract_minus_sign())


def _rounded(c):
    """A coefficient as a key: a float to 13 significant digits, so that two pieces equal up
    to the derivation's rounding (1 or 2 ulp apart) are shared."""
    return float(f"{c:.13g}") if isinstance(c, float) else c


class _Piece:
    """One factored polynomial (positive first term): a term, a plain sum, or v Q + R."""

    __slots__ = ("terms", "var", "q", "r", "uses")

    def __init__(self, terms, var=None, q=None, r=None):
        self.terms = terms  # the polynomial's items, sorted
        self.var = var
        self.q = q  # (piece, sign) or None
        self.r = r
        self.uses = 0


class Factoring:
    """Factors and shares the AtomPolys of one form.

    names: variable -> name (the order of ties); symbols: variable -> SymPy symbol;
    taken: names the shared quantities must not use.
    """

    def __init__(self, symbols: Sequence[sp.Expr], name: Callable[[int], str], taken: set[str]) -> None:
        self.symbols = symbols
        self.name = name
        self._pieces: dict[tuple, _Piece] = {}
        self._taken = taken
        self._named: dict[int, sp.Symbol] = {}
        self._done: dict[int, sp.Expr] = {}
        #: the shared quantities (name, expression) in order of first appearance
        self.shared: list[tuple[sp.Symbol, sp.Expr]] = []

    # -- factoring --------------------------------------------------------------------
    def piece(self, p: AtomPoly) -> tuple[_Piece, int] | None:
        """(piece, sign) of p (None for 0)."""
        if not p:
            return None
        items = sorted(p.items(), key=lambda item: self._order(item[0]))
        sign = -1 if _negative(items[0][1]) else 1
        if sign < 0:
            items = [(m, -c) for m, c in items]
        key = tuple((m, _rounded(c)) for m, c in items)
        hit = self._pieces.get(key)
        if hit is None:
            hit = self._pieces[key] = self._build(items)
        return hit, sign

    def _build(self, items: list) -> _Piece:
        if len(items) == 1:
            return _Piece(items)
        counts: dict[int, int] = {}
        for mono, _ in items:
            for v, _e in mono:
                counts[v] = counts.get(v, 0) + 1
        best = min(counts, key=lambda v: (-counts[v], self.name(v)), default=None)
        if best is None or counts[best] < 2:
            return _Piece(items)
        q: AtomPoly = {}
        r: AtomPoly = {}
        for mono, c in items:
            d = dict(mono)
            if best in d:
                d[best] -= 1
                if not d[best]:
                    del d[best]
                q[tuple(sorted(d.items()))] = c
            else:
                r[mono] = c
        return _Piece(items, best, self.piece(q), self.piece(r))

    def _order(self, mono: tuple) -> tuple:
        """A monomial's place among the terms, by the variables' names (not their numbers,
        which follow the order a route met them): the same order from either route."""
        return tuple(sorted((self.name(v), e) for v, e in mono))

    # -- sharing ----------------------------------------------------------------------
    def count(self, ref: tuple[_Piece, int] | None) -> None:
        """Count the references to a piece of an entry (a piece's parts only at its first)."""
        if ref is None:
            return
        piece = ref[0]
        piece.uses += 1
        if piece.uses == 1 and piece.var is not None:
            self.count(piece.q)
            self.count(piece.r)

    def expr(self, ref: tuple[_Piece, int] | None) -> sp.Expr:
        """The expression of a counted piece, shared ones by name (defined at first use)."""
        if ref is None:
            return sp.S.Zero
        piece, sign = ref
        key = id(piece)
        e = self._named.get(key)
        if e is None:
            e = self._done.get(key)
            if e is None:
                e = self._done[key] = self._write(piece)
                if piece.uses > 1 and self._worth(piece, e):
                    name = self._fresh()
                    self.shared.append((name, e))
                    e = self._named[key] = name
            else:
                e = self._named.get(key, e)
        return -e if sign < 0 else e

    def _worth(self, piece: _Piece, e: sp.Expr) -> bool:
        """Share sums, and single terms of at least three operations."""
        return e.is_Add or sp.count_ops(e) >= 3

    def _fresh(self) -> sp.Symbol:
        k = len(self.shared) + 1
        name = f"x{k}"
        while name in self._taken:
            name = f"{name}_"
        return sp.Symbol(name)

    def _write(self, piece: _Piece) -> sp.Expr:
        """v1 Q1 + v2 Q2 + ... + (plain sum): the chain of remainders R written in one sum
        (not nested Adds, whose flattening would cost the square of the length), up to a
        remainder used elsewhere too, which is written by name when shared."""
        terms: list[sp.Expr] = []
        p, sign = piece, 1
        while True:
            if p.var is None:
                terms += [self._term(m, c if sign > 0 else -c) for m, c in p.terms]
                break
            t = self.symbols[p.var] * self.expr(p.q)
            terms.append(t if sign > 0 else -t)
            if p.r is None:
                break
            r, s = p.r
            if r.uses > 1:
                terms.extend(sp.Add.make_args(self.expr((r, s * sign))))
                break
            p, sign = r, sign * s
        return fast_add(terms)

    def _term(self, mono: tuple, c) -> sp.Expr:
        return fast_mul([to_sympy_number(c), *[self.symbols[v] ** e for v, e in mono]])


class _Printer(StrPrinter):
    """SymPy's str, floats to 15 significant digits as the configuration form prints them."""

    def _print_Float(self, expr) -> str:
        return number_text(float(expr))


_PRINTER = _Printer()


def product_text(expr: sp.Expr) -> str:
    """expr as text (SymPy syntax; sympy.sympify reads it back), floats to 15 digits."""
    return _PRINTER.doprint(expr)
