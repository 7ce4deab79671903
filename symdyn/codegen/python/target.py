"""The NumPy target: `NAME_numpy.py`, a standalone module (imports only numpy).

It holds the seven functions of docs/generated-code.md with the C target's names and
arguments (p optional when the robot has no free parameters), plus NDOF,
NPARAM and PARAM_NAMES. Every function evaluates the eliminated form of its
FunctionSpec, one statement per temporary, elementwise: it works for one
state (vectors of shape (n,)) or a batch with leading axes ((N, n); p either
(k,) or (N, k)). The outputs are assembled by broadcasting every entry to the
common leading shape, so constant entries (0) get the batch shape too.
Inputs and outputs are float64 (DTYPE), float32 with precision "float".
forward_dynamics is the unrolled LDL^T solve of the spec, elementwise as well.

This module builds the render context as plain data (names, shapes, printed
expressions); every Python statement is spelled in templates/python/module.py.j2.
"""

from __future__ import annotations

from ..functions import FunctionSpec
from ..render import RenderContext, environment, header_lines
from .printer import NumpyPrinter, dtype, local_names

__all__ = ["render", "file_name", "TOOLS"]

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


def _function(spec: FunctionSpec, printer: NumpyPrinter, floating: bool = False) -> dict:
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


def render(ctx: RenderContext) -> dict[str, str]:
    """{NAME_numpy.py: module text} for the robot of `ctx`."""
    printer = NumpyPrinter(local_names(ctx))
    text = (
        environment()
        .get_template("python/module.py.j2")
        .render(
            header=header_lines(ctx),
            name=ctx.name,
            ndof=ctx.robot.nv,
            nq=ctx.robot.nq if ctx.robot.floating else None,
            param_names=[s.name for s in ctx.dynamics.params],
            dtype=dtype(ctx.precision),
            functions=[_function(spec, printer, ctx.robot.floating) for spec in ctx.functions],
        )
    )
    return {file_name(ctx.name): text}
