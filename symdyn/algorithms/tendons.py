"""The terms fixed tendons and joint springs add to M, G and F (symdyn.model.tendons).

With L(q) = c^T q_b(q) a tendon's length and J = dL/dq its constant Jacobian (1 x n over the
independent coordinates; J = c^T S with mimic joints):

    M += a J^T J,    F += d J^T (J qd) + f J^T sign(J qd),    G += k (L - L0) J^T

(armature a, damping d, frictionloss f as Coulomb's law, stiffness k, spring length L0), the
last the gradient of the spring's potential energy k/2 (L - L0)^2. `derive` (symdyn.dynamics)
adds them once, after either route, to M, G, F, tau and the bias; every generated function
reads them there.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import sympy as sp

from ..model.robot import Robot

__all__ = ["TendonTerms", "tendon_terms"]


@dataclass(frozen=True)
class TendonTerms:
    """What the tendons add: M (n x n), G (n x 1, springs) and F (n x 1, damping and friction)."""

    M: sp.Matrix
    G: sp.Matrix
    F: sp.Matrix


def tendon_terms(robot: Robot, q: Sequence, qd: Sequence) -> TendonTerms:
    """The tendons' M, G and F over the independent coordinates q, qd (n symbols each; module
    docstring); zero matrices for a robot without tendons."""
    n = len(q)
    M, G, F = sp.zeros(n, n), sp.zeros(n, 1), sp.zeros(n, 1)
    q_b = robot.body_positions(list(q))
    for t in robot.tendons:
        length = sum((sp.sympify(c) * x for c, x in zip(t.coefficients, q_b, strict=True)), sp.S.Zero)
        J = sp.Matrix([[sp.diff(length, s) for s in q]])
        rate = (J * sp.Matrix(list(qd)))[0, 0]
        M += sp.sympify(t.armature) * J.T * J
        F += J.T * (sp.sympify(t.damping) * rate + sp.sympify(t.frictionloss) * sp.sign(rate))
        G += J.T * (sp.sympify(t.stiffness) * (length - sp.sympify(t.springlength)))
    return TendonTerms(M, G, F)
