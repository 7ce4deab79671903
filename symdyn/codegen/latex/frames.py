"""The frame functions in the LaTeX target: each as definitions x_k and its output entries.

Each function of the kinematics and operational_space groups (symdyn.codegen.frame_functions)
is one align* block: the eliminated temporaries x_k it needs, then its outputs' entries
(T, J, a, c, Jc, Lambda, mu; row-major, 1-based indices), with q_{i} and \\dot{q}_{i} for the
joint symbols and the free parameters under their names.
"""

from __future__ import annotations

import sympy as sp

from ...model.names import comment_text, latex_text
from ..frame_functions import frame_function_names
from ..render import RenderContext, environment

__all__ = ["frames_latex", "function_blocks"]


def frames_latex(ctx: RenderContext) -> str:
    """The section of ctx's frame functions (empty without them)."""
    known = frame_function_names(ctx.frames) if ctx.frames else set()
    names = [f.name for f in ctx.functions if f.name in known]
    if not names:
        return ""
    blocks = function_blocks(ctx, names)
    frames = [(latex_text(n), latex_text(i), latex_text(link)) for n, i, link in ctx.frames]
    return environment().get_template("latex/frames.tex.j2").render(blocks=blocks, frames=frames)


def function_blocks(ctx: RenderContext, names: list[str], extra: dict | None = None) -> list[dict]:
    """One block per generated function of `names`: its name, doc and align rows (the
    definitions x_k, then every output entry); `extra` names more input symbols (symbol -> LaTeX)."""
    dyn = ctx.dynamics
    symbols = dict(extra or {})
    for head, v in (("q", dyn.q), ("\\dot{q}", dyn.qd)):
        symbols.update({s: f"{head}_{{{i + 1}}}" for i, s in enumerate(v)})
    blocks = []
    for name in names:
        spec = ctx.function(name)
        local = dict(symbols)
        local.update({s: f"x_{{{k + 1}}}" for k, (s, _) in enumerate(spec.temporaries)})
        rows = [f"{local[s]} &= {sp.latex(e, symbol_names=local)}" for s, e in spec.temporaries]
        for r in spec.results:
            label = latex_text(r.name)
            for k, e in enumerate(spec.entries(r)):
                i, j = divmod(k, r.cols)
                index = f"{i + 1},{j + 1}" if r.matrix else f"{i + 1}"
                rows.append(f"{label}_{{{index}}} &= {sp.latex(sp.sympify(e), symbol_names=local)}")
        blocks.append({"name": latex_text(name), "doc": comment_text(spec.doc), "rows": rows})
    return blocks
