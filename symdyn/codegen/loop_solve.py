"""NAME_solve_loops, the one generated function with a loop (docs/closed-loops.md): Newton's
method on the passive coordinates q_p of a robot with closed loops, the actuated ones held at qa,

    q_p <- q_p + dq_p,   dq_p = -K_p(q)^-1 phi(q)      (NAME_loop_newton_step)

from q_guess, until max |phi| <= tol (returning the number of steps taken, 0 when q_guess
already closes the loops) or MAX_ITERATIONS steps (returning -1). The step solves the normal
equations K_p^T K_p dq_p = -K_p^T phi by an unrolled L D L^T; a relative pivot D_j / N_jj at or
below PIVOT (K_p singular or nearly so: a guess at a singular configuration) returns -1 before
the step is taken, and so does a residual or step that is not finite: the function never loops
for ever and never divides silently. Every target's
template spells the loop from `loop_solve_view`.
"""

from __future__ import annotations

from ..model.robot import Robot
from .render import RenderContext

__all__ = ["MAX_ITERATIONS", "TOLERANCE", "PIVOT", "loop_solve_view", "loop_solve_context"]

#: The bound on Newton steps of NAME_solve_loops.
MAX_ITERATIONS = 50
#: Convergence: max |phi| (m, rad) at or below this, per precision.
TOLERANCE = {"double": "1e-12", "float": "1e-5"}
#: The smallest relative pivot of the step's solve (about 1 / cond(K_p)^2), per precision.
PIVOT = {"double": "1e-14", "float": "1e-7"}


def loop_solve_view(robot: Robot, npas: int) -> dict:
    """The actuated and passive coordinates (0-based, coordinate order), the bound and the
    tolerances of NAME_solve_loops for a robot with loops."""
    own = sorted({c.index for i, c in enumerate(robot.coordinates) if i in robot.actuated_links})
    passive = [j for j in range(robot.n) if j not in own]
    assert len(passive) == npas, (passive, npas)
    return {
        "actuated": own,
        "passive": passive,
        "max_iterations": MAX_ITERATIONS,
        "tol": dict(TOLERANCE),
        "pivot": dict(PIVOT),
    }


def loop_solve_context(ctx: RenderContext, precision: str | None = None) -> dict | None:
    """`loop_solve_view` with the tolerance and pivot bound of `precision` (ctx's by default),
    for a rendering whose functions include loop_newton_step; None otherwise."""
    step = next((f for f in ctx.functions if f.name == "loop_newton_step"), None)
    if step is None:
        return None
    view = loop_solve_view(ctx.robot, step.results[0].rows)
    precision = precision or ctx.precision
    return {**view, "tol": view["tol"][precision], "pivot": view["pivot"][precision]}
