"""The MATLAB/Octave backend: a config (names, reserved words), a printer, and templates/matlab/.

`render(ctx)` gives one NAME_<function>.m per generated function (docs/generated-code.md).
"""

from .config import MATLAB_RESERVED, MatlabNames, matlab_names
from .printer import MatlabPrinter
from .target import TOOLS, render

__all__ = ["render", "MatlabPrinter", "MatlabNames", "matlab_names", "MATLAB_RESERVED", "TOOLS"]
