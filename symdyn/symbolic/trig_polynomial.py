"""Trigonometric polynomials: the canonical closed form of M(q) and G(q).

An entry of M or G is a polynomial in the free parameters (and the coordinates of
prismatic joints) whose coefficients are sums of cos(k . q) and sin(k . q), k an integer
vector (a sum of angles such as q2 + q3 or 2 q2 + q3). Written as

    sum_t  c_t  g^e_t  trig_t(k_t . q),    trig in {cos, sin},

with k_t's first non-zero component positive (cos(-x) = cos x, sin(-x) = -sin x) and a sin
never of k = 0, the representation is unique: products of sines and cosines become sums
of angles (cos a cos b = (cos(a - b) + cos(a + b))/2 and its three siblings), so
sin^2 + cos^2 = 1 holds by construction and two expressions that are equal as functions
have the same terms. That makes the closed form independent of the route that produced
it (Newton-Euler or Lagrange), and makes every step linear: each named intermediate of a
`Program` is turned into a `TrigPoly` once, from the polynomials of the intermediates it
uses, instead of expanding the nested expression with sympy.expand.

A `TrigPoly` is a dict key -> coefficient with key = (monomial, k, kind): monomial a
sorted tuple of (generator index, exponent) over the `TrigRing`'s generators (the
coordinates q_i, then parameters and other q-free atoms as met), kind 0 for cos, 1 for
sin. Coefficients are Fractions (exact data), floats (float data) or SymPy numbers
(pi, sqrt(2), ...); Python ints never occur, so halving stays exact.

References: Armstrong, Khatib, Burdick, "The explicit dynamic model and inertial
parameters of the PUMA 560 arm", Proc. IEEE ICRA 1986 (the explicit model written in
sines and cosines of sums of joint angles); Craig, Introduction to Robotics (3rd ed., 2005),
sec. 6.8 (the configuration-space form).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from fractions import Fraction
from operator import add, neg, sub

import sympy as sp
from sympy.core.add import _addsort
from sympy.core.mul import _mulsort

from ..errors import SymdynError
from .simplify import CHOP

__all__ = [
    "TrigRing",
    "TrigPoly",
    "Key",
    "add_into",
    "scale",
    "number",
    "chop",
    "largest",
    "is_float_data",
    "print_order",
    "mono_mul",
]

Monomial = tuple[tuple[int, int], ...]
Key = tuple[Monomial, tuple, int]
TrigPoly = dict

_ONE_MONO: Monomial = ()


def number(x: sp.Expr):
    """A SymPy number as a coefficient: Fraction (rational), float (Float), else the SymPy number."""
    if x.is_Rational:
        return Fraction(int(x.p), int(x.q))
    if x.is_Float:
        return float(x)
    return x


def to_sympy_number(c) -> sp.Expr:
    if isinstance(c, Fraction):
        return sp.Rational(c.numerator, c.denominator)
    if isinstance(c, float):
        return sp.Float(c)
    return sp.sympify(c)


def _is_zero(c) -> bool:
    return c == 0


def _canonical(c):
    """A coefficient in canonical form: SymPy numbers (sqrt(3)/2, ...) expanded, and rational
    or float results as Fraction or float."""
    if type(c) is Fraction or type(c) is float:
        return c
    c = sp.expand(c)
    return number(c) if c.is_Number else c


def _frequency(c: sp.Expr):
    """A multiple of a joint angle as a key component: int when integral, else Fraction or float."""
    x = number(c)
    if isinstance(x, Fraction) and x.denominator == 1:
        return int(x)
    if isinstance(x, float) and x.is_integer():
        return int(x)
    return x


def add_into(acc: TrigPoly, p: TrigPoly, factor=None) -> TrigPoly:
    """acc += factor * p, in place (factor None: 1)."""
    for key, c in p.items():
        if factor is not None:
            c = c * factor
        old = acc.get(key)
        new = _canonical(c if old is None else old + c)
        if _is_zero(new):
            acc.pop(key, None)
        else:
            acc[key] = new
    return acc


def scale(p: TrigPoly, factor) -> TrigPoly:
    """factor * p (factor a coefficient)."""
    if _is_zero(factor):
        return {}
    return {key: c * factor for key, c in p.items()}


def mono_mul(a: Monomial, b: Monomial) -> Monomial:
    """The product of two monomials (sorted tuples of (variable, exponent))."""
    if not a:
        return b
    if not b:
        return a
    d = dict(a)
    for g, e in b:
        d[g] = d.get(g, 0) + e
    return tuple(sorted(d.items()))


def _put(acc: TrigPoly, mono: Monomial, k: tuple, kind: int, c) -> None:
    """acc += c mono cos(k . q) (kind 0) or c mono sin(k . q) (kind 1), stored with k's first
    non-zero component positive (sin(-a) = -sin a); sin(0) adds nothing. Written out in one
    function: multiply calls it millions of times on the Panda."""
    for x in k:
        if x != 0:
            if x < 0:
                k = tuple(map(neg, k))
                if kind:
                    c = -c
            break
    else:
        if kind:  # sin(0)
            return
    key = (mono, k, kind)
    old = acc.get(key)
    if old is not None:
        c = old + c
    if type(c) is not Fraction and type(c) is not float:
        c = _canonical(c)
    if c == 0:
        acc.pop(key, None)
    else:
        acc[key] = c


def multiply(p: TrigPoly, r: TrigPoly) -> TrigPoly:
    """p * r, products of sines and cosines turned into sums of angles."""
    if len(p) > len(r):
        p, r = r, p
    out: TrigPoly = {}
    for (ma, ka, ta), ca in p.items():
        a_const = not any(ka)
        for (mb, kb, tb), cb in r.items():
            mono = mono_mul(ma, mb)
            c = ca * cb
            if a_const:  # cos(0) = 1
                _put(out, mono, kb, tb, c)
                continue
            if not any(kb):
                _put(out, mono, ka, ta, c)
                continue
            h = c / 2
            plus = tuple(map(add, ka, kb))  # keys of one ring: of one length
            minus = tuple(map(sub, ka, kb))
            if ta == 0 and tb == 0:  # cos a cos b = (cos(a - b) + cos(a + b)) / 2
                _put(out, mono, minus, 0, h)
                _put(out, mono, plus, 0, h)
            elif ta == 1 and tb == 1:  # sin a sin b = (cos(a - b) - cos(a + b)) / 2
                _put(out, mono, minus, 0, h)
                _put(out, mono, plus, 0, -h)
            elif ta == 1:  # sin a cos b = (sin(a + b) + sin(a - b)) / 2
                _put(out, mono, plus, 1, h)
                _put(out, mono, minus, 1, h)
            else:  # cos a sin b = (sin(a + b) - sin(a - b)) / 2
                _put(out, mono, plus, 1, h)
                _put(out, mono, minus, 1, -h)
    return out


def power(p: TrigPoly, e: int) -> TrigPoly:
    """p**e for an integer e >= 1 (square and multiply)."""
    assert e >= 1, e
    result: TrigPoly | None = None
    base = p
    while e:
        if e & 1:
            result = base if result is None else multiply(result, base)
        e >>= 1
        if e:
            base = multiply(base, base)
    assert result is not None
    return result


def largest(polys) -> float:
    """The largest |coefficient| of some polynomials (0.0 for none)."""
    return max((abs(float(c)) for p in polys for c in p.values()), default=0.0)


def chop(p: TrigPoly, big: float | None = None) -> TrigPoly:
    """p without float rounding residues: float coefficients below CHOP times `big` (default:
    p's largest coefficient; pass the largest of the whole matrix, since an entry that is
    exactly zero keeps only residues)."""
    if not any(isinstance(c, float) for c in p.values()):
        return p
    if big is None:
        big = largest([p])
    return {k: c for k, c in p.items() if not isinstance(c, float) or abs(c) >= CHOP * big}


def is_float_data(p: TrigPoly) -> bool:
    return any(isinstance(c, float) for c in p.values())


def fast_mul(factors: Sequence[sp.Expr]) -> sp.Expr:
    """The product of factors with distinct non-numeric bases, built without SymPy's flatten
    (the same canonical Mul: number first, the rest in SymPy's sort order)."""
    coeff = sp.S.One
    rest = []
    for f in factors:
        if f.is_Number:
            coeff = coeff * f
        elif f.is_Mul:
            c, fs = f.as_coeff_mul()
            coeff = coeff * c
            rest.extend(fs)
        elif f is not sp.S.One:
            rest.append(f)
    if coeff == 0:
        return sp.S.Zero
    if not rest:
        return coeff
    if coeff is not sp.S.One and len(rest) == 1 and rest[0].is_Add:
        return sp.Mul(coeff, rest[0])  # SymPy's own rule for a number times a sum
    _mulsort(rest)
    if coeff is not sp.S.One:
        rest.insert(0, coeff)
    return rest[0] if len(rest) == 1 else sp.Mul._from_args(rest, is_commutative=True)


def fast_add(terms: Sequence[sp.Expr]) -> sp.Expr:
    """The sum of terms that differ in their non-numeric part (no two to collect), built
    without SymPy's flatten (the same canonical Add)."""
    terms = [t for t in terms if t is not sp.S.Zero]
    numbers = [t for t in terms if t.is_Number]
    rest = [t for t in terms if not t.is_Number]
    if not rest:
        return sp.Add(*numbers)
    _addsort(rest)
    coeff = sp.Add(*numbers)
    if coeff is not sp.S.Zero:
        rest.insert(0, coeff)
    return rest[0] if len(rest) == 1 else sp.Add._from_args(rest, is_commutative=True)


class TrigRing:
    """The generators of the trigonometric polynomials of one derivation.

    Generators 0 .. n-1 are the coordinates q (as polynomial variables, for prismatic
    joints); the others are q-free atoms (parameters, cos(alpha) of a symbolic twist, ...)
    numbered as they are met. Keys carry k with n components.
    """

    def __init__(self, q: Sequence[sp.Symbol]) -> None:
        self.q = tuple(q)
        self.n = len(self.q)
        self.gens: list[sp.Expr] = list(self.q)
        self._gen_index: dict[sp.Expr, int] = {s: i for i, s in enumerate(self.q)}
        self.zero_k = (0,) * (self.n + 1)  # k: one multiple per joint, then radians
        self._qset = set(self.q)
        #: SymPy expression (intermediates of programs included) -> its TrigPoly
        self.memo: dict[sp.Expr, TrigPoly] = {}
        self._named: set[sp.Symbol] = set()
        self._trig_cache: dict[tuple, sp.Expr] = {}
        self._coefficients: dict[tuple, sp.Expr] = {}  # group_coefficient's, by its items

    # -- construction -----------------------------------------------------------------
    def constant(self, c) -> TrigPoly:
        return {} if _is_zero(c) else {(_ONE_MONO, self.zero_k, 0): c}

    def generator(self, atom: sp.Expr) -> TrigPoly:
        g = self._gen_index.get(atom)
        if g is None:
            g = self._gen_index[atom] = len(self.gens)
            self.gens.append(atom)
        return {(((g, 1),), self.zero_k, 0): Fraction(1)}

    def _trig(self, func, arg: sp.Expr) -> TrigPoly:
        """cos or sin of arg = k . q + r + phase: r a rational number (kept in the key as a
        multiple of one radian, so cos(q3 + 1/5) stays exact and canonical), phase the rest
        (floats, multiples of pi, parameters), split off by the angle-sum formulas."""
        n = self.n
        k: list = [0] * (n + 1)
        phase = []
        for t in sp.Add.make_args(arg):
            c, rest = t.as_coeff_Mul()
            idx = self._gen_index.get(rest)
            if idx is not None and idx < n:
                k[idx] += _frequency(c)
            elif t.is_Rational:
                k[n] += _frequency(t)
            elif t.free_symbols & self._qset:
                raise SymdynError(
                    f"closed form: {func(arg)} is not a sine or cosine of a sum of joint angles"
                )
            else:
                phase.append(t)
        kt = tuple(k)
        ph = sp.Add(*phase)
        if not any(kt):  # free of q: a number, or a function of the parameters
            value = func(ph)
            return self.constant(number(value)) if value.is_number else self.generator(value)
        base: TrigPoly = {}
        _put(base, _ONE_MONO, kt, 0 if func is sp.cos else 1, Fraction(1))
        if ph == 0:
            return base
        other: TrigPoly = {}
        _put(other, _ONE_MONO, kt, 1 if func is sp.cos else 0, Fraction(1))
        # cos(x + f) = cos f cos x - sin f sin x;  sin(x + f) = cos f sin x + sin f cos x
        cf, sf = self.convert(sp.cos(ph)), self.convert(sp.sin(ph))
        out = multiply(cf, base)
        add_into(out, multiply(sf, other), Fraction(-1) if func is sp.cos else None)
        return out

    def name(self, symbol: sp.Symbol, e: sp.Expr) -> TrigPoly:
        """Convert the assignment symbol = e of a program (e over earlier named symbols)."""
        p = self.convert(e)
        self._named.add(symbol)
        self.memo[symbol] = p
        return p

    def convert(self, e: sp.Expr) -> TrigPoly:
        """The TrigPoly of a SymPy expression over q, q-free atoms and `name`d intermediates."""
        memo = self.memo
        hit = memo.get(e)
        if hit is not None:
            return hit
        if e.is_Number or e.is_NumberSymbol:
            out = self.constant(number(e))
        elif e.is_Symbol:
            out = self.generator(e)
        elif isinstance(e, (sp.cos, sp.sin)):
            out = self._trig(type(e), e.args[0])
        elif e.is_Add or e.is_Mul or (e.is_Pow and e.exp.is_Integer and e.exp >= 0):
            out = self._compose(e)
        elif not (e.free_symbols & self._qset) and not (e.free_symbols & self._named):
            # a number (sqrt(2)) or a parameter function (sqrt(m), 1/m)
            out = self.constant(number(e)) if e.is_number else self.generator(e)
        else:
            raise SymdynError(
                f"closed form: {e} is not a polynomial in sines and cosines of the joint angles"
            )
        memo[e] = out
        return out

    def _compose(self, e: sp.Expr) -> TrigPoly:
        if e.is_Add:
            out: TrigPoly = {}
            for a in e.args:
                add_into(out, self.convert(a))
            return out
        if e.is_Mul:
            c, factors = e.as_coeff_mul()
            out = self.constant(number(c))
            for f in factors:
                out = multiply(out, self.convert(f))
                if not out:
                    break
            return out
        if e.is_Pow and e.exp.is_Integer and e.exp >= 0:
            if e.exp == 0:
                return self.constant(Fraction(1))
            return power(self.convert(e.base), int(e.exp))
        raise AssertionError(e)

    # -- calculus ---------------------------------------------------------------------
    def diff(self, p: TrigPoly, j: int) -> TrigPoly:
        """dp/dq_j: d cos(k.q)/dq_j = -k_j sin(k.q), d sin(k.q)/dq_j = k_j cos(k.q), and
        the power rule for q_j as a polynomial variable."""
        out: TrigPoly = {}
        for (mono, k, kind), c in p.items():
            kj = k[j]
            if kj != 0:
                _put(out, mono, k, 1 - kind, c * kj if kind else -(c * kj))
            for idx, (g, e) in enumerate(mono):
                if g == j:
                    rest = mono[:idx] + (((g, e - 1),) if e > 1 else ()) + mono[idx + 1 :]
                    _put(out, rest, k, kind, c * e)
        return out

    def named(self, p: TrigPoly) -> dict[tuple, object]:
        """p keyed by generator names instead of indices: comparable across rings (routes)."""
        return {
            (tuple(sorted((str(self.gens[g]), e) for g, e in mono)), k, kind): c
            for (mono, k, kind), c in p.items()
        }

    def numeric(self, p: TrigPoly, values: dict[sp.Expr, float] | None = None):
        """A NumPy function q -> p(q) for states q of shape (..., n), the parameter generators
        set to `values` (name -> number); vectorised over the terms."""
        import numpy as np

        values = values or {}
        if not p:
            return lambda q: np.zeros(np.shape(q)[:-1])
        items = list(p.items())
        K = np.array([[float(x) for x in k] for (_, k, _), _ in items])  # terms x (n + 1)
        kinds = np.array([kind for (_, _, kind), _ in items], dtype=bool)
        coef = np.empty(len(items))
        qpow = np.zeros((len(items), self.n))
        for t, ((mono, _, _), c) in enumerate(items):
            value = float(c)
            for g, e in mono:
                if g < self.n:
                    qpow[t, g] = e
                else:
                    value *= float(sp.sympify(self.gens[g]).xreplace(values)) ** e
            coef[t] = value

        def f(q):
            q = np.asarray(q, dtype=float)
            phi = q @ K[:, : self.n].T + K[:, self.n]
            trig = np.where(kinds, np.sin(phi), np.cos(phi))
            mono = np.prod(q[..., None, :] ** qpow, axis=-1)
            return (coef * mono * trig).sum(axis=-1)

        return f

    # -- back to SymPy ----------------------------------------------------------------
    def trig_expr(self, k: tuple, kind: int) -> sp.Expr:
        """cos(k . q) or sin(k . q), k normalised already (so SymPy need not evaluate it)."""
        hit = self._trig_cache.get((k, kind))
        if hit is None:
            if not any(k):
                hit = sp.S.One
            elif not any(k[: self.n]):  # cos(1/5): a number
                hit = (sp.cos if kind == 0 else sp.sin)(sp.sympify(k[self.n]))
            else:
                arg = fast_add(
                    [
                        fast_mul([sp.sympify(x), qi])
                        for x, qi in zip(k, (*self.q, sp.S.One), strict=True)
                        if x != 0
                    ]
                )
                hit = sp.Basic.__new__(sp.cos if kind == 0 else sp.sin, arg)
            self._trig_cache[(k, kind)] = hit
        return hit

    def mono_expr(self, mono: Monomial) -> sp.Expr:
        return fast_mul([self.gens[g] ** e for g, e in mono])

    def groups(self, p: TrigPoly) -> list[tuple[tuple, list]]:
        """p's terms grouped by their angle part (monomial in the coordinates, k, kind): a list
        of (group key, [(number, parameter monomial), ...]) in printed order (`print_order`)."""
        out: dict[tuple, list] = {}
        for (mono, k, kind), c in p.items():
            qpart = tuple((g, e) for g, e in mono if g < self.n)
            ppart = tuple((g, e) for g, e in mono if g >= self.n)
            out.setdefault((qpart, k, kind), []).append((c, ppart))
        return sorted(out.items(), key=lambda item: print_order(item[0]))

    def group_coefficient(self, items: list) -> sp.Expr:
        """The coefficient of one angle group as a SymPy expression: the sum of number times
        parameter monomial, common factors pulled out of a sum of several (memoised: printing
        and lumping ask for the same ones)."""
        key = tuple(items)
        hit = self._coefficients.get(key)
        if hit is None:
            hit = fast_add([fast_mul([to_sympy_number(c), self.mono_expr(pp)]) for c, pp in items])
            if hit.is_Add and len(items) > 1:
                hit = sp.factor_terms(hit)
            self._coefficients[key] = hit
        return hit

    def to_sympy(self, p: TrigPoly, coefficient: Callable | None = None) -> sp.Expr:
        """The expression: terms grouped by their angle part (trig and coordinates), each with
        its polynomial in the parameters as a factor (`group_coefficient`).

        coefficient: maps a group's coefficient to the SymPy expression to use instead (lumped
        constants); called in printed order.
        """
        terms = []
        for (qpart, k, kind), items in self.groups(p):
            coef = self.group_coefficient(items)
            if coefficient is not None:
                coef = coefficient(coef)
            terms.append(fast_mul([coef, self.mono_expr(qpart), self.trig_expr(k, kind)]))
        return fast_add(terms)


def print_order(key: tuple) -> tuple:
    """The order of angle groups: the constant first, then angles by the joints they involve and
    their multiples, cos before sin."""
    qpart, k, kind = key
    joints = tuple(i for i, x in enumerate(k[:-1]) if x != 0)
    return (len(joints), joints, tuple(float(x) for x in k), kind, qpart)
