"""Trigonometric polynomials rewritten over trig atoms c_i, s_i, c_23, s_23 (the product form).

The configuration form (symdyn.symbolic.trig_polynomial) writes an entry as a sum of
cos(k . q) and sin(k . q), k an integer vector. The product form writes the same function
as a polynomial in the atoms

    c_b = cos(q_i + ... + q_j),   s_b = sin(q_i + ... + q_j),

b = (i, ..., j) a single joint or a block of consecutive joints of one group of parallel
axes (the PUMA's q2 + q3). Each angle k . q is first written as a signed sum of blocks
(k restricted to a group is split greedily into maximal runs of one sign, so 2 q2 + 2 q3
becomes 2 (q2 + q3) and 2 q2 + q3 becomes q2 + (q2 + q3)); then the angle-sum formulas

    cos(a + b) = cos a cos b - sin a sin b,   sin(a + b) = sin a cos b + cos a sin b,

and cos(m a), sin(m a) by the same recurrence turn it into products of atoms, every
s_b^2 replaced by 1 - c_b^2. The result depends only on the trigonometric polynomial, so
equal configuration forms give equal product forms.

An `AtomPoly` is a dict monomial -> coefficient, monomial a sorted tuple of
(variable, exponent), variables numbered by the `Atoms` registry: the atoms, then the
ring's generators (coordinates of prismatic joints, parameters).

References: Armstrong, Khatib, Burdick, "The explicit dynamic model and inertial
parameters of the PUMA 560 arm", Proc. IEEE ICRA 1986 (the model over c_i, s_i, c_23, s_23);
Craig, Introduction to Robotics (3rd ed., 2005), sec. 6.8.
"""

from __future__ import annotations

from collections.abc import Sequence
from fractions import Fraction
from math import comb

import sympy as sp

from .trig_polynomial import TrigPoly, TrigRing, mono_mul, number, to_sympy_number

__all__ = ["Atoms", "AtomPoly", "split_blocks"]

AtomPoly = dict


def _mul_coef(a, b):
    if isinstance(a, (Fraction, float)) and isinstance(b, (Fraction, float)):
        return a * b
    out = sp.expand(to_sympy_number(a) * to_sympy_number(b))
    return number(out)


def _add_coef(a, b):
    if isinstance(a, (Fraction, float)) and isinstance(b, (Fraction, float)):
        return a + b
    return number(sp.expand(to_sympy_number(a) + to_sympy_number(b)))


def _put(acc: AtomPoly, mono: tuple, c) -> None:
    old = acc.get(mono)
    new = c if old is None else _add_coef(old, c)
    if new == 0:
        acc.pop(mono, None)
    else:
        acc[mono] = new


def split_blocks(k: Sequence, groups: Sequence[Sequence[int]]) -> list[tuple[tuple[int, ...], object]]:
    """k . q as a signed sum of blocks: [(block, multiple), ...], a block a tuple of
    consecutive joints of one group (or a single joint), in a fixed order (by first joint)."""
    out = []
    seen = set()
    for group in groups:
        v = [k[i] for i in group]
        seen.update(group)
        while any(v):
            a = next(i for i, x in enumerate(v) if x)
            sign = 1 if v[a] > 0 else -1
            b = a
            while b + 1 < len(v) and v[b + 1] * sign > 0:
                b += 1
            m = min(abs(x) for x in v[a : b + 1])
            for i in range(a, b + 1):
                v[i] -= sign * m
            out.append((tuple(group[a : b + 1]), sign * m))
    out += [((i,), x) for i, x in enumerate(k) if x and i not in seen]
    return sorted(out, key=lambda item: (item[0][0], len(item[0]), item[0]))


class Atoms:
    """The variables of the product form of one derivation: atoms c_b, s_b (made as met) and
    the ring's generators, with the conversion of TrigPolys into AtomPolys."""

    def __init__(self, ring: TrigRing, groups: Sequence[Sequence[int]], taken: set[str]) -> None:
        self.ring = ring
        self.groups = [tuple(g) for g in groups if len(g) > 1]
        self.symbols: list[sp.Expr] = []  # variable -> SymPy symbol or generator
        self.definitions: dict[int, sp.Expr] = {}  # atom variable -> cos/sin of its angle
        self._cosine_of: dict[int, int] = {}  # sine variable -> cosine variable
        self._atoms: dict[tuple, tuple[int, int]] = {}
        self._gens: dict[int, int] = {}
        self._angles: dict[tuple, tuple[AtomPoly, AtomPoly]] = {}  # by (block, multiple)
        self._sums: dict[tuple, tuple[AtomPoly, AtomPoly]] = {}  # by k
        self._prefixes: dict[tuple, tuple[AtomPoly, AtomPoly]] = {}  # by leading (block, multiple)s
        self._floats: dict[tuple, list] = {}  # by (k, kind), float coefficients
        self._monomials: list[tuple] = []  # atom monomials met in float sums, by number
        self._monomial_numbers: dict[tuple, int] = {}
        self._names: list[str] = []
        self._taken = set(taken)
        self._sep = "" if ring.n < 10 else "_"

    # -- variables --------------------------------------------------------------------
    def _variable(self, symbol: sp.Expr) -> int:
        self.symbols.append(symbol)
        self._names.append(sp.sstr(symbol))
        return len(self.symbols) - 1

    def atom(self, block: tuple[int, ...], m=1) -> tuple[int, int]:
        """The variables (c, s) of cos and sin of m times the sum of the block's angles."""
        key = (block, m)
        hit = self._atoms.get(key)
        if hit is None:
            tag = self._sep.join(str(i + 1) for i in block)
            if m != 1:
                tag += f"{self._sep or '_'}x{len(self._atoms) + 1}"
            names = []
            for head in ("c", "s"):
                name = f"{head}{tag}"
                while name in self._taken:
                    name = f"{name}_"
                names.append(name)
            angle = sp.sympify(m) * sp.Add(*[self.ring.q[i] for i in block])
            c = self._variable(sp.Symbol(names[0]))
            s = self._variable(sp.Symbol(names[1]))
            self.definitions[c], self.definitions[s] = sp.cos(angle), sp.sin(angle)
            self._cosine_of[s] = c
            hit = self._atoms[key] = (c, s)
        return hit

    def generator(self, g: int) -> int:
        hit = self._gens.get(g)
        if hit is None:
            hit = self._gens[g] = self._variable(self.ring.gens[g])
        return hit

    def name(self, v: int) -> str:
        return self._names[v]

    def is_atom(self, v: int) -> bool:
        return v in self.definitions

    # -- arithmetic -------------------------------------------------------------------
    def _reduce(self, mono: tuple) -> list[tuple[tuple, object]]:
        """mono with every s^e, e >= 2, written as s^(e mod 2) (1 - c^2)^(e div 2)."""
        out = [((), Fraction(1))]
        for v, e in mono:
            c = self._cosine_of.get(v)
            if c is None or e < 2:
                out = [(mono_mul(m, ((v, e),)), x) for m, x in out]
                continue
            h, r = divmod(e, 2)
            base = ((v, r),) if r else ()
            # (1 - c^2)^h = sum_j binom(h, j) (-1)^j c^(2j)
            parts = [
                (mono_mul(base, ((c, 2 * j),) if j else ()), Fraction((-1) ** j * comb(h, j)))
                for j in range(h + 1)
            ]
            out = [(mono_mul(m, pm), x * px) for m, x in out for pm, px in parts]
        return out

    def multiply(self, p: AtomPoly, r: AtomPoly) -> AtomPoly:
        out: AtomPoly = {}
        for ma, ca in p.items():
            for mb, cb in r.items():
                c = _mul_coef(ca, cb)
                mono = mono_mul(ma, mb)
                if any(e >= 2 and v in self._cosine_of for v, e in mono):
                    for m, x in self._reduce(mono):
                        _put(out, m, _mul_coef(c, x))
                else:
                    _put(out, mono, c)
        return out

    def _cos_sin(self, block: tuple[int, ...], m) -> tuple[AtomPoly, AtomPoly]:
        """(cos, sin) of m times the block's angle: atoms for m = 1 (or m not an integer),
        the angle-sum recurrence for integer m >= 2, cos even and sin odd for m < 0."""
        key = (block, m)
        hit = self._angles.get(key)
        if hit is not None:
            return hit
        one = Fraction(1)
        if m < 0:
            c, s = self._cos_sin(block, -m)
            hit = (c, {k: -x for k, x in s.items()})
        elif m == 1 or not float(m).is_integer():
            cv, sv = self.atom(block, 1 if m == 1 else m)
            hit = ({((cv, 1),): one}, {((sv, 1),): one})
        else:
            c1, s1 = self._cos_sin(block, 1)
            cm, sm = self._cos_sin(block, int(m) - 1)
            cos = self.multiply(cm, c1)
            for mono, x in self.multiply(sm, s1).items():
                _put(cos, mono, -x)
            sin = self.multiply(sm, c1)
            for mono, x in self.multiply(cm, s1).items():
                _put(sin, mono, x)
            hit = (cos, sin)
        self._angles[key] = hit
        return hit

    def angle(self, k: tuple) -> tuple[AtomPoly, AtomPoly]:
        """(cos, sin) of k . q + k_radians over the atoms (the radian part as number factors)."""
        hit = self._sums.get(k)
        if hit is None:
            hit = self._sums[k] = self._angle(k)
        return hit

    def _angle(self, k: tuple) -> tuple[AtomPoly, AtomPoly]:
        n = self.ring.n
        cos: AtomPoly = {(): Fraction(1)}
        sin: AtomPoly = {}
        prefix: tuple = ()
        for block, m in split_blocks(k[:n], self.groups):
            # angles that begin with the same blocks share the products of those blocks
            prefix += ((block, m),)
            hit = self._prefixes.get(prefix)
            if hit is None:
                cb, sb = self._cos_sin(block, m)
                hit = self._prefixes[prefix] = (
                    _sub(self.multiply(cos, cb), self.multiply(sin, sb)),
                    _sub(self.multiply(sin, cb), self.multiply(cos, sb), plus=True),
                )
            cos, sin = hit
        r = k[n]
        if r:
            cr, sr = (number(f(to_sympy_number(r))) for f in (sp.cos, sp.sin))
            cos, sin = (
                _sub(_scaled(cos, cr), _scaled(sin, sr)),
                _sub(_scaled(sin, cr), _scaled(cos, sr), plus=True),
            )
        return cos, sin

    def _float_angle(self, k: tuple, kind: int) -> list[tuple[int, float]]:
        """angle(k)[kind] with float coefficients, for terms with float coefficients: pairs
        (number of the atom monomial in self._monomials, coefficient)."""
        hit = self._floats.get((k, kind))
        if hit is None:
            hit = self._floats[(k, kind)] = [
                (self._monomial_number(m), float(x)) for m, x in self.angle(k)[kind].items()
            ]
        return hit

    def _monomial_number(self, mono: tuple) -> int:
        number = self._monomial_numbers.get(mono)
        if number is None:
            number = self._monomial_numbers[mono] = len(self._monomials)
            self._monomials.append(mono)
        return number

    def convert(self, p: TrigPoly) -> AtomPoly:
        """The TrigPoly p over the atoms: each term's angle expanded, times its monomial. Terms
        with float coefficients are summed in floats (the Panda: 15 million products)."""
        out: AtomPoly = {}
        # Float sums keyed by the pair (atom monomial, generator monomial) packed in one int,
        # factor number << 32 | atom monomial number: the two monomials use disjoint variables,
        # so a pair is one monomial, merged (mono_mul) once per pair rather than once per product.
        floats: dict[int, float] = {}
        factors: dict[tuple, int] = {}
        for (mono, k, kind), c in p.items():
            factor = tuple(sorted((self.generator(g), e) for g, e in mono))
            if type(c) is float:
                base = factors.setdefault(factor, len(factors)) << 32
                for number, x in self._float_angle(k, kind):
                    key = base | number
                    floats[key] = floats.get(key, 0.0) + c * x
                continue
            for tm, x in self.angle(k)[kind].items():
                _put(out, mono_mul(tm, factor), _mul_coef(c, x))
        by_number = list(factors)
        for key, x in floats.items():
            if x != 0.0:
                _put(out, mono_mul(self._monomials[key & 0xFFFFFFFF], by_number[key >> 32]), x)
        return out


def _scaled(p: AtomPoly, c) -> AtomPoly:
    return {m: _mul_coef(x, c) for m, x in p.items()} if c != 0 else {}


def _sub(a: AtomPoly, b: AtomPoly, plus: bool = False) -> AtomPoly:
    """a - b (a + b with plus)."""
    out = dict(a)
    for m, x in b.items():
        _put(out, m, x if plus else -x)
    return out
