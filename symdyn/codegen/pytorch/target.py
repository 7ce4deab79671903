"""The PyTorch target: `NAME_torch.py`, a module of torch functions (imports only torch).

It holds every function of the context (docs/generated-code.md) with the NumPy target's
names and arguments, for one state (tensors of shape (n,)) or a batch with leading axes
((N, n); p either (k,) or (N, k)), like the NumPy module. The bodies are the eliminated
straight-line code, one statement per temporary, elementwise, with no branch on a value, no
in-place write and no NumPy call, so that torch.autograd, torch.func (vmap, grad, jacrev,
jacfwd) and torch.compile apply to them unchanged. Inputs are converted to DTYPE (float64,
float32 with --precision float) with Tensor.to, which keeps their autograd graph, on the
device of the tensors given (tensors on two devices are refused); outputs are tensors of DTYPE
on that device.

Why a target beside the NumPy module, which runs on torch tensors through array-api-compat
(tests/test_torch_target.py runs it too): torch.compile traces into array-api-compat's
namespace lookup (a warning for each of its cached helpers, and a longer trace), and
torch.asarray warns on every input that requires a gradient. Here the namespace is torch itself.

The names, shapes and printed expressions are the NumPy target's (symdyn.codegen.python,
printed with the namespace `torch`); every Python statement is spelled in templates/torch/module.py.j2.
"""

from __future__ import annotations

from ..python.target import render_module
from ..render import RenderContext

__all__ = ["render", "file_name", "TOOLS"]

#: The tools the file's bytes depend on besides symdyn: SymPy builds and prints every expression.
TOOLS = {"_torch.py": ("sympy",)}


def file_name(name: str) -> str:
    return f"{name}_torch.py"


def render(ctx: RenderContext) -> dict[str, str]:
    """{NAME_torch.py: module text} for the robot of `ctx`."""
    return {file_name(ctx.name): render_module(ctx, "torch/module.py.j2", "torch")}
