"""The generated regressor functions: regressor(q, qd, qdd, p, Y) and base_regressor(q, qd, qdd, p, Yb).

tau = Y(q, qd, qdd) pi with pi the standard parameters (symdyn.standard_parameters: 13 per body,
nstd = 13 nb columns) and tau = Y_b(q, qd, qdd) pi_b with pi_b the base parameters
(`Dynamics.base_parameters`, nbase columns; symdyn.algorithms.base_parameters), both row-major
n x columns (NV rows and the base body's 10 columns last on a floating base), from the
Newton-Euler recursion (symdyn.algorithms.regressor). The size names
"nstd" and "nbase" (symdyn.codegen.functions.DIMS) are spelled by each target; `columns` gives
every target the same table of column names (and, for Y_b, each base parameter's definition).
"""

from __future__ import annotations

import warnings

import sympy as sp

from ..dynamics import Dynamics
from ..errors import SymdynError, SymdynWarning
from ..model.parameters import standard_parameters
from .function_rows import FunctionRow, Inputs, Output

__all__ = ["regressor_rows", "columns", "base_definitions"]


def columns(dyn: Dynamics, dim: str) -> list[tuple[str, str]]:
    """(name, meaning) of each column of the output with size name `dim` ("nstd" or "nbase")."""
    if dim == "nstd":
        return [(name, "standard parameter") for name in standard_parameters(dyn.robot)[0]]
    assert dim == "nbase", dim
    return [(name, str(expr)) for name, expr in dyn.base_parameters]


def base_definitions(dyn: Dynamics) -> list[tuple[str, sp.Expr]]:
    """(name, expression) of each base parameter over the standard parameters' symbols."""
    return list(dyn.base_parameters)


def regressor_rows(dyn: Dynamics, x: Inputs) -> list[FunctionRow]:
    """The two regressor functions over `dyn.program` (the regressor's own intermediates); only
    `regressor`, with a SymdynWarning, when the base parameters cannot be found exactly."""
    Y = dyn.regressor_compact()
    n = dyn.n
    state = (x.q, x.qd, x.qdd, x.p)
    per_body = "13 per body"
    if Y.cols - (10 if dyn.robot.floating else 0) > 13 * dyn.robot.nb:
        per_body += ", then fcn per joint with direction-dependent Coulomb friction"
    if dyn.robot.floating:
        per_body += ", then the base body's 10 (m0 ... Izz0)"
    rows = [
        FunctionRow(
            "regressor",
            f"Y(q, qd, qdd) with tau = Y pi, pi the standard parameters ({per_body})",
            state,
            (
                Output(
                    "Y",
                    n,
                    Y.cols,
                    "regressor of the standard parameters (symdyn.standard_parameters order)",
                    ("n", "nstd"),
                ),
            ),
            tuple(Y),
            cse="regressor",
        )
    ]
    try:
        base = dyn.linear_compact()[1]
    except SymdynError as exc:
        warnings.warn(f"base_regressor is not generated: {exc}", SymdynWarning, stacklevel=3)
        return rows
    Yb = Y.extract(list(range(n)), list(base.columns))
    rows.append(
        FunctionRow(
            "base_regressor",
            "Y_b(q, qd, qdd) with tau = Y_b pi_b, pi_b the base parameters",
            state,
            (
                Output(
                    "Yb",
                    n,
                    Yb.cols,
                    "regressor of the base parameters (Dynamics.base_parameters order)",
                    ("n", "nbase"),
                ),
            ),
            tuple(Yb),
            cse="regressor",
        )
    )
    return rows
