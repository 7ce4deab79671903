"""The CasADi target: a standalone Python module of SX graphs, plus one serialised file per function.

For a robot NAME, `render` returns
* `NAME_casadi.py`: imports only casadi (and math when pi appears); its
  `functions()` returns {name: casadi.Function} for the seven functions of
  docs/generated-code.md, each with the inputs of its FunctionSpec (q, qd, qdd or tau, p;
  p of size k, possibly 0), named so, and one output named like the spec
  (M and C n x n, vectors n x 1). Every function body is the eliminated
  straight-line code, one Python statement per temporary, so the SX graph
  shares what the CSE shared;
* `NAME_<function>.casadi` (bytes): each function as written by
  `casadi.Function.save`, readable with `casadi.Function.load`. They are made
  by executing the rendered module text (symdyn's own output, never user
  input) in a fresh namespace, so the files and the module cannot disagree.

This module builds the render context as plain data (names, numbers, printed
expressions); every Python statement is spelled in templates/casadi/module.py.j2.
"""

from __future__ import annotations

import os
import re
import tempfile
from dataclasses import asdict, replace
from pathlib import Path

from ...errors import SymdynError
from ...generated_modules import load_module
from ...leftovers import sweep_folders
from ..contact_functions import contacts_of
from ..functions import FunctionSpec
from ..loop_solve import loop_solve_context
from ..render import RenderContext, environment, header_lines
from .printer import CasadiPrinter, input_names

__all__ = ["render", "render_module", "serialise", "module_name", "TOOLS"]

#: The tools each file's bytes depend on besides symdyn. The module text is SymPy's expressions
#: printed by symdyn; the serialised functions are also in CasADi's own format.
TOOLS = {"_casadi.py": ("sympy",), ".casadi": ("sympy", "casadi")}


def module_name(ctx: RenderContext) -> str:
    return f"{ctx.name}_casadi"


def _docstring(text: str) -> str:
    """`text` made safe inside a triple-quoted Python docstring."""
    return text.replace("\\", "\\\\").replace('"""', '\\"\\"\\"')


def _function_view(spec: FunctionSpec) -> tuple[dict, bool]:
    """What the template needs for one function: inputs, temporaries, output entries (and math use)."""
    names = input_names(spec.inputs)
    for x, _ in spec.temporaries:
        if x in names:
            raise SymdynError(f"casadi target: temporary '{x}' has the name of an input symbol")
        names[x] = str(x)
    taken = {inp.name for inp in spec.inputs} | {str(x) for x, _ in spec.temporaries}
    for result in spec.results:
        if result.name in taken:
            raise SymdynError(f"casadi target: output name '{result.name}' of {spec.name} is taken")
    printer = CasadiPrinter(names)
    o = spec.ops
    cost = {"temporaries": len(spec.temporaries), "total": o.total, **asdict(o)} if spec.temporaries else None
    view = {
        "name": spec.name,
        "doc": _docstring(re.sub(r",? row-major( n x n)?", "", spec.doc)),
        "inputs": [(inp.name, len(inp.symbols)) for inp in spec.inputs],
        "cost": cost,
        "temporaries": [(str(x), printer.doprint(e)) for x, e in spec.temporaries],
        "outputs": [
            {
                "name": r.name,
                "rows": r.rows,
                "cols": r.cols,
                "entries": [
                    (k // r.cols, k % r.cols, printer.doprint(e))
                    for k, e in enumerate(spec.entries(r))
                    if e != 0
                ],
            }
            for r in spec.results
        ],
    }
    return view, printer.uses_math


def render_module(ctx: RenderContext) -> str:
    """The text of NAME_casadi.py."""
    views, uses_math = [], False
    for spec in ctx.functions:
        view, m = _function_view(spec)
        views.append(view)
        uses_math = uses_math or m
    template = environment().get_template("casadi/module.py.j2")
    return template.render(
        header=header_lines(ctx),
        name=ctx.name,
        module=module_name(ctx),
        n=ctx.robot.n,
        params=[str(p) for p in ctx.dynamics.params],
        functions=views,
        uses_math=uses_math,
        loops=loop_solve_context(ctx, "double"),
        contacts=contacts_of(ctx),
    )


#: the temporary folders of `serialise`: TMPDIR/symdyn-casadi-PID-XXXXXXXX
TEMPORARY_PREFIX = "symdyn-casadi-"


def serialise(text: str, ctx: RenderContext) -> dict[str, bytes]:
    """Write the module text to a temporary file, import it from there (symdyn.generated_modules:
    never exec'd from a string) and save every function with casadi. The folders that runs killed
    on the way left (their process gone, or an hour old) are removed first."""
    files: dict[str, bytes] = {}
    sweep_folders(Path(tempfile.gettempdir()), TEMPORARY_PREFIX)
    with tempfile.TemporaryDirectory(prefix=f"{TEMPORARY_PREFIX}{os.getpid()}-") as tmp:
        source = os.path.join(tmp, f"{module_name(ctx)}.py")
        with open(source, "w", encoding="utf-8") as fh:
            fh.write(text)
        functions = load_module(source, module_name(ctx)).functions()
        for spec in ctx.functions:
            path = os.path.join(tmp, f"{spec.name}.casadi")
            functions[spec.name].save(path)
            with open(path, "rb") as fh:
                files[f"{ctx.name}_{spec.name}.casadi"] = fh.read()
    return files


def render(ctx: RenderContext) -> dict[str, str | bytes]:
    """NAME_casadi.py and one NAME_<function>.casadi per function. CasADi's SX is double only,
    so --precision float does not apply here (the header says double)."""
    text = render_module(replace(ctx, precision="double"))
    files: dict[str, str | bytes] = {f"{module_name(ctx)}.py": text}
    files.update(serialise(text, ctx))
    return files
