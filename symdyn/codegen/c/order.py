"""The order of a C function's statements: each output store's temporaries computed just before it.

The common-subexpression pass names the temporaries in the order it finds them, which keeps a
value computed early alive until a late statement reads it. A compiler rarely moves straight-line
statements far (at -Os gcc schedules nothing), so the order of the C is close to the order of the
machine code, and every value alive at once beyond the CPU's registers costs a store to the stack
and a load back for each later read: 32 single-precision registers on a Cortex-M4F, whose
Panda inverse dynamics in the generated order spent 380 of its 1,086 instructions on such spills.

`statement_order` is a depth-first walk of the statements' dependency graph from the output stores,
in the order of their values' last temporaries (the order of the previous layout): each store is
preceded by the temporaries it needs that are not yet computed, and among the operands of a
temporary the one needing the most registers comes first (Sethi and Ullman's labelling, J. ACM
17(4), 1970, on the graph as if it were a tree), so that fewer values wait in registers while it is
computed. The statements and their values are unchanged (every expression is the same; only
independent statements swap), so the results are bit-identical; on the Panda's float inverse
dynamics for the Cortex-M4F at -Os the function itself takes 984 instructions instead of 1,086
(docs/embedded.md). The walk is iterative (a function of ten thousand temporaries has chains
deeper than Python's recursion limit) and deterministic: ties keep the previous order.
"""

from __future__ import annotations

from collections.abc import Sequence

__all__ = ["statement_order"]


def _labels(deps: Sequence[Sequence[int]]) -> list[int]:
    """Sethi-Ullman's register need of each temporary: 1 for one that reads no temporary, else
    max over its operands sorted by need (largest first) of need + position."""
    need = [1] * len(deps)
    for k, operands in enumerate(deps):  # operands come before their readers
        ranked = sorted((need[d] for d in operands), reverse=True)
        need[k] = max([1, *(r + i for i, r in enumerate(ranked))])
    return need


def statement_order(deps: Sequence[Sequence[int]], stores: Sequence[Sequence[int]]) -> list[tuple[str, int]]:
    """The order of a function's statements: ("let", k) for temporary k, ("store", j) for store j.

    `deps[k]` are the temporaries temporary k reads (each an index below k), `stores[j]` those
    store j reads; stores come in the given order, each right after the last temporary it needs,
    and a temporary no store needs comes where the walk ends (after every store)."""
    need = _labels(deps)
    ranked = [sorted(operands, key=lambda d: -need[d]) for operands in deps]
    done = [False] * len(deps)
    order: list[tuple[str, int]] = []

    def emit(roots: Sequence[int]) -> None:
        stack = [(k, 0) for k in reversed(roots)]
        while stack:
            k, i = stack.pop()
            if done[k]:
                continue
            if i < len(ranked[k]):
                stack.append((k, i + 1))
                if not done[ranked[k][i]]:
                    stack.append((ranked[k][i], 0))
                continue
            done[k] = True
            order.append(("let", k))

    for j, reads in enumerate(stores):
        emit(sorted(reads, key=lambda d: -need[d]))
        order.append(("store", j))
    emit(range(len(deps)))
    return order
