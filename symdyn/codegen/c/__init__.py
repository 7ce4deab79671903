"""The C backend: a config (names, types, reserved words), a printer, and templates/c/.

`render(ctx)` gives NAME_dynamics.h and NAME_dynamics.c (docs/generated-code.md), `render_both(ctx)`
the same files holding both precisions (symdyn.codegen.c.both).
"""

from .both import render_both
from .config import C_RESERVED, CConfig, CNames, c_names
from .printer import CPrinter
from .target import TOOLS, render, render_context

__all__ = [
    "render",
    "render_both",
    "render_context",
    "CPrinter",
    "CConfig",
    "CNames",
    "c_names",
    "C_RESERVED",
    "TOOLS",
]
