"""The LaTeX backend: a notation and printer (symdyn.codegen.latex.notation) and templates/latex/.

`render(ctx)` gives NAME_dynamics.tex; `dynamics_latex(dyn)` is `symdyn derive --format latex`.
"""

from .notation import DynamicsLatexPrinter, Notation
from .target import AMSMATH_NOTE, TOOLS, dynamics_latex, file_name, latex_document_body, render

__all__ = [
    "render",
    "latex_document_body",
    "dynamics_latex",
    "file_name",
    "AMSMATH_NOTE",
    "DynamicsLatexPrinter",
    "Notation",
    "TOOLS",
]
