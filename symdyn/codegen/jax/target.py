"""The JAX target: `NAME_jax.py`, a module of jax.numpy functions of one state (imports only jax).

It holds every function of the context (docs/generated-code.md) with the NumPy target's
names and arguments, written for ONE state: vectors of shape (n,), p of shape (k,). The
bodies are the eliminated straight-line code, one statement per temporary, with no branch
on a value, no in-place update and no NumPy call, so that jax.jit, jax.vmap, jax.grad and
jax.lax.scan apply to them unchanged; p is an argument, so parameters can be fitted by
gradient. Vectors are returned through jax.lax.select_n (the module's _vector_of), not
jnp.array, a concatenate that XLA's CPU fusion emitters made 280 times slower under jax.vmap
for the Panda; matrices as one selection, a concatenate of more than 8 selected blocks (which
XLA's CPU compiler computes apart, each block's statements once) or jnp.array, per output
(matrix_builders; docs/jax.md). Each
function has a batched twin NAME_batch (vmapped over the leading axis of the arguments that
have one, jitted). Inputs and outputs are float64
(--precision double, which needs JAX's x64 mode: the module refuses to import without it
rather than compute in float32) or float32.

The functions of ADJOINTS are jax.custom_jvp functions whose tangent is a linear primitive
(the module's _adjoint_ruled: JAX's forward mode of the body for jax.jvp and jax.jacfwd) whose
transpose, for jax.grad and jax.jacrev, is their adjoint program (symdyn.symbolic.adjoint:
w^T dy/dx for every input, p included, one straight-line function whose cotangents are selected
vectors too): XLA's own reverse mode of the long
straight-line bodies makes every cotangent entry a fusion of its own that recomputes what it
reads (docs/jax.md), 10 times slower. The functions of RULES are jax.custom_jvp functions whose
rule is their generated derivative function (the module's _analytic_jvp; on a floating base
q's NQ entries mapped to the tangent space by _q_to_tangent).

The names, shapes and printed expressions are the NumPy target's (symdyn.codegen.python,
printed with the namespace `jnp`); every Python statement is spelled in templates/jax/module.py.j2.
"""

from __future__ import annotations

import re
from collections.abc import Iterator

import sympy as sp

from ...symbolic.adjoint import adjoint_program
from ..function_rows import FunctionSpec
from ..python.printer import NumpyPrinter, local_names
from ..python.target import JOINT_INPUTS, render_module
from ..render import RenderContext
from . import stages as staging

__all__ = [
    "render",
    "file_name",
    "TOOLS",
    "ADJOINTS",
    "RULES",
    "IDENTITIES",
    "STAGED",
    "SELECTED_ENTRIES",
    "SELECTED_BODY",
    "adjoint_view",
    "matrix_builders",
]

#: The functions whose derivative is a linear primitive transposed by their generated adjoint program
#: (adjoint_view), when their one output is a vector named as no input (its cotangent is the
#: argument of that name). Chosen by measurement (bench/jax.py, docs/jax.md): for the Panda,
#: jax.jit(jax.grad(...)) through jax.vmap of the inverse dynamics took 7.9 us a state by XLA's
#: reverse mode, 17.6 us through a custom_jvp rule of the generated tangent program (JAX
#: transposing it) and 0.59 us through the adjoint program (3.3 times the forward pass); the
#: forward dynamics' own adjoint program took 9.2 ms, twice XLA's reverse mode, so it goes
#: through IDENTITIES (or RULES).
ADJOINTS = ("inverse_dynamics",)

#: The functions differentiated by a jax.custom_jvp rule made of a generated derivative function,
#: {function: derivative function}, when the module holds both: the derivative function returns
#: the Jacobians by each input of the function but p, in the order of the inputs (forward
#: dynamics: dqdd/dq, dqdd/dqd, dqdd/dtau = M^-1). Chosen by measurement (bench/jax.py,
#: docs/jax.md): for the Panda, jax.jit(jax.grad(...)) through jax.vmap of the forward dynamics
#: took 6.2 ms a state by XLA's reverse mode and 108 us by the rule; the inverse dynamics keeps
#: XLA's autodiff, which was faster than its rule (12 against 17 us; jacfwd 16 against 31 us).
#: IDENTITIES takes the forward dynamics over when the module holds the inverse dynamics.
RULES = {"forward_dynamics": "forward_dynamics_derivatives"}


#: The functions reverse-differentiated through another's adjoint program by an identity,
#: {function: inverse dynamics}: differentiating ID(q, qd, FD(q, qd, tau)) = tau gives
#: w^T dqdd/dx = -(M^-1 w)^T dID/dx for x = q, qd, p (at qdd = FD) and w^T dqdd/dtau = (M^-1 w)^T,
#: where M^-1 w is FD's derivative along tau = w (FD is affine in tau): one pass of FD's body in
#: forward mode and the inverse dynamics' adjoint program. Chosen by measurement (bench/jax.py,
#: docs/jax.md): for the Panda (on the loaded machine, M^-1 w then by jnp.linalg.solve of M),
#: jax.jit(jax.grad(...)) through jax.vmap 15.5 us a state (2.7 times the forward pass, compiled
#: in 19 s), against 108 us by RULES (compiled in 551 s); for the Talos (quiet, 2,000 states, one
#: process, its stages then while loops) 23.7 us a state (3.1 times the forward pass; 4.0 to 5.0
#: times in bench runs), against 48 us by jnp.linalg.solve of M (a batch of 38 x 38 solves took
#: 15 us a state); with the stages as conds 12.1 us, 2.6 times (bench/results/jax_talos.txt).
#: Taken over RULES when the module holds both functions with these inputs.
IDENTITIES = {"forward_dynamics": "inverse_dynamics"}

#: The functions without an adjoint program or rule that are staged when their body is long
#: (symdyn.codegen.jax.stages), differentiated by JAX through the stages. Chosen by measurement on
#: the Talos (2,000 states, loaded about once): jax.jit(jax.vmap(mass_matrix)) 18 us a state
#: staged against 31 us in one body (f_batch 24, 29); the functions of ADJOINTS and IDENTITIES
#: are staged too (the Talos' forward dynamics 70 us then). Its jax.jit(jax.grad(...)) of the
#: vmapped loss through the stages (quiet, one process): 13.5 us a state, compiled in 23 s, where
#: JAX's forward mode of the body in one piece, transposed, took 31 to 38 us, compiled in 200 s.
STAGED = ("mass_matrix",)

#: The tools the file's bytes depend on besides symdyn: SymPy builds and prints every expression.
TOOLS = {"_jax.py": ("sympy",)}


#: A matrix of at most SELECTED_ENTRIES entries, of a body of at most SELECTED_BODY statements, is
#: one selection (the module's _selection_of); a longer body's, or a larger matrix, concatenated
#: selected blocks (_matrix_of); a body of more than staging.STAGE_ABOVE statements keeps one
#: concatenate of every entry (_array_of). Chosen by measurement (the Panda, jax.jit(jax.vmap(f)),
#: 20,000 states, one process, docs/jax.md): one selection against blocks, link7_jacobian (42
#: entries) 257 against 685 ns a state, M (49, 184 statements) 442 against 711, the
#: operational-space inertia (36, 481 statements) 1,592 against 1,730, coriolis_matrix (49, 648
#: statements) 3,389 against 889.
SELECTED_ENTRIES = 64
SELECTED_BODY = 500


def matrix_builders(spec: FunctionSpec) -> list[str | None]:
    """The module's function that builds each output of `spec` (None for a vector): _selection_of,
    _matrix_of or _array_of (SELECTED_ENTRIES)."""
    if staging.long_body(spec):
        whole = "_array_of"
    elif len(spec.temporaries) <= SELECTED_BODY:
        whole = None  # per output: one selection when small enough
    else:
        whole = "_matrix_of"

    def builder(out) -> str | None:
        if not out.matrix:
            return None
        return whole or ("_selection_of" if out.size <= SELECTED_ENTRIES else "_matrix_of")

    return [builder(out) for out in spec.results]


def file_name(name: str) -> str:
    return f"{name}_jax.py"


def _numbered_after(spec: FunctionSpec) -> Iterator[sp.Symbol]:
    """Fresh temporaries x<k>, numbered after the spec's own (no parameter is named so: local_names)."""
    taken = [int(m.group(1)) for s, _ in spec.temporaries if (m := re.fullmatch(r"x(\d+)", s.name))]
    return sp.numbered_symbols("x", start=max(taken, default=-1) + 1)


def adjoint_view(spec: FunctionSpec, printer: NumpyPrinter) -> dict | None:
    """The adjoint program of `spec` as the template prints it: arguments (the inputs, p, then the
    output's cotangent, named as the output), the entries it reads, temporaries, and one vector of
    cotangent entries per input (p's last); None unless `spec` has one vector output named as no
    input."""
    (out,) = spec.results if len(spec.results) == 1 else (None,)
    names = [inp.name for inp in spec.inputs]
    if out is None or out.matrix or out.name in names or out.name not in JOINT_INPUTS:
        return None
    fresh = _numbered_after(spec)
    weights = [next(fresh) for _ in range(out.size)]
    inputs = [s for inp in spec.inputs for s in inp.symbols]
    program = adjoint_program(spec.temporaries, spec.outputs, weights, inputs, fresh)
    exprs = [e for _, e in program.temporaries] + list(program.outputs)
    free = set().union(*(e.free_symbols for e in exprs))
    read = [(s, inp.name, k) for inp in spec.inputs for k, s in enumerate(inp.symbols) if s in free]
    read += [(w, out.name, k) for k, w in enumerate(weights) if w in free]
    cotangents, start = [], 0
    for inp in spec.inputs:
        cotangents.append([printer.doprint(e) for e in program.outputs[start : start + len(inp.symbols)]])
        start += len(inp.symbols)
    return {
        "args": [*names, out.name],
        "shape": [out.size],
        "unpack": [(printer.doprint(s), array, k) for s, array, k in read],
        "temporaries": [(printer.doprint(s), printer.doprint(e)) for s, e in program.temporaries],
        "cotangents": cotangents,
        "stages": (
            staging.cut_into_stages(
                program.temporaries, program.outputs, {s for s, _, _ in read}, printer, staging.STAGE_SIZE
            )
            if staging.long_body(spec)
            else None
        ),
    }


def rules(ctx: RenderContext) -> dict[str, str]:
    """The entries of RULES whose two functions are both in `ctx`, with the same inputs, and
    the derivative function with one Jacobian per input but p."""
    specs = {spec.name: spec for spec in ctx.functions}
    out = {}
    for name, derivative in RULES.items():
        f, d = specs.get(name), specs.get(derivative)
        if f is None or d is None:
            continue
        inputs = [inp.name for inp in f.inputs]
        moving = [i for i in inputs if i != "p"]
        if inputs == [inp.name for inp in d.inputs] and len(d.results) == len(moving):
            out[name] = derivative
    return out


def identities(ctx: RenderContext, adjoints: dict[str, dict]) -> dict[str, dict]:
    """{function: {"inverse": ..., "shape": ...}} for the entries of IDENTITIES whose two functions
    are in `ctx` with the inputs (q, qd, tau, p) and (q, qd, qdd, p), the inverse dynamics having an
    adjoint program (`adjoints`)."""
    specs = {spec.name: spec for spec in ctx.functions}
    wanted = (["q", "qd", "tau", "p"], ["q", "qd", "qdd", "p"])
    out = {}
    for name, inverse in IDENTITIES.items():
        found = [specs.get(n) for n in (name, inverse)]
        if inverse not in adjoints or any(s is None for s in found):
            continue
        if [[inp.name for inp in s.inputs] for s in found] == list(wanted) and len(found[0].results) == 1:
            out[name] = {"inverse": inverse, "shape": [found[0].results[0].size]}
    return out


def adjoint_views(ctx: RenderContext) -> dict[str, dict]:
    """{function: adjoint_view} for the functions of ADJOINTS in `ctx`."""
    printer = NumpyPrinter(local_names(ctx), module="jnp")
    views = {spec.name: adjoint_view(spec, printer) for spec in ctx.functions if spec.name in ADJOINTS}
    return {name: view for name, view in views.items() if view is not None}


def stage_views(
    ctx: RenderContext, adjoints: dict[str, dict], through: dict[str, dict], derived: dict[str, str]
) -> dict[str, list[dict]]:
    """{function: its stages (symdyn.codegen.jax.stages)} for the functions of `adjoints`,
    `through` (IDENTITIES) and STAGED whose body has more than staging.STAGE_ABOVE statements,
    but those differentiated by a rule of `derived` (RULES, not measured in stages). Reverse mode
    goes through the stages for STAGED (JAX's transpose of the body) and is the adjoint program
    for the others (ADJOINTS, IDENTITIES)."""
    printer = NumpyPrinter(local_names(ctx), module="jnp")
    return {
        spec.name: staging.stages(spec, printer, staging.STAGE_SIZE)
        for spec in ctx.functions
        if spec.name not in derived
        and (spec.name in adjoints or spec.name in through or spec.name in STAGED)
        and any(inp.name != "p" for inp in spec.inputs)
        and staging.long_body(spec)
    }


def render(ctx: RenderContext) -> dict[str, str]:
    """{NAME_jax.py: module text} for the robot of `ctx`, its matrices built as matrix_builders says."""
    adjoints = adjoint_views(ctx)
    through = identities(ctx, adjoints)
    derived = {name: d for name, d in rules(ctx).items() if name not in through}
    staged = stage_views(ctx, adjoints, through, derived)
    builders = {spec.name: matrix_builders(spec) for spec in ctx.functions}
    text = render_module(
        ctx,
        "jax/module.py.j2",
        "jnp",
        rules=derived,
        adjoints=adjoints,
        identities=through,
        stages=staged,
        builders=builders,
    )
    return {file_name(ctx.name): text}
