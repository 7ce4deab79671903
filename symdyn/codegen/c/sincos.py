"""The sines and cosines of one generated C function, gathered for one call of NAME_sincos.

In double precision every distinct argument `a` of `sin(a)` and `cos(a)` in a function's
temporaries and outputs becomes one entry of a local array filled at the top of the
function; one call of the file's static helper NAME_sincos (templates/c/sincos.c.j2)
computes all the sines and cosines, and every `sin(a)` or `cos(a)` reads its entry
(docs/generated-code.md, "Sines and cosines"). An argument that is a temporary (or
contains one) is resolved to the inputs, since the array is filled before any
temporary; a temporary that was read only inside such arguments is then dead and
left out. Arguments are in the order they are first met, temporaries first, so the
text is deterministic.
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from dataclasses import dataclass

import sympy as sp

__all__ = ["BLOCK", "FREESTANDING_ERROR", "SinCos", "gather", "trig_calls"]

#: The helper computes the angles in blocks of this many (one 256-bit vector of doubles):
#: the arrays are padded with zeros to a multiple of it.
BLOCK = 4

TRIG = (sp.sin, sp.cos)

#: The error of a freestanding file's own sines and cosines (templates/c/sincos_free.c.j2), per
#: precision, as its header states it (the float bound is checked by tests/test_embedded.py).
FREESTANDING_ERROR = {
    "double": "within 1 ulp of the C library's sin and cos for |x| < 2^19 pi/2 (823549.6 rad)",
    "float": "at most 1e-7 absolute for |x| <= 8192 rad (9.3e-8 measured over every float in "
    "[-8, 8] and 2^24 random floats in [-8192, 8192])",
}


@dataclass(frozen=True)
class SinCos:
    """The angles of one function, where their sines and cosines are read, and what stays live."""

    angles: tuple[sp.Expr, ...]  # the distinct arguments, over the inputs only
    calls: dict[sp.Expr, tuple[int, int]]  # sin(a) or cos(a) -> (0 for sine or 1 for cosine, index)
    live: frozenset[sp.Symbol]  # the temporaries still read once the calls read the arrays
    inputs: frozenset[sp.Symbol]  # the input symbols still read outside the calls

    def contiguous(self, inputs: Sequence) -> tuple[str, int] | None:
        """(input, start) when the angles are entries start, start + 1, ... of one input array
        (the Panda's q[1] to q[6]): NAME_sincos can then read them there, with no array to fill;
        else None. `inputs` are the function's inputs (each with .name and .symbols)."""
        for inp in inputs:
            if self.angles and self.angles[0] in inp.symbols:
                start = list(inp.symbols).index(self.angles[0])
                if tuple(inp.symbols[start : start + len(self.angles)]) == self.angles:
                    return inp.name, start
        return None

    @property
    def size(self) -> int:
        """The length of the arrays: the number of angles rounded up to a multiple of BLOCK."""
        return -(-len(self.angles) // BLOCK) * BLOCK


def trig_calls(exprs: Iterable[sp.Expr]) -> list[sp.Expr]:
    """The distinct sin(a) and cos(a) with a non-constant argument, in first-met (preorder) order."""
    found: dict[sp.Expr, None] = {}
    for expr in exprs:
        for node in sp.preorder_traversal(sp.sympify(expr)):
            if isinstance(node, TRIG) and node.free_symbols:
                found.setdefault(node, None)
    return list(found)


def _reads(expr: sp.Expr, calls: dict[sp.Expr, tuple[int, int]]) -> set[sp.Symbol]:
    """The symbols `expr` reads outside the calls that read the arrays."""
    symbols: set[sp.Symbol] = set()
    stack = [sp.sympify(expr)]
    while stack:
        node = stack.pop()
        if node in calls:
            continue
        if node.is_Symbol:
            symbols.add(node)
        else:
            stack.extend(node.args)
    return symbols


def gather(temporaries: Sequence[tuple[sp.Symbol, sp.Expr]], outputs: Sequence[sp.Expr]) -> SinCos:
    """The angles of a function's code (temporaries x_k = expr, then the outputs over them)."""
    definitions = dict(temporaries)
    resolved: dict[sp.Symbol, sp.Expr] = {}

    def resolve(expr: sp.Expr) -> sp.Expr:
        """`expr` over the inputs: every temporary replaced by its definition, recursively."""
        inner = {s: resolve_symbol(s) for s in expr.free_symbols if s in definitions}
        return expr.xreplace(inner) if inner else expr

    def resolve_symbol(s: sp.Symbol) -> sp.Expr:
        if s not in resolved:
            resolved[s] = resolve(definitions[s])
        return resolved[s]

    index: dict[sp.Expr, int] = {}
    calls: dict[sp.Expr, tuple[int, int]] = {}
    for call in trig_calls([e for _, e in temporaries] + list(outputs)):
        angle = resolve(call.args[0])
        k = index.setdefault(angle, len(index))
        calls[call] = (0 if isinstance(call, sp.sin) else 1, k)
    live: set[sp.Symbol] = set()
    for expr in outputs:
        live |= _reads(expr, calls)
    for s, expr in reversed(temporaries):
        if s in live:
            live |= _reads(expr, calls)
    return SinCos(
        tuple(index),
        calls,
        frozenset(s for s in live if s in definitions),
        frozenset(s for s in live if s not in definitions),
    )
