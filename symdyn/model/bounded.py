"""Bounds on the numbers and powers of robot-file expressions, checked before SymPy evaluates them.

SymPy merges powers as it builds them ((x**64)**64 is x**4096, x**40*x**40 is x**80) and
evaluates numeric ones at once (3**4096 is computed when it is built, 2**(9**9) would take
hours), so a limit on the exponents as written is not enough: a tower of small exponents, or an
exponent that a parameter's value fills in, passes it. These checks hold at every stage, when an
expression is parsed and again when parameter values are substituted (`bounded_subs` rebuilds
the expression node by node and checks each power before SymPy evaluates it):

* every power whose exponent is a number has an exponent of at most MAX_EXPONENT = 64 in
  absolute value, after SymPy's merging;
* a numeric power of rational numbers is built only if the result has at most MAX_POWER_BITS
  = 4096 bits (MAX_ROOT_BITS = 256 for a root: exact roots of huge integers make SymPy factorise);
* every rational number has a numerator and a denominator of at most MAX_NUMBER_BITS = 8192 bits;
* every number is at most MAX_MAGNITUDE = 1e150 in absolute value (a robot has no quantity near
  it, and products of two such numbers stay finite as doubles), and floats are finite;
* the expression, and every part of it, expands to at most MAX_EXPANDED_TERMS = 100 terms, or
  to as many as it has nodes when it is written out longer (`expanded_terms`, an upper bound
  computed from the factors' term counts and the exponents before anything is expanded: each
  exponent is capped, but (a+b+c+d)**64*(e+f+g+h)**64 would expand to 2.3e9 terms); answers of
  `symdyn check` are allowed MAX_ANSWER_TERMS = 1000.

A violation is one SymdynError naming the file, the link and the field (through `fail`).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping

import sympy as sp

from ..errors import SymdynError
from .parameter_names import MAX_MAGNITUDE

__all__ = [
    "MAX_EXPONENT",
    "MAX_POWER_BITS",
    "MAX_ROOT_BITS",
    "MAX_NUMBER_BITS",
    "MAX_MAGNITUDE",
    "MAX_EXPANDED_TERMS",
    "MAX_ANSWER_TERMS",
    "check_power",
    "check_bounded",
    "check_expansion",
    "expanded_terms",
    "bounded_subs",
]

MAX_EXPONENT = 64
MAX_POWER_BITS = 4096
MAX_ROOT_BITS = 256
MAX_NUMBER_BITS = 8192
_MAX_MAGNITUDE_INT = 10**150
#: Most terms a robot-file expression (or any part of it) may expand to: a derivation multiplies
#: the fields of a link together, so a field of 100 terms already gives entries of 10,000.
MAX_EXPANDED_TERMS = 100
#: Most terms an answer of `symdyn check` may expand to (the expanded difference is compiled with
#: sympy.lambdify, whose sums of 3000 terms break Python's compiler).
MAX_ANSWER_TERMS = 1000

Fail = Callable[[str], SymdynError]


def _short(text: str) -> str:
    return text if len(text) <= 60 else text[:57] + "..."


def _bits(expr: sp.Expr) -> int:
    """An upper bound on the bits of the rational factor of `expr` (its Rational atoms' bits summed)."""
    return sum(max(int(a.p).bit_length(), int(a.q).bit_length()) for a in expr.atoms(sp.Rational))


def check_power(base: sp.Expr, exponent: sp.Expr, fail: Fail, where: str) -> None:
    """Refuse base**exponent before SymPy builds it if the exponent or the number it makes is too large.

    `where` is the text shown in the message (the expression as written, or the power).
    """
    if not exponent.is_Number:
        return
    if abs(exponent) > MAX_EXPONENT:
        raise fail(
            f"exponent {_short(str(exponent))} in '{where}' is larger than {MAX_EXPONENT} in absolute value"
        )
    if base.is_zero and exponent.is_negative:
        raise fail(f"division by zero in '{where}'")
    if exponent.is_Rational and base.has(sp.Rational):
        limit = MAX_POWER_BITS if exponent.is_Integer else MAX_ROOT_BITS
        if _bits(base) * max(abs(exponent), 1) > limit:
            raise fail(f"number '{where}' is too large")


def _problem(node: sp.Basic) -> str | None:
    """Why one node of an expression is out of bounds, or None."""
    if node.is_Pow and node.exp.is_Number and abs(node.exp) > MAX_EXPONENT:
        return (
            f"exponent {_short(str(node.exp))} of '{_short(str(node))}' is larger than "
            f"{MAX_EXPONENT} in absolute value (once powers of powers are multiplied out)"
        )
    if node.is_Rational:
        p, q = abs(int(node.p)), int(node.q)
        if max(p.bit_length(), q.bit_length()) > MAX_NUMBER_BITS or p > _MAX_MAGNITUDE_INT * q:
            return f"number {_short(str(node))} is too large (more than {MAX_MAGNITUDE:g} in absolute value)"
    elif node.is_Float:
        x = float(node)
        if not math.isfinite(x):
            return f"number {_short(str(node))} is not finite as a double"
        if abs(x) > MAX_MAGNITUDE:
            return f"number {x!r} is too large (more than {MAX_MAGNITUDE:g} in absolute value)"
    return None


def check_bounded(expr: sp.Expr, fail: Fail) -> None:
    """Refuse `expr` if any of its nodes breaks a bound of this module."""
    for node in sp.preorder_traversal(expr):
        problem = _problem(node)
        if problem:
            raise fail(problem)


def _count(n: int) -> str:
    return f"{n:,}" if n < 10**12 else f"about 10**{len(str(n)) - 1}"


def expanded_terms(expr: sp.Expr, limit: int, fail: Fail) -> int:
    """An upper bound on the terms of `expr` expanded, or `fail` once `expr` or a part of it exceeds `limit`.

    Counted bottom-up without expanding: a sum has the terms of its summands, a product the
    product of its factors' counts, base**k (k an integer, or the integer part of a rational
    exponent, in absolute value: SymPy expands denominators too) at most C(t + k - 1, k) for a
    base of t terms (the monomials of degree k in t variables), a sine or cosine two (the
    exponentials e^(ix), e^(-ix): sin(x)**64 expands to 65 terms over angles k x); numbers,
    symbols, other functions and powers with a symbolic exponent one.
    """
    memo: dict[sp.Basic, int] = {}

    def terms(node: sp.Basic) -> int:
        done = memo.get(node)
        if done is not None:
            return done
        counts = [terms(a) for a in node.args]
        if node.is_Add:
            n = sum(counts)
        elif node.is_Mul:
            n = 1
            for c in counts:
                n *= c
                if n > limit:
                    break
        elif node.is_Pow and node.exp.is_Rational:
            k = abs(int(node.exp))
            n = math.comb(counts[0] + k - 1, k) if k else 1
        elif isinstance(node, (sp.sin, sp.cos)):
            n = 2
        else:
            n = 1
        if n > limit:
            raise fail(
                f"'{_short(str(node))}' would expand to {_count(n)} terms, more than the limit of "
                f"{limit:,} (counted from its factors' terms and exponents)"
            )
        memo[node] = n
        return n

    return terms(expr)


def check_expansion(expr: sp.Expr, fail: Fail, limit: int = MAX_EXPANDED_TERMS) -> None:
    """Refuse `expr` if it or a part of it would expand to more than `limit` terms (`expanded_terms`),
    or than its own nodes when it has more (a sum written out term by term is no expansion)."""
    size = sum(1 for _ in sp.preorder_traversal(expr))
    expanded_terms(expr, max(limit, size), fail)


def bounded_subs(expr: sp.Expr, mapping: Mapping[sp.Basic, sp.Expr], fail: Fail) -> sp.Expr:
    """expr.xreplace(mapping), every power checked (`check_power`) before SymPy evaluates it,
    every rebuilt node checked against the bounds of this module and the result's expansion
    (`check_expansion`)."""
    if not mapping:
        return expr
    memo: dict[sp.Basic, sp.Expr] = {}

    def walk(node: sp.Basic) -> sp.Basic:
        if node in mapping:
            return mapping[node]
        if not node.args:
            return node
        done = memo.get(node)
        if done is not None:
            return done
        args = [walk(a) for a in node.args]
        if all(a is b for a, b in zip(args, node.args, strict=True)):
            out = node
        else:
            if node.is_Pow:
                check_power(args[0], args[1], fail, _short(str(node)))
            out = node.func(*args)
            problem = _problem(out)
            if problem:
                raise fail(f"{problem}, after substituting parameters")
        memo[node] = out
        return out

    try:
        out = walk(expr)
    except RecursionError:
        raise fail("expression is nested too deeply after substituting parameters") from None
    if out is not expr:
        check_expansion(out, lambda message: fail(f"{message}, after substituting parameters"))
    return out
