"""The generated functions (docs/generated-code.md), as target-independent straight-line code.

Each `FunctionSpec` names its inputs (q, qd, qdd or tau, p: vectors of SymPy
symbols), its outputs (`Output`: tau, M, C, V, G, F, qdd, ...; any number, any shape,
row-major), and the eliminated temporaries (symdyn.symbolic.simplify) that compute them.
Functions come in families (FAMILIES): each is a builder returning `FunctionRow`s over the
derived program, and `build_functions` eliminates all rows in one CSE pass. Printers for C,
CasADi, NumPy and LaTeX render these specs; nothing here is target-specific.

forward_dynamics solves M qdd = tau - (V + G + F) with an LDL^T factorisation
unrolled symbolically (no square roots), left-looking, one column j at a time:
    U_ij = M_ij - sum_{k<j} L_jk U_ik  (i >= j),  D_j = U_jj,  L_jk = U_jk / D_k,
    y_j = b_j - sum_{k<j} L_jk y_k,  then  qdd_j = (y_j - sum_{i>j} U_ij qdd_i) / D_j
(U_ij = L_ij D_j: each product L_jk U_ik is one multiply-add, and L_jk, formed in column j
from the shared reciprocal 1/D_k, is never stored). The temporaries are laid out in this order
(FunctionRow.lead): column j's b_j, then its updates descendant k by descendant k (the entries
of M and the bias computed where first read, so the code of the CRBA and of the bias is emitted
just before the column that reads it), so the column's running sums stay in registers
(measured standalone, gcc -O3 -march=native: Talos floating 2420 -> 2025 ns, Solo-12 floating
660 -> 450 ns, Panda 253 -> 250 ns; the code is bound by instruction fetch, about 50 bytes of
machine code per ns, so spills and reloads count as much as arithmetic). Structural zeros of
M fold away. Unless the robot is a serial chain (Robot.is_chain) the coordinates are
eliminated from the last to the first instead, M = L^T D L (Featherstone, Rigid Body Dynamics
Algorithms (2008), ch. 6, the LTDL factorization that exploits branch-induced sparsity): on a
tree numbered parents first this creates no fill-in, so L keeps the zeros of joints on
different branches, and a floating base's dense 6 x 6 block is factored last. A chain, whose
M is dense, keeps the forward order.

A generated function cannot raise, so the functions that invert M (INVERTING: forward_dynamics
and three derivative functions) are not generated for a robot whose M is singular by
construction: some pivot D_j is an exact zero once the numbers are in, because a joint moves no
mass or inertia, or only mass on its own axis (Dynamics.singular_joints,
symdyn.algorithms.singular). `build_functions` then leaves them out with one SymdynWarning
naming the joints, why, and the functions left out; the others are generated as usual. With
symbolic masses only a pivot that is identically zero counts.
"""

from __future__ import annotations

import warnings
from collections.abc import Callable, Sequence

import sympy as sp

from ..dynamics import QUANTITIES, Dynamics, singular_message
from ..errors import SymdynWarning
from ..progress import stage as progress_stage
from ..symbolic.program import Program
from ..symbolic.simplify import eliminate_many
from .centroidal_functions import centroidal_rows
from .configuration_functions import configuration_rows
from .contact_baumgarte import BAUMGARTE_FUNCTIONS, baumgarte_rows
from .contact_functions import CONTACT_FUNCTIONS, contact_derivative_rows, contact_rows_of
from .derivative_functions import DERIVATIVE_FUNCTION_NAMES, derivative_rows
from .frame_functions import choose_frames, kinematics_rows, operational_space_rows
from .function_rows import (
    DIMS,
    FrameChoice,
    FunctionRow,
    FunctionSpec,
    Input,
    Inputs,
    Output,
    joint_matrix_output,
    vector_output,
)
from .loop_functions import loop_rows
from .regressor_functions import regressor_rows
from .tip_wrench import TIP_WRENCH_DOC, TIP_WRENCH_FUNCTION, tip_wrench_exprs, tip_wrench_symbols

__all__ = [
    "FunctionSpec",
    "FunctionRow",
    "Input",
    "Inputs",
    "Output",
    "DIMS",
    "FAMILIES",
    "GROUPS",
    "FRAME_GROUPS",
    "NAMED_ONLY",
    "build_functions",
    "vector_output",
    "joint_matrix_output",
    "FUNCTION_NAMES",
]

FUNCTION_NAMES = (
    "inverse_dynamics",
    "mass_matrix",
    "coriolis_matrix",
    "coriolis",
    "gravity",
    "friction",
    "forward_dynamics",
    "regressor",
    "base_regressor",
)


def ldlt_column_solve(M: sp.Matrix, b: list[sp.Expr], prog: Program) -> tuple[list[sp.Expr], list[sp.Expr]]:
    """x solving M x = b by the left-looking LDL^T of the module docstring (M in elimination
    order, entries over the program; exact zeros and fill-in tracked), and the intermediates in
    the order to lay them out: (x, layout)."""
    n = M.rows
    layout: list[sp.Expr] = []

    def let(e, hint, always=False):
        out = prog.name(e, hint) if always else prog.let(e, hint)
        named = out if out.is_Symbol else -out  # let names -e's positive form
        if named.is_Symbol and prog.is_intermediate(named):
            layout.append(named)
        return out

    U: dict[tuple[int, int], sp.Expr] = {}
    r: list[sp.Expr] = [sp.S.Zero] * n
    y: list[sp.Expr] = [sp.S.Zero] * n
    for j in range(n):
        below = [k for k in range(j) if (j, k) in U]  # the coordinates eliminated before j that j couples to
        rows = [i for i in range(j + 1, n) if M[i, j] != 0 or any((i, k) in U for k in below)]
        acc = {i: let(M[i, j], "fdM") for i in [j, *rows]}
        acc_y = let(b[j], "fdb")
        for k in below:
            l = let(U[(j, k)] * r[k], "fdL", always=True)
            for i in acc:
                if (i, k) in U:
                    acc[i] = let(acc[i] - l * U[(i, k)], "fdH")
            acc_y = let(acc_y - l * y[k], "fdy")
        y[j] = acc_y
        r[j] = let(1 / acc[j], "fdr")
        for i in rows:
            U[(i, j)] = acc[i]
    x: list[sp.Expr] = [sp.S.Zero] * n
    for j in reversed(range(n)):
        s = y[j] - sum((U[(i, j)] * x[i] for i in range(j + 1, n) if (i, j) in U), sp.S.Zero)
        x[j] = let(r[j] * let(s, "fds"), "fdx", always=True)  # a number r_j must not distribute over s
    return x, layout


def dynamics_rows(dyn: Dynamics, x: Inputs) -> list[FunctionRow]:
    """The six functions of tau = M qdd + V + G + F and its terms (slide 16), over `dyn.program`."""
    n = dyn.n
    c = dyn.compact
    friction = "F(qd) = viscous qd + coulomb sign(qd)"
    if any(link.friction.asymmetric for link in dyn.robot.links):
        friction += ", or c+ [qd > 0] - c- [qd < 0] per direction"
    table = [
        ("inverse_dynamics", "tau = M(q) qdd + V(q, qd) + G(q) + F(qd)", (x.q, x.qd, x.qdd, x.p), "tau"),
        ("mass_matrix", "M(q), row-major n x n", (x.q, x.p), "M"),
        ("coriolis_matrix", "C(q, qd) from Christoffel symbols, row-major; C qd = V", (x.q, x.qd, x.p), "C"),
        ("coriolis", "V(q, qd) = C(q, qd) qd", (x.q, x.qd, x.p), "V"),
        ("gravity", "G(q)", (x.q, x.p), "G"),
        ("friction", friction, (x.qd, x.p), "F"),
    ]
    rows = []
    for name, doc, inputs, out in table:
        shape = joint_matrix_output if out in ("M", "C") else vector_output
        exprs = tuple(c[out])
        # M's temporaries laid out from its last entry back: column by column from the leaves, as
        # the composite bodies are built, each column's carried force used as soon as it is known
        # (row by row from the first kept every column's force alive: Talos M 920 -> 820 ns)
        visit = tuple(reversed(range(len(exprs)))) if out == "M" else None
        rows.append(FunctionRow(name, doc, inputs, (shape(out, n, _OUTPUT_DOCS[out]),), exprs, visit=visit))
    return rows


def forward_dynamics_rows(dyn: Dynamics, x: Inputs) -> list[FunctionRow]:
    """forward_dynamics, the unrolled LDL^T solve of M qdd = tau - bias (module docstring), or
    nothing when M is singular by construction (build_functions warns)."""
    if dyn.singular_joints:
        return []
    n = dyn.n
    c = dyn.compact
    fd = Program()
    # a floating base is the root of the tree, its six coordinates first: eliminating the last
    # coordinate first leaves its 6 x 6 block, dense, for the end and fills nothing else in
    chain = dyn.robot.is_chain and not dyn.robot.floating
    order = list(range(n)) if chain else list(reversed(range(n)))
    b = [x.tau.symbols[i] - c["bias"][i] for i in order]
    solved, layout = ldlt_column_solve(sp.Matrix(c["M"]).extract(order, order), b, fd)
    qdd_out = [solved[order.index(i)] for i in range(n)]
    return [
        FunctionRow(
            "forward_dynamics",
            "qdd solving M(q) qdd = tau - V(q, qd) - G(q) - F(qd) (unrolled LDL^T)",
            (x.q, x.qd, x.tau, x.p),
            (vector_output("qdd", n, _OUTPUT_DOCS["qdd"]),),
            tuple(qdd_out),
            tuple(fd.needed(qdd_out)),
            lead=tuple(dict.fromkeys(layout)),
        )
    ]


def tip_wrench_rows(dyn: Dynamics, x: Inputs) -> list[FunctionRow]:
    """tip_wrench_torque(q, F, p) for product-of-exponentials robots (symdyn.codegen.tip_wrench)."""
    exprs = tip_wrench_exprs(dyn)
    if exprs is None:
        return []
    F = Input("F", tip_wrench_symbols())
    out = vector_output("tau_tip", dyn.n, "joint torques J_b^T F holding the end-effector wrench F")
    return [FunctionRow(TIP_WRENCH_FUNCTION, TIP_WRENCH_DOC, (x.q, F, x.p), (out,), tuple(exprs))]


_OUTPUT_DOCS = {
    "tau": "joint efforts tau = M qdd + V + G + F",
    "M": "joint-space mass (inertia) matrix M(q)",
    "C": "Coriolis matrix C(q, qd) (Christoffel symbols), C qd = V",
    "V": "Coriolis and centrifugal efforts V(q, qd)",
    "G": "gravity efforts G(q)",
    "F": "friction efforts F(qd)",
    "qdd": "joint accelerations",
}


#: The families of generated functions, in the order of the generated files: each maps a derived
#: robot and the input vectors to its FunctionRows (a new family is one module and one entry here;
#: the families in modules of their own build on symdyn.codegen.function_rows, never on this
#: module, so that codegen has no import cycle).

FAMILIES: tuple[Callable[[Dynamics, Inputs], list[FunctionRow]], ...] = (
    dynamics_rows,
    forward_dynamics_rows,
    regressor_rows,
    tip_wrench_rows,
    derivative_rows,
    kinematics_rows,
    operational_space_rows,
    loop_rows,
    configuration_rows,
    centroidal_rows,
    contact_rows_of,
    contact_derivative_rows,
    baumgarte_rows,
)


#: Per family, the functions it leaves out when M is singular by construction (they invert M).
INVERTING: dict[Callable[[Dynamics, Inputs], list[FunctionRow]], tuple[str, ...]] = {
    forward_dynamics_rows: ("forward_dynamics",),
    derivative_rows: DERIVATIVE_FUNCTION_NAMES[1:],
    operational_space_rows: ("operational_space_inertia", "operational_space_bias"),
    contact_rows_of: CONTACT_FUNCTIONS[2:4],
    contact_derivative_rows: CONTACT_FUNCTIONS[4:],
    baumgarte_rows: BAUMGARTE_FUNCTIONS[1:],
}


def _warn_singular(dyn: Dynamics, families) -> None:
    """One SymdynWarning: M is singular (which joints, why) and the functions left out."""
    families = [
        f
        for f in families
        if f not in (contact_rows_of, contact_derivative_rows, baumgarte_rows) or dyn.robot.contacts
    ]
    left_out = [name for family in families for name in INVERTING.get(family, ())]
    if not dyn.singular_joints or not left_out:
        return
    listed = ", ".join(left_out[:-1]) + (" and " if len(left_out) > 1 else "") + left_out[-1]
    warnings.warn(
        f"{singular_message(dyn)}; so {listed} {'are' if len(left_out) > 1 else 'is'} not generated "
        "(the other functions are)",
        SymdynWarning,
        stacklevel=3,
    )


#: The groups of functions `symdyn generate --functions` selects, by the builders of FAMILIES.
GROUPS: dict[str, tuple[Callable[[Dynamics, Inputs], list[FunctionRow]], ...]] = {
    "dynamics": (dynamics_rows, forward_dynamics_rows, loop_rows),
    "regressor": (regressor_rows,),
    "tip_wrench": (tip_wrench_rows,),
    "derivatives": (derivative_rows,),
    "kinematics": (kinematics_rows,),
    "operational_space": (operational_space_rows,),
    "configuration": (configuration_rows,),
    "centroidal": (centroidal_rows,),
    "contacts": (contact_rows_of,),
    "contact_derivatives": (contact_derivative_rows,),
    "contact_baumgarte": (baumgarte_rows,),
}

#: The groups built per frame (symdyn.codegen.frame_functions): only when named, never by default.
FRAME_GROUPS = ("kinematics", "operational_space")
#: The groups built only when named (the frame groups, the centroidal functions and Baumgarte's).
NAMED_ONLY = (*FRAME_GROUPS, "centroidal", "contact_baumgarte")
#: Functions two groups both have (com: kinematics and centroidal): built once, by the first.
SHARED_FUNCTIONS = ("com",)


def _first(rows: list[FunctionRow], name: str) -> FunctionRow:
    return next(row for row in rows if row.name == name)


#: the groups a floating robot gets by default (every group is generated for it when named:
#: docs/floating-base.md, docs/centroidal.md)
FLOATING_DEFAULT = ("dynamics", "configuration", "contacts")


def build_functions(
    dyn: Dynamics, groups: Sequence[str] | None = None, frames: FrameChoice | None = None
) -> list[FunctionSpec]:
    """The generated functions of a derived robot, one CSE pass per `FunctionRow.cse` group.

    All of FAMILIES' rows: the seven of docs/generated-code.md, or six without forward_dynamics
    (and one SymdynWarning naming what is left out) when M is singular by construction (see the
    module docstring), then
    regressor and base_regressor (symdyn.codegen.regressor_functions), tip_wrench_torque for
    product-of-exponentials robots, and the derivatives (symdyn.codegen.derivative_functions);
    the frame groups (FRAME_GROUPS: kinematics, operational_space; symdyn.codegen.frame_functions)
    only when `groups` names them, for the frames and task axes of `frames` (None: the default
    frames, symdyn.codegen.frame_functions.choose_frames).
    The regressor and the derivatives add intermediates to `dyn.program`; each family has a pass
    of its own so that it cannot change the other functions' temporaries. `groups` (names of
    GROUPS; all but NAMED_ONLY, the frame groups and centroidal, by default) keeps only those
    families: their code is the same as in a full build.
    Every row's outputs and extra steps draw on `dyn.program` (with the bias V + G + F always
    among the needs, so adding a family never changes the others' temporaries).
    """
    if dyn.robot.floating and groups is None:
        groups = FLOATING_DEFAULT
    if dyn.robot.tendons and groups is None:  # the regressor takes no tendons (Dynamics.regressor_compact)
        groups = [g for g in GROUPS if g not in (*NAMED_ONLY, "regressor")]
    per_frame = {b for g in FRAME_GROUPS for b in GROUPS[g]}
    named_only = {b for g in NAMED_ONLY for b in GROUPS[g]}
    chosen = set(FAMILIES) - named_only if groups is None else {b for g in groups for b in GROUPS[g]}
    if frames is None and chosen & per_frame:
        frames = choose_frames(dyn.robot)
    x = Inputs.of(dyn, frames)
    families = [family for family in FAMILIES if family in chosen]
    _warn_singular(dyn, families)
    rows = []
    with progress_stage("building the functions", total=len(families), unit="family") as advance:
        for family in families:
            rows += family(dyn, x)
            advance()
    shared = [row for row in rows if row.name in SHARED_FUNCTIONS]
    rows = [row for row in rows if row.name not in SHARED_FUNCTIONS or row is _first(shared, row.name)]
    names = [row.name for row in rows]
    assert len(set(names)) == len(names), f"duplicate generated function names: {names}"
    code = {}
    passes = list(dict.fromkeys(row.cse for row in rows))
    with progress_stage("common subexpressions", total=len(passes), unit="pass") as advance:
        for group in passes:
            code |= _eliminate(dyn, x, [row for row in rows if row.cse == group], group)
            advance()
    return [FunctionSpec(row.name, row.doc, row.inputs, row.results, code[row.name]) for row in rows]


def _eliminate(dyn: Dynamics, x, members: list, group) -> dict:
    """One CSE pass over the rows `members` (of cse group `group`: '' is the shared pass)."""
    needs = [e for row in members for e in row.exprs] + [e for row in members for _, e in row.steps]
    if not group:
        needs += [e for name in QUANTITIES for e in dyn.compact[name]] + list(dyn.compact["bias"])
    steps = dyn.program.needed(needs) + [s for row in members for s in row.steps]
    visits = {row.name: row.visit for row in members if row.visit is not None}
    leads = {row.name: row.lead for row in members if row.lead}
    groups = {row.name: list(row.exprs) for row in members}
    return eliminate_many(steps, groups, reserved=x.symbols, visits=visits, leads=leads)
