"""The adjoint (reverse-mode, vector-Jacobian product) program of a straight-line program.

A straight-line program is a list of statements s_k = e_k(x, s_1, ..., s_{k-1}) over inputs
x, and outputs y_j = o_j(x, s). For output weights w, the adjoint program computes
xbar = w^T dy/dx for every input x as one more straight-line program, built symbolically
statement by statement from the partial derivatives of each small expression (no expression
is ever expanded): in reverse program order, starting from
    sbar_i = sum_j w_j (d o_j / d s_i),
each statement's adjoint sbar_k, once complete, is passed on to what e_k reads:
    sbar_i += sbar_k (d e_k / d s_i),  xbar += sbar_k (d e_k / d x),
for a few times the cost of the program (the Panda's inverse dynamics: 302 statements, 220 more).

The partial derivatives read only the program's own statements and inputs, so they are
computed after the program, their common subexpressions shared (symdyn.symbolic.cse); each
adjoint is then one statement. sign and Heaviside (Coulomb friction) have derivative 0, as
everywhere but at 0.
"""

from __future__ import annotations

from collections.abc import Iterator, Sequence
from dataclasses import dataclass

import sympy as sp

from .cse import fast_cse
from .program import derivative

__all__ = ["Derived", "partial", "adjoint_program"]

_ZERO = sp.S.Zero


@dataclass(frozen=True)
class Derived:
    """A derivative program: `temporaries` (symbol, expression) in evaluation order, the
    original program's first, and `outputs`, expressions over them and the inputs."""

    temporaries: tuple[tuple[sp.Symbol, sp.Expr], ...]
    outputs: tuple[sp.Expr, ...]


def partial(e: sp.Expr, s: sp.Symbol) -> sp.Expr:
    """d e / d s: symdyn.symbolic.program.derivative with s's derivative 1 (the forms of generated
    code directly: sums, products, numeric powers, sin, cos, sign, Heaviside, Abs)."""
    return derivative(e, {s: sp.S.One}, {})


def _partials(
    statements: Sequence[tuple[sp.Symbol, sp.Expr]],
    outputs: Sequence[sp.Expr],
    known: set[sp.Symbol],
    names: Iterator[sp.Symbol],
):
    """The partial derivatives of every statement and output by each known symbol it reads, with
    their common subexpressions named: (new temporaries, [{symbol: partial} per statement, then
    per output])."""
    keys: list[tuple[int, sp.Symbol]] = []
    exprs: list[sp.Expr] = []
    for k, e in enumerate([e for _, e in statements] + list(outputs)):
        for s in sorted(sp.sympify(e).free_symbols & known, key=sp.default_sort_key):
            d = partial(e, s)
            if d is not _ZERO:
                keys.append((k, s))
                exprs.append(d)
    named, reduced = fast_cse(exprs, "", names)
    table: list[dict[sp.Symbol, sp.Expr]] = [{} for _ in range(len(statements) + len(outputs))]
    for (k, s), d in zip(keys, reduced, strict=True):
        table[k][s] = d
    return named, table


def adjoint_program(
    temporaries: Sequence[tuple[sp.Symbol, sp.Expr]],
    outputs: Sequence[sp.Expr],
    weights: Sequence[sp.Expr],
    inputs: Sequence[sp.Symbol],
    names: Iterator[sp.Symbol],
) -> Derived:
    """The program of xbar = w^T dy/dx (the module docstring), `weights[j]` the weight of
    `outputs[j]` (a symbol, or 0). Its outputs are xbar, in the order of `inputs`; its new
    temporaries are named by `names`, which must not meet the program's own."""
    known = {s for s, _ in temporaries} | set(inputs)
    named, table = _partials(temporaries, outputs, known, names)
    bar: dict[sp.Symbol, list[sp.Expr]] = {}

    def send(weight: sp.Expr, parts: dict[sp.Symbol, sp.Expr]) -> None:
        for r, p in parts.items():
            bar.setdefault(r, []).append(weight * p)

    for w, parts in zip(weights, table[len(temporaries) :], strict=True):
        if w != 0:
            send(w, parts)
    steps: list[tuple[sp.Symbol, sp.Expr]] = []
    for (s, _), parts in zip(reversed(temporaries), reversed(table[: len(temporaries)]), strict=True):
        b = sp.Add(*bar.pop(s, ()))
        if b is _ZERO:
            continue
        if not b.is_Atom:
            t = next(names)
            steps.append((t, b))
            b = t
        send(b, parts)
    return Derived((*temporaries, *named, *steps), tuple(sp.Add(*bar.get(x, ())) for x in inputs))
