"""The C target: NAME_dynamics.h and NAME_dynamics.c (C99, no allocation, libm only), and a
CMakeLists.txt building them as a static library.

The contract is docs/generated-code.md. Each of the seven functions
(symdyn.codegen.functions) becomes straight-line code: the inputs it reads are
copied into named locals, then one constant per temporary, then the outputs
(row-major for M and C). Inputs a function does not read are cast to void so
-Wextra stays quiet, and `p` is never read when the robot has no free
parameters (it may be NULL then).

This module builds the render context as plain data: names (symdyn.codegen.c.config)
and expression texts (symdyn.codegen.c.printer) in lists of pairs and triples.
Every C statement, declaration, signature, macro and comment is spelled in
templates/c/*.j2.
"""

from __future__ import annotations

import sympy as sp

from ...errors import SymdynError
from ..contact_functions import contacts_of
from ..frame_functions import comment_text
from ..functions import FunctionSpec
from ..loop_solve import loop_solve_context
from ..regressor_functions import columns
from ..render import RenderContext, environment, header_lines
from .config import TEMPORARY, CConfig, CNames, c_names
from .order import statement_order
from .parts import layout, part_counts, placement, reads_in, source_file_name, split_body
from .printer import CPrinter
from .sincos import BLOCK, FREESTANDING_ERROR, gather

__all__ = ["render", "render_context", "symbol_names", "function_inputs", "TOOLS"]

#: The inputs with one value per joint (NAME_NDOF); any other input has a fixed size (F: 6) or one
#: value per actuated joint (NAME_NACT, ACTUATED_INPUTS: robots with loops).
JOINT_INPUTS = ("q", "qd", "qdd", "tau")
ACTUATED_INPUTS = ("qda", "qdda", "tau_a")

#: an output with at least this many exact zeros, a third of its entries or more, has its runs of
#: consecutive zeros zeroed by loops (vector stores) before its other entries are stored: a
#: floating robot's or a tree's M has more zeros than non-zeros (joints on different branches),
#: and one store per zero costs more
FILL_ZEROS = 16

#: The tools each file's bytes depend on besides symdyn (SymPy builds every expression; the
#: CMakeLists.txt header carries the operation counts).
TOOLS = {
    "_dynamics.h": ("sympy",),
    "_dynamics_parts.h": ("sympy",),
    ".c": ("sympy",),
    "CMakeLists.txt": ("sympy",),
}  # .c: NAME_dynamics.c, NAME_dynamics_2.c, ...

#: the build file written beside the C files (templates/c/CMakeLists.txt.j2)
CMAKE_FILE = "CMakeLists.txt"


def _sincos_view(
    ctx: RenderContext, names: CNames, spec: FunctionSpec, symbol_names: dict
) -> tuple[CPrinter, list, dict | None]:
    """The printer of a function's code, the temporaries it keeps, and its angles as data.

    In double precision sin(a) and cos(a) become NAME_SIN(k, a) and NAME_COS(k, a) over the
    function's k-th angle a (symdyn.codegen.c.sincos): entry k of the arrays NAME_sincos fills
    when the compiler targets AVX2, else sin(a) and cos(a) (templates/c/sincos.c.j2). The
    angles are printed with the C library's calls (an angle may itself hold a sine) and padded
    with zeros to the arrays' size. Under --precision float every call stays sinf or cosf, unless
    the file is freestanding: then, in either precision, the arrays are always filled by
    NAME_sincos, symdyn's own (templates/c/sincos.c.j2), and no other call of the C library may
    appear (symdyn.codegen.c.config.CConfig.math).
    """
    plain = CPrinter(symbol_names, ctx.precision, freestanding=ctx.freestanding)
    if ctx.precision != "double" and not ctx.freestanding:
        return plain, list(spec.temporaries), None
    trig = gather(spec.temporaries, spec.outputs)
    temporaries = [(s, e) for s, e in spec.temporaries if s in trig.live]
    angles = [plain.doprint(a) for a in trig.angles]
    macros = (names.sincos["sin"], names.sincos["cos"])
    calls = {call: f"{macros[which]}({k}, {angles[k]})" for call, (which, k) in trig.calls.items()}
    printer = CPrinter(symbol_names, ctx.precision, calls, ctx.freestanding)
    if not angles:
        return printer, temporaries, None
    padding = [CPrinter({}, ctx.precision).literal(0.0)] * (trig.size - len(angles))
    view = {"count": len(angles), "size": trig.size, "angles": angles + padding, "pointer": None}
    run = trig.contiguous(spec.inputs) if ctx.freestanding else None
    if run is not None:
        # a freestanding NAME_sincos reads exactly `count` angles: it reads them in the input
        # array, and the inputs read only as angles are not copied into locals (saved on the
        # Cortex-M4F: a load and a store per angle, and the array on the stack)
        view["pointer"] = f"{run[0]} + {run[1]}" if run[1] else run[0]
        view["inputs"] = {names.locals[s] for s in trig.inputs}
    return printer, temporaries, view


def symbol_names(ctx: RenderContext, names: CNames, spec: FunctionSpec) -> dict:
    """The C name of every symbol a function's code reads: its input locals and temporaries."""
    known = dict(names.locals)
    for sym, _ in spec.temporaries:
        if sym in known or not TEMPORARY.match(sym.name):
            raise SymdynError(
                f"robot '{ctx.name}': temporary '{sym}' of {spec.name} has the name of an input "
                "(or no C name); rename the parameter"
            )
        known[sym] = sym.name
    return known


def function_inputs(names: CNames, spec: FunctionSpec) -> tuple[list, list, list]:
    """(inputs, unused, reads) of a function: each input's name, whether it is read and its size;
    the inputs it never reads; (local, input, index) of every input value it copies into a local."""
    used_symbols = spec.free_symbols
    inputs, unused, reads = [], [], []
    for inp in spec.inputs:
        used = [s for s in inp.symbols if s in used_symbols]
        size = names.ndof if inp.name in JOINT_INPUTS else str(len(inp.symbols))
        size = names.dims["nact"] if inp.name in ACTUATED_INPUTS else size
        size = names.dims["ncontact"] if inp.name == "active" else size
        size = names.dims["nanchor"] if inp.name == "anchor" else size
        if inp.name == "q" and names.nq is not None:
            size = names.nq
        inputs.append({"name": inp.name, "read": bool(used), "size": size})
        if not used:
            unused.append(inp.name)
        for s in used:
            index = names.param_macro[s] if inp.name == "p" else str(inp.symbols.index(s))
            reads.append((names.locals[s], inp.name, index))
    return inputs, unused, reads


def _function_view(ctx: RenderContext, names: CNames, spec: FunctionSpec, count: int | None = None) -> dict:
    """One function as data: its inputs, the locals it reads, temporaries and output stores;
    `count`: the number of parts to cut it into (0: whole; None: symdyn.codegen.c.parts decides)."""
    printer, temporaries, sincos = _sincos_view(ctx, names, spec, symbol_names(ctx, names, spec))
    inputs, unused, reads = function_inputs(names, spec)
    if sincos and sincos["pointer"]:
        reads = [read for read in reads if read[0] in sincos["inputs"]]
    real = CConfig(ctx.precision).real
    outputs = []
    for result in spec.results:
        rows, cols = (names.dims[d] for d in result.dims)
        if result.matrix:
            size = f"{rows}*{cols} values, row-major: {result.name}[i*{cols} + j] is row i, column j"
        else:
            size = f"{rows} values"
        entries = spec.entries(result)
        zeros = sum(1 for e in entries if e == 0)
        fill = zeros >= FILL_ZEROS and 3 * zeros >= len(entries)
        outputs.append(
            {
                "name": result.name,
                "doc": result.doc,
                "size": size,
                "fill": len(entries) if fill else 0,
                "zero_runs": _zero_runs(entries) if fill else [],
                "stores": [(k, printer.doprint(e)) for k, e in enumerate(entries) if not (fill and e == 0)],
                # a matrix's entries through a volatile lvalue, ((volatile double *)M)[k] = x: the
                # compiler then writes each where the code computes it, instead of gathering values
                # computed far apart into vector registers to store adjacent entries at once (GCC's
                # SLP vectorizer at -O2 and -O3: shuffles, values kept alive across the function).
                # gcc 12, AMD EPYC (Zen 4): Talos' floating M 690 -> 575 ns, the Panda's M 91 -> 74
                # ns; vector outputs (tau, qdd) gained nothing and keep plain stores
                "target": f"((volatile {real} *){result.name})" if result.matrix else result.name,
            }
        )
    printed = [(sym.name, printer.doprint(expr)) for sym, expr in temporaries]
    body = _body(spec, temporaries, printed, outputs)
    arguments = [inp["name"] for inp in inputs] + [out["name"] for out in outputs]
    parts = split_body(body, reads, names.functions[spec.name], arguments, count)
    return {
        "body": body,
        "parts": parts,
        # with parts, the function itself reads only the inputs of its angles (symdyn.codegen.c.parts)
        "angle_reads": (
            reads_in(sincos["angles"], reads) if parts and sincos and not sincos["pointer"] else []
        ),
        "name": spec.name,
        "c_name": names.functions[spec.name],
        "doc": spec.doc,
        "ops": spec.ops.summary(),
        "inputs": inputs,
        "outputs": outputs,
        "width": max(len(a) for a in [*(inp.name for inp in spec.inputs), *(r.name for r in spec.results)]),
        "unused": unused,
        "reads": reads,
        "sincos": sincos,
        "temporaries": printed,
    }


def _zero_runs(entries: list) -> list[tuple[int, int]]:
    """The runs [start, end) of consecutive exact zeros among an output's entries (row-major): each
    is zeroed by one loop that the compiler turns into vector stores. Zeroing the whole output and
    then storing the rest wrote a Talos M (1444 entries, 762 of them zero) twice: 150 of its 750 ns."""
    runs: list[list[int]] = []
    for k, e in enumerate(entries):
        if e == 0:
            if runs and runs[-1][1] == k:
                runs[-1][1] = k + 1
            else:
                runs.append([k, k + 1])
    return [(a, b) for a, b in runs]


def last_reads(temporaries: list, entries: list) -> list[int]:
    """For each output entry, the index of the last of `temporaries` ((symbol, expression), in
    order) that it reads, or -1 when it reads none: where the entry can be stored."""
    position = {sym: k for k, (sym, _) in enumerate(temporaries)}
    return [
        max((position[s] for s in sp.sympify(e).free_symbols if s in position), default=-1) for e in entries
    ]


def _body(spec: FunctionSpec, temporaries: list, printed: list[tuple[str, str]], outputs: list[dict]) -> list:
    """The statements of a function after its inputs are read: ("let", name, value) for each
    temporary (`printed`: their names and printed values) and ("store", "OUT[k]", value) for each
    output entry of `outputs` (their printed stores), every store right after the last temporary
    it reads (or first, when it reads none), and each store's temporaries computed just before it
    (symdyn.codegen.c.order). A value stored as soon as it is known needs no register or stack
    slot to the end of the function: the stores of a large M at the end made the compiler spill
    hundreds of temporaries to the stack and load them back."""
    position = {sym: k for k, (sym, _) in enumerate(temporaries)}

    def reads(expr: sp.Expr) -> list[int]:
        return sorted(position[s] for s in sp.sympify(expr).free_symbols if s in position)

    stores = []
    for result, view in zip(spec.results, outputs, strict=True):
        entries = spec.entries(result)
        for k, value in view["stores"]:
            stores.append((reads(entries[k]), ("store", f"{view['target']}[{k}]", value)))
    # the stores in the order of the last temporary each reads (the first: those reading none)
    stores.sort(key=lambda store: store[0][-1] if store[0] else -1)
    deps = [reads(expr) for _, expr in temporaries]
    lets = [("let", name, value) for name, value in printed]
    return [
        lets[k] if kind == "let" else stores[k][1]
        for kind, k in statement_order(deps, [r for r, _ in stores])
    ]


def render_context(ctx: RenderContext, counts: list[int] | None = None) -> dict:
    """Everything templates/c/ needs for the robot of `ctx`: names, numbers and printed expressions
    (`counts`: the number of parts of each function, 0 for a whole one; None: the rule's)."""
    names = c_names(ctx)
    functions = [
        _function_view(ctx, names, spec, None if counts is None else counts[k])
        for k, spec in enumerate(ctx.functions)
    ]
    return {
        "name": ctx.name,
        "real": CConfig(ctx.precision).real,
        "header_lines": header_lines(ctx),
        "header_file": names.header_file,
        "source_file": names.source_file,
        "guard": names.guard,
        "ndof": names.ndof,
        "n": ctx.robot.nv,
        "floating": ctx.robot.floating,
        "joints": ctx.robot.n,
        "nq_macro": names.nq,
        "nv_macro": names.nv,
        "nq": ctx.robot.nq,
        "nparam": names.nparam,
        "k": len(ctx.dynamics.params),
        "param_pattern": names.param_pattern,
        "param_macros": list(names.param_macros),
        "aliases": list(names.aliases),
        "functions": functions,
        "column_sizes": _column_sizes(ctx, names),
        "frames": [(comment_text(name), ident, link) for name, ident, link in ctx.frames],
        "sincos": {**names.sincos, "block": BLOCK} if any(f["sincos"] for f in functions) else None,
        "freestanding": ctx.freestanding,
        "sincos_error": FREESTANDING_ERROR[ctx.precision],
        "parts": names.parts if any(f["parts"] for f in functions) else None,
        "loops": _loops_view(ctx, names),
        "contacts": _contacts_view(ctx, names),
    }


def _contacts_view(ctx: RenderContext, names: CNames) -> dict | None:
    """The contacts' macros and table (templates/c/dynamics.h.j2) when the contact functions are built."""
    contacts = contacts_of(ctx)
    if not contacts:
        return None
    return {
        "ncontact": names.dims["ncontact"],
        "nlambda": names.dims["nlambda"],
        "nanchor": names.dims["nanchor"] if any(f.name == "contact_error" for f in ctx.functions) else None,
        "count": len(contacts),
        "rows": sum(c.rows for c in contacts),
        "table": [(c.name, comment_text(c.frame), c.kind, c.rows) for c in contacts],
    }


def _loops_view(ctx: RenderContext, names: CNames) -> dict | None:
    """NAME_solve_loops' data (templates/c/dynamics.c.j2) for a robot with loops: sizes, the
    coordinates it sets and solves, its tolerance and iteration bound (symdyn.codegen.loop_solve)."""
    view = loop_solve_context(ctx)
    if view is None:
        return None
    if ctx.freestanding:
        raise SymdynError(
            f"robot '{ctx.name}': --freestanding: the solver of its closed loops needs the C library's "
            "<math.h> (fabs, isnan, isfinite); generate it without --freestanding"
        )
    suffix = CConfig(ctx.precision).literal_suffix
    return {
        **view,
        "nact": names.dims["nact"],
        "npas": names.dims["npas"],
        "tol": f"{view['tol']}{suffix}",
        "pivot": f"{view['pivot']}{suffix}",
        "abs": "fabsf" if ctx.precision == "float" else "fabs",
        "step": names.functions["loop_newton_step"],
        "c_name": f"{ctx.name}_solve_loops",
    }


def _column_sizes(ctx: RenderContext, names: CNames) -> list[dict]:
    """The column counts of the regressor outputs (size names nstd, nbase): macro, count and the
    table naming every column (symdyn.codegen.regressor_functions.columns)."""
    sizes = {}
    for spec in ctx.functions:
        for r in spec.results:
            if r.dims[1] in ("nstd", "nbase") and r.dims[1] not in sizes:
                table = columns(ctx.dynamics, r.dims[1])
                assert len(table) == r.cols and not any("*/" in t for _, t in table)
                sizes[r.dims[1]] = {
                    "macro": names.dims[r.dims[1]],
                    "count": r.cols,
                    "output": r.name,
                    "columns": table,
                    "width": max(len(c) for c, _ in table),
                }
    return list(sizes.values())


def render(ctx: RenderContext, groups: list[list[tuple[int, int]]] | None = None) -> dict[str, str]:
    """NAME_dynamics.h, NAME_dynamics.c and CMakeLists.txt (a static library of every .c file
    written, for a parent project's add_subdirectory; docs/embedded.md) for the robot of `ctx`; a
    large robot's functions and parts go into NAME_dynamics.c, NAME_dynamics_2.c, ..., and the parts
    that lie in another file than their function are declared in NAME_dynamics_parts.h
    (symdyn.codegen.c.parts.file_units decides, unless `groups` gives the units of each file, and
    so the number of parts of each function: symdyn.codegen.c.both renders both precisions into
    the same files)."""
    counts = None if groups is None else part_counts(groups, len(ctx.functions))
    values = render_context(ctx, counts)
    env = environment()
    files = {values["header_file"]: env.get_template("c/dynamics.h.j2").render(values)}
    functions = values["functions"]
    if groups is None:
        groups = layout(functions)
    shared, placed = placement(groups, [f["parts"]["parts"] if f["parts"] else [] for f in functions])
    # the parts in another file than their function: not static, declared in the internal header
    parts_header = values["parts"]["header"] if shared else None
    if parts_header:
        shared = [(functions[i], part) for i, part in shared]
        files[parts_header] = env.get_template("c/parts.h.j2").render(values, shared=shared)
    for k, (members, linked) in enumerate(placed):
        chosen = [{**functions[i], "here": here, "defined": defined} for i, here, defined in members]
        defined = [f for f in chosen if f["defined"]]
        files[source_file_name(ctx.name, k)] = env.get_template("c/dynamics.c.j2").render(
            values,
            functions=chosen,
            sincos=values["sincos"] if any(f["sincos"] for f in chosen) else None,
            sincos_helper=any(f["sincos"] for f in defined),
            parts=values["parts"] if any(f["parts"] for f in chosen) else None,
            parts_header=parts_header if linked else None,
            loops=values["loops"] if k == 0 else None,
        )
    sources = sorted(name for name in files if name.endswith(".c"))
    files[CMAKE_FILE] = env.get_template("c/CMakeLists.txt.j2").render(
        {**values, "sources": sources, "switch": None}
    )
    return files


def file_groups_of(ctx: RenderContext) -> list[list[tuple[int, int]]]:
    """The units of each source file `render` writes for `ctx` (symdyn.codegen.c.parts.file_units)."""
    return layout(render_context(ctx)["functions"])
