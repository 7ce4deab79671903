"""Joint friction: viscous, and Coulomb friction symmetric or direction-dependent (slide 16).

F_i(qd_i) = viscous qd_i + coulomb sign(qd_i)                            (symmetric)
F_i(qd_i) = viscous qd_i + coulomb H(qd_i) - coulomb_minus H(-qd_i)     (direction-dependent)

with H the Heaviside step taken as 0 at 0 (`sp.Heaviside(x, 0)`), so F_i(0) = 0 either way and
both Coulomb magnitudes are >= 0 (the Robotics Toolbox writes the second one negative, Tc-).
The effort is linear in the coefficients; `Friction.coulomb_columns` gives the factors of the
Coulomb magnitudes (the regressor's columns, symdyn.model.parameters).
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass

import sympy as sp

__all__ = ["Friction", "coulomb_fields"]


@dataclass(frozen=True)
class Friction:
    """Joint friction at the joint rate qd_i (slide 16), symmetric or direction-dependent.

    Symmetric (`coulomb_minus` None): F_i = viscous qd_i + coulomb sign(qd_i).
    Direction-dependent: F_i = viscous qd_i + coulomb H(qd_i) - coulomb_minus H(-qd_i), with
    H the Heaviside step that is 0 at 0 (`sp.Heaviside(x, 0)`): + coulomb when moving
    forwards, - coulomb_minus when moving backwards, 0 at rest; both are magnitudes (>= 0).
    """

    viscous: sp.Expr = sp.S.Zero
    coulomb: sp.Expr = sp.S.Zero
    coulomb_minus: sp.Expr | None = None

    def __repr__(self) -> str:
        minus = "" if self.coulomb_minus is None else f", coulomb_minus={self.coulomb_minus!r}"
        return f"Friction(viscous={self.viscous!r}, coulomb={self.coulomb!r}{minus})"

    @property
    def asymmetric(self) -> bool:
        """Whether the Coulomb friction has a magnitude of its own for each direction."""
        return self.coulomb_minus is not None

    def coulomb_columns(self, rate) -> list[sp.Expr]:
        """The factors of the Coulomb magnitudes in F_i: [sign(rate)] when symmetric, else
        [H(rate), -H(-rate)] (the regressor's Coulomb columns, symdyn.model.parameters)."""
        if self.coulomb_minus is None:
            return [sp.sign(rate)]
        return [sp.Heaviside(rate, 0), -sp.Heaviside(-rate, 0)]

    def effort(self, rate) -> sp.Expr:
        """F_i at the joint rate `rate` (see the class docstring)."""
        magnitudes = [self.coulomb] if self.coulomb_minus is None else [self.coulomb, self.coulomb_minus]
        columns = self.coulomb_columns(rate)
        coulomb = sum((sp.sympify(c) * x for c, x in zip(magnitudes, columns, strict=True)), sp.S.Zero)
        return sp.sympify(self.viscous) * rate + coulomb

    def subs(self, x: Mapping) -> Friction:
        """The friction with `x` substituted into its coefficients."""
        minus = None if self.coulomb_minus is None else sp.sympify(self.coulomb_minus).xreplace(x)
        return Friction(sp.sympify(self.viscous).xreplace(x), sp.sympify(self.coulomb).xreplace(x), minus)

    def coefficients(self) -> tuple[sp.Expr, ...]:
        """(viscous, coulomb) or (viscous, coulomb, coulomb_minus): every coefficient it has."""
        minus = () if self.coulomb_minus is None else (self.coulomb_minus,)
        return (self.viscous, self.coulomb, *minus)


def coulomb_fields(coulomb, coulomb_minus=None) -> dict[str, object]:
    """The Coulomb magnitudes by the field names a robot file gives them ('friction.coulomb',
    or 'friction.coulomb.plus' and 'friction.coulomb.minus' when direction-dependent), for
    messages and checks that name the field."""
    if coulomb_minus is None:
        return {"friction.coulomb": coulomb}
    return {"friction.coulomb.plus": coulomb, "friction.coulomb.minus": coulomb_minus}
