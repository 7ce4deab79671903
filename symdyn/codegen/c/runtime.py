"""What `symdyn.compile` builds beside the generated C: batch wrappers, the stepping loop, a table.

`function_table(ctx)` describes every generated function as plain data (its C name,
its inputs and outputs with their sizes), so the Python binding (symdyn.apps.compilation.compile)
needs no knowledge of which functions exist: whatever `build_functions` generates,
with any number of outputs of any shape, becomes a method; `solve_loops_entry(ctx)` describes
NAME_solve_loops of a robot with closed loops, the one function with a loop (not in the table:
it returns an int). `render_runtime(ctx)` gives
NAME_batch.c (one NAME_batch(count, ...) per function, the loop over a batch in C, W states
per instruction through the function's body over vectors: symdyn.codegen.c.vector; and
NAME_solve_loops_batch, a plain loop over the states; a large robot's in NAME_batch.c,
NAME_batch_2.c ..., symdyn.codegen.c.vector_files),
symdyn_step.c (the fixed-step integrators of symdyn.apps.simulation.simulate) and symdyn_csv.c (the
CSV writer of symdyn.apps.simulation.csv_format), the last two robot-independent. Every C statement
is spelled in templates/c/batch.c.j2, templates/c/step.c.j2 and templates/c/csv.c.j2.
"""

from __future__ import annotations

from ..loop_solve import loop_solve_context
from ..render import RenderContext, environment, header_lines
from .config import CConfig, c_names
from .parts import placement
from .sincos import BLOCK
from .vector import LANE_CALLS, simd_prefix, vector_view
from .vector_files import batch_file_name, vector_layout

__all__ = ["function_table", "solve_loops_entry", "render_runtime", "STEP_SOURCE", "CSV_SOURCE"]

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


def solve_loops_entry(ctx: RenderContext) -> dict | None:
    """NAME_solve_loops(qa, q_guess, p, q) as JSON-ready data (its C name, the sizes of qa and of
    q) for a robot with closed loops; None for a tree."""
    view = loop_solve_context(ctx)
    if view is None:
        return None
    return {
        "c_name": f"{ctx.name}_solve_loops",
        "nact": len(view["actuated"]),
        "n": len(view["actuated"]) + len(view["passive"]),
    }


def render_runtime(ctx: RenderContext) -> dict[str, str]:
    """NAME_batch.c (a large robot's also NAME_batch_2.c ... and NAME_batch_parts.h), symdyn_step.c
    and symdyn_csv.c for the robot of `ctx` (compiled with NAME_dynamics.c ...)."""
    names = c_names(ctx)
    config = CConfig(ctx.precision)
    prefix = simd_prefix(ctx)
    functions = []
    for f, spec in zip(function_table(ctx), ctx.functions, strict=True):
        inputs = [(name, size) for name, size in f["inputs"]]
        functions.append(
            {
                "c_name": f["c_name"],
                "inputs": inputs,
                "outputs": [(name, rows * cols) for name, rows, cols, _ in f["outputs"]],
                "vector": vector_view(ctx, names, spec),
            }
        )
    hidden = f"{ctx.name}_SIMD_HIDDEN"
    added = {prefix + f.name for f in ctx.functions} | {f"{ctx.name}_batch_width", hidden}
    taken = set(names.functions.values()) | {c + "_batch" for c in names.functions.values()}
    assert not added & taken, f"a generated function has the name of a batch helper: {added & taken}"
    env = environment()
    trig = any(f["vector"] and (f["vector"]["angles"] or f["vector"]["lane_pairs"]) for f in functions)
    values = {
        "name": ctx.name,
        "header_lines": header_lines(ctx),
        "header_file": names.header_file,
        "real": config.real,
        "W": f"{ctx.name}_SIMD_W",
        "width": f"{ctx.name}_batch_width",
        "vd": f"{ctx.name}_vd",
        "vi": f"{ctx.name}_vi",
        "P": prefix,
        "hidden": hidden,
        "lane_calls": [config.math(c) for c in LANE_CALLS],
        "pow": config.math("pow"),
        "sincos": {**names.sincos, "block": BLOCK} if trig else None,
    }
    files = _batch_files(ctx, env, values, functions)
    files[STEP_SOURCE] = env.get_template("c/step.c.j2").render(
        header_lines=values["header_lines"], real=config.real
    )
    files[CSV_SOURCE] = env.get_template("c/csv.c.j2").render(header_lines=values["header_lines"])
    return files


def _batch_files(ctx: RenderContext, env, values: dict, functions: list[dict]) -> dict[str, str]:
    """NAME_batch.c, and for a large robot NAME_batch_2.c ... and the internal header
    NAME_batch_parts.h (symdyn.codegen.c.vector_files): each file with the parts, blocks and
    wrappers of its units, and the helpers these need."""
    vectors = [f["vector"] for f in functions]
    shared, placed = placement(
        vector_layout(vectors), [v["parts"]["parts"] if v and v["parts"] else [] for v in vectors]
    )
    files = {}
    header = f"{ctx.name}_batch_parts.h" if shared else None
    if header:
        guard = f"{ctx.name.upper()}_SIMD_PARTS_H"
        shared = [(vectors[i], part) for i, part in shared]
        files[header] = env.get_template("c/batch_parts.h.j2").render(values, shared=shared, guard=guard)
    for k, (members, linked) in enumerate(placed):
        chosen = [{**functions[i], "here": here, "defined": defined} for i, here, defined in members]
        blocks = [f["vector"] for f in chosen if f["defined"] and f["vector"]]
        files[batch_file_name(ctx.name, k)] = env.get_template("c/batch.c.j2").render(
            values,
            functions=chosen,
            first=k == 0,
            parts_header=header if linked else None,
            sincos_helper=any(v["angles"] or v["lane_pairs"] for v in blocks),
            sincos_groups=sorted({len(group) for v in blocks for _, group in v["angle_groups"]}),
            loops=solve_loops_entry(ctx) if k == 0 else None,
        )
    return files
