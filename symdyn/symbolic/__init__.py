"""Symbolic machinery under the derivations: the program of named intermediates,
common-subexpression elimination and simplification of closed forms."""
