"""The generated contact functions (docs/contacts.md) of a robot with contacts: group `contacts`,

    contact_jacobian(q, p, Jc)                                   Jc, NLAMBDA x NV
    contact_drift(q, qd, p, gamma)                               gamma = Jc_dot qd at qdd = 0
    contact_forward_dynamics(q, qd, tau, active, p, qdd, lam)    M qdd + b = tau + Jc^T lam,
                                                                 Jc qdd + gamma = 0 (active rows)
    impulse_dynamics(q, qd, active, e, p, qd_plus, impulse)      M (qd_plus - qd) = Jc^T impulse,
                                                                 Jc qd_plus = -e Jc qd

and group `contact_derivatives` (as `derivatives` beside `dynamics`):

    contact_forward_dynamics_derivatives(q, qd, tau, active, p, dqdd_dq, dqdd_dqd, dqdd_dtau,
                                         dlambda_dq, dlambda_dqd, dlambda_dtau)
    impulse_dynamics_derivatives(q, qd, active, e, p, dqd_plus_dq, dqd_plus_dqd, dimpulse_dq,
                                 dimpulse_dqd)

Jc and gamma are symdyn.algorithms.contacts', the solves and derivatives
symdyn.algorithms.contact_dynamics' (branch-free masked KKT system, damping DAMPING), over a copy
of the dynamics' program (b = V + G + F, M). `active` holds NCONTACT numbers, 1 for a contact
that holds and 0 for a free one (only 0 or 1: the mask multiplies rows); `e` is the restitution
(0: the contacts stick; an input of its own, not a robot parameter). The contact force is named
`lam` (lambda is a Python keyword). On a floating robot q has NQ entries and the rest NV
(the base twist in the base frame first), and the derivatives by q are in the tangent space, as
Pinocchio's. The functions that invert M are not generated when M is singular by construction
(symdyn.codegen.functions.build_functions warns), nor any for a robot without contacts.
"""

from __future__ import annotations

import sympy as sp

from ..algorithms.contact_dynamics import DAMPING, KKT
from ..algorithms.contacts import ContactKinematics
from ..algorithms.derivatives import elimination_order, floating_effort_jacobians, jacobian, substitute
from ..algorithms.floating import inertia_efforts
from ..dynamics import Dynamics
from .frame_functions import frames_of
from .function_rows import FunctionRow, Input, Inputs, Output

__all__ = [
    "CONTACT_FUNCTIONS",
    "carried_rows",
    "contact_setup",
    "kkt_of",
    "contact_rows_of",
    "contact_derivative_rows",
    "contact_inputs",
    "contacts_of",
]

CONTACT_FUNCTIONS = (
    "contact_jacobian",
    "contact_drift",
    "contact_forward_dynamics",
    "impulse_dynamics",
    "contact_forward_dynamics_derivatives",
    "impulse_dynamics_derivatives",
)


#: the damping of the Delassus matrix as the functions' comments state it
MU_TEXT = f"{float(DAMPING):.0e}"


def contact_inputs(ncontact: int) -> tuple[Input, Input]:
    """The inputs active (NCONTACT) and e (1); their symbols end in `_c`."""
    return (
        Input("active", tuple(sp.Symbol(f"active{k + 1}_c") for k in range(ncontact))),
        Input("e", (sp.Symbol("e_c"),)),
    )


def _entries(*matrices: sp.Matrix) -> tuple[sp.Expr, ...]:
    return tuple(m[i, j] for m in matrices for i in range(m.rows) for j in range(m.cols))


def _tangent(
    prog, outputs: list, q: list, qd: list, floating: bool, hint: str
) -> tuple[sp.Matrix, sp.Matrix]:
    """d outputs / dq (tangent space on a floating base) and d outputs / dqd, forward mode."""
    if floating:
        return floating_effort_jacobians(prog, outputs, q, qd)
    return jacobian(prog, outputs, q, f"{hint}q"), jacobian(prog, outputs, qd, f"{hint}v")


def contact_setup(dyn: Dynamics, x: Inputs, tag: str):
    """The program copy, its first new step, the inputs, Jc, gamma, the row activities, sizes and
    the contacts' kinematics (whose `frames` give the contact frames' poses)."""
    robot = dyn.robot
    prog = dyn.program.copy(tag)
    first = len(prog.assignments)
    fk, q_in, v_in, nv, cols = frames_of(dyn, x, prog)
    qd = list(v_in.symbols)
    assert list(q_in.symbols) == list(dyn.q) and qd == list(dyn.qd), (
        "the frames' inputs are the dynamics' own"
    )
    active, e = contact_inputs(len(robot.contacts))
    kin = ContactKinematics(fk, robot.contacts, qd, prog)
    Jc, gamma = kin.jacobian(), kin.drift()
    row_active = [active.symbols[k] for k in kin.row_contacts()]
    return prog, first, (Input("qd", tuple(qd)), active, e), Jc, gamma, row_active, nv, cols, kin


def kkt_of(dyn: Dynamics, x: Inputs, prog, Jc, row_active) -> tuple[KKT, list]:
    """The masked KKT system of the robot over `prog` and the force tau - b it is driven by."""
    robot, c = dyn.robot, dyn.compact
    order = elimination_order(Jc.cols, robot.is_chain and not robot.floating)
    kkt = KKT(sp.Matrix(c["M"]), Jc, row_active, order, prog)
    return kkt, [prog.let(t - b, "cf") for t, b in zip(x.tau.symbols, c["bias"], strict=True)]


def _solved(dyn: Dynamics, x: Inputs, prog, Jc, gamma, row_active, e) -> tuple:
    """The KKT system and (qdd, lam, qd_plus, impulse) over `prog`."""
    kkt, force = kkt_of(dyn, x, prog, Jc, row_active)
    qdd, lam = kkt.forward_dynamics(force, list(gamma))
    qd_plus, imp = kkt.impulse(list(dyn.qd), e.symbols[0])
    return kkt, (qdd, lam, qd_plus, imp)


def carried_rows(rows: list[tuple], prog, first: int, cse: str) -> list[FunctionRow]:
    new = {s for s, _ in prog.assignments[first:]}
    steps = tuple(a for a in prog.needed([v for row in rows for v in row[4]]) if a[0] in new)
    carried = [steps] + [()] * (len(rows) - 1)
    return [FunctionRow(*row, s, cse=cse) for row, s in zip(rows, carried, strict=True)]


def contact_rows_of(dyn: Dynamics, x: Inputs) -> list[FunctionRow]:
    """The first four contact functions of the module docstring (group `contacts`); none for a robot
    without contacts, only Jc and gamma when M is singular by construction."""
    robot = dyn.robot
    if not robot.contacts:
        return []
    prog, first, (qd_in, active, e), Jc, gamma, row_active, nv, cols, _ = contact_setup(dyn, x, "c")
    m = Jc.rows

    def out(name, rows, dims, doc):
        return Output(name, rows, nv if dims[1] != "1" else 1, doc, dims)

    lam_doc = "contact forces on the robot, rows of the contacts in order (0 for a free contact)"
    rows: list[tuple] = [
        (
            "contact_jacobian",
            "Jc(q): per contact, a point's world-aligned linear rows or a 6d frame's local rows",
            (x.q, x.p),
            (out("Jc", m, ("nlambda", cols), "contact Jacobian"),),
            _entries(Jc),
        ),
        (
            "contact_drift",
            "gamma = Jc_dot qd at qdd = 0: a point's classical acceleration (world-aligned), a 6d "
            "frame's spatial acceleration (its own axes)",
            (x.q, qd_in, x.p),
            (out("gamma", m, ("nlambda", "1"), "contact drift"),),
            _entries(gamma),
        ),
    ]
    if not dyn.singular_joints:
        _, (qdd, lam, qd_plus, imp) = _solved(dyn, x, prog, Jc, gamma, row_active, e)
        rows += [
            (
                "contact_forward_dynamics",
                "qdd and lam solving M qdd + V + G + F = tau + Jc^T lam, Jc qdd + gamma = 0 for the "
                f"active contacts (masked KKT solve, Delassus matrix damped by mu = {MU_TEXT})",
                (x.q, qd_in, x.tau, active, x.p),
                (out("qdd", nv, (cols, "1"), "accelerations"), out("lam", m, ("nlambda", "1"), lam_doc)),
                (*qdd, *lam),
            ),
            (
                "impulse_dynamics",
                "qd_plus and impulse solving M (qd_plus - qd) = Jc^T impulse, Jc qd_plus = -e Jc qd "
                f"for the active contacts (Delassus matrix damped by mu = {MU_TEXT})",
                (x.q, qd_in, active, e, x.p),
                (
                    out("qd_plus", nv, (cols, "1"), "velocities after the impact"),
                    out(
                        "impulse", m, ("nlambda", "1"), "contact impulses on the robot (0 for a free contact)"
                    ),
                ),
                (*qd_plus, *imp),
            ),
        ]
    return carried_rows(rows, prog, first, "contacts")


def contact_derivative_rows(dyn: Dynamics, x: Inputs) -> list[FunctionRow]:
    """The two derivative functions (group `contact_derivatives`; symdyn.algorithms.contact_dynamics'
    module docstring); none without contacts or when M is singular by construction."""
    robot = dyn.robot
    if not robot.contacts or dyn.singular_joints:
        return []
    prog, first, inputs, Jc, gamma, row_active, _, cols, _ = contact_setup(dyn, x, "C")
    kkt, solved = _solved(dyn, x, prog, Jc, gamma, row_active, inputs[2])
    rows = _derivative_rows(dyn, x, prog, kkt, Jc, gamma, solved, inputs, cols)
    return carried_rows(rows, prog, first, "contact_derivatives")


def _derivative_rows(dyn, x, prog, kkt: KKT, Jc, gamma, solved, inputs, cols) -> list[tuple]:
    """The two derivative functions (symdyn.algorithms.contact_dynamics' module docstring)."""
    robot, c = dyn.robot, dyn.compact
    qdd, lam, qd_plus, imp = solved
    qd_in, active, e = inputs
    q, qd = list(dyn.q), list(dyn.qd)
    nv, m = Jc.cols, Jc.rows
    held = [sp.Symbol(f"_cl{r}") for r in range(m)]  # lambda or the impulse, held
    vel = [sp.Symbol(f"_cv{j}") for j in range(nv)]  # qd_plus, held
    JT = [sp.Add(*[Jc[r, j] * held[r] for r in range(m) if Jc[r, j] != 0]) for j in range(nv)]
    # forward dynamics: r1 = d(ID - Jc^T lam), r2 = d(Jc qdd + gamma), qdd and lam held
    e1 = [t - f for t, f in zip(c["tau"], JT, strict=True)]
    e2 = [sp.Add(*[Jc[r, j] * dyn.qdd[j] for j in range(nv) if Jc[r, j] != 0]) + gamma[r] for r in range(m)]
    d1q, d1v = _tangent(prog, e1 + e2, q, qd, robot.floating, "cD")
    at = dict(zip(dyn.qdd, qdd, strict=True)) | dict(zip(held, lam, strict=True))
    d1q, d1v = (sp.Matrix(nv + m, nv, substitute(prog, _entries(d), at, "cS")) for d in (d1q, d1v))
    ddq, dlq = kkt.sensitivities(d1q[:nv, :], d1q[nv:, :], "cq")
    ddv, dlv = kkt.sensitivities(d1v[:nv, :], d1v[nv:, :], "cv")
    ddt, dlt = kkt.tau_sensitivities("ct")  # r1 = -I, r2 = 0: dqdd/dtau symmetric
    # impulse: r1 = d(M (qd_plus - qd) - Jc^T impulse), r2 = d(Jc (qd_plus + e qd)), both held;
    # M (qd_plus - qd) by the recursion at rest (its q-dependent part, inertia_efforts)
    Mx = inertia_efforts(robot, q, [v - w for v, w in zip(vel, qd, strict=True)], prog)
    e3 = [a - b for a, b in zip(Mx, JT, strict=True)]
    er = e.symbols[0]
    e4 = [sp.Add(*[Jc[r, j] * (vel[j] + er * qd[j]) for j in range(nv) if Jc[r, j] != 0]) for r in range(m)]
    d2q, _ = _tangent(prog, e3 + e4, q, qd, robot.floating, "cI")
    at = dict(zip(vel, qd_plus, strict=True)) | dict(zip(held, imp, strict=True))
    d2q = sp.Matrix(nv + m, nv, substitute(prog, _entries(d2q), at, "cT"))
    dpq, diq = kkt.sensitivities(d2q[:nv, :], d2q[nv:, :], "cp")
    dpv, div = kkt.jump_sensitivities(er, "cw")  # by qd: r1 = -M, r2 = e Jc, in closed form

    def square(name, doc):
        return Output(name, nv, nv, doc, (cols, cols))

    def wide(name, doc):
        return Output(name, m, nv, doc, ("nlambda", cols))

    return [
        (
            "contact_forward_dynamics_derivatives",
            "dqdd/dq, dqdd/dqd, dqdd/dtau, dlam/dq, dlam/dqd, dlam/dtau of contact_forward_dynamics "
            f"(the KKT system with mu = {MU_TEXT} differentiated; by q in the tangent space on a floating "
            "base)",
            (x.q, qd_in, x.tau, active, x.p),
            (
                square("dqdd_dq", "dqdd_i/dq_j"),
                square("dqdd_dqd", "dqdd_i/dqd_j"),
                square("dqdd_dtau", "dqdd_i/dtau_j"),
                wide("dlambda_dq", "dlam_i/dq_j"),
                wide("dlambda_dqd", "dlam_i/dqd_j"),
                wide("dlambda_dtau", "dlam_i/dtau_j"),
            ),
            _entries(ddq, ddv, ddt, dlq, dlv, dlt),
        ),
        (
            "impulse_dynamics_derivatives",
            "dqd_plus/dq, dqd_plus/dqd, dimpulse/dq, dimpulse/dqd of impulse_dynamics (by q in the "
            "tangent space on a floating base)",
            (x.q, qd_in, active, e, x.p),
            (
                square("dqd_plus_dq", "dqd_plus_i/dq_j"),
                square("dqd_plus_dqd", "dqd_plus_i/dqd_j"),
                wide("dimpulse_dq", "dimpulse_i/dq_j"),
                wide("dimpulse_dqd", "dimpulse_i/dqd_j"),
            ),
            _entries(dpq, dpv, diq, div),
        ),
    ]


def contacts_of(ctx) -> tuple:
    """The robot's contacts when a RenderContext's functions include the contact functions (group
    contacts or contact_baumgarte), else () (the targets' NCONTACT, NLAMBDA and CONTACT_NAMES
    constants)."""
    marks = ("contact_jacobian", "contact_error")
    return ctx.robot.contacts if any(f.name in marks for f in ctx.functions) else ()
