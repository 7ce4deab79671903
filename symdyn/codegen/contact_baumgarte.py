"""The generated functions of Baumgarte's stabilisation (docs/contacts.md), group
`contact_baumgarte`, named only (never built by default), for a robot with contacts:

    contact_error(q, anchor, p, err)                                 err, NLAMBDA
    contact_forward_dynamics_baumgarte(q, qd, tau, active, anchor, gains, p, qdd, lam)

err is each contact's position error against its anchor and the stabilised solve keeps
Jc qdd + gamma = -Kd Jc qd - Kp err on the active rows (symdyn.algorithms.contact_error, whose
docstring defines both; the KKT solve is contact_forward_dynamics' own,
symdyn.algorithms.contact_dynamics.KKT, with the stabilised drift). `anchor` holds NCONTACT *
ANCHOR_SIZE numbers (per contact its origin, then its rotation matrix row-major: the C header's
NAME_NANCHOR), `gains` the two numbers (Kp, Kd). With gains 0 the second function is
contact_forward_dynamics. Not built when M is singular by construction (the solve inverts M).
"""

from __future__ import annotations

import sympy as sp

from ..algorithms.contact_error import anchor_symbols, contact_error, stabilised_drift
from ..dynamics import Dynamics
from .contact_functions import MU_TEXT, carried_rows, contact_setup, kkt_of
from .function_rows import FunctionRow, Input, Inputs, Output

__all__ = ["BAUMGARTE_FUNCTIONS", "baumgarte_inputs", "baumgarte_rows"]

BAUMGARTE_FUNCTIONS = ("contact_error", "contact_forward_dynamics_baumgarte")


def baumgarte_inputs(ncontact: int) -> tuple[Input, Input]:
    """The inputs anchor (NCONTACT * ANCHOR_SIZE) and gains (Kp, Kd); their symbols end in `_c`."""
    return Input("anchor", anchor_symbols(ncontact)), Input("gains", (sp.Symbol("kp_c"), sp.Symbol("kd_c")))


def baumgarte_rows(dyn: Dynamics, x: Inputs) -> list[FunctionRow]:
    """The two functions of the module docstring; none without contacts, only contact_error when
    M is singular by construction."""
    robot = dyn.robot
    if not robot.contacts:
        return []
    prog, first, (qd_in, active, _), Jc, gamma, row_active, nv, cols, kin = contact_setup(dyn, x, "B")
    anchor, gains = baumgarte_inputs(len(robot.contacts))
    error = contact_error(kin.frames, robot.contacts, anchor.symbols, prog)
    m = Jc.rows
    rows: list[tuple] = [
        (
            "contact_error",
            "err: per contact, its position error against its anchor (a point: p - p_a, world axes; a "
            "6d contact: R^T (p - p_a) and vee(skew(R_a^T R)) = sin(theta) axis, its own axes)",
            (x.q, anchor, x.p),
            (Output("err", m, 1, "position errors of the contacts against their anchors", ("nlambda", "1")),),
            tuple(error),
        )
    ]
    if not dyn.singular_joints:
        kp, kd = gains.symbols
        drift = stabilised_drift(Jc, list(gamma), list(qd_in.symbols), error, kp, kd, prog)
        kkt, force = kkt_of(dyn, x, prog, Jc, row_active)
        qdd, lam = kkt.forward_dynamics(force, drift)
        rows.append(
            (
                "contact_forward_dynamics_baumgarte",
                "qdd and lam solving M qdd + V + G + F = tau + Jc^T lam, Jc qdd + gamma = -Kd Jc qd - "
                "Kp err for the active contacts, gains = (Kp, Kd) (masked KKT solve, Delassus matrix "
                f"damped by mu = {MU_TEXT})",
                (x.q, qd_in, x.tau, active, anchor, gains, x.p),
                (
                    Output("qdd", nv, 1, "accelerations", (cols, "1")),
                    Output(
                        "lam", m, 1, "contact forces on the robot (0 for a free contact)", ("nlambda", "1")
                    ),
                ),
                (*qdd, *lam),
            )
        )
    return carried_rows(rows, prog, first, "contact_baumgarte")
