"""The former module of the C target, kept for old imports: the backend is symdyn.codegen.c."""

from .c import CPrinter, c_names, render

__all__ = ["render", "CPrinter", "c_names"]
