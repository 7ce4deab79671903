"""The closed loops in the LaTeX target: the closure equations phi(q) = 0 and the closure
Jacobian K(q) (symdyn.codegen.loop_functions' loop_residual and loop_jacobian), each as the
definitions x_k it needs and its entries, after a paragraph on the actuated coordinates and
the projection of the dynamics (Khalil and Dombre (2002), ch. 14)."""

from __future__ import annotations

from ...model.names import latex_text
from ..loop_solve import loop_solve_context
from ..render import RenderContext, environment
from .frames import function_blocks

__all__ = ["loops_latex"]


def loops_latex(ctx: RenderContext) -> str:
    """The section of ctx's closed loops (empty for a robot without them)."""
    view = loop_solve_context(ctx)
    if view is None:
        return ""
    robot = ctx.robot
    loops = [
        (
            latex_text(lp.name),
            latex_text(robot.links[lp.link].name),
            "the base" if lp.to < 0 else latex_text(robot.links[lp.to].name),
            lp.type,
        )
        for lp in robot.loops
    ]
    return (
        environment()
        .get_template("latex/loops.tex.j2")
        .render(
            loops=loops,
            actuated=[f"q_{{{j + 1}}}" for j in view["actuated"]],
            passive=[f"q_{{{j + 1}}}" for j in view["passive"]],
            blocks=function_blocks(ctx, ["loop_residual", "loop_jacobian"]),
        )
    )
