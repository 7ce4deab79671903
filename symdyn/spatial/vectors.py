"""Zero-aware 3-vector and 3x3-matrix arithmetic on tuples of SymPy expressions.

The recursions multiply rotation matrices that are mostly 0 and +-1 (DH twists
of 0 and +-pi/2) by vectors that are often sparse (planar motion, axes along
z). SymPy's Matrix builds every product and sum before folding zeros; these
helpers skip zero factors and unit coefficients up front, which keeps both the
derivation time and the size of the resulting expressions down.
"""

from __future__ import annotations

from collections.abc import Sequence

import sympy as sp

__all__ = [
    "Vec",
    "Mat",
    "ZERO3",
    "ZERO33",
    "vec",
    "mat",
    "product",
    "sum_terms",
    "add",
    "sub",
    "scale",
    "cross",
    "dot",
    "mul",
    "mul_t",
    "neg",
]

Vec = tuple[sp.Expr, sp.Expr, sp.Expr]
Mat = tuple[Vec, Vec, Vec]
ZERO = sp.S.Zero
#: the zero 3-vector and the zero 3x3 matrix (SymPy's singleton zero in every entry)
ZERO3: Vec = (ZERO, ZERO, ZERO)
ZERO33: Mat = (ZERO3, ZERO3, ZERO3)


def vec(v: Sequence) -> Vec:
    """A 3-vector of SymPy expressions from any sequence of three numbers or expressions."""
    return tuple(sp.sympify(x) for x in v)  # type: ignore[return-value]


def mat(m) -> Mat:
    """Rows of a 3x3 matrix (SymPy Matrix or nested sequence)."""
    return tuple(
        tuple(sp.sympify(m[i, j] if hasattr(m, "shape") else m[i][j]) for j in range(3)) for i in range(3)
    )  # type: ignore[return-value]


_ONE, _MINUS_ONE = sp.S.One, sp.S.NegativeOne


def _s(x) -> sp.Expr:
    return x if isinstance(x, sp.Basic) else sp.sympify(x)


def product(a: sp.Expr, b: sp.Expr) -> sp.Expr:
    """The scalar product a b, with 0 and +-1 factors folded before SymPy multiplies."""
    # SymPy's 0, 1 and -1 are singletons: identity tests avoid SymPy's (slow) comparisons
    a, b = _s(a), _s(b)
    if a is ZERO or b is ZERO:
        return ZERO
    if a is _ONE:
        return b
    if b is _ONE:
        return a
    if a is _MINUS_ONE:
        return -b
    if b is _MINUS_ONE:
        return -a
    return a * b


def sum_terms(terms) -> sp.Expr:
    """The sum of scalar terms, zeros dropped before SymPy adds."""
    terms = [t for t in map(_s, terms) if t is not ZERO]
    if not terms:
        return ZERO
    if len(terms) == 1:
        return terms[0]
    return sp.Add(*terms)


def add(*vs: Vec) -> Vec:
    """The sum of 3-vectors."""
    return tuple(sum_terms(v[i] for v in vs) for i in range(3))  # type: ignore[return-value]


def sub(a: Vec, b: Vec) -> Vec:
    """a - b."""
    return tuple(sum_terms((a[i], product(_MINUS_ONE, b[i]))) for i in range(3))  # type: ignore[return-value]


def neg(a: Vec) -> Vec:
    """-a."""
    return tuple(product(_MINUS_ONE, x) for x in a)  # type: ignore[return-value]


def scale(k: sp.Expr, a: Vec) -> Vec:
    """k a for a scalar k."""
    return tuple(product(k, x) for x in a)  # type: ignore[return-value]


def dot(a: Sequence[sp.Expr], b: Sequence[sp.Expr]) -> sp.Expr:
    """a^T b (sequences of equal length)."""
    return sum_terms(product(x, y) for x, y in zip(a, b, strict=True))


def cross(a: Vec, b: Vec) -> Vec:
    """a x b."""
    return (
        sum_terms((product(a[1], b[2]), -product(a[2], b[1]))),
        sum_terms((product(a[2], b[0]), -product(a[0], b[2]))),
        sum_terms((product(a[0], b[1]), -product(a[1], b[0]))),
    )


def mul(R: Mat, v: Vec) -> Vec:
    """R v."""
    return tuple(dot(R[i], v) for i in range(3))  # type: ignore[return-value]


def mul_t(R: Mat, v: Vec) -> Vec:
    """R^T v."""
    return tuple(dot((R[0][j], R[1][j], R[2][j]), v) for j in range(3))  # type: ignore[return-value]
