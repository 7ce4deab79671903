"""A generated C function's code on W states at once, for the SIMD batch wrappers (NAME_batch.c).

The body of NAME_f is printed a second time over GCC/Clang vector types (`NAME_vd`, W lanes
of double or float, templates/c/batch.c.j2 picks W from the compiler's target macros): every
local that depends on the state (q, qd, qdd, tau and what is computed from them) is a vector,
the parameters p and what depends on them alone stay scalars (C broadcasts them in a mixed
operation). +, -, * and / act lane by lane with the rounding of the scalar operation, so a lane
computes exactly what NAME_f computes for its state; every call that has no vector form
(sqrt, pow, fabs, tan, sign, the step of Coulomb friction) goes through a lane-by-lane helper
calling the same <math.h> function or comparison as the scalar code, branch-free. The sines and
cosines of double precision go through the same helper as NAME_f (NAME_sincos,
symdyn.codegen.c.sincos) on the angles of all W lanes at once. In single precision NAME_f calls
sinf and cosf, which the compiler merges into one sincosf where both take the same argument; the
batch asks for both in one lane loop (NAME_simd_sincos_lanes), merged the same way, instead of
one loop for each: on the Panda in float it took M's batch from 1.18 to 0.72 times the scalar
loop, the inverse dynamics from 0.81 to 0.52 and the forward dynamics from 0.54 to 0.37.

A function whose code holds anything else gets no vector form (`vector_view` returns None): its
batch wrapper then calls NAME_f once per state. So does a function with fewer than
MIN_OPS_PER_OUTPUT operations per output value (the friction of a robot without Coulomb
friction, whose outputs are plain products): there the transposes that carry the outputs from
the W lanes to the batch's rows are most of the work. The regressors gain: the Panda's base
regressor (434 outputs, 1429 operations) vectorised takes 0.69 to 0.72 of the scalar loop's
time over identify's chunk of 4,832 states, its full regressor (637 outputs, 1743 operations)
0.65 to 0.67 (AVX-512, gcc 12, -O2); they took 1.6 to 1.7 times the scalar loop when each
group's outputs went through a buffer on the stack and a copy.

A body longer than the scalar parts' bound is cut into parts as the scalar function is
(symdyn.codegen.c.vector_parts).
"""

from __future__ import annotations

import sympy as sp

from ...errors import SymdynError
from ...symbolic.simplify import MAX_UNROLLED_POWER
from ..functions import FunctionSpec
from ..printing import step_comparison
from ..render import RenderContext
from .config import MATH_CALLS, CNames
from .parts import reads_in
from .printer import ATOM, MUL, CPrinter
from .sincos import gather, trig_calls
from .target import function_inputs, last_reads, symbol_names
from .vector_parts import vector_parts

__all__ = [
    "VectorPrinter",
    "vector_view",
    "simd_prefix",
    "LANE_CALLS",
    "MIN_OPS_PER_OUTPUT",
    "ANGLES_PER_CALL",
]

#: Fewer operations per output value than this: the batch keeps the scalar loop (module docstring;
#: nothing below it was measured to gain, the regressors at 2.7 and 3.3 do).
MIN_OPS_PER_OUTPUT = 2

#: The angles whose sines and cosines one call of NAME_simd_sincosK computes, their steps
#: alternating (templates/c/sincos_vector.c.j2). Each angle is a chain of dependent operations;
#: three side by side gave the out-of-order core enough independent work: the Panda's M over
#: 10,000 states took 30.5 ns a state with one angle at a time, 29.9 with two, 28.3 with three
#: and 28.9 with all six (AVX-512, gcc 12, -O2).
ANGLES_PER_CALL = 3

#: The <math.h> functions (double names) the lane helpers wrap: one argument, and pow with two.
LANE_CALLS = (*sorted(set(MATH_CALLS.values())), "sqrt")


def simd_prefix(ctx: RenderContext) -> str:
    """The prefix of every name NAME_batch.c adds: NAME_simd_ (helpers, blocks of W states)."""
    return f"{ctx.name}_simd_"


class VectorPrinter(CPrinter):
    """SymPy expression -> C text over W states: a vector where it depends on `varying` symbols.

    `varying`: the symbols held as vectors (the state's inputs, then the temporaries computed from
    them, added by the caller in order); `calls` (sin(a), cos(a) read from the arrays of angles)
    are vectors. `prefix` names the lane helpers (NAME_simd_sqrt, ...).
    """

    def __init__(self, names: dict, precision: str, calls: dict, varying: set, prefix: str):
        super().__init__(names, precision, calls)
        self.vary = set(varying)
        self.prefix = prefix
        self._memo: dict[sp.Expr, bool] = {}

    def varying(self, e: sp.Expr) -> bool:
        """Whether the text of `e` is a vector (it reads a varying symbol or an array of sines)."""
        if e in self.calls:
            return True
        if e.is_Symbol:
            return e in self.vary
        if e not in self._memo:
            self._memo[e] = any(self.varying(a) for a in e.args)
        return self._memo[e]

    def vector(self, e: sp.Expr) -> str:
        """The text of `e` as a vector: a scalar is broadcast to every lane (NAME_simd_splat)."""
        text = self.doprint(e)
        return text if self.varying(sp.sympify(e)) else f"{self.prefix}splat({text})"

    def _call(self, e: sp.Expr) -> tuple[str, int]:
        if e in self.calls or not self.varying(e):
            return super()._call(e)
        if isinstance(e, sp.sign):
            return f"{self.prefix}sign({self._print(e.args[0])[0]})", ATOM
        if isinstance(e, sp.Heaviside):
            x, op = step_comparison(e)
            side = "positive" if op == ">" else "negative"
            return f"{self.prefix}{side}({self._print(x)[0]})", ATOM
        call = MATH_CALLS.get(type(e))
        if call is not None and len(e.args) == 1:
            return f"{self.prefix}{self.config.math(call)}({self._print(e.args[0])[0]})", ATOM
        raise SymdynError(f"no vector form of '{type(e).__name__}'")

    def _pow(self, e: sp.Pow) -> tuple[str, int]:
        if not self.varying(e) or (e.exp.is_Integer and 0 < abs(e.exp) <= MAX_UNROLLED_POWER):
            return super()._pow(e)  # small integer powers are products and quotients: lane by lane
        sqrt = self.prefix + self.config.math("sqrt")
        if e.exp == sp.Rational(1, 2):
            return f"{sqrt}({self._print(e.base)[0]})", ATOM
        if e.exp == sp.Rational(-1, 2):
            return f"{self.literal(1.0)}/{sqrt}({self._print(e.base)[0]})", MUL
        return f"{self.prefix}{self.config.math('pow')}({self.vector(e.base)}, {self.vector(e.exp)})", ATOM


def vector_view(ctx: RenderContext, names: CNames, spec: FunctionSpec) -> dict | None:
    """One function's body on W states as data for templates/c/batch.c.j2, or None without a vector form.

    Keys: block (the static function's name), inputs (name, size: a state's values), outputs
    (name, size, stores: (index, vector text)), unused, reads ((local, input, index, vector?)),
    angles (their vector texts, double precision only), angle_groups (_angle_groups), lane_pairs (the
    angles whose sinf and cosf are computed together, single precision only, _sine_cosine_pairs)
    and body (_interleaved: the temporaries and, right after each group's last one, the stores of
    the output groups it completes).
    """
    if spec.ops.total < MIN_OPS_PER_OUTPUT * len(spec.outputs):
        return None
    known = symbol_names(ctx, names, spec)
    _, unused, reads = function_inputs(names, spec)
    varying = {s for inp in spec.inputs if inp.name != "p" for s in inp.symbols}
    prefix = simd_prefix(ctx)
    temporaries = list(spec.temporaries)
    angles: list[str] = []
    calls: dict = {}
    lane_pairs: list[str] = []
    arrays = (names.sincos["sine"], names.sincos["cosine"])
    plain = VectorPrinter(known, ctx.precision, {}, varying, prefix)
    try:
        if ctx.precision == "double":
            trig = gather(spec.temporaries, spec.outputs)
            temporaries = [(s, e) for s, e in spec.temporaries if s in trig.live]
            angles = [plain.vector(a) for a in trig.angles]
            calls = {call: f"{arrays[which]}[{k}]" for call, (which, k) in trig.calls.items()}
        else:
            pairs = _sine_cosine_pairs(spec, varying)
            lane_pairs = [plain.vector(a) for a in pairs]
            for k, angle in enumerate(pairs):
                calls[sp.sin(angle)] = f"{arrays[0]}[{k}]"
                calls[sp.cos(angle)] = f"{arrays[1]}[{k}]"
        printer = VectorPrinter(known, ctx.precision, calls, varying, prefix)
        lets = []
        for s, e in temporaries:
            vector = printer.varying(e)
            if vector:
                printer.vary.add(s)
            lets.append((vector, s.name, printer.doprint(e)))
        outputs = [
            {
                "name": r.name,
                "size": r.rows * r.cols,
                "stores": [(k, printer.vector(e)) for k, e in enumerate(spec.entries(r))],
            }
            for r in spec.results
        ]
    except SymdynError:
        return None
    body = _interleaved(spec, temporaries, lets, outputs, ctx.precision == "double")
    sizes = {inp.name: len(inp.symbols) for inp in spec.inputs}
    lanes = [(local, array, index, array != "p") for local, array, index in reads]
    arguments = [inp.name for inp in spec.inputs] + [r.name for r in spec.results]
    parts = vector_parts(body, lanes, prefix + spec.name, arguments)
    return {
        "block": prefix + spec.name,
        "inputs": [(inp.name, sizes[inp.name]) for inp in spec.inputs],
        "outputs": outputs,
        "unused": unused,
        "reads": lanes,
        "parts": parts,
        # with parts, the block itself reads only the inputs of its angles
        "angle_reads": [r for r in lanes if r[:3] in reads_in([*angles, *lane_pairs], reads)]
        if parts
        else [],
        "angles": angles,
        "angle_groups": _angle_groups(angles),
        "lane_pairs": lane_pairs,
        "body": body,
    }


def _angle_groups(angles: list[str]) -> list[tuple[int, list[str]]]:
    """The angles in calls of NAME_simd_sincosK: (index of the first, its K <= ANGLES_PER_CALL texts)."""
    return [(k, angles[k : k + ANGLES_PER_CALL]) for k in range(0, len(angles), ANGLES_PER_CALL)]


def _sine_cosine_pairs(spec: FunctionSpec, varying: set) -> list[sp.Expr]:
    """The arguments a of a single-precision function that has both sin(a) and cos(a), a over the
    state (not p alone) and reading no temporary, in first-met order: NAME_simd_sincos_lanes
    computes both at the top of the body. (Every example robot's angles are inputs, sums of inputs
    or such sums plus parameters; any other keeps one lane loop per call.)"""
    calls = trig_calls([e for _, e in spec.temporaries] + list(spec.outputs))
    temporaries = {s for s, _ in spec.temporaries}
    sines = {call.args[0] for call in calls if isinstance(call, sp.sin)}
    cosines = {call.args[0] for call in calls if isinstance(call, sp.cos)}
    angles = dict.fromkeys(call.args[0] for call in calls)
    return [
        a
        for a in angles
        if a in sines and a in cosines and a.free_symbols & varying and not a.free_symbols & temporaries
    ]


def _interleaved(
    spec: FunctionSpec, temporaries: list, lets: list, outputs: list[dict], transposed: bool
) -> list:
    """The body's statements: ("let", vector?, name, text) for each temporary, and after the last
    temporary that a group of outputs reads, ("store", {width: [(output, offset, size, texts)]})
    for the groups of 8 and of 4 consecutive entries that the register transposes write (doubles;
    the last size mod W entries and floats one by one: width 1). A group stored as soon as it is
    known needs no register or stack slot to the end of the body (symdyn.codegen.c.target._body)."""
    after: dict[int, dict[int, list]] = {}
    for result, view in zip(spec.results, outputs, strict=True):
        last = last_reads(temporaries, spec.entries(result))
        size = view["size"]
        for width in (8, 4) if transposed else (1,):
            full = size - size % width
            for start in range(0, full, width):
                at = max(last[start : start + width])
                texts = [t for _, t in view["stores"][start : start + width]]
                after.setdefault(at, {}).setdefault(width, []).append((view["name"], start, size, texts))
            for k in range(full, size):
                group = after.setdefault(last[k], {}).setdefault(-width, [])
                group.append((view["name"], k, size, [view["stores"][k][1]]))
    body: list = [("store", after[-1])] if -1 in after else []
    for k, (vector, name, text) in enumerate(lets):
        body.append(("let", vector, name, text))
        if k in after:
            body.append(("store", after[k]))
    return body
