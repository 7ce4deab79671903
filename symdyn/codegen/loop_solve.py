"""NAME_solve_loops, the one generated function with a loop (docs/closed-loops.md): Newton's
method on the passive coordinates q_p of a robot with closed loops, the actuated ones held at qa,

    q_p <- q_p + dq_p,   dq_p = -K_p(q)^-1 phi(q)      (NAME_loop_newton_step)

from q_guess, until max |phi| <= tol (returning the number of steps taken, 0 when q_guess
already closes the loops) or MAX_ITERATIONS steps (returning -1). A singular K_p makes a pivot
of the step's L D L^T vanish, its step infinite or NaN: the function returns -1 at once, and
also when phi is not finite; it never loops for ever and never divides silently. Every target's
template spells the loop from `loop_solve_view`.
"""

from __future__ import annotations

from ..model.robot import Robot

__all__ = ["MAX_ITERATIONS", "TOLERANCE", "loop_solve_view"]

#: The bound on Newton steps of NAME_solve_loops.
MAX_ITERATIONS = 50
#: Convergence: max |phi| (m, rad) at or below this, per precision.
TOLERANCE = {"double": "1e-12", "float": "1e-5"}


def loop_solve_view(robot: Robot, npas: int) -> dict:
    """The actuated and passive coordinates (0-based, coordinate order), the bound and the
    tolerances of NAME_solve_loops for a robot with loops."""
    own = sorted({c.index for i, c in enumerate(robot.coordinates) if i in robot.actuated_links})
    passive = [j for j in range(robot.n) if j not in own]
    assert len(passive) == npas, (passive, npas)
    return {"actuated": own, "passive": passive, "max_iterations": MAX_ITERATIONS, "tol": dict(TOLERANCE)}
