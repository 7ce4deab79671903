"""Fixed tendons: couplings of the joints with constant coefficients (MuJoCo's <fixed> tendons).

A fixed tendon has the length L(q) = sum_i c_i q_b,i over the bodies' joint positions q_b
(`coefficients`, one per link; Robot.body_positions, so a mimic joint's offset enters), hence
the constant Jacobian J = dL/dq (1 x n over the independent coordinates: J = c^T S). Its
passive properties add to the equations of motion tau = M qdd + V + G + F (slide 16):

    M += a J^T J                                  (armature a)
    F += d J^T (J qd) + f J^T sign(J qd)          (damping d; frictionloss f, as Coulomb's law)
    G += k (L - L0) J^T                           (stiffness k, spring length L0)

the last the gradient of the spring's potential energy k/2 (L - L0)^2, so that G stays the
gradient of the potential energy (gravity and springs). A joint's own spring (MJCF joint
`stiffness` and `springref`) is the tendon with one coefficient 1. The terms are added in one
place for both derivation routes (symdyn.algorithms.tendons) and, separately, by the numeric
oracle (symdyn.oracle).
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass

import sympy as sp

from ..errors import SymdynError

__all__ = ["Tendon", "refuse_tendons"]


@dataclass(frozen=True)
class Tendon:
    """A fixed tendon: L = sum_i coefficients[i] q_b,i over the links (module docstring).

    `name` names it in messages (MuJoCo's tendon name, or "joint 'j' spring" for a joint's own
    stiffness); `coefficients` has one entry per link (zero for the joints it does not span).
    """

    name: str
    coefficients: tuple[sp.Expr, ...]
    armature: sp.Expr = sp.S.Zero
    damping: sp.Expr = sp.S.Zero
    frictionloss: sp.Expr = sp.S.Zero
    stiffness: sp.Expr = sp.S.Zero
    #: the length L0 at which the spring is relaxed (MuJoCo's springlength, or springref)
    springlength: sp.Expr = sp.S.Zero

    def subs(self, x: Mapping) -> Tendon:
        """The tendon with `x` substituted into its numbers."""

        def s(v):
            return sp.sympify(v).xreplace(dict(x))

        return Tendon(
            self.name,
            tuple(s(c) for c in self.coefficients),
            s(self.armature),
            s(self.damping),
            s(self.frictionloss),
            s(self.stiffness),
            s(self.springlength),
        )


def refuse_tendons(robot, what: str, alternative: str) -> None:
    """A SymdynError naming the robot's first tendon when `what` cannot take tendons (their
    terms are not linear in the inertial parameters, or have no place in `what`'s form);
    `alternative` says what to do instead. Nothing for a robot without tendons."""
    tendons = getattr(robot, "tendons", ())
    if not tendons:
        return
    more = f" (and {len(tendons) - 1} more)" if len(tendons) > 1 else ""
    raise SymdynError(
        f"robot '{robot.name}': {what} does not take fixed tendons or joint springs "
        f"('{tendons[0].name}'{more}): {alternative}",
        file=getattr(robot, "source", None),
    )
