"""Stages of a long straight-line body, for the JAX target: each a jax.lax.while_loop of one pass.

Under jax.jit(jax.vmap(f)) with XLA's default CPU flags, a body of thousands of statements is
compiled into a few huge fusions whose every root recomputes the statements it reads (the Talos'
inverse dynamics on a free flyer, 1,870 statements: 212 sines for its 32, 109 ms a state against
60 us for its f_batch, compiled with the fusion emitters off; docs/jax.md). XLA does not fuse
across a while loop, so the body is cut into stages of STAGE_SIZE statements, each the body of a
jax.lax.while_loop whose trip count is 1 computed at run time (the module's _once: a population
count XLA cannot bound), carrying the values that later statements read. Measured on the Talos'
inverse dynamics (2,000 states, the machine loaded about fivefold): 32 us a state under
jax.jit(jax.vmap(...)), compiled in 21 s, its f_batch 66 us, in stages of 150.

STAGE_SIZE was then measured on the generated Talos module with nothing else running (2,000
states; jit(vmap) and jit(grad) of the vmapped inverse dynamics' loss timed in turns, one process
a size), in us a state, jit(vmap) / jit(grad): 150: 24.5-27.5 / 57-63; 200: 20.9 / 49.8; 250:
15.3 / 38.0; 300: 9.9-12.0 / 33-37 (f_batch 8.8); 400: 6.7-7.7 / 27-28 (jit(grad) 3.7-4.1 times
the forward pass); 600: 7.3 / 26.5 (f_batch 5.0); 1,000: 6.4 / 636, where the adjoint program's
stages grow past what XLA fuses well. At 300 against 150 the mass matrix was unchanged (17.6 and
15.7 us under jit(vmap), f_batch 13.8 and 14.9) and the forward dynamics faster (43 against 71 us,
compiled in 55 s against 126). 300 halves the times of 150. The ratio of jit(grad) to jit(vmap)
is not steady between processes at any size: at 300, 2.7 to 3.4 in the runs above and 6.0 in a
bench run (bench/results/jax_talos.txt: 42.9 against 7.2 us, where stages of 150 had 65.2 against
16.6 us, 3.9 times), the forward pass moving from 7 to 15 us.

Reverse mode does not go through a while_loop, so only functions differentiated in reverse by
their own adjoint program (ADJOINTS of symdyn.codegen.jax.target) are staged, and only when
their body exceeds STAGE_ABOVE statements; their adjoint program (plain jnp code evaluated
forward) is staged with them. The Talos' jax.jit(jax.grad(...)) of the vmapped inverse dynamics'
loss (2,000 states, the machine loaded about once): with the adjoint program in one body it did
not finish compiling in 7 minutes; in stages of 150, compiled in 144 s, 81 us a state against the
forward pass's 19 us (4.3 times); in stages of 300, 33-43 us, compiled in 45-68 s.
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
    `defined`, the symbols the body reads from its arguments, or temporaries) that it or later
    statements read, and `outputs`, those defined up to its end read after it (the next stage's
    inputs), all printed by `printer`, in a fixed order."""
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
        inputs = defined & after[start]
        defined |= {s for s, _ in temporaries[start:stop]}
        outputs = names(defined & after[stop])
        out.append({"start": start, "stop": stop, "inputs": names(inputs), "outputs": outputs})
    return out
