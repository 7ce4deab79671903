"""What `symdyn.compile` builds beside the generated C: batch wrappers, the stepping loop, a table.

`function_table(ctx)` describes every generated function as plain data (its C name,
its inputs and outputs with their sizes), so the Python binding (symdyn.apps.compile)
needs no knowledge of which functions exist: whatever `build_functions` generates,
with any number of outputs of any shape, becomes a method. `render_runtime(ctx)` gives
NAME_batch.c (one NAME_batch(count, ...) per function, the loop over a batch in C),
symdyn_step.c (the fixed-step integrators of symdyn.apps.simulate) and symdyn_csv.c (the
CSV writer of symdyn.apps.csv_format), the last two robot-independent. Every C statement
is spelled in templates/c/batch.c.j2, templates/c/step.c.j2 and templates/c/csv.c.j2.
"""

from __future__ import annotations

from ..render import RenderContext, environment, header_lines
from .config import CConfig, c_names

__all__ = ["function_table", "render_runtime", "STEP_SOURCE", "CSV_SOURCE"]

#: The stepping loop's file name (symdyn_simulate, robot-independent).
STEP_SOURCE = "symdyn_step.c"
#: The CSV writer's file name (symdyn_csv, robot-independent, always double).
CSV_SOURCE = "symdyn_csv.c"


def function_table(ctx: RenderContext) -> list[dict]:
    """Every generated function as JSON-ready data: name, C name, doc, inputs and outputs with sizes."""
    names = c_names(ctx)
    return [
        {
            "name": spec.name,
            "c_name": names.functions[spec.name],
            "doc": spec.doc,
            "inputs": [[inp.name, len(inp.symbols)] for inp in spec.inputs],
            "outputs": [[r.name, r.rows, r.cols, r.matrix] for r in spec.results],
        }
        for spec in ctx.functions
    ]


def render_runtime(ctx: RenderContext) -> dict[str, str]:
    """NAME_batch.c, symdyn_step.c and symdyn_csv.c for the robot of `ctx` (compiled with NAME_dynamics.c)."""
    names = c_names(ctx)
    real = CConfig(ctx.precision).real
    functions = [
        {
            "c_name": f["c_name"],
            "inputs": [(name, size) for name, size in f["inputs"]],
            "outputs": [(name, rows * cols) for name, rows, cols, _ in f["outputs"]],
        }
        for f in function_table(ctx)
    ]
    env = environment()
    lines = header_lines(ctx)
    return {
        f"{ctx.name}_batch.c": env.get_template("c/batch.c.j2").render(
            header_lines=lines, header_file=names.header_file, real=real, functions=functions
        ),
        STEP_SOURCE: env.get_template("c/step.c.j2").render(header_lines=lines, real=real),
        CSV_SOURCE: env.get_template("c/csv.c.j2").render(header_lines=lines),
    }
