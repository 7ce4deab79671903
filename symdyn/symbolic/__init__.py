"""Symbolic machinery under the derivations: the program of named intermediates,
common-subexpression elimination and simplification of closed forms."""

from . import float_zero as _float_zero  # noqa: E402,F401  (SymPy's Float.is_zero, fast)
