"""The LaTeX target: `NAME_dynamics.tex`, the equations of motion for people who read them.

The file is a fragment for the body of a document (no preamble) that needs
only amsmath. It prints M, V, G, F (and C for up to three joints) of
tau = M(q) qdd + V(q, qd) + G(q) + F(qd) in the notation of
symdyn.codegen.latex.notation. Three forms:
- closed form (up to three joints): the trigonometrically simplified entries
  (`Dynamics.simplified`), matrices entry by entry in a bmatrix when the rows
  are short, else one equation per entry, long sums broken over lines;
- product form (more joints): the atoms c_i, s_i, c_23 (abbreviations), the
  shared quantities x_1, x_2, ..., then M, B, Csq, G and F over them, with
  V = B [qd qd] + Csq [qd^2] (symdyn.codegen.latex.product), unless it is
  larger than its bound (printed in the file);
- eliminated form (beyond that bound): the common subexpressions of M, V, G and F
  as one align* list of definitions x_{1}, x_{2}, ... in evaluation order,
  then the entries over them (M by its upper triangle). Definitions that are
  just s_{..} or c_{..} are inlined.

This module decides the layout as plain data (entries printed, labels, lines);
every LaTeX display and sentence is spelled in templates/latex/.
`latex_document_body(dyn)` gives the fragment's body, `dynamics_latex(dyn)`
the text of `symdyn derive --format latex`, and `render(ctx)` the file.
"""

from __future__ import annotations

import dataclasses

import sympy as sp

from ...algorithms.configuration_space import pair_columns
from ...dynamics import AUTO_SIMPLIFY_MAX_JOINTS, Dynamics
from ...model.names import comment_text, latex_text
from ...symbolic.simplify import eliminate
from ..render import RenderContext, environment, header_lines
from .base_parameters import base_parameters_latex
from .contacts import contacts_latex
from .frames import frames_latex
from .loops import loops_latex
from .notation import MATRIX_WIDTH, Notation, width
from .product import product_blocks, product_choice

__all__ = ["render", "latex_document_body", "dynamics_latex", "file_name", "AMSMATH_NOTE", "TOOLS"]

AMSMATH_NOTE = "% A fragment for a document body (\\input it); it needs only \\usepackage{amsmath}."

#: The tools the file's bytes depend on besides symdyn: SymPy derives, simplifies and prints.
TOOLS = {"_dynamics.tex": ("sympy",)}


def file_name(name: str) -> str:
    return f"{name}_dynamics.tex"


def _quantity(
    nt: Notation,
    name: str,
    entries: list[sp.Expr],
    shape: tuple[int, int],
    symmetric: bool,
    expand: bool = True,
) -> dict:
    """One of M, C, V, G, F: a bmatrix when its rows are short, else one equation per entry
    (expand False: a factored entry stays factored when broken over lines)."""
    rows, cols = shape
    texts = [nt.latex(e) for e in entries]
    grid = [texts[r * cols : (r + 1) * cols] for r in range(rows)]
    widest = max(sum(width(t) for t in row) + 3 * (cols - 1) for row in grid)
    if widest <= MATRIX_WIDTH:
        return {"name": name, "grid": grid, "equations": None, "mirror": None}
    eqs = []
    for r in range(rows):
        for c in range(cols):
            if symmetric and c < r:
                continue
            label = nt.label(name, r) if cols == 1 else nt.label(name, r, c)
            eqs.append((label, nt.lines(entries[r * cols + c], expand=expand)))
    mirror = (nt.label(name, 1, 0), nt.label(name, 0, 1)) if symmetric else None
    return {"name": name, "grid": None, "equations": eqs, "mirror": mirror}


def _closed_view(dyn: Dynamics) -> Dynamics:
    """`dyn` with trigonometrically simplified closed forms (a copy unless already so)."""
    return dyn if dyn.simplified else dataclasses.replace(dyn, simplified=True, _closed={})


def _closed_blocks(dyn: Dynamics, nt: Notation) -> list[dict]:
    dyn = _closed_view(dyn)
    blocks = []
    for name in ("M", "C", "V", "G", "F"):
        m = dyn.closed_form(name)
        entries = [nt.prepare(e) for e in m]
        blocks.append(_quantity(nt, name, entries, m.shape, name == "M"))
    return blocks


def _eliminated_blocks(dyn: Dynamics, nt: Notation) -> tuple[list[dict], list[tuple[str, list[str]]]]:
    n = dyn.n
    c = dyn.compact
    upper = [(i, j) for i in range(n) for j in range(i, n)]
    outputs = [c["M"][i, j] for i, j in upper] + [c[k][i] for k in ("V", "G", "F") for i in range(n)]
    code = eliminate(dyn.assignments(("M", "V", "G", "F")), outputs, prefix="_latex_x")
    subs: dict[sp.Symbol, sp.Expr] = {}
    definitions: list[tuple[sp.Symbol, sp.Expr]] = []
    for s, e in code.temporaries:
        e = nt.prepare(e.xreplace(subs))
        if e in nt.trig:  # a bare s_{..} or c_{..}: inline it
            subs[s] = e
            continue
        ph = sp.Symbol(f"~0x{len(definitions) + 1:06d}")
        nt.names[ph] = f"x_{{{len(definitions) + 1}}}"
        subs[s] = ph
        definitions.append((ph, e))
    outs = [nt.prepare(e.xreplace(subs)) for e in code.outputs]
    M = sp.zeros(n, n)
    for (i, j), e in zip(upper, outs, strict=False):
        M[i, j] = M[j, i] = e
    rest = outs[len(upper) :]
    blocks = [_quantity(nt, "M", list(M), (n, n), True)]
    for k, name in enumerate(("V", "G", "F")):
        blocks.append(_quantity(nt, name, rest[k * n : (k + 1) * n], (n, 1), False))
    return blocks, [(nt.names[s], nt.lines(e)) for s, e in definitions]


def latex_document_body(dyn: Dynamics, form: str = "auto") -> str:
    """The LaTeX fragment (without header) for `dyn`.

    form: "closed" (simplified closed forms, with C), "product" (the product form: atoms,
    shared quantities x_k, then M, B, Csq, G, F over them), "eliminated" (definitions x_k then
    M, V, G, F over them) or "auto": closed up to three joints, beyond that the product form
    unless it is larger than its bound (symdyn.codegen.latex.product: product_choice).
    """
    if form not in ("auto", "closed", "product", "eliminated"):
        raise ValueError(f"unknown form '{form}' (auto, closed, product or eliminated)")
    if form == "auto":
        form = "closed" if dyn.n <= AUTO_SIMPLIFY_MAX_JOINTS else "product"
    nt = Notation(dyn)
    pf, choice = (None, None)
    if form == "product":
        pf, choice = product_choice(dyn)
        form = "product" if pf is not None else "eliminated"
    if form == "closed":
        blocks, definitions = _closed_blocks(dyn, nt), []
    elif form == "product":
        blocks, definitions = product_blocks(dyn, nt, pf, _quantity)
    else:
        blocks, definitions = _eliminated_blocks(dyn, nt)
    robot = dyn.robot
    n = dyn.n
    pairs = [f"\\dot{{q}}_{{{i + 1}}} \\dot{{q}}_{{{j + 1}}}" for i, j in pair_columns(n)]
    return (
        environment()
        .get_template("latex/body.tex.j2")
        .render(
            name=comment_text(robot.name),
            tex_name=latex_text(robot.name),
            n=n,
            joints=[str(i) for i in range(1, n + 1)] if n <= 3 else ["1", "\\dots", str(n)],
            method=dyn.method,
            form=form,
            choice=choice,
            pairs=pairs if n <= 3 else [pairs[0], "\\dots", pairs[-1]],
            params=nt.params,
            legend=nt.legend(),
            definitions=definitions,
            blocks=blocks,
        )
    )


def dynamics_latex(dyn: Dynamics, form: str = "auto") -> str:
    """The text of `symdyn derive --format latex`: the amsmath note and the fragment (form: as
    `latex_document_body`)."""
    return AMSMATH_NOTE + "\n" + latex_document_body(dyn, form)


def render(ctx: RenderContext) -> dict[str, str]:
    """{NAME_dynamics.tex: fragment} for the robot of `ctx`."""
    body = latex_document_body(ctx.dynamics)
    if any(f.name == "base_regressor" for f in ctx.functions):
        body += base_parameters_latex(ctx.dynamics)
    body += frames_latex(ctx)
    body += loops_latex(ctx)
    body += contacts_latex(ctx)
    text = (
        environment()
        .get_template("latex/dynamics.tex.j2")
        .render(header=header_lines(ctx), note=AMSMATH_NOTE, body=body)
    )
    return {file_name(ctx.name): text}
