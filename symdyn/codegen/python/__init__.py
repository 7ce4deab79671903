"""The NumPy backend (target "python"): a printer, Python names, and templates/python/.

`render(ctx)` gives NAME_numpy.py (docs/generated-code.md).
"""

from .printer import NumpyPrinter, local_names
from .target import TOOLS, file_name, render

__all__ = ["render", "file_name", "NumpyPrinter", "local_names", "TOOLS"]
