"""The CasADi backend: a printer (Python over casadi SX), templates/casadi/, and casadi's serialiser.

`render(ctx)` gives NAME_casadi.py and NAME_<function>.casadi (docs/generated-code.md).
"""

from .printer import CASADI_FUNCTIONS, CasadiPrinter
from .target import TOOLS, module_name, render, render_module, serialise

__all__ = [
    "render",
    "render_module",
    "serialise",
    "module_name",
    "CasadiPrinter",
    "CASADI_FUNCTIONS",
    "TOOLS",
]
