"""The end-effector wrench term of Modern Robotics' InverseDynamics as a generated function.

tip_wrench_torque(q, F, p) = J_b(q)^T F (symdyn.algorithms.tip_wrench): the joint torques that
hold the wrench F = [m; f] the end effector applies to its environment, in the end-effector
frame {n+1}. It is generated for robots given as product-of-exponentials data (`convention:
poe`, symdyn.robot_from_poe), whose end-effector frame is part of the description; add it to
inverse_dynamics for MR's torques with F_tip. codegen.functions builds the function row.
"""

from __future__ import annotations

import sympy as sp

from ..algorithms.tip_wrench import tip_wrench_torque
from ..dynamics import Dynamics

__all__ = ["TIP_WRENCH_FUNCTION", "TIP_WRENCH_DOC", "tip_wrench_symbols", "tip_wrench_exprs"]

TIP_WRENCH_FUNCTION = "tip_wrench_torque"
TIP_WRENCH_DOC = "tau_tip = J_b(q)^T F: the torques holding the end-effector wrench F = [m; f] (frame {n+1})"


def tip_wrench_symbols() -> tuple[sp.Symbol, ...]:
    """The symbols of the input F: Ftip1..Ftip6 (moment first, as Modern Robotics' Ftip)."""
    return tuple(sp.Symbol(f"Ftip{k}") for k in range(1, 7))


def tip_wrench_exprs(dyn: Dynamics) -> list[sp.Expr] | None:
    """The n entries of J_b(q)^T F over dyn.q, F and dyn.params; None unless the robot came from
    product-of-exponentials data (the only description with an end-effector frame of its own)."""
    if dyn.robot.convention != "poe":
        return None
    return list(tip_wrench_torque(dyn.robot, tip_wrench_symbols(), list(dyn.q)))
