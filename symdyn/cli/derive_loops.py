"""What `symdyn derive` adds for a robot with closed loops (docs/closed-loops.md).

derive prints closed forms of M, C, G, F, and those are the spanning tree's: the loops cut open,
every joint free. The closed mechanism's dynamics lives in its actuated coordinates,

    tau_a = W^T tau(q, W qd_a, W qdd_a - [0; K_p^-1 Kdot qd]),   M_a = W^T M W,   W = [I; -K_p^-1 K_a],

on closed configurations only (phi(q) = 0, K = dphi/dq = [K_a K_p]; Khalil and Dombre (2002),
ch. 14; symdyn.algorithms.closed_loops). K_p^-1 has no closed form worth printing in general (a
rational function of q, K_p up to 9 x 9 for a Delta), so derive prints no M_a: `symdyn generate`
writes it as straight-line code (symdyn.codegen.loop_functions). What derive does instead:

- checks the loops with generate's check (symdyn.algorithms.closed_loops.check_loops): a loop
  that cannot close or an `actuated` list that does not match the mobility is refused in one
  line, exactly as by `generate`; a geometry with free parameters (a student's four-bar in
  symbols) cannot be checked, which needs numbers: the header says so, and every closure row is
  printed;
- says so in a header before the equations (comment lines of the text and LaTeX outputs, the
  key "loops" of JSON): that the equations are the tree's, the formulas above, the closure rows
  kept, the actuated and passive joints, and where the actuated dynamics is generated;
- prints the closure phi(q) and its Jacobian K(q), the kept rows, after the equations, in the
  canonical form of the configuration-space entries (sums of cos and sin of sums of joint angles:
  symdyn.symbolic.trig_polynomial, printed by symdyn.symbolic.trig_text), so that the projection
  can be formed from what is printed.
"""

from __future__ import annotations

import json
from dataclasses import dataclass

import sympy as sp

from ..algorithms.closed_loops import check_loops, closure, geometry_parameters, loop_rows_text
from ..algorithms.frame_kinematics import FrameKinematics
from ..dynamics import state_symbols
from ..model.names import comment_text
from ..model.robot import Robot
from ..symbolic.program import Program
from ..symbolic.trig_polynomial import TrigRing, chop
from ..symbolic.trig_text import TrigText

__all__ = ["LoopReport", "loop_report", "with_loops"]

#: What the printed equations are, and where the closed mechanism's dynamics is.
_FORMULAS = (
    "the closed mechanism's dynamics, in the actuated coordinates and on closed q only: "
    "tau_a = W^T tau(q, W qd_a, W qdd_a - [0; K_p^-1 Kdot qd]), M_a = W^T M W, "
    "W = [I; -K_p^-1 K_a], K = dphi/dq = [K_a K_p] (phi and K follow the equations)"
)
_WHY = (
    "no closed form of M_a or tau_a is printed: K_p^-1 has none in general (a rational function "
    "of q, valid on the closure only); symdyn generate writes them as the functions "
    "actuated_mass_matrix, actuated_inverse_dynamics, actuated_forward_dynamics and loop_forces, "
    "K_p^-1 applied by an unrolled L D L^T (docs/closed-loops.md)"
)


_CLOSURE = (
    "closure rows phi(q) = 0 and their Jacobian K = dphi/dq "
    "(kept rows, in the axes of `to`; zeros of K left out)"
)


@dataclass(frozen=True)
class LoopReport:
    """The header lines (without comment marks; the robot's names in them spelled by
    symdyn.model.names.comment_text, so each stays one line), and the kept closure rows: their
    names, phi(q) and K(q) as canonical closed forms over the joint coordinates q, in SymPy's
    syntax, and the same as expressions (`exprs`: phi's entries, then K's row by row)."""

    header: tuple[str, ...]
    rows: tuple[str, ...]
    phi: tuple[str, ...]
    K: tuple[tuple[str, ...], ...]
    exprs: tuple[sp.Expr, ...]


def _joints(robot: Robot, coords) -> str:
    own = [link.name for link in robot.links if link.mimic is None]
    return ", ".join(f"q{j + 1} ({comment_text(own[j])})" for j in coords)


def loop_report(robot: Robot) -> LoopReport | None:
    """The report of `robot`'s loops (None without loops), after generate's check.

    Raises:
        SymdynError: whatever `symdyn generate` refuses the loops for (check_loops).
    """
    if not robot.loops:
        return None
    r = robot.resolved()
    unchecked = sorted(str(s) for s in geometry_parameters(r))
    an = None if unchecked else check_loops(r)
    q = list(state_symbols(r)[0])
    program = Program()
    fk = FrameKinematics(r, q, [0] * len(q), program)
    phi_all, K_all, _ = closure(fk, r, drift=False)
    kept_rows = list(range(len(phi_all))) if an is None else an.rows
    kept = [phi_all[i] for i in kept_rows] + [e for i in kept_rows for e in K_all[i]]
    ring = TrigRing(q)
    printer = TrigText(ring)
    polys = [chop(ring.convert(e)) for e in program.expand(kept)]
    flat = [printer.text(p) or "0" for p in polys]
    m = len(kept_rows)
    phi, K = flat[:m], flat[m:]
    rows = [comment_text(row) for row in loop_rows_text(r, kept_rows)]
    dropped = [i for i in range(len(phi_all)) if i not in kept_rows]
    dropped_rows = comment_text(", ".join(loop_rows_text(r, dropped)))
    note = f" ({dropped_rows} dropped: dependent on the others)" if dropped else ""
    loops = ", ".join(f"{comment_text(lp.name)} ({lp.type})" for lp in r.loops)
    if an is None:
        analysis = (
            f"closure phi(q) = 0: rows {', '.join(rows)}, not checked: whether the loops close, "
            "their independent rows and the mobility are found on numbers, and the geometry has "
            f"free parameters ({', '.join(unchecked)}); give them values (--params) to check"
        )
    else:
        freedom = f"{an.mobility} degree{'s' if an.mobility > 1 else ''} of freedom"
        analysis = (
            f"closure phi(q) = 0: rows {', '.join(rows)}{note}; {freedom}: actuated "
            f"{_joints(r, an.actuated)}; passive {_joints(r, an.passive)}"
        )
    header = (
        f"closed loops {loops}: the equations below are the spanning tree's (the loops cut open, "
        "every joint free), not the closed mechanism's",
        analysis,
        _FORMULAS,
        _WHY,
    )
    n = len(q)
    K_rows = tuple(tuple(K[i * n : (i + 1) * n]) for i in range(m))
    return LoopReport(header, tuple(rows), tuple(phi), K_rows, tuple(ring.to_sympy(p) for p in polys))


def _text(report: LoopReport, text: str) -> str:
    lines = [f"# {h}" for h in report.header] + [text.rstrip("\n"), ""]
    lines.append(f"# {_CLOSURE}")
    lines += [
        f"phi[{i + 1}] = {e}    # {name}"
        for i, (e, name) in enumerate(zip(report.phi, report.rows, strict=True))
    ]
    lines += [
        f"K[{i + 1},{j + 1}] = {e}" for i, row in enumerate(report.K) for j, e in enumerate(row) if e != "0"
    ]
    return "\n".join(lines) + "\n"


def _latex(report: LoopReport, text: str) -> str:
    lines = [f"% {h}" for h in report.header] + [text.rstrip("\n"), "", "\\begin{align*}"]
    m, n = len(report.phi), len(report.K[0]) if report.K else 0
    entries = [f"\\phi_{{{i + 1}}} &= {sp.latex(report.exprs[i])}" for i in range(m)]
    entries += [
        f"K_{{{i + 1},{j + 1}}} &= {sp.latex(report.exprs[m + i * n + j])}"
        for i, row in enumerate(report.K)
        for j, e in enumerate(row)
        if e != "0"
    ]
    return "\n".join(lines) + "\n" + " \\\\\n".join(entries) + "\n\\end{align*}\n"


def _json(report: LoopReport, text: str) -> str:
    doc = json.loads(text)
    doc["loops"] = {
        "note": list(report.header),
        "rows": list(report.rows),
        "phi": list(report.phi),
        "K": [list(row) for row in report.K],
    }
    return json.dumps(doc, indent=2) + "\n"


def with_loops(report: LoopReport | None, text: str, fmt: str) -> str:
    """derive's output `text` (format `fmt`: text, latex or json) with the loops' header and
    closure (module docstring); unchanged without loops (`report` None)."""
    if report is None:
        return text
    return {"text": _text, "latex": _latex, "json": _json}[fmt](report, text)
