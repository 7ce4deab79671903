"""The generated centroidal functions (docs/centroidal.md), group `centroidal`:

    centroidal_momentum_matrix(q, p, Ag)   A_g, 6 x NV: h_g = A_g v, linear then angular
                                           momentum about the centre of mass, world-aligned
    centroidal_momentum_drift(q, v, p, h)  Adot_g v (6): the rate of h_g at vdot = 0
    com(q, p, c)                           the centre of mass in the world (3)
    total_mass(p, m)                       the total mass (1)

as symdyn.algorithms.centroidal computes them, over a copy of the dynamics' program. On a
floating robot q and v are symdyn.model.free_flyer's (NQ = 7 + n, NV = 6 + n: the base's
coordinates, then the joints'); on a fixed base they are the joints' (v = qd) and the base's
columns are absent. `floating_inputs` gives these two inputs for any family of functions.
"""

from __future__ import annotations

from dataclasses import replace

import sympy as sp

from ..algorithms.centroidal import Centroidal
from ..dynamics import Dynamics
from ..model.free_flyer import NQ_BASE, NV_BASE, base_symbols
from .function_rows import FunctionRow, Input, Inputs, Output, with_steps

__all__ = ["CENTROIDAL_FUNCTIONS", "centroidal_rows", "com_row", "floating_inputs", "centroidal_of"]

CENTROIDAL_FUNCTIONS = ("centroidal_momentum_matrix", "centroidal_momentum_drift", "com", "total_mass")


def floating_inputs(dyn: Dynamics, x: Inputs) -> tuple[Input, Input]:
    """(q, v): NQ and NV symbols on a floating robot (the base's, then the joints'), else x.q and
    the joint rates x.qd named v."""
    if not dyn.robot.floating:
        return x.q, Input("v", x.qd.symbols)
    qb, vb, _ = base_symbols()
    q = x.q.symbols if len(x.q.symbols) == dyn.robot.nq else (*qb, *x.q.symbols)
    v = x.qd.symbols if len(x.qd.symbols) == dyn.robot.nv else (*vb, *x.qd.symbols)
    return Input("q", tuple(q)), Input("v", tuple(v))


def centroidal_of(dyn: Dynamics, x: Inputs, program) -> Centroidal:
    """The Centroidal quantities of `dyn`'s robot over `program`, on the inputs of floating_inputs."""
    q, v = floating_inputs(dyn, x)
    robot, n = dyn.robot, dyn.robot.n
    if robot.floating:
        base_q, base_v = q.symbols[:NQ_BASE], v.symbols[:NV_BASE]
        return Centroidal(robot, q.symbols[NQ_BASE:], v.symbols[NV_BASE:], program, base_q, base_v)
    return Centroidal(robot, q.symbols[:n], v.symbols[:n], program)


def _entries(M: sp.Matrix) -> tuple[sp.Expr, ...]:
    return tuple(M[i, j] for i in range(M.rows) for j in range(M.cols))


def com_row(q: Input, p: Input, c: sp.Matrix) -> tuple:
    """The row of com(q, p, c) (in the kinematics and the centroidal groups) over c (3 x 1)."""
    out = Output("c", 3, 1, "centre of mass in the world", ("3", "1"))
    return ("com", "the centre of mass c(q), world frame", (q, p), (out,), _entries(c))


def centroidal_rows(dyn: Dynamics, x: Inputs) -> list[FunctionRow]:
    """The four centroidal functions (module docstring), one CSE group."""
    prog = dyn.program.copy("G")
    first = len(prog.assignments)
    cen = centroidal_of(dyn, x, prog)
    q, v = floating_inputs(dyn, x)
    nv = dyn.robot.nv
    cols = ("6", "nv") if dyn.robot.floating else ("6", "n")
    rows = [
        (
            "centroidal_momentum_matrix",
            "A_g(q): h_g = A_g v, linear then angular momentum about the centre of mass, world-aligned",
            (q, x.p),
            (Output("Ag", 6, nv, "centroidal momentum matrix", cols),),
            _entries(cen.momentum_matrix()),
        ),
        (
            "centroidal_momentum_drift",
            "Adot_g(q, v) v: the rate of the centroidal momentum at vdot = 0, world-aligned",
            (q, v, x.p),
            (Output("h", 6, 1, "Adot_g v: linear then angular", ("6", "1")),),
            _entries(cen.drift()),
        ),
        com_row(q, x.p, cen.com()),
        (
            "total_mass",
            "the total mass m, " + ("the base body's and the links'" if dyn.robot.floating else "the links'"),
            (x.p,),
            (Output("m", 1, 1, "total mass", ("1", "1")),),
            (cen.mass,),
        ),
    ]
    out = with_steps(rows, prog, first, "centroidal")
    # A_g's temporaries laid out column by column (each coordinate's momentum at once): row by
    # row kept every column's intermediates alive to the last row (stack spills, 1.4x the time)
    ncols = cen.momentum_matrix().cols
    column_major = tuple(r * ncols + j for j in range(ncols) for r in range(6))
    return [replace(r, visit=column_major) if r.name == "centroidal_momentum_matrix" else r for r in out]
