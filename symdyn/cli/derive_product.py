"""What `symdyn derive --form product` prints (text, JSON or LaTeX).

The product form (symdyn.algorithms.product_form): the configuration-space form

    tau = M(q) qdd + B(q) [qd qd] + Csq(q) [qd^2] + G(q) + F(qd)

written over the trig atoms c_i = cos(q_i), s_i = sin(q_i) and c_23 = cos(q2 + q3), ... for
consecutive parallel axes, each defined once at the top, then the shared quantities x1, x2, ...
(pieces that occur more than once, equal or opposite), then M (upper triangle), the nonzero
entries of B and Csq, G and F over them.

JSON: keys `atoms` and `shared` (name -> expression, in the order defined), `M` (rows), `B`,
`Csq` (rows), `G`, `F` (lists), every string read by sympy.sympify.

Beyond MAX_PRODUCT_JOINTS joints (or MAX_PRODUCT_TERMS terms of the configuration form) it is
refused, pointing to --form compact (symdyn.algorithms.product_form.check_product_size).

With `lumped` (`derive --form product --lumped`) the coefficients are the lumped constants of
`derive --lumped` (symdyn.lumped.lumped_product_form: named by value, or over the base
parameters when the inertial data is symbolic), defined after the atoms as `derive --lumped`
defines them (JSON: keys `lumped`, `base_parameters`, `standard_parameters`, `notes`).
"""

from __future__ import annotations

import json

import sympy as sp

from ..algorithms.configuration_space import pair_columns
from ..algorithms.product_form import ProductForm, check_product_size
from ..dynamics import Dynamics
from ..lumped import LumpedConstants, lumped_product_form
from ..symbolic.horner import product_text as text
from .derive_output import (
    header,
    json_header,
    latex_align,
    latex_notes,
    lumped_json,
    lumped_latex,
    lumped_lines,
)

__all__ = ["product_text", "product_json", "product_json_text", "product_latex"]

_EQUATION = "tau = M(q) qdd + B(q) [qd qd] + Csq(q) [qd^2] + G(q) + F(qd), product form"


def _groups_note(dyn: Dynamics, pf: ProductForm) -> str:
    sums = [" + ".join(str(dyn.q[i]) for i in g) for g in pf.groups]
    parallel = f"; consecutive parallel axes: {', '.join(sums)}" if sums else ""
    return f"# atoms c_i = cos(q_i), s_i = sin(q_i), c_ij.. = cos(q_i + q_j + ..){parallel}"


def _form(dyn: Dynamics, lumped: bool) -> tuple[ProductForm, LumpedConstants | None]:
    check_product_size(dyn.robot)  # within seconds: before the configuration form is built
    return lumped_product_form(dyn) if lumped else (dyn.product_form(), None)


def product_text(dyn: Dynamics, pf: ProductForm | None = None, lumped: bool = False) -> str:
    """The product form as text: atoms, lumped constants (with `lumped`), shared quantities,
    then the entries, one a line (pf: another product form of dyn, a pruned one, instead of
    its own)."""
    lc = None
    if pf is None:
        pf, lc = _form(dyn, lumped)
    n = dyn.n
    pairs = ", ".join(f"{dyn.qd[i]}*{dyn.qd[j]}" for i, j in pair_columns(n)) or "none"
    lines = header(dyn, _EQUATION)
    lines.append(f"# [qd qd] = ({pairs}); [qd^2] = ({', '.join(f'{v}**2' for v in dyn.qd)})")
    lines.append(_groups_note(dyn, pf))
    lines += [f"# note: {note}" for note in (lc.notes() if lc is not None else [])]
    lines += ["", "# atoms"] + [f"{s} = {text(e)}" for s, e in pf.atoms]
    lines += lumped_lines(lc) if lc is not None else []
    if pf.shared:
        lines += ["", "# shared"] + [f"{s} = {text(e)}" for s, e in pf.shared]
    for name, items in pf.entries.items():
        lines.append("")
        lines += [f"{label} = {text(e)}" for label, e in items] or [f"# {name} = 0"]
    return "\n".join(lines) + "\n"


def product_json(dyn: Dynamics, pf: ProductForm | None = None) -> dict:
    """The keys atoms, shared, M, B, Csq, G, F of the product form (strings)."""
    pf = pf or dyn.product_form()
    n = dyn.n
    index = {label: text(e) for items in pf.entries.values() for label, e in items}
    return {
        "atoms": {str(s): text(e) for s, e in pf.atoms},
        "shared": {str(s): text(e) for s, e in pf.shared},
        "M": [[index[f"M[{min(i, j) + 1},{max(i, j) + 1}]"] for j in range(n)] for i in range(n)],
        "B": [
            [index.get(f"B[{k + 1},({i + 1},{j + 1})]", "0") for i, j in pair_columns(n)] for k in range(n)
        ],
        "Csq": [[index.get(f"Csq[{k + 1},{i + 1}]", "0") for i in range(n)] for k in range(n)],
        "G": [index[f"G[{k + 1}]"] for k in range(n)],
        "F": [index[f"F[{k + 1}]"] for k in range(n)],
    }


def product_json_text(dyn: Dynamics, lumped: bool = False) -> str:
    """The JSON of `derive --form product`: json_header's keys, then product_json's (and with
    `lumped` the lumped constants' keys, derive_output.lumped_json)."""
    pf, lc = _form(dyn, lumped)
    doc = json_header(dyn, "product")
    doc.update(product_json(dyn, pf))
    if lc is not None:
        doc.update(lumped_json(lc))
    return json.dumps(doc, indent=2) + "\n"


def _label(name: str, label: str) -> str:
    """M[1,2] -> M_{1,2}, B[1,(2,3)] -> B_{1,(2,3)}, Csq[2,1] -> C^{\\mathrm{sq}}_{2,1}, x3 -> x_{3}."""
    head = "C^{\\mathrm{sq}}" if name == "Csq" else name
    return f"{head}_{{{label[len(name) + 1 : -1]}}}"


def product_latex(dyn: Dynamics, lumped: bool = False) -> str:
    """The product form in LaTeX (amsmath): the atoms c_{23} = cos(q_2 + q_3), the lumped
    constants (with `lumped`), the shared quantities x_{1}, ..., and one equation per entry,
    long ones broken at their top-level + and - (the factored products are kept whole)."""
    from ..codegen.latex.notation import Notation

    pf, lc = _form(dyn, lumped)
    nt = Notation(dyn)
    definitions = lumped_latex(nt, lc) if lc is not None else []
    qnames = {q: f"q_{{{i + 1}}}" for i, q in enumerate(dyn.q)}
    for s, _ in pf.atoms:
        nt.names[s] = f"{s.name[0]}_{{{s.name[1:]}}}"
    for s, _ in pf.shared:
        nt.names[s] = f"x_{{{s.name[1:]}}}"

    def rows(items) -> str:
        return latex_align(nt, items, expand=False)

    parts = [f"% {_EQUATION}  (needs \\usepackage{{amsmath}})"]
    atoms = [f"{nt.names[s]} &= {sp.latex(e, symbol_names=qnames)}" for s, e in pf.atoms]
    parts.append("\\begin{align*}\n" + " \\\\\n".join(atoms) + "\n\\end{align*}")
    parts += latex_notes(lc) + definitions
    if pf.shared:
        parts.append(rows([(nt.names[s], e) for s, e in pf.shared]))
    for name, items in pf.entries.items():
        if items:
            parts.append(rows([(_label(name, label), e) for label, e in items]))
    return "\n".join(parts) + "\n"
