"""Straight-line programs: the named intermediates that keep derivations small.

A `Program` is an ordered list of assignments ``t_k = expr_k`` where each
expression uses the inputs (joint symbols, free parameters) and earlier
intermediates only. The Newton-Euler recursion and the Lagrange kinematics
write their vectors into a program component by component instead of
nesting whole expressions, so the work stays linear in the number of links.

Operations:
- `let` names a non-trivial expression (atoms and numbers pass through);
  `let_vector` and `let_symmetric` name vectors and symmetric 3x3 matrices entry by entry;
- `diff` differentiates outputs by forward-mode propagation through the
  assignments (dt_k/dx = sum of partials times dt_j/dx);
- `expand` substitutes the intermediates back, for closed forms;
- `needed` lists the assignments that some outputs depend on, in order.

Intermediate symbols are named ``_<hint><k>``; a leading underscore is never a
parameter name, so they cannot clash with the robot file's symbols.
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence

import sympy as sp

__all__ = ["Program", "dependencies", "derivative", "is_trivial"]


def _negated(expr: sp.Expr) -> sp.Expr | None:
    """-expr with the sign moved inside, when expr reads as a negative; else None."""
    if expr.is_Mul:
        c, rest = expr.as_coeff_Mul()
        return (-c) * rest if c.is_negative else None
    return None  # sums are left as they are: normalising their sign costs more than it saves


def is_trivial(expr: sp.Expr) -> bool:
    """True for expressions not worth a name: numbers, symbols and number*symbol."""
    if expr.is_Atom:
        return True
    if expr.is_Mul and len(expr.args) == 2:
        a, b = expr.args
        return bool(a.is_Number and b.is_Atom)
    return False


_ZERO = sp.S.Zero  # a singleton: `is` tests avoid SymPy's slow comparisons


def derivative(e: sp.Expr, dmap: dict, memo: dict) -> sp.Expr:
    """Total derivative of e, given the derivatives `dmap` of the symbols it uses (others 0);
    `memo` caches it for the subexpressions (a dict the caller keeps, or a fresh one).

    Handles the forms the recursions produce (sums, products, integer powers,
    sin, cos, sign, Heaviside, Abs) directly, which is much faster than SymPy's general diff
    (whose derivative of Abs, for symbols not declared real, is written with re and im).
    """
    if e.is_Symbol:
        return dmap.get(e, sp.S.Zero)
    if e.is_Number or e.is_NumberSymbol:
        return sp.S.Zero
    hit = memo.get(e)
    if hit is not None:
        return hit
    args = e.args
    if e.is_Add:
        out = sp.Add(*[d for d in (derivative(a, dmap, memo) for a in args) if d is not _ZERO])
    elif e.is_Mul:
        terms = []
        for i, a in enumerate(args):
            da = derivative(a, dmap, memo)
            if da is not _ZERO:
                terms.append(sp.Mul(*args[:i], *args[i + 1 :], da))
        out = sp.Add(*terms)
    elif e.is_Pow and args[1].is_Number:
        db = derivative(args[0], dmap, memo)
        out = args[1] * args[0] ** (args[1] - 1) * db if db is not _ZERO else _ZERO
    elif isinstance(e, (sp.sin, sp.cos)):
        da = derivative(args[0], dmap, memo)
        slope = sp.cos(args[0]) if isinstance(e, sp.sin) else -sp.sin(args[0])
        out = slope * da if da is not _ZERO else _ZERO
    elif isinstance(e, (sp.sign, sp.Heaviside)):
        out = sp.S.Zero  # almost everywhere (Coulomb friction)
    elif isinstance(e, sp.Abs):
        da = derivative(args[0], dmap, memo)
        out = sp.sign(args[0]) * da if da is not _ZERO else _ZERO
    else:
        out = sp.Add(*[e.diff(s) * d for s, d in dmap.items() if s in e.free_symbols])
        out = out.replace(sp.DiracDelta, lambda *_: _ZERO)  # steps' derivatives: 0, as sign's
    memo[e] = out
    return out


def dependencies(
    assignments: Sequence[tuple[sp.Symbol, sp.Expr]], index: dict[sp.Symbol, int], outputs: Iterable[sp.Expr]
) -> set[int]:
    """Indices of the assignments that the outputs use, directly or through one another."""
    marked: set[int] = set()
    stack = [s for e in outputs for s in e.free_symbols if s in index]
    while stack:
        k = index[stack.pop()]
        if k in marked:
            continue
        marked.add(k)
        stack.extend(s for s in assignments[k][1].free_symbols if s in index)
    return marked


class Program:
    """An ordered list of named intermediate assignments (symbol, expression)."""

    def __init__(self) -> None:
        self.assignments: list[tuple[sp.Symbol, sp.Expr]] = []
        self._index: dict[sp.Symbol, int] = {}
        self._by_expr: dict[sp.Expr, sp.Symbol] = {}
        self._count = 0
        self._tag = ""

    def __len__(self) -> int:
        return len(self.assignments)

    def copy(self, tag: str) -> Program:
        """An independent copy: new intermediates go into it alone, their names marked with `tag`
        (``_<tag><hint><k>``), so they never clash with names this program gives later."""
        twin = Program()
        twin.assignments = list(self.assignments)
        twin._index = dict(self._index)
        twin._by_expr = dict(self._by_expr)
        twin._count = self._count
        twin._tag = self._tag + tag
        return twin

    def is_intermediate(self, s: sp.Basic) -> bool:
        return s in self._index

    def let(self, expr, hint: str = "t") -> sp.Expr:
        """Name `expr` unless it is trivial; identical expressions share one name."""
        expr = sp.sympify(expr)
        if is_trivial(expr):
            return expr
        pos = _negated(expr)
        if pos is not None and not is_trivial(pos):
            # store the positive form once, so -e and e share one intermediate
            return -self._name(pos, hint)
        return self._name(expr, hint)

    def name(self, expr, hint: str = "t") -> sp.Expr:
        """Name `expr` even when `let` finds it trivial (a number times a symbol, which every use
        would multiply again); atoms pass through."""
        expr = sp.sympify(expr)
        return expr if expr.is_Atom else self._name(expr, hint)

    def _name(self, expr: sp.Expr, hint: str) -> sp.Symbol:
        found = self._by_expr.get(expr)
        if found is not None:
            return found
        self._count += 1
        sym = sp.Symbol(f"_{self._tag}{hint}{self._count}")
        self._index[sym] = len(self.assignments)
        self.assignments.append((sym, expr))
        self._by_expr[expr] = sym
        return sym

    def let_vector(self, v: Iterable, hint: str) -> tuple:
        """Name each component of a vector (see `let`): a tuple, as symdyn.spatial.vectors uses."""
        return tuple(self.let(x, hint) for x in v)

    def let_symmetric(self, rows: Sequence[Sequence], hint: str) -> tuple:
        """Name the 6 distinct entries of a symmetric 3x3 matrix (upper triangle, by rows);
        rows of a tuple, each entry below the diagonal the name of its mirror image."""
        e = {(r, c): self.let(rows[r][c], hint) for r in range(3) for c in range(r, 3)}
        return tuple(tuple(e[(min(r, c), max(r, c))] for c in range(3)) for r in range(3))

    def _deps(self, expr: sp.Expr) -> set[sp.Symbol]:
        return {s for s in expr.free_symbols if s in self._index}

    def needed(self, outputs: Iterable[sp.Expr]) -> list[tuple[sp.Symbol, sp.Expr]]:
        """The assignments the outputs depend on, in program order."""
        marked = dependencies(self.assignments, self._index, [sp.sympify(e) for e in outputs])
        return [self.assignments[k] for k in sorted(marked)]

    def diff(self, outputs: Sequence[sp.Expr], x: sp.Symbol, hint: str = "d") -> list[sp.Expr]:
        """d(outputs)/dx by forward-mode propagation; derivatives become new intermediates."""
        dmap: dict[sp.Basic, sp.Expr] = {x: sp.S.One}
        for sym, expr in self.needed(outputs):
            d = derivative(expr, dmap, {})
            if d is not _ZERO:
                dmap[sym] = self.let(d, hint)
        memo: dict = {}
        return [derivative(sp.sympify(e), dmap, memo) for e in outputs]

    def expand(self, exprs: Iterable[sp.Expr]) -> list[sp.Expr]:
        """Substitute every intermediate back: closed forms over inputs only."""
        exprs = [sp.sympify(e) for e in exprs]
        full: dict[sp.Symbol, sp.Expr] = {}
        for sym, expr in self.needed(exprs):
            full[sym] = expr.xreplace(full)
        return [e.xreplace(full) for e in exprs]
