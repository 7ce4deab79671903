"""The frame functions in the LaTeX target: each as definitions x_k and its output entries.

Each function of the kinematics and operational_space groups (symdyn.codegen.frame_functions)
is one align* block: the eliminated temporaries x_k it needs, then its outputs' entries
(T, J, a, c, Jc, Lambda, mu; row-major, 1-based indices), with q_{i} and \\dot{q}_{i} for the
joint symbols and the free parameters under their names.
"""

from __future__ import annotations

import re

import sympy as sp

from ..frame_functions import comment_text, frame_function_names
from ..render import RenderContext, environment

__all__ = ["frames_latex", "function_blocks", "tex_text"]


def _tex(text: str) -> str:
    """Text for LaTeX's text mode: a comment-safe name (comment_text) with `^`, `~` as `?`, and
    `_ # & { } $` escaped."""
    return re.sub(r"([_#%&{}$])", r"\\\1", re.sub(r"[\^~\\]", "?", comment_text(text)))


tex_text = _tex


def frames_latex(ctx: RenderContext) -> str:
    """The section of ctx's frame functions (empty without them)."""
    known = frame_function_names(ctx.frames) if ctx.frames else set()
    names = [f.name for f in ctx.functions if f.name in known]
    if not names:
        return ""
    blocks = function_blocks(ctx, names)
    frames = [(_tex(n), _tex(i), comment_text(link)) for n, i, link in ctx.frames]
    return environment().get_template("latex/frames.tex.j2").render(blocks=blocks, frames=frames)


def function_blocks(ctx: RenderContext, names: list[str]) -> list[dict]:
    """One block per generated function of `names`: its name, doc and align rows (the
    definitions x_k, then every output entry)."""
    dyn = ctx.dynamics
    symbols = {}
    for head, v in (("q", dyn.q), ("\\dot{q}", dyn.qd)):
        symbols.update({s: f"{head}_{{{i + 1}}}" for i, s in enumerate(v)})
    blocks = []
    for name in names:
        spec = ctx.function(name)
        local = dict(symbols)
        local.update({s: f"x_{{{k + 1}}}" for k, (s, _) in enumerate(spec.temporaries)})
        rows = [f"{local[s]} &= {sp.latex(e, symbol_names=local)}" for s, e in spec.temporaries]
        for r in spec.results:
            label = _tex(r.name)
            for k, e in enumerate(spec.entries(r)):
                i, j = divmod(k, r.cols)
                index = f"{i + 1},{j + 1}" if r.matrix else f"{i + 1}"
                rows.append(f"{label}_{{{index}}} &= {sp.latex(sp.sympify(e), symbol_names=local)}")
        blocks.append({"name": _tex(name), "doc": comment_text(spec.doc), "rows": rows})
    return blocks
