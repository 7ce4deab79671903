"""Stages of a long straight-line body, for the JAX target: each the taken branch of a jax.lax.cond.

Under jax.jit(jax.vmap(f)) with XLA's default CPU flags, a body of thousands of statements is
compiled into a few huge fusions whose every root recomputes the statements it reads (the Talos'
inverse dynamics on a free flyer, 1,870 statements: 212 sines for its 32, 109 ms a state against
60 us for its f_batch, compiled with the fusion emitters off; docs/jax.md). XLA does not fuse
across a conditional, so the body is cut into stages of STAGE_SIZE statements, each the true
branch of a jax.lax.cond whose predicate is true at run time but not provably so (the module's
_once: a population count XLA cannot bound, not batched under jax.vmap), taking the values its
statements read and returning those later statements read (cut_into_stages). Measured on the
Talos' inverse dynamics (2,000 states, the machine loaded about fivefold): 32 us a state under
jax.jit(jax.vmap(...)), compiled in 21 s, its f_batch 66 us, in stages of 150.

Each stage takes only the values it reads and returns only its own that later statements read.
Every stage first carried every value live across it (those it reads and those later stages
read), up to 870 values a stage in the Talos' adjoint program (the stages' bookkeeping, not their
arithmetic, then dominated: the while loops' copies and selections, below): on the
generated Talos module with nothing else running (2,000 states, stages of 300, us a state),
jax.jit(jax.vmap(...)) of the inverse dynamics 10.6 -> 6.6, its adjoint program 27.8 -> 9.3,
jax.jit(jax.grad(...)) of the vmapped loss 37.3 -> 16.4 (compiled in 67 -> 33 s), f_batch 7.5
-> 5.6. STAGE_SIZE was measured then (the same runs, jit(vmap) / adjoint / jit(grad)): 200: 7.4 /
12.7 / 22.9; 300: 6.6 / 9.3 / 16.4; 500: 6.9 / 11.8 / 17.8. Before, with every live value
carried: 150: 24.5-27.5 / - / 57-63; 300: 9.9-12.0 / 27.8 / 33-37; 1,000: 6.4 / - / 636, where
the adjoint program's stages grow past what XLA fuses well.

The stages were while loops of one pass before (issue 37). XLA copied each loop's inputs into
its carry, and JAX turned the loop's trip count, batched under jax.vmap, into a selection of
every carried value: the Talos' jax.jit(jax.grad(...)) of its vmapped forward dynamics had
3,600 copies and 3,600 selections, and 65 MB of XLA's temporary buffer at 2,000 states where the
conds need 18 MB. Above 32 MB, glibc maps such a buffer afresh at every call, and every page
faults when first touched: 15,900 faults a call, 11 of that gradient's 27 us a state. With conds
(us a state, one process): jax.jit(jax.vmap(...)) of the inverse dynamics 6.1 -> 5.3 and its
jit(grad) 15.5 -> 9.6; the forward dynamics 6.8 -> 4.9 and its jit(grad) 24.1 -> 13.3. Stages
of 600 as conds against 300 (the same script; jit(vmap) and jit(grad)): the inverse dynamics 3.8
and 9.7 against 5.0 and 10.2, M 16.3 and 14.4 against 12.7 and 13.9, the forward dynamics 16.0
and 34.0 against 5.4 and 12.9: 300 kept.

Forward and reverse mode go through the conds (the predicate's input has its gradient stopped:
JAX does not linearize a custom_vmap function of a differentiated input), but the functions with
an adjoint program (ADJOINTS of symdyn.codegen.jax.target, and the forward dynamics through it)
are differentiated in reverse by it; the others (STAGED) by JAX through the stages. Only bodies
longer than STAGE_ABOVE statements are staged; an adjoint program (plain jnp code evaluated
forward) is staged with them. The Talos' jax.jit(jax.grad(...)) of the vmapped inverse dynamics'
loss (2,000 states, the machine loaded about once): with the adjoint program in one body it did
not finish compiling in 7 minutes; in stages of 150, compiled in 144 s, 81 us a state against the
forward pass's 19 us (4.3 times); in stages of 300, 33-43 us, compiled in 45-68 s; each loop
carrying only what its stage reads, 11-22 us in bench runs (2.2 and 3.1 times the forward pass),
compiled in 34 s.
"""

from __future__ import annotations

import sympy as sp

from ..function_rows import FunctionSpec
from ..python.printer import NumpyPrinter

__all__ = ["STAGE_ABOVE", "STAGE_SIZE", "long_body", "cut_into_stages", "stages"]

#: Bodies of more statements than this are staged (the Solo-12's inverse dynamics, 650, is not:
#: it compiles well as one body).
STAGE_ABOVE = 1000
#: Statements per stage (chosen by measurement on the Talos: module docstring).
STAGE_SIZE = 300


def long_body(spec: FunctionSpec) -> bool:
    """Whether `spec`'s body has more than STAGE_ABOVE statements (then it and its adjoint
    program are staged)."""
    return len(spec.temporaries) > STAGE_ABOVE


def stages(spec: FunctionSpec, printer: NumpyPrinter, size: int = STAGE_SIZE) -> list[dict]:
    """The stages of `spec`'s temporaries (cut_into_stages of its body)."""
    defined = {s for inp in spec.inputs for s in inp.symbols}
    return cut_into_stages(spec.temporaries, spec.outputs, defined, printer, size)


def cut_into_stages(
    temporaries: list[tuple[sp.Symbol, sp.Expr]],
    outputs: list,
    defined: set[sp.Symbol],
    printer: NumpyPrinter,
    size: int = STAGE_SIZE,
) -> list[dict]:
    """The stages of the straight-line body `temporaries` (then `outputs` read), runs of `size`:
    for each, the slice of temporaries [start, stop), `inputs`, the names defined before it (of
    `defined`, the symbols the body reads from its arguments, or temporaries) that its own
    statements read, and `outputs`, its temporaries read after it, all printed by `printer`, in
    a fixed order. A value goes into the stages that read it only: one defined in stage 1 and
    read in stage 5 is an output of stage 1 and an input of stage 5, and stages 2 to 4 do not
    carry it (module docstring: carrying every live value made the Talos' adjoint
    program three times slower)."""
    after: list[set[sp.Symbol]] = [set() for _ in range(len(temporaries) + 1)]
    after[-1] = set().union(*(sp.sympify(e).free_symbols for e in outputs))
    for k in range(len(temporaries) - 1, -1, -1):
        after[k] = after[k + 1] | temporaries[k][1].free_symbols
    defined = set(defined)

    def names(symbols: set[sp.Symbol]) -> list[str]:
        return [printer.doprint(s) for s in sorted(symbols, key=sp.default_sort_key)]

    out = []
    for start in range(0, len(temporaries), size):
        stop = min(start + size, len(temporaries))
        read = set().union(*(e.free_symbols for _, e in temporaries[start:stop]))
        own = {s for s, _ in temporaries[start:stop]}
        inputs = names(defined & read)
        defined |= own
        out.append({"start": start, "stop": stop, "inputs": inputs, "outputs": names(own & after[stop])})
    return out
