"""The JAX target: `NAME_jax.py`, a module of jax.numpy functions of one state (imports only jax).

It holds every function of the context (docs/generated-code.md) with the NumPy target's
names and arguments, written for ONE state: vectors of shape (n,), p of shape (k,). The
bodies are the eliminated straight-line code, one statement per temporary, with no branch
on a value, no in-place update and no NumPy call, so that jax.jit, jax.vmap, jax.grad and
jax.jacfwd, and jax.lax.scan apply to them unchanged; p is an argument, so parameters can
be fitted by gradient. Vectors are returned through jax.lax.select_n (the module's
_vector_of), not jnp.array, a concatenate that XLA's CPU fusion emitters made 280 times
slower under jax.vmap for the Panda (docs/jax.md). Each function has a batched twin NAME_batch
(vmapped over the leading axis of the arguments that have one, jitted). Inputs and outputs are float64
(--precision double, which needs JAX's x64 mode: the module refuses to import without it
rather than compute in float32) or float32. The functions of RULES are jax.custom_jvp functions
whose rule is their generated derivative function (the module's _analytic_jvp; on a floating
base q's NQ entries mapped to the tangent space by _q_to_tangent).

The names, shapes and printed expressions are the NumPy target's (symdyn.codegen.python,
printed with the namespace `jnp`); every Python statement is spelled in templates/jax/module.py.j2.
"""

from __future__ import annotations

from ..python.target import render_module
from ..render import RenderContext

__all__ = ["render", "file_name", "TOOLS", "RULES"]

#: The functions differentiated by a jax.custom_jvp rule made of a generated derivative function,
#: {function: derivative function}, when the module holds both: the derivative function returns
#: the Jacobians by each input of the function but p, in the order of the inputs (forward
#: dynamics: dqdd/dq, dqdd/dqd, dqdd/dtau = M^-1). Chosen by measurement (bench/jax.py,
#: docs/jax.md): for the Panda, jax.jit(jax.grad(...)) through jax.vmap of the forward dynamics
#: took 6.2 ms a state by XLA's reverse mode and 108 us by the rule; the inverse dynamics keeps
#: XLA's autodiff, which was faster than its rule (12 against 17 us; jacfwd 16 against 31 us).
RULES = {"forward_dynamics": "forward_dynamics_derivatives"}

#: The tools the file's bytes depend on besides symdyn: SymPy builds and prints every expression.
TOOLS = {"_jax.py": ("sympy",)}


def file_name(name: str) -> str:
    return f"{name}_jax.py"


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


def render(ctx: RenderContext) -> dict[str, str]:
    """{NAME_jax.py: module text} for the robot of `ctx`."""
    return {file_name(ctx.name): render_module(ctx, "jax/module.py.j2", "jnp", rules=rules(ctx))}
