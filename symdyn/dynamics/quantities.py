"""The names of a derivation's quantities, and the simplification of their closed forms.

Shared by the joint-space model (symdyn.dynamics.joint_space), its numeric evaluation
(symdyn.dynamics.numeric) and the frame facade (symdyn.dynamics.frames).
"""

from __future__ import annotations

import sympy as sp

from ..errors import SymdynError
from ..symbolic.simplify import chop_float_noise

__all__ = ["QUANTITIES", "ALL_QUANTITIES", "check_quantity", "simplify_entry"]

#: the terms of tau = M qdd + V + G + F (slide 16), and tau itself
QUANTITIES = ("M", "C", "V", "G", "F", "tau")
#: every name `Dynamics.closed_form` and `Dynamics.evaluate` accept: QUANTITIES and the bias V + G + F
ALL_QUANTITIES = (*QUANTITIES, "bias")


def check_quantity(name, where: str) -> str:
    """`name` if it is one of ALL_QUANTITIES, else a SymdynError naming `where`."""
    if name not in ALL_QUANTITIES:
        raise SymdynError(f"{where}: unknown quantity {name!r} (one of {', '.join(ALL_QUANTITIES)})")
    return name


def simplify_entry(expr: sp.Expr) -> sp.Expr:
    """A readable closed form: expanded, trigonometric identities applied, float rounding
    residues dropped, common factors pulled out."""
    if expr == 0 or expr.is_Atom:
        return expr
    e = sp.trigsimp(sp.expand(expr))
    return sp.factor_terms(chop_float_noise(e))
