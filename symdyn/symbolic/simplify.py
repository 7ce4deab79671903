"""Common-subexpression elimination and operation counts for generated functions.

`eliminate` turns a set of outputs, given over a program's named intermediates
(symdyn.symbolic.program), into one straight-line sequence of temporaries x0, x1, ...
followed by the outputs:
1. only the intermediates the outputs need are kept;
2. common-subexpression elimination (symdyn.symbolic.cse: SymPy's algorithm with
   order="none", see docs/speed.md, rebuilt for speed) runs over the
   intermediates and outputs together, so sin/cos of a joint and repeated
   products are computed once across every output of the function;
3. the result is ordered topologically (each temporary before its first use)
   and renamed in evaluation order, which makes the output deterministic.

`OpCount` counts what a C compiler would execute: a power with a small integer
exponent is counted as repeated multiplications (the printers emit it so).
"""

from __future__ import annotations

import itertools
from collections.abc import Iterable, Sequence
from dataclasses import dataclass
from functools import cached_property

import sympy as sp

from .cse import fast_cse, is_negated_atom

__all__ = ["OpCount", "count_ops", "eliminate", "eliminate_many", "Eliminated", "chop_float_noise"]

MAX_UNROLLED_POWER = 8


@dataclass(frozen=True)
class OpCount:
    """Operations of a straight-line function: multiplications, additions, divisions, calls."""

    mul: int = 0
    add: int = 0
    div: int = 0
    trig: int = 0
    other: int = 0  # sqrt, sign, non-integer powers

    @property
    def total(self) -> int:
        return self.mul + self.add + self.div + self.trig + self.other

    def __add__(self, o: OpCount) -> OpCount:
        return OpCount(
            self.mul + o.mul, self.add + o.add, self.div + o.div, self.trig + o.trig, self.other + o.other
        )

    def summary(self) -> str:
        return (
            f"{self.total} operations: {self.mul} multiplications, {self.add} additions, "
            f"{self.div} divisions, {self.trig} trigonometric calls, {self.other} other calls"
        )


_TRIG = (sp.sin, sp.cos, sp.tan)
#: Terms of a sum whose float coefficient is below CHOP times the largest are rounding residues.
CHOP = 1e-12


def _chop_sum(expr: sp.Expr) -> sp.Expr:
    """A sum without the terms whose float coefficient is a rounding residue of the others."""
    coeffs = [abs(t.as_coeff_Mul()[0]) for t in expr.args]
    if not any(isinstance(c, sp.Float) for c in coeffs):
        return expr
    big = max(coeffs)
    kept = [t for t, c in zip(expr.args, coeffs, strict=True) if c >= CHOP * big]
    return sp.Add(*kept) if len(kept) < len(expr.args) else expr


def chop_float_noise(expr: sp.Expr) -> sp.Expr:
    """Drop float rounding residues from closed forms (e.g. 6.9e-18*sin(q3) beside
    0.048*sin(q3)): terms below CHOP times the largest coefficient of their sum."""
    if not expr.has(sp.Float):
        return expr
    return expr.replace(lambda e: e.is_Add, _chop_sum)


def _count(expr: sp.Expr) -> OpCount:
    mul = add = div = trig = other = 0
    stack = [expr]
    while stack:
        e = stack.pop()
        if e.is_Atom:
            continue
        if e.is_Add:
            add += len(e.args) - 1
        elif e.is_Mul:
            c, factors = e.as_coeff_mul()
            den = [a for a in factors if a.is_Pow and a.exp.is_Integer and a.exp < 0]
            num = [a for a in factors if a not in den]
            n_num = len(num) + (0 if c in (1, -1) else 1)
            mul += max(n_num - 1, 0) + max(len(den) - 1, 0)
            if den:
                div += 1
            stack.extend(num)
            stack.extend(sp.Pow(a.base, -a.exp) for a in den)
            continue
        elif e.is_Pow:
            k = e.exp
            if k.is_Integer and 0 < k <= MAX_UNROLLED_POWER:
                mul += int(k) - 1
            elif k.is_Integer and -MAX_UNROLLED_POWER <= k < 0:
                div += 1
                mul += int(-k) - 1
            else:
                other += 1
            stack.append(e.base)
            continue
        elif isinstance(e, _TRIG):
            trig += 1
        elif e.is_Function:
            other += 1
        stack.extend(e.args)
    return OpCount(mul, add, div, trig, other)


def count_ops(temporaries: Sequence[tuple[sp.Symbol, sp.Expr]], outputs: Sequence[sp.Expr]) -> OpCount:
    """Operations to evaluate the temporaries then the outputs, as the printers emit them."""
    total = OpCount()
    for _, e in temporaries:
        total += _count(e)
    for e in outputs:
        total += _count(sp.sympify(e))
    return total


@dataclass(frozen=True)
class Eliminated:
    """Temporaries (x_k = expr over inputs and earlier temporaries) and outputs over them."""

    temporaries: tuple[tuple[sp.Symbol, sp.Expr], ...]
    outputs: tuple[sp.Expr, ...]

    @cached_property
    def ops(self) -> OpCount:
        return count_ops(self.temporaries, self.outputs)


def _topological(nodes: dict[sp.Symbol, sp.Expr], roots: Sequence[sp.Expr]) -> list[sp.Symbol]:
    """Every node reachable from the roots, each after the nodes it uses (stable DFS order)."""
    order: list[sp.Symbol] = []
    done: set[sp.Symbol] = set()

    def deps(e: sp.Expr) -> list[sp.Symbol]:
        return sorted((s for s in e.free_symbols if s in nodes), key=lambda s: _rank[s])

    _rank = {s: k for k, s in enumerate(nodes)}
    for root in roots:
        stack: list[tuple[sp.Symbol, bool]] = [(s, False) for s in reversed(deps(root))]
        while stack:
            s, expanded = stack.pop()
            if s in done:
                continue
            if expanded:
                done.add(s)
                order.append(s)
                continue
            stack.append((s, True))
            stack.extend((d, False) for d in reversed(deps(nodes[s])) if d not in done)
    return order


def _cse_nodes(
    assignments: Sequence[tuple[sp.Symbol, sp.Expr]], outputs: Sequence[sp.Expr]
) -> tuple[dict[sp.Symbol, sp.Expr], list[sp.Expr]]:
    """CSE over assignments and outputs together (symdyn.symbolic.cse): (symbol -> expression nodes,
    reduced outputs)."""
    syms = [s for s, _ in assignments]
    repl, reduced = fast_cse([e for _, e in assignments] + list(outputs), "_cse")
    nodes: dict[sp.Symbol, sp.Expr] = dict(repl)
    nodes.update(zip(syms, reduced[: len(syms)], strict=True))
    outs = list(reduced[len(syms) :])

    # inline temporaries that are a bare symbol or number (no work, only a name), to a fixpoint
    # since an alias may name another alias
    alias = {s: e for s, e in nodes.items() if e.is_Atom or is_negated_atom(e)}
    while True:
        resolved = {s: e.xreplace(alias) for s, e in alias.items()}
        if resolved == alias:
            break
        alias = resolved
    kept = {s: e.xreplace(alias) for s, e in nodes.items() if s not in alias}
    return kept, [e.xreplace(alias) for e in outs]


def _renamed(expr: sp.Expr, rename: dict[sp.Symbol, sp.Symbol], memo: dict) -> sp.Expr:
    """expr with symbols swapped, keeping its argument order (no re-canonicalisation, so fast)."""
    if expr.is_Symbol:
        return rename.get(expr, expr)
    if expr.is_Atom:
        return expr
    hit = memo.get(expr)
    if hit is not None:
        return hit
    args = tuple(_renamed(a, rename, memo) for a in expr.args)
    out = expr.func._from_args(args) if (expr.is_Add or expr.is_Mul) else expr.func(*args)
    memo[expr] = out
    return out


def _inputs(nodes: dict[sp.Symbol, sp.Expr], outputs: Sequence[sp.Expr]) -> set[sp.Symbol]:
    """Every symbol that is not a temporary: joint symbols, parameters, tau."""
    used = set().union(*(e.free_symbols for e in (*nodes.values(), *outputs)))
    return used - set(nodes)


def _extract(
    nodes: dict[sp.Symbol, sp.Expr],
    outputs: Sequence[sp.Expr],
    prefix: str,
    taken: set[sp.Symbol],
    visit: Sequence[int] | None = None,
    lead: Sequence[sp.Symbol] = (),
) -> Eliminated:
    """The temporaries the outputs need, in order (each output's, depth first, the outputs taken
    in the order `visit` of their indices, or in their own; the intermediates of `lead` first,
    in their order, each after what it uses); fresh names that no input (a parameter called x0)
    already has, for every function generated from the same robot."""
    roots = [outputs[k] for k in visit] if visit is not None else list(outputs)
    order = _topological(nodes, [s for s in lead if s in nodes] + roots)
    fresh = (t for t in (sp.Symbol(f"{prefix}{k}") for k in itertools.count()) if t not in taken)
    rename = {s: next(fresh) for s in order}
    memo: dict = {}
    temporaries = tuple((rename[s], _renamed(nodes[s], rename, memo)) for s in order)
    return Eliminated(temporaries, tuple(_renamed(e, rename, memo) for e in outputs))


def eliminate(
    assignments: Sequence[tuple[sp.Symbol, sp.Expr]],
    outputs: Sequence[sp.Expr],
    prefix: str = "x",
) -> Eliminated:
    """CSE over a program's assignments and outputs; temporaries renamed prefix0, prefix1, ..."""
    return eliminate_many(assignments, {"": outputs}, prefix)[""]


def eliminate_many(
    assignments: Sequence[tuple[sp.Symbol, sp.Expr]],
    groups: dict[str, Sequence[sp.Expr]],
    prefix: str = "x",
    reserved: Iterable[sp.Symbol] = (),
    visits: dict[str, Sequence[int]] | None = None,
    leads: dict[str, Sequence[sp.Symbol]] | None = None,
) -> dict[str, Eliminated]:
    """`eliminate` for several functions sharing one program: one CSE pass, then each
    group keeps only the temporaries its outputs need (renamed from prefix0 per group,
    skipping the names of inputs and of the `reserved` symbols). `visits` may give, per group,
    the order in which its outputs' temporaries are laid out (the order of the computation: a
    matrix column by column keeps fewer values alive at once than row by row), and `leads` the
    intermediates of `assignments` laid out first, in their order (an algorithm's own order of
    steps, where it keeps fewer values alive than any order of the outputs)."""
    outputs = [sp.sympify(e) for name in groups for e in groups[name]]
    nodes, reduced = _cse_nodes(assignments, outputs)
    taken = _inputs(nodes, reduced) | set(reserved)
    result: dict[str, Eliminated] = {}
    k = 0
    for name, outs in groups.items():
        visit = (visits or {}).get(name)
        lead = (leads or {}).get(name, ())
        result[name] = _extract(nodes, reduced[k : k + len(outs)], prefix, taken, visit, lead)
        k += len(outs)
    return result
