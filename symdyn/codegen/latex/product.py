"""The product form in the LaTeX target: which form `NAME_dynamics.tex` prints, and its layout.

Beyond three joints the target prints the product form (symdyn.algorithms.product_form) of

    tau = M(q) qdd + V(q, qd) + G(q) + F(qd),   V = B(q) [qd qd] + Csq(q) [qd^2],

the entries written over the atoms c_i, s_i, c_23, ... (abbreviations of the notation, listed
once), the shared quantities x_1, x_2, ... defined once in order, then M (upper triangle), the
nonzero entries of B and Csq, G and F, each factored as the product form has it. It is chosen when
the configuration form has at most READABLE_TERMS terms (the bound `derive` uses; beyond it the
product form is slow to build: the Panda's 228,647 terms take 21 s) and the product form at most
PRODUCT_MAX_OPS operations (sympy.count_ops over the atoms, shared quantities and M, B, Csq, G, as
bench/derive.py counts them); otherwise the eliminated form (named intermediates) stays. The
choice and the bound are printed in the file.
"""

from __future__ import annotations

import sympy as sp

from ...algorithms.configuration_space import READABLE_TERMS, pair_columns
from ...algorithms.product_form import ProductForm
from ...dynamics import Dynamics
from ...errors import SymdynError
from .notation import Notation

__all__ = ["PRODUCT_MAX_OPS", "product_choice", "product_blocks", "product_ops"]

#: the largest product form (operations) the target prints instead of the eliminated form
PRODUCT_MAX_OPS = 5_000

_BOUND = (
    f"the product form is printed when the configuration form has at most {READABLE_TERMS:,} terms "
    f"and the product form at most {PRODUCT_MAX_OPS:,} operations (sympy.count_ops over the atoms, "
    "shared quantities and M, B, Csq, G), else the eliminated form"
)


def product_ops(pf: ProductForm) -> int:
    """sympy.count_ops over the atoms, shared quantities and the entries of M, B, Csq and G."""
    exprs = [e for _, e in [*pf.atoms, *pf.shared]]
    exprs += [e for name in ("M", "B", "Csq", "G") for _, e in pf.entries[name]]
    return sum(sp.count_ops(e) for e in exprs)


def product_choice(dyn: Dynamics) -> tuple[ProductForm | None, str]:
    """(the product form to print, or None for the eliminated form; the comment saying why)."""
    try:
        cs = dyn.configuration_space
    except SymdynError as e:
        return None, f"eliminated form (no configuration form: {e}); {_BOUND}"
    if not cs.readable:
        return None, f"eliminated form (the configuration form has {cs.terms:,} terms); {_BOUND}"
    pf = dyn.product_form()
    ops = product_ops(pf)
    if ops > PRODUCT_MAX_OPS:
        return None, f"eliminated form (the product form has {ops:,} operations); {_BOUND}"
    return pf, f"product form, {ops:,} operations; {_BOUND}"


def _equations(nt: Notation, items: list[tuple[str, sp.Expr]]) -> list[tuple[str, list[str]]]:
    return [(label, nt.lines(e, expand=False)) for label, e in items]


def product_blocks(dyn: Dynamics, nt: Notation, pf: ProductForm, quantity) -> tuple[list[dict], list]:
    """(blocks of M, B, Csq, G, F; the shared quantities as (x_{k}, lines)) over nt, the atoms
    written back as sines and cosines so the notation abbreviates them (s_{23}); quantity: the
    target's layout of a matrix or vector (bmatrix or equations)."""
    n = dyn.n
    sub: dict[sp.Symbol, sp.Expr] = dict(pf.atoms)
    shared = []
    for k, (s, e) in enumerate(pf.shared, start=1):
        ph = sp.Symbol(f"~0x{k:06d}")
        nt.names[ph] = f"x_{{{k}}}"
        shared.append((nt.names[ph], nt.prepare(e.xreplace(sub))))
        sub[s] = ph
    entries = {
        name: [(label, nt.prepare(e.xreplace(sub))) for label, e in items]
        for name, items in pf.entries.items()
    }
    index = {label: e for items in entries.values() for label, e in items}
    M = [index[f"M[{min(i, j) + 1},{max(i, j) + 1}]"] for i in range(n) for j in range(n)]
    blocks = [quantity(nt, "M", M, (n, n), True, expand=False)]
    labels = {"B": [], "Csq": []}  # (LaTeX label, entry label) of each printed entry
    for k in range(n):
        for i, j in pair_columns(n):
            labels["B"].append((f"B_{{{k + 1},({i + 1},{j + 1})}}", f"B[{k + 1},({i + 1},{j + 1})]"))
        for i in range(n):
            labels["Csq"].append((f"C^{{\\mathrm{{sq}}}}_{{{k + 1},{i + 1}}}", f"Csq[{k + 1},{i + 1}]"))
    for name, pairs in labels.items():
        items = [(tex, index[label]) for tex, label in pairs if label in index]
        blocks.append({"name": name, "grid": None, "equations": _equations(nt, items), "mirror": None})
    for name in ("G", "F"):
        blocks.append(quantity(nt, name, [e for _, e in entries[name]], (n, 1), False, expand=False))
    return blocks, _equations(nt, shared)
