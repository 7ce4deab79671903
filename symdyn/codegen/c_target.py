"""The C target: NAME_dynamics.h and NAME_dynamics.c (C99, no allocation, libm only).

The contract is docs/generated-code.md. Each of the seven functions
(symdyn.codegen.functions) becomes straight-line code: the inputs it reads are
copied into named locals (`const double q1 = q[0];`, `const double m1 =
p[NAME_P_m1];`), then one `const double x<k> = ...;` per temporary, then the
outputs (`tau[0] = ...;`, `M[i*n + j] = ...;` row-major). Inputs a function
does not read are cast to void so -Wextra stays quiet, and `p` is never read
when the robot has no free parameters (it may be NULL then).

`CPrinter` prints SymPy expressions as C: small integer powers as repeated
multiplication, 1/x as a division, sign(x) as ((x > 0) - (x < 0)) converted to
the floating type, numbers as floating literals that round-trip a double
(float precision: the same literal with an f suffix, and sinf, cosf, ...).
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass

import sympy as sp

from ..errors import SymdynError
from ..model.expressions import C_KEYWORDS
from ..symbolic.simplify import MAX_UNROLLED_POWER
from .functions import FunctionSpec
from .render import PRECISIONS, RenderContext, environment, header_lines

__all__ = ["render", "CPrinter", "c_names"]

# --- names -------------------------------------------------------------------------

_MATH_FUNCTIONS = """
acos acosh asin asinh atan atan2 atanh cbrt ceil copysign cos cosh erf erfc exp exp2 expm1
fabs fdim floor fma fmax fmin fmod frexp hypot ilogb ldexp lgamma llrint llround log log10
log1p log2 logb lrint lround modf nan nearbyint nextafter nexttoward pow remainder remquo
rint round scalbln scalbn sin sinh sqrt tan tanh tgamma trunc
""".split()  # noqa: SIM905

#: Names a local variable of the generated C must not take: keywords, everything <math.h>
#: may declare or define (C99 and POSIX), and the argument names of the seven functions.
C_RESERVED = frozenset(
    set(C_KEYWORDS)
    | set(_MATH_FUNCTIONS)
    | {f + "f" for f in _MATH_FUNCTIONS}
    | {f + "l" for f in _MATH_FUNCTIONS}
    | set(
        """
        HUGE_VAL HUGE_VALF HUGE_VALL INFINITY NAN FP_INFINITE FP_NAN FP_NORMAL FP_SUBNORMAL
        FP_ZERO FP_FAST_FMA FP_FAST_FMAF FP_FAST_FMAL FP_ILOGB0 FP_ILOGBNAN MATH_ERRNO
        MATH_ERREXCEPT math_errhandling fpclassify isfinite isinf isnan isnormal signbit
        isgreater isgreaterequal isless islessequal islessgreater isunordered float_t
        double_t M_E M_LOG2E M_LOG10E M_LN2 M_LN10 M_PI M_PI_2 M_PI_4 M_1_PI M_2_PI
        M_2_SQRTPI M_SQRT2 M_SQRT1_2 j0 j1 jn y0 y1 yn gamma signgam errno drem finite
        significand main NULL
        q qd qdd tau p M C V G F
        """.split()  # noqa: SIM905
    )
)

_TEMPORARY = re.compile(r"x[0-9]+\Z")


@dataclass(frozen=True)
class CNames:
    """Every identifier the generated files define, and the locals of the function bodies."""

    guard: str
    ndof: str
    nparam: str
    param_macros: tuple[tuple[str, int], ...]  # (NAME_P_<param>, index) in dyn.params order
    aliases: tuple[tuple[str, str], ...]  # (UPPER_CASE alias, macro it stands for)
    functions: dict[str, str]  # spec name -> C function name
    locals: dict[sp.Symbol, str]  # input symbol -> C local name
    param_macro: dict[sp.Symbol, str]  # parameter symbol -> its index macro


def c_names(ctx: RenderContext) -> CNames:
    """The macro, function and local names for one robot (deterministic, collision-free)."""
    name = ctx.name
    params = tuple(ctx.dynamics.params)
    ndof, nparam = f"{name}_NDOF", f"{name}_NPARAM"
    param_macros = tuple((f"{name}_P_{p}", k) for k, p in enumerate(params))
    functions = {f.name: f"{name}_{f.name}" for f in ctx.functions}
    guard = f"{name.upper()}_DYNAMICS_H"

    written = [ndof, nparam] + [m for m, _ in param_macros]
    upper_count: dict[str, int] = {}
    for m in written:
        upper_count[m.upper()] = upper_count.get(m.upper(), 0) + 1
    taken = set(written) | set(functions.values()) | {guard}
    aliases = tuple(
        (m.upper(), m)
        for m in written
        if m.upper() != m and upper_count[m.upper()] == 1 and m.upper() not in taken
    )

    joint_symbols: list[sp.Symbol] = []
    for f in ctx.functions:
        for inp in f.inputs:
            if inp.name != "p":
                joint_symbols.extend(s for s in inp.symbols if s not in joint_symbols)
    clash = sorted(str(p) for p in params if p in joint_symbols)
    if clash:
        raise SymdynError(
            f"robot '{name}': parameter name(s) {', '.join(clash)} clash with the joint or effort "
            "symbols of the generated functions"
        )
    reserved = C_RESERVED | taken | {a for a, _ in aliases}
    used = {str(s) for s in joint_symbols}
    local_names: dict[sp.Symbol, str] = {s: str(s) for s in joint_symbols}
    for s in joint_symbols:
        if str(s) in reserved or _TEMPORARY.match(str(s)):
            raise SymdynError(f"internal: joint symbol '{s}' clashes with a C name")
    for p in params:
        base = str(p)
        candidate = base
        k = 0
        while candidate in reserved or candidate in used or _TEMPORARY.match(candidate):
            candidate = f"{base}_" if k == 0 else f"{base}_{k}"
            k += 1
        local_names[p] = candidate
        used.add(candidate)
    param_macro = {p: m for p, (m, _) in zip(params, param_macros, strict=True)}
    return CNames(guard, ndof, nparam, param_macros, aliases, functions, local_names, param_macro)


# --- expressions ---------------------------------------------------------------------

ADD, MUL, UNARY, ATOM = 1, 3, 4, 5


class CPrinter:
    """SymPy expression -> C99 expression text for one floating type ("double" or "float")."""

    _CALLS = {sp.sin: "sin", sp.cos: "cos", sp.tan: "tan", sp.Abs: "fabs"}

    def __init__(self, names: dict[sp.Symbol, str], precision: str = "double"):
        if precision not in PRECISIONS:
            raise SymdynError(f"unknown precision '{precision}' (double or float)")
        self.names = names
        self.precision = precision
        self.suffix = "f" if precision == "float" else ""

    # numbers
    def literal(self, value: float) -> str:
        """A floating literal that round-trips the double `value` (repr: up to 17 digits)."""
        if not math.isfinite(value):
            raise SymdynError(f"cannot print the non-finite constant {value} as C")
        text = repr(float(value))
        if not any(c in text for c in ".eE"):
            text += ".0"
        return text + self.suffix

    def _number(self, e: sp.Expr) -> tuple[str, int]:
        if e.is_Rational:
            value = float(int(e.p)) if e.q == 1 else int(e.p) / int(e.q)
        else:
            try:
                value = float(e.evalf(30))
            except (TypeError, ValueError) as exc:
                raise SymdynError(f"cannot print the constant {e} as C") from exc
        if value < 0:
            return "-" + self.literal(-value), UNARY
        return self.literal(value), ATOM

    def func(self, name: str) -> str:
        return name + self.suffix

    # expressions
    def doprint(self, e) -> str:
        return self._print(sp.sympify(e))[0]

    def _wrap(self, e: sp.Expr, need: int) -> str:
        text, prec = self._print(e)
        return f"({text})" if prec < need else text

    def _print(self, e: sp.Expr) -> tuple[str, int]:
        if e.is_Symbol:
            try:
                return self.names[e], ATOM
            except KeyError:
                raise SymdynError(f"internal: symbol '{e}' is neither an input nor a temporary") from None
        if e.is_Number or e.is_NumberSymbol:
            return self._number(e)
        if e.is_Add:
            return self._add(e)
        if e.is_Mul:
            return self._mul(e)
        if e.is_Pow:
            if not e.free_symbols:
                return self._number(e)
            return self._pow(e)
        if isinstance(e, sp.sign):
            x = self._print(e.args[0])[0]
            return f"(({self.precision})(({x} > 0) - ({x} < 0)))", ATOM
        call = self._CALLS.get(type(e))
        if call is not None:
            if not e.free_symbols:
                return self._number(e)
            return f"{self.func(call)}({self._print(e.args[0])[0]})", ATOM
        raise SymdynError(f"cannot print '{type(e).__name__}' as C: {e}")

    def _add(self, e: sp.Add) -> tuple[str, int]:
        parts: list[str] = []
        for term in e.args:
            coeff, rest = term.as_coeff_Mul()
            negative = coeff.is_Number and coeff < 0
            positive = -term if negative else term
            text = self._wrap(positive, MUL)
            if not parts:
                parts.append(f"-{text}" if negative else text)
            else:
                parts.append(f" - {text}" if negative else f" + {text}")
        return "".join(parts), ADD

    def _mul(self, e: sp.Mul) -> tuple[str, int]:
        coeff, rest = e.as_coeff_Mul()
        if coeff.is_Number and coeff < 0:
            text, prec = self._print_product(-coeff, rest)
            return f"-{text}", (UNARY if prec == ATOM else MUL)
        return self._print_product(coeff, rest)

    def _print_product(self, coeff: sp.Expr, rest: sp.Expr) -> tuple[str, int]:
        num: list[tuple[str, int]] = []
        den: list[sp.Expr] = []
        if coeff != 1:
            num.append(self._print(coeff))
        for f in sp.Mul.make_args(rest):
            if f == 1:
                continue
            if f.is_Pow and f.exp.is_Rational and f.exp < 0 and f.free_symbols:
                den.append(f.base if f.exp == -1 else sp.Pow(f.base, -f.exp, evaluate=False))
            else:
                text, prec = self._print(f)
                num.append((f"({text})" if prec < MUL else text, max(prec, MUL)))
        if not den:
            if not num:
                return self.literal(1.0), ATOM
            if len(num) == 1:
                return num[0]
            return "*".join(t for t, _ in num), MUL
        top = "*".join(t for t, _ in num) if num else self.literal(1.0)
        if len(den) == 1:
            bottom = self._wrap(den[0], ATOM)
        else:
            bottom = "(" + "*".join(self._wrap(d, MUL) for d in den) + ")"
        return f"{top}/{bottom}", MUL

    def _pow(self, e: sp.Pow) -> tuple[str, int]:
        base, exp = e.base, e.exp
        if exp.is_Integer and 0 < exp <= MAX_UNROLLED_POWER:
            b = self._wrap(base, ATOM)
            return ("*".join([b] * int(exp)), ATOM if exp == 1 else MUL)
        if exp.is_Integer and -MAX_UNROLLED_POWER <= exp < 0:
            k = int(-exp)
            b = self._wrap(base, ATOM)
            bottom = b if k == 1 else "(" + "*".join([b] * k) + ")"
            return f"{self.literal(1.0)}/{bottom}", MUL
        if exp == sp.Rational(1, 2):
            return f"{self.func('sqrt')}({self._print(base)[0]})", ATOM
        if exp == sp.Rational(-1, 2):
            return f"{self.literal(1.0)}/{self.func('sqrt')}({self._print(base)[0]})", MUL
        return f"{self.func('pow')}({self._print(base)[0]}, {self._print(exp)[0]})", ATOM


# --- functions -----------------------------------------------------------------------

_INPUT_DOC = {
    "q": "joint positions q1..qn (rad or m)",
    "qd": "joint velocities qd1..qdn (rad/s or m/s)",
    "qdd": "joint accelerations qdd1..qddn (rad/s^2 or m/s^2)",
    "tau": "joint efforts tau1..taun (N m or N)",
}

_OUTPUT_DOC = {
    "tau": "joint efforts tau = M qdd + V + G + F",
    "M": "joint-space mass (inertia) matrix M(q)",
    "C": "Coriolis matrix C(q, qd) (Christoffel symbols), C qd = V",
    "V": "Coriolis and centrifugal efforts V(q, qd)",
    "G": "gravity efforts G(q)",
    "F": "friction efforts F(qd)",
    "qdd": "joint accelerations",
}


def _function_view(ctx: RenderContext, names: CNames, spec: FunctionSpec) -> dict:
    n = ctx.robot.n
    real = ctx.precision
    symbol_names = dict(names.locals)
    for sym, _ in spec.temporaries:
        if sym in symbol_names or not _TEMPORARY.match(sym.name):
            raise SymdynError(
                f"robot '{ctx.name}': temporary '{sym}' of {spec.name} has the name of an input "
                "(or no C name); rename the parameter"
            )
        symbol_names[sym] = sym.name
    printer = CPrinter(symbol_names, real)
    used_symbols = spec.free_symbols

    args: list[str] = []
    params_doc: list[tuple[str, str, str]] = []
    body: list[str] = []
    reads: list[str] = []
    for inp in spec.inputs:
        args.append(f"const {real} {inp.name}[]")
        used = [s for s in inp.symbols if s in used_symbols]
        if inp.name == "p":
            if inp.symbols:
                desc = f"free parameters, {names.nparam} values, index p with the {ctx.name}_P_<name> macros"
            else:
                desc = f"free parameters: none ({names.nparam} is 0), so p may be NULL"
        else:
            desc = f"{_INPUT_DOC[inp.name]}, {names.ndof} values"
        if not used:
            desc += "; not read by this function"
            body.append(f"(void){inp.name};")
        params_doc.append(("in", inp.name, desc))
        for s in used:
            index = names.param_macro[s] if inp.name == "p" else str(inp.symbols.index(s))
            reads.append(f"const {real} {names.locals[s]} = {inp.name}[{index}];")
    args.append(f"{real} {spec.output}[]")
    rows, cols = spec.shape
    if cols == 1:
        size = f"{names.ndof} values"
    else:
        size = (
            f"{names.ndof}*{names.ndof} values, row-major: {spec.output}[i*{names.ndof} + j] "
            "is row i, column j"
        )
    params_doc.append(("out", spec.output, f"{_OUTPUT_DOC[spec.output]}, {size}"))

    body.extend(reads)
    for sym, expr in spec.temporaries:
        body.append(f"const {real} {sym.name} = {printer.doprint(expr)};")
    if len(spec.outputs) != rows * cols or cols not in (1, n):
        raise SymdynError(f"internal: {spec.name} has {len(spec.outputs)} outputs for shape {spec.shape}")
    for k, e in enumerate(spec.outputs):
        body.append(f"{spec.output}[{k}] = {printer.doprint(e)};")
    width = max(len(a) for _, a, _ in params_doc)
    return {
        "name": spec.name,
        "c_name": names.functions[spec.name],
        "doc": spec.doc,
        "signature": f"void {names.functions[spec.name]}({', '.join(args)})",
        "params": [(d, a.ljust(width), text) for d, a, text in params_doc],
        "ops": spec.ops.summary(),
        "body": body,
    }


def _comment(lines: list[str]) -> list[str]:
    return [line.replace("*/", "* /").rstrip() for line in lines]


def render(ctx: RenderContext) -> dict[str, str]:
    """NAME_dynamics.h and NAME_dynamics.c for the robot of `ctx`."""
    names = c_names(ctx)
    functions = [_function_view(ctx, names, spec) for spec in ctx.functions]
    header_file = f"{ctx.name}_dynamics.h"
    values = {
        "name": ctx.name,
        "real": ctx.precision,
        "header_lines": _comment(header_lines(ctx)),
        "header_file": header_file,
        "guard": names.guard,
        "ndof": names.ndof,
        "n": ctx.robot.n,
        "nparam": names.nparam,
        "k": len(ctx.dynamics.params),
        "param_macros": list(names.param_macros),
        "aliases": list(names.aliases),
        "functions": functions,
    }
    env = environment()
    return {
        header_file: env.get_template("c/dynamics.h.j2").render(values),
        f"{ctx.name}_dynamics.c": env.get_template("c/dynamics.c.j2").render(values),
    }
