"""The MATLAB/Octave target: one NAME_<function>.m per generated function (plain .m, no toolbox).

Each function of symdyn.codegen.functions becomes a function file whose outputs are returned,
`tau = NAME_inverse_dynamics(q, qd, qdd, p)`, several of them as `[A, B] = ...`: the inputs
it reads are copied into named locals (q(1) into q1, ...), then one assignment per temporary,
then the outputs as column vectors or matrices (MATLAB's own indexing, from 1). Vectors may be
rows or columns; `p` (the free parameters in the robot's order) may be [] or left out when the
robot has none. Every file starts with the help line and the header of every target (source,
parameters, operation counts).

This module builds the render context as plain data: names (symdyn.codegen.matlab.config)
and expression texts (symdyn.codegen.matlab.printer); every MATLAB statement is spelled in
templates/matlab/function.m.j2.
"""

from __future__ import annotations

import re

from ...errors import SymdynError
from ..functions import FunctionSpec
from ..loop_solve import loop_solve_context
from ..render import RenderContext, environment, header_lines
from .config import TEMPORARY, MatlabNames, matlab_names
from .printer import MatlabPrinter

__all__ = ["render", "TOOLS", "function_view"]

#: The tools each file's bytes depend on besides symdyn (SymPy builds every expression).
TOOLS = {".m": ("sympy",)}


def function_view(ctx: RenderContext, names: MatlabNames, spec: FunctionSpec) -> dict:
    """One function as data: signature, checks of the input sizes, locals, temporaries, outputs."""
    symbol_names = dict(names.locals)
    for sym, _ in spec.temporaries:
        if sym in symbol_names or not TEMPORARY.match(sym.name):
            raise SymdynError(
                f"robot '{ctx.name}': temporary '{sym}' of {spec.name} has the name of an input"
            )
        symbol_names[sym] = sym.name
    printer = MatlabPrinter(symbol_names)
    used = spec.free_symbols
    reads = [
        (names.locals[s], inp.name, k + 1)
        for inp in spec.inputs
        for k, s in enumerate(inp.symbols)
        if s in used
    ]
    outputs = []
    for r in spec.results:
        entries = spec.entries(r)
        stores = [((k // r.cols) + 1, (k % r.cols) + 1, printer.doprint(e)) for k, e in enumerate(entries)]
        outputs.append(
            {
                "name": r.name,
                "doc": r.doc,
                "rows": r.rows,
                "cols": r.cols,
                "matrix": r.matrix,
                "stores": [s for s in stores if s[2] != "0.0"],
            }
        )
    return {
        "name": names.functions[spec.name],
        "doc": re.sub(r", row-major( n x n)?", "", spec.doc),  # MATLAB returns matrices as such
        "ops": spec.ops.summary(),
        "inputs": [{"name": inp.name, "size": len(inp.symbols)} for inp in spec.inputs],
        "outputs": outputs,
        "reads": reads,
        "temporaries": [(sym.name, printer.doprint(expr)) for sym, expr in spec.temporaries],
    }


def render(ctx: RenderContext) -> dict[str, str]:
    """{NAME_<function>.m: text} for every generated function of the robot of `ctx`."""
    if ctx.precision != "double":
        raise SymdynError("the matlab target computes in double precision only (no --precision float)")
    names = matlab_names(ctx)
    template = environment().get_template("matlab/function.m.j2")
    params = [str(p) for p in ctx.dynamics.params]
    files = {}
    for spec in ctx.functions:
        view = function_view(ctx, names, spec)
        files[f"{view['name']}.m"] = template.render(
            f=view, header_lines=header_lines(ctx), n=ctx.robot.n, params=params
        )
    loops = loop_solve_context(ctx)
    if loops is not None:
        name = f"{ctx.name}_solve_loops"
        files[f"{name}.m"] = (
            environment()
            .get_template("matlab/solve_loops.m.j2")
            .render(
                name=name,
                step=names.functions["loop_newton_step"],
                loops=loops,
                header_lines=header_lines(ctx),
                n=ctx.robot.n,
                actuated=[j + 1 for j in loops["actuated"]],
                passive=[j + 1 for j in loops["passive"]],
            )
        )
    return files
