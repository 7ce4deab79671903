"""The NumPy target: `NAME_numpy.py`, a standalone module (imports numpy and array-api-compat).

It holds the seven functions of docs/generated-code.md with the C target's names and
arguments (p optional when the robot has no free parameters), plus NDOF,
NPARAM and PARAM_NAMES. Every function evaluates the eliminated form of its
FunctionSpec, one statement per temporary, elementwise: it works for one
state (vectors of shape (n,)) or a batch with leading axes ((N, n); p either
(k,) or (N, k)). The outputs are assembled by broadcasting every entry to the
common leading shape, so constant entries (0) get the batch shape too.
Inputs and outputs are float64 (DTYPE), float32 with precision "float".
forward_dynamics is the unrolled LDL^T solve of the spec, elementwise as well. The module is
written against the Python array API standard: each call takes its namespace from its
inputs (array-api-compat), so that NumPy, JAX, PyTorch and CuPy arrays all work; NumPy
arrays, lists and numbers take NumPy's own namespace at once (no wrapper: NumPy's speed).

This module builds the render context as plain data (names, shapes, printed
expressions); every Python statement is spelled in templates/python/module.py.j2.
"""

from __future__ import annotations

import weakref

from ..contact_functions import contacts_of
from ..functions import FunctionSpec
from ..loop_solve import loop_solve_context
from ..render import RenderContext, environment, header_lines
from .printer import NumpyPrinter, dtype, local_names

__all__ = ["render", "render_module", "file_name", "function_view", "TOOLS"]

#: The inputs with one value per joint (NDOF); any other input has a fixed size (F: 6).
JOINT_INPUTS = ("q", "qd", "qdd", "tau")

#: The tools the file's bytes depend on besides symdyn: SymPy builds and prints every expression.
TOOLS = {"_numpy.py": ("sympy",)}


def file_name(name: str) -> str:
    return f"{name}_numpy.py"


def _size(inp, floating: bool) -> str:
    """An input's size: NDOF for the joint vectors (NQ for a floating robot's q), else a number."""
    if inp.name == "q" and floating:
        return "NQ"
    return "NDOF" if inp.name in JOINT_INPUTS else str(len(inp.symbols))


def function_view(spec: FunctionSpec, printer: NumpyPrinter, floating: bool = False) -> dict:
    """One function as data: arguments (and their sizes: NDOF or a number), the input elements
    it reads, temporaries, output entries."""
    free = spec.free_symbols
    return {
        "name": spec.name,
        "doc": spec.doc,
        "inputs": [inp.name for inp in spec.inputs if inp.name != "p"],
        "sizes": {inp.name: _size(inp, floating) for inp in spec.inputs},
        "has_p": any(inp.name == "p" for inp in spec.inputs),
        "lead": [inp.name for inp in spec.inputs],
        "unpack": [
            (printer.doprint(s), inp.name, k)
            for inp in spec.inputs
            for k, s in enumerate(inp.symbols)
            if s in free
        ],
        "temporaries": [(printer.doprint(s), printer.doprint(e)) for s, e in spec.temporaries],
        "outputs": [
            {
                "name": r.name,
                "shape": [r.rows, r.cols] if r.matrix else [r.rows],
                "entries": [printer.doprint(e) for e in spec.entries(r)],
            }
            for r in spec.results
        ],
    }


#: Printed in place of the array namespace, then replaced by the module's own ("xp", "jnp"), so
#: that one printing of a context's expressions serves both the NumPy and the JAX module (the
#: printer writes the namespace only as the prefix of its functions; NUL is never in printed code).
_NAMESPACE = "\x00"
#: [weak reference to the last context printed, its function views with _NAMESPACE]
_last: list = [None, None]


def _printed_views(ctx: RenderContext) -> list[dict]:
    ref, views = _last
    if ref is None or ref() is not ctx:
        printer = NumpyPrinter(local_names(ctx), module=_NAMESPACE)
        views = [function_view(spec, printer, ctx.robot.floating) for spec in ctx.functions]
        _last[:] = [weakref.ref(ctx), views]
    return views


def _in_namespace(view: dict, namespace: str) -> dict:
    """A view of _printed_views with its printed expressions calling `namespace`."""

    def fix(text: str) -> str:
        return text.replace(_NAMESPACE, namespace)

    return {
        **view,
        "unpack": [(fix(name), inp, k) for name, inp, k in view["unpack"]],
        "temporaries": [(fix(name), fix(value)) for name, value in view["temporaries"]],
        "outputs": [{**out, "entries": [fix(e) for e in out["entries"]]} for out in view["outputs"]],
    }


def render_module(ctx: RenderContext, template: str, namespace: str, **extra) -> str:
    """The text of a Python module of the robot of `ctx` from `template` (a path under templates/),
    its expressions printed with the array namespace `namespace` ("xp", "jnp"); `extra` are
    further variables of the template (a target's own)."""
    return (
        environment()
        .get_template(template)
        .render(
            header=header_lines(ctx),
            name=ctx.name,
            ndof=ctx.robot.nv,
            nq=ctx.robot.nq if ctx.robot.floating else None,
            param_names=[s.name for s in ctx.dynamics.params],
            dtype=dtype(ctx.precision),
            functions=[_in_namespace(view, namespace) for view in _printed_views(ctx)],
            loops=loop_solve_context(ctx),
            contacts=contacts_of(ctx),
            **extra,
        )
    )


def render(ctx: RenderContext) -> dict[str, str]:
    """{NAME_numpy.py: module text} for the robot of `ctx`."""
    return {file_name(ctx.name): render_module(ctx, "python/module.py.j2", "xp")}
