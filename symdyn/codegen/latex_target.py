"""The former module of the LaTeX target, kept for old imports: the backend is symdyn.codegen.latex."""

from .latex import dynamics_latex, latex_document_body, render

__all__ = ["render", "latex_document_body", "dynamics_latex"]
