"""The configuration-space form of the equations of motion (Craig; Armstrong, Khatib, Burdick):

    tau = M(q) qdd + B(q) [qd qd] + Csq(q) [qd^2] + G(q) + F(qd)

with [qd qd] = (qd1 qd2, qd1 qd3, ..., qd(n-1) qdn) and [qd^2] = (qd1^2, ..., qdn^2). B and
Csq hold the Christoffel symbols of the first kind of M, in joint space,

    Gamma^k_ij = 1/2 (dM_kj/dq_i + dM_ki/dq_j - dM_ij/dq_k)    (= Gamma^k_ji),
    B[k, (i, j)] = 2 Gamma^k_ij  (i < j),    Csq[k, i] = Gamma^k_ii,

so that V_k = sum_ij Gamma^k_ij qd_i qd_j = (B [qd qd] + Csq [qd^2])_k and the Coriolis
matrix is C_kj = sum_i Gamma^k_ij qd_i (V = C qd, dM/dt - 2 C skew-symmetric).

M and G are read off the program of named intermediates either route wrote
(symdyn.symbolic.program), each intermediate turned once into a canonical trigonometric
polynomial (symdyn.symbolic.trig_polynomial); the Christoffel symbols are derivatives of
M's polynomials. Nothing expands the recursion, and since the representation is unique,
the Newton-Euler and Lagrange routes give the same closed forms.

References: Armstrong, Khatib, Burdick, "The explicit dynamic model and inertial
parameters of the PUMA 560 arm", Proc. IEEE ICRA 1986; Craig, Introduction to Robotics
(3rd ed., 2005), sec. 6.8; Spong, Hutchinson, Vidyasagar, Robot Modeling and Control
(2006), sec. 7.3 (Christoffel symbols); R. Grupen, "Dynamics" (2015), slide 16.
"""

from __future__ import annotations

from collections.abc import Callable, Iterator, Sequence
from dataclasses import dataclass, field
from fractions import Fraction
from functools import lru_cache

import sympy as sp

from ..symbolic.program import Program
from ..symbolic.trig_polynomial import TrigPoly, TrigRing, add_into, chop, largest, scale
from ..symbolic.trig_text import TrigText

__all__ = [
    "ConfigurationSpace",
    "configuration_space",
    "pair_columns",
    "pair_column",
    "christoffel_name",
]

_HALF = Fraction(1, 2)


#: Above this many terms (M, G and the Christoffel symbols together) the canonical form is not
#: a readable closed form: PUMA 560 1,198 terms, Stanford 795, the PUMA with its 60 inertial
#: parameters symbolic 34,019; the Panda's 228,647 would take minutes to print and megabytes of
#: text, so Dynamics.closed_form expands the recursion for it and `derive` prints --form compact.
READABLE_TERMS = 100_000


@lru_cache(maxsize=4)
def pair_columns(n: int) -> tuple[tuple[int, int], ...]:
    """The columns of B: (i, j), i < j, in the order (0, 1), (0, 2), ..., (n-2, n-1) (0-based);
    built once per n (a B entry's lookup must not cost n^2)."""
    return tuple((i, j) for i in range(n) for j in range(i + 1, n))


def pair_column(n: int, i: int, j: int) -> int:
    """The column of B holding (i, j), i < j (0-based): the inverse of `pair_columns(n)`."""
    assert 0 <= i < j < n, (n, i, j)
    return i * n - i * (i + 1) // 2 + j - i - 1


def christoffel_name(k: int, i: int, j: int) -> str:
    """Gamma^k_ij with 1-based indices, as printed: Gamma[2;1,3]."""
    return f"Gamma[{k + 1};{i + 1},{j + 1}]"


@dataclass
class ConfigurationSpace:
    """M, G and the Christoffel symbols of one derivation as canonical trigonometric
    polynomials (joint space), with their SymPy closed forms on demand."""

    ring: TrigRing
    M: list[list[TrigPoly]]  # n x n, symmetric
    G: list[TrigPoly]
    #: Gamma^k_ij for i <= j (0-based (k, i, j)), zero ones left out
    gamma: dict[tuple[int, int, int], TrigPoly]
    #: maps a SymPy coefficient (a number times parameters) to its printed form
    coefficient: Callable | None = None
    _sympy: dict = field(default_factory=dict, repr=False)
    _printers: dict = field(default_factory=dict, repr=False)

    @property
    def terms(self) -> int:
        """The size of the form: terms of M's upper triangle, of G and of the Christoffel symbols."""
        n = self.n
        upper = sum(len(self.M[i][j]) for i in range(n) for j in range(i, n))
        return upper + sum(len(p) for p in self.G) + sum(len(p) for p in self.gamma.values())

    @property
    def readable(self) -> bool:
        """Small enough to print and to serve as closed form (READABLE_TERMS)."""
        return self.terms <= READABLE_TERMS

    @property
    def n(self) -> int:
        return self.ring.n

    def poly(self, name: str, k: int, c: int = 0) -> TrigPoly:
        """The polynomial of entry (k, c) of M, B or Csq, or entry k of G."""
        n = self.n
        if name == "M":
            return self.M[k][c]
        if name == "G":
            return self.G[k]
        if name == "Csq":
            return self.gamma.get((k, c, c), {})
        if name == "B":
            i, j = pair_columns(n)[c]
            g = self.gamma.get((k, i, j))
            return scale(g, Fraction(2)) if g else {}
        raise KeyError(name)

    def nonzero(self, name: str) -> Iterator[tuple[int, int]]:
        """(k, c) of the nonzero entries of B or Csq in row-major order, read off the nonzero
        Christoffel symbols: work in proportion to them, not to the n^3 / 2 entries of B."""
        n = self.n
        for k, i, j in sorted(self.gamma):
            if name == "B" and i < j:
                yield k, pair_column(n, i, j)
            elif name == "Csq" and i == j:
                yield k, i

    def shape(self, name: str) -> tuple[int, int]:
        n = self.n
        return {"M": (n, n), "G": (n, 1), "Csq": (n, n), "B": (n, n * (n - 1) // 2)}[name]

    def expr(self, name: str, k: int, c: int = 0) -> sp.Expr:
        key = (name, k, c)
        hit = self._sympy.get(key)
        if hit is None:
            hit = self._sympy[key] = self.ring.to_sympy(self.poly(name, k, c), self.coefficient)
        return hit

    def text(self, name: str, k: int, c: int = 0, coefficient: Callable | None = None) -> str:
        """Entry (k, c) of M, B or Csq, or entry k of G, as SymPy-syntax text written straight
        from its polynomial (symdyn.symbolic.trig_text: fast, canonical order); coefficient:
        maps each group's coefficient to what to print (lumped constants), after the form's own."""
        printer = self._printers.get(coefficient)
        if printer is None:
            own = self.coefficient
            both = coefficient
            if coefficient is not None and own is not None:
                both = lambda x: coefficient(own(x))  # noqa: E731
            printer = self._printers[coefficient] = TrigText(self.ring, both or own)
        return printer.text(self.poly(name, k, c))

    def matrix(self, name: str) -> sp.ImmutableMatrix:
        """M, B, Csq (matrices) or G (a column) as SymPy closed forms."""
        rows, cols = self.shape(name)
        return sp.ImmutableMatrix(
            rows, cols, [self.expr(name, r, c) for r in range(rows) for c in range(cols)]
        )

    def christoffel(self) -> dict[tuple[int, int, int], sp.Expr]:
        """The nonzero Gamma^k_ij, i <= j, keyed by 0-based (k, i, j)."""
        return {key: self.ring.to_sympy(p, self.coefficient) for key, p in self.gamma.items()}

    def velocity_terms(self, qd: Sequence[sp.Expr]) -> sp.ImmutableMatrix:
        """V = B [qd qd] + Csq [qd^2], each entry a sum of (closed form) * qd_i qd_j."""
        n = self.n
        pairs = pair_columns(n)
        out = []
        for k in range(n):
            terms = [self.expr("Csq", k, i) * qd[i] ** 2 for i in range(n)]
            terms += [self.expr("B", k, c) * qd[i] * qd[j] for c, (i, j) in enumerate(pairs)]
            out.append(sp.Add(*terms))
        return sp.ImmutableMatrix(n, 1, out)

    def coriolis(self, qd: Sequence[sp.Expr]) -> sp.ImmutableMatrix:
        """C_kj = sum_i Gamma^k_ij qd_i (the Christoffel-symbol matrix, V = C qd)."""
        n = self.n
        rows = []
        for k in range(n):
            for j in range(n):
                terms = []
                for i in range(n):
                    p = self.gamma.get((k, min(i, j), max(i, j)))
                    if p:
                        terms.append(self.ring.to_sympy(p, self.coefficient) * qd[i])
                rows.append(sp.Add(*terms))
        return sp.ImmutableMatrix(n, n, rows)

    def closed(self, name: str, qd, qdd, F) -> list[sp.Expr]:
        """Closed form of M, C, V, G, tau or bias = V + G + F, entries in row-major order
        (F: the friction vector, already closed)."""
        n = self.n
        if name in ("M", "G"):
            return list(self.matrix(name))
        if name == "C":
            return list(self.coriolis(qd))
        V, G = self.velocity_terms(qd), self.matrix("G")
        bias = [V[k] + G[k] + F[k] for k in range(n)]
        if name == "V":
            return list(V)
        if name == "bias":
            return bias
        assert name == "tau", name
        return [sp.Add(*[self.expr("M", k, j) * qdd[j] for j in range(n)], bias[k]) for k in range(n)]


def joints_of(p: TrigPoly, n: int) -> set[int]:
    """The joints j < n whose angle or coordinate q_j a polynomial depends on (dp/dq_j may be
    nonzero only for these)."""
    out: set[int] = set()
    for mono, k, _kind in p:
        out.update(j for j in range(n) if k[j])
        out.update(g for g, _e in mono if g < n)
    return out


def _christoffel_keys(M: list[list[TrigPoly]], n: int) -> list[tuple[int, int, int]]:
    """The (k, i, j), i <= j, whose Gamma^k_ij has a nonzero term, in (k, i, j) order: each
    nonzero dM_ab/dq_x (a <= b) enters Gamma^a_xb, Gamma^b_xa and Gamma^x_ab, indices sorted.
    On a tree that is the entries within the ancestry of each other, not all n^3 / 2."""
    keys = set()
    for a in range(n):
        for b in range(a, n):
            if not M[a][b]:
                continue
            for x in joints_of(M[a][b], n):
                keys.add((a, min(x, b), max(x, b)))
                keys.add((b, min(x, a), max(x, a)))
                keys.add((x, a, b))
    return sorted(keys)


def _christoffel(ring: TrigRing, M: list[list[TrigPoly]], big: float) -> dict[tuple[int, int, int], TrigPoly]:
    """Gamma^k_ij = 1/2 (dM_kj/dq_i + dM_ki/dq_j - dM_ij/dq_k), i <= j, nonzero ones (float
    residues below CHOP * big dropped); only the (k, i, j) some nonzero derivative of M enters
    (_christoffel_keys) are summed, each as the full sum in the same order of terms."""
    dM: dict[tuple[int, int, int], TrigPoly] = {}

    def d(a: int, b: int, x: int) -> TrigPoly:
        key = (min(a, b), max(a, b), x)
        hit = dM.get(key)
        if hit is None:
            hit = dM[key] = ring.diff(M[key[0]][key[1]], x)
        return hit

    gamma = {}
    for k, i, j in _christoffel_keys(M, ring.n):
        acc: TrigPoly = {}
        add_into(acc, d(k, j, i), _HALF)
        add_into(acc, d(k, i, j), _HALF)
        add_into(acc, d(i, j, k), -_HALF)
        acc = chop(acc, big)
        if acc:
            gamma[(k, i, j)] = acc
    return gamma


class FormTooLargeError(Exception):
    """The configuration-space form grows past the budget it was built with (`terms`: how many
    terms were reached when the building stopped)."""

    def __init__(self, terms: int) -> None:
        super().__init__(f"more than {terms:,} terms")
        self.terms = terms


def configuration_space(
    program: Program, M: sp.Matrix, G: Sequence[sp.Expr], q: Sequence[sp.Symbol], budget: int | None = None
):
    """The configuration-space form from M and G over a program's named intermediates.

    Args:
        program: the derivation's program (either route).
        M: n x n mass matrix over the program's intermediates (joint space).
        G: n gravity terms over the program's intermediates.
        q: the n joint position symbols.
        budget: None, or the most terms the form may have: building stops (FormTooLargeError) as soon
            as one intermediate, or M's upper triangle and G together, have more. A long chain's
            form grows exponentially with its joints (a 12-joint arm: 6.3 million terms, 77 s to
            build), so the readable test is made on the way, not at the end.

    Returns:
        The `ConfigurationSpace`: M, G and the Christoffel symbols as canonical trigonometric
        polynomials, float rounding residues dropped.
    """
    ring = TrigRing(q)
    n = len(q)
    outputs = [*list(M), *list(G)]
    for sym, expr in program.needed(outputs):
        size = len(ring.name(sym, expr))
        if budget is not None and size > budget:
            raise FormTooLargeError(size)
    Mp = [[{} for _ in range(n)] for _ in range(n)]
    for i in range(n):
        for j in range(i, n):
            Mp[i][j] = Mp[j][i] = ring.convert(M[i, j])
    big = largest(Mp[i][j] for i in range(n) for j in range(i, n))
    Mp = [[chop(p, big) for p in row] for row in Mp]
    Gp = [ring.convert(g) for g in G]
    big_g = largest(Gp)
    Gp = [chop(p, big_g) for p in Gp]
    size = sum(len(Mp[i][j]) for i in range(n) for j in range(i, n)) + sum(len(p) for p in Gp)
    if budget is not None and size > budget:
        raise FormTooLargeError(size)
    return ConfigurationSpace(ring, Mp, Gp, _christoffel(ring, Mp, big))
