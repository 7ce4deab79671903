"""The C backend's configuration: floating type, literals, <math.h> names, reserved words, naming.

Nothing here prints an expression or a statement (that is symdyn.codegen.c.printer
and templates/c/): this module only decides *names*. `CConfig` holds what
depends on --precision (the type `double` or `float`, the literal suffix,
`sin` or `sinf`); `c_names` gives one robot's macros, function names and the
locals its function bodies declare, collision-free against `C_RESERVED`.
The contract of the names is docs/generated-code.md.
"""

from __future__ import annotations

import re
from dataclasses import dataclass

import sympy as sp

from ...errors import SymdynError
from ...model.expressions import C_KEYWORDS
from ..contact_functions import contacts_of
from ..printing import free_name
from ..render import PRECISIONS, RenderContext

__all__ = ["CConfig", "CNames", "c_names", "C_RESERVED", "MATH_CALLS", "TEMPORARY"]

_MATH_FUNCTIONS = """
acos acosh asin asinh atan atan2 atanh cbrt ceil copysign cos cosh erf erfc exp exp2 expm1
fabs fdim floor fma fmax fmin fmod frexp hypot ilogb ldexp lgamma llrint llround log log10
log1p log2 logb lrint lround modf nan nearbyint nextafter nexttoward pow remainder remquo
rint round scalbln scalbn sin sinh sqrt tan tanh tgamma trunc
""".split()  # noqa: SIM905

#: Functions POSIX (and the BSDs) add to <math.h>, each with float and long double variants in glibc.
_POSIX_FUNCTIONS = "j0 j1 jn y0 y1 yn gamma drem finite isinf isnan scalb significand".split()  # noqa: SIM905

#: Names a local variable of the generated C must not take: keywords, everything <math.h>
#: may declare or define (C99 and POSIX), and the argument names of the seven functions.
C_RESERVED = frozenset(
    set(C_KEYWORDS)
    | {f + suffix for f in _MATH_FUNCTIONS + _POSIX_FUNCTIONS for suffix in ("", "f", "l")}
    | {"lgamma_r", "lgammaf_r", "lgammal_r"}
    | set(
        """
        HUGE_VAL HUGE_VALF HUGE_VALL INFINITY NAN FP_INFINITE FP_NAN FP_NORMAL FP_SUBNORMAL
        FP_ZERO FP_FAST_FMA FP_FAST_FMAF FP_FAST_FMAL FP_ILOGB0 FP_ILOGBNAN MATH_ERRNO
        MATH_ERREXCEPT math_errhandling fpclassify isfinite isinf isnan isnormal signbit
        isgreater isgreaterequal isless islessequal islessgreater isunordered float_t
        double_t M_E M_LOG2E M_LOG10E M_LN2 M_LN10 M_PI M_PI_2 M_PI_4 M_1_PI M_2_PI
        M_2_SQRTPI M_SQRT2 M_SQRT1_2 signgam errno main NULL
        q qd qdd tau p M C V G F
        """.split()  # noqa: SIM905
    )
)

#: SymPy functions of one argument and their double-precision <math.h> names.
MATH_CALLS = {sp.sin: "sin", sp.cos: "cos", sp.tan: "tan", sp.Abs: "fabs"}

#: The names of the eliminated temporaries (symdyn.symbolic.simplify): x0, x1, ...
TEMPORARY = re.compile(r"x[0-9]+\Z")


@dataclass(frozen=True)
class CConfig:
    """What the generated C depends on besides the robot: the floating type ("double" or "float"),
    and whether it may use the C library (`freestanding`: no <math.h>, docs/embedded.md)."""

    precision: str = "double"
    freestanding: bool = False

    def __post_init__(self) -> None:
        if self.precision not in PRECISIONS:
            raise SymdynError(f"unknown precision '{self.precision}' (double or float)")

    @property
    def real(self) -> str:
        """The C type of every input, output, local and temporary."""
        return self.precision

    @property
    def literal_suffix(self) -> str:
        """Appended to every floating literal: 1.5f is a float constant, 1.5 a double."""
        return "f" if self.precision == "float" else ""

    def math(self, name: str) -> str:
        """The <math.h> function for `name` (a double function) in this precision: sin or sinf.
        A freestanding build has no <math.h>: every call but the sines and cosines, which the
        file computes itself (symdyn.codegen.c.sincos), is refused."""
        if self.freestanding:
            raise SymdynError(
                f"--freestanding: the generated code needs {name + self.literal_suffix} from the C "
                "library's <math.h>, which a freestanding build does not have (only sin and cos are "
                "symdyn's own): leave out the functions that need it or drop --freestanding"
            )
        return name + self.literal_suffix


@dataclass(frozen=True)
class CNames:
    """Every identifier the generated files define, and the locals of the function bodies."""

    header_file: str
    source_file: str
    guard: str
    ndof: str
    nparam: str
    #: NAME_NQ and NAME_NV of a floating robot (the sizes of q and of qd, qdd, tau), else None
    nq: str | None
    nv: str | None
    param_pattern: str  # how the index macros are spelled, for the documentation: NAME_P_<name>
    param_macros: tuple[tuple[str, int], ...]  # (NAME_P_<param>, index) in dyn.params order
    aliases: tuple[tuple[str, str], ...]  # (UPPER_CASE alias, macro it stands for)
    functions: dict[str, str]  # spec name -> C function name
    locals: dict[sp.Symbol, str]  # input symbol -> C local name
    param_macro: dict[sp.Symbol, str]  # parameter symbol -> its index macro
    dims: dict[str, str]  # size name of an output (symdyn.codegen.functions.DIMS) -> C expression
    # the sines and cosines (symdyn.codegen.c.sincos): "helper" (the static function computing
    # them for an array of angles), the macros "sin", "cos" (reading them) and "vector" (defined
    # when the helper is used), the locals "angle", "sine" and "cosine" (the arrays)
    sincos: dict[str, str]
    # the parts of a large function (symdyn.codegen.c.parts): the macro "noinline" (keeps each part a
    # function of its own), the local array "stash" (the temporaries passed between parts), and for
    # the parts in another file than their function the internal "header" NAME_dynamics_parts.h,
    # its include "guard" and the macro "hidden" (their visibility)
    parts: dict[str, str]


def _aliases(written: list[str], taken: set[str]) -> tuple[tuple[str, str], ...]:
    """UPPER_CASE aliases of the macros whose upper-case spelling is free and unambiguous."""
    upper_count: dict[str, int] = {}
    for m in written:
        upper_count[m.upper()] = upper_count.get(m.upper(), 0) + 1
    return tuple(
        (m.upper(), m)
        for m in written
        if m.upper() != m and upper_count[m.upper()] == 1 and m.upper() not in taken
    )


def _joint_symbols(ctx: RenderContext) -> list[sp.Symbol]:
    """The symbols of the q, qd, qdd and tau arguments, in first-use order over the functions."""
    symbols: list[sp.Symbol] = []
    for f in ctx.functions:
        for inp in f.inputs:
            if inp.name != "p":
                symbols.extend(s for s in inp.symbols if s not in symbols)
    return symbols


def _task_size(ctx: RenderContext) -> int:
    """k, the rows of the operational-space functions' outputs (size name "k"; 6 without them)."""
    return next((r.rows for f in ctx.functions for r in f.results if r.dims[0] == "k"), 6)


def c_names(ctx: RenderContext) -> CNames:
    """The file, macro, function and local names for one robot (deterministic, collision-free).

    Joint symbols keep their names (q1, qd2, ...); a parameter whose name is reserved, taken
    or looks like a temporary gets `_` then `_1`, `_2`, ... appended, and so do the arrays of
    angles, sines and cosines (`angle`, `sine`, `cosine`) when a parameter has their name.
    """
    name = ctx.name
    params = tuple(ctx.dynamics.params)
    ndof, nparam = f"{name}_NDOF", f"{name}_NPARAM"
    floating = ctx.robot.floating
    nq, nv = (f"{name}_NQ", f"{name}_NV") if floating else (None, None)
    param_macros = tuple((f"{name}_P_{p}", k) for k, p in enumerate(params))
    functions = {f.name: f"{name}_{f.name}" for f in ctx.functions}
    sincos = {
        "helper": f"{name}_sincos",
        "sin": f"{name}_SIN",
        "cos": f"{name}_COS",
        "vector": f"{name}_SINCOS_VECTOR",
    }
    assert not set(sincos.values()) & set(functions.values()), "a generated function has the sines' name"
    guard = f"{name.upper()}_DYNAMICS_H"
    column_dims = {r.dims[1] for f in ctx.functions for r in f.results} & {"nstd", "nbase"}
    written = (
        [ndof, nparam]
        + ([nq, nv] if floating else [])
        + [m for m, _ in param_macros]
        + [f"{name}_{d.upper()}" for d in ("nstd", "nbase") if d in column_dims]
        + ([f"{name}_NFRAMES"] if ctx.frames else [])
        + ([f"{name}_NACT", f"{name}_NPAS"] if "loop_newton_step" in functions else [])
        + ([f"{name}_NCONTACT", f"{name}_NLAMBDA"] if contacts_of(ctx) else [])
        + ([f"{name}_NANCHOR"] if "contact_error" in functions else [])
    )
    parts = {
        "noinline": f"{name}_NOINLINE",
        "hidden": f"{name}_HIDDEN",
        "guard": f"{name.upper()}_DYNAMICS_PARTS_H",
        "header": f"{name}_dynamics_parts.h",
    }
    macros = {parts[k] for k in ("noinline", "hidden", "guard")}
    taken = set(written) | set(functions.values()) | {guard} | set(sincos.values()) | macros
    aliases = _aliases(written, taken)

    joint_symbols = _joint_symbols(ctx)
    clash = sorted(str(p) for p in params if p in joint_symbols)
    if clash:
        raise SymdynError(
            f"robot '{name}': parameter name(s) {', '.join(clash)} clash with the joint or effort "
            "symbols of the generated functions"
        )
    arguments = {r.name for f in ctx.functions for r in f.results} | {
        inp.name for f in ctx.functions for inp in f.inputs
    }
    # the macros of a file in both precisions (symdyn.codegen.c.both) are taken in every file
    both = {f"{name}_real", f"{name}_USE_FLOAT"}
    reserved = C_RESERVED | taken | {a for a, _ in aliases} | arguments | both
    used = {str(s) for s in joint_symbols}
    local_names: dict[sp.Symbol, str] = {s: str(s) for s in joint_symbols}
    for s in joint_symbols:
        assert str(s) not in reserved and not TEMPORARY.match(str(s)), f"joint symbol '{s}' is a C name"
    for p in params:
        local_names[p] = free_name(str(p), reserved | used, TEMPORARY)
        used.add(local_names[p])
    for array in ("angle", "sine", "cosine"):
        sincos[array] = free_name(array, reserved | used, TEMPORARY)
    parts["stash"] = free_name("stash", reserved | used, TEMPORARY)
    param_macro = {p: m for p, (m, _) in zip(params, param_macros, strict=True)}
    return CNames(
        header_file=f"{name}_dynamics.h",
        source_file=f"{name}_dynamics.c",
        guard=guard,
        ndof=ndof,
        nparam=nparam,
        nq=nq,
        nv=nv,
        param_pattern=f"{name}_P_<name>",
        param_macros=param_macros,
        aliases=aliases,
        functions=functions,
        locals=local_names,
        param_macro=param_macro,
        dims={
            "1": "1",
            "n": ndof,
            "2n": f"(2*{ndof})",
            "nstd": f"{name}_NSTD",
            "nbase": f"{name}_NBASE",
            **{d: d for d in ("3", "4", "6")},
            "k": str(_task_size(ctx)),
            "nact": f"{name}_NACT",
            "npas": f"{name}_NPAS",
            "ncontact": f"{name}_NCONTACT",
            "nlambda": f"{name}_NLAMBDA",
            "nanchor": f"{name}_NANCHOR",
            "nq": nq or str(ctx.robot.nq),
            "nv": nv or str(ctx.robot.nv),
        },
        sincos=sincos,
        parts=parts,
    )
