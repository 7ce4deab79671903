"""The MATLAB/Octave backend's names: function and file names, and the locals of the bodies.

Nothing here prints an expression or a statement (symdyn.codegen.matlab.printer and
templates/matlab/ do): this module only decides names, collision-free against
`MATLAB_RESERVED` (the language's keywords, the functions the generated files call, and
the argument names of the generated functions). A MATLAB identifier starts with a letter
and has at most 63 characters (namelengthmax), so a robot name that cannot prefix the
function names is refused.
"""

from __future__ import annotations

import re
from dataclasses import dataclass

import sympy as sp

from ...errors import SymdynError
from ..printing import free_name
from ..render import RenderContext

__all__ = ["MatlabNames", "matlab_names", "MATLAB_RESERVED", "TEMPORARY", "NAME_LENGTH_MAX"]

#: MATLAB's namelengthmax: longer identifiers (and so function and file names) are cut off.
NAME_LENGTH_MAX = 63

_KEYWORDS = """
break case catch classdef continue else elseif end for function global if otherwise parfor
persistent return spmd switch try while
do until endfor endfunction endif endwhile endswitch end_try_catch unwind_protect
unwind_protect_cleanup end_unwind_protect
""".split()  # noqa: SIM905  (MATLAB's iskeyword list, then Octave's own)

#: Names a local of a generated function must not take: keywords, the functions and constants
#: the files use, and the arguments of the generated functions.
MATLAB_RESERVED = frozenset(
    set(_KEYWORDS)
    | set(
        """
        sin cos tan abs sqrt sign zeros numel error nargin isempty pi eps Inf NaN inf nan i j e
        ans q qd qdd tau p M C V G F
        """.split()  # noqa: SIM905
    )
)

#: The names of the eliminated temporaries (symdyn.symbolic.simplify): x0, x1, ...
TEMPORARY = re.compile(r"x[0-9]+\Z")
_IDENTIFIER = re.compile(r"[A-Za-z][A-Za-z0-9_]*\Z")


@dataclass(frozen=True)
class MatlabNames:
    """The function names (= file names without .m) and the locals of the function bodies."""

    functions: dict[str, str]  # spec name -> MATLAB function name
    locals: dict[sp.Symbol, str]  # input symbol -> local variable name


def _frame_hint(ctx: RenderContext, function: str) -> str:
    """The end of the message when `function` is one of frame F's functions: shorten F's name."""
    for name, ident, _ in ctx.frames:
        if function.startswith(f"{ctx.name}_{ident}_"):
            return f" or frame {name!r}'s (or leave out --target matlab)"
    return ""


def matlab_names(ctx: RenderContext) -> MatlabNames:
    """Function and local names for one robot (deterministic, collision-free).

    Joint symbols keep their names (q1, qd2, ...); a parameter whose name is reserved, taken or
    looks like a temporary gets `_` then `_1`, `_2`, ... appended (as in the C target).

    Raises:
        SymdynError: a robot name that is not a MATLAB identifier (a leading underscore) or
            makes a function name longer than NAME_LENGTH_MAX.
    """
    name = ctx.name
    functions = {f.name: f"{name}_{f.name}" for f in ctx.functions}
    if not _IDENTIFIER.match(name):
        raise SymdynError(f"robot '{name}': a MATLAB function name must start with a letter")
    longest = max(functions.values(), key=len)
    if len(longest) > NAME_LENGTH_MAX:
        raise SymdynError(
            f"robot '{name}': the MATLAB function name '{longest}' is longer than {NAME_LENGTH_MAX} "
            f"characters (namelengthmax); shorten the robot's name{_frame_hint(ctx, longest)}"
        )
    arguments = {r.name for f in ctx.functions for r in f.results} | {
        i.name for f in ctx.functions for i in f.inputs
    }
    reserved = MATLAB_RESERVED | arguments | set(functions.values())
    joints = [s for f in ctx.functions for i in f.inputs if i.name != "p" for s in i.symbols]
    locals_: dict[sp.Symbol, str] = {s: str(s) for s in dict.fromkeys(joints)}
    used = set(locals_.values())
    for s in locals_:
        assert s.name not in reserved and not TEMPORARY.match(s.name), f"joint symbol '{s}' is reserved"
    for p in ctx.dynamics.params:
        if p in locals_:
            raise SymdynError(f"robot '{name}': parameter name {p} clashes with a joint symbol")
        locals_[p] = free_name(str(p), reserved | used, TEMPORARY)
        used.add(locals_[p])
    return MatlabNames(functions, locals_)
