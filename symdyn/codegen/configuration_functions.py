"""The generated configuration arithmetic of a floating robot (docs/centroidal.md):

    integrate(q, v, dt, q_next)    q_next = q (+) v dt, NQ entries (a unit quaternion)
    difference(q0, q_next, v)      v = difference(q0, q_next), NV entries, with q0 (+) v = q_next

as symdyn.algorithms.lie_group defines them (Pinocchio's JointModelFreeFlyer: the SE(3)
exponential and logarithm in the base frame; the joints add). A fixed-base robot has neither.
Their inputs have symbols of their own (ending in `_b`, which no parameter of a floating robot
may), so that neither function reads the dynamics' program; each is its own CSE group. The
second configuration of difference is called q_next (not q1, the first joint's symbol), so
that difference(q, q_next) undoes integrate's step.
"""

from __future__ import annotations

import sympy as sp

from ..algorithms.lie_group import difference, integrate
from ..dynamics import Dynamics
from ..model.free_flyer import base_symbols
from ..symbolic.program import Program
from .function_rows import FunctionRow, Input, Inputs, Output

__all__ = ["CONFIGURATION_FUNCTIONS", "configuration_rows", "configuration_inputs"]

CONFIGURATION_FUNCTIONS = ("integrate", "difference")


def configuration_inputs(dyn: Dynamics) -> tuple[Input, Input, Input, Input]:
    """The inputs q (NQ), v (NV), dt (1) and q_next (NQ) of the two functions (q0 reads q's symbols)."""
    qb, vb, _ = base_symbols()
    n = dyn.robot.n
    q_joints, v_joints = list(dyn.q)[len(dyn.q) - n :], list(dyn.qd)[len(dyn.qd) - n :]
    joints = [sp.Symbol(f"{s}_1_b") for s in q_joints]
    q = Input("q", (*qb, *q_joints))
    v = Input("v", (*vb, *v_joints))
    dt = Input("dt", (sp.Symbol("dt_b"),))
    q1 = Input("q_next", (*(sp.Symbol(f"{str(s)[:-2]}_1_b") for s in qb), *joints))
    return q, v, dt, q1


def configuration_rows(dyn: Dynamics, x: Inputs) -> list[FunctionRow]:
    """integrate and difference of a floating robot (module docstring); none on a fixed base."""
    robot = dyn.robot
    if not robot.floating:
        return []
    n = robot.n
    q, v, dt, q1 = configuration_inputs(dyn)
    rows = []
    prog = Program()
    out = integrate(n, q.symbols, v.symbols, dt.symbols[0], prog)
    rows.append(
        FunctionRow(
            "integrate",
            "q_next = q (+) v dt: the base by the SE(3) exponential of its twist in the base frame "
            "(quaternion normalised), the joints by q + qd dt",
            (q, v, dt),
            (Output("q_next", robot.nq, 1, "the configuration after dt", ("nq", "1")),),
            tuple(out),
            tuple(prog.needed(out)),
            cse="integrate",
        )
    )
    prog = Program()
    q0 = Input("q0", q.symbols)
    out = difference(n, q0.symbols, q1.symbols, prog)
    rows.append(
        FunctionRow(
            "difference",
            "v with q0 (+) v = q_next: the base by the SE(3) logarithm of base0_T_base1, the "
            "joints by q_next - q0",
            (q0, q1),
            (Output("v", robot.nv, 1, "the velocity leading from q0 to q_next in unit time", ("nv", "1")),),
            tuple(out),
            tuple(prog.needed(out)),
            cse="difference",
        )
    )
    return rows
