"""The contacts in the LaTeX target: the contact Jacobian Jc and the drift gamma
(symdyn.codegen.contact_functions' contact_jacobian and contact_drift), each as the definitions x_k
it needs and its entries, after the list of contacts and the KKT system the constrained and
impulse dynamics solve (symdyn.algorithms.contact_dynamics); with the group contact_baumgarte,
the stabilised constraint and the position error e(q) (symdyn.codegen.contact_baumgarte), its
anchor's numbers written a_{k,i} (contact k; i = 1..3 the origin, 4..12 the rotation row-major)."""

from __future__ import annotations

from ...algorithms.contact_error import ANCHOR_SIZE, anchor_symbols
from ...model.names import latex_text
from ..contact_functions import contacts_of
from ..render import RenderContext, environment
from .frames import function_blocks

__all__ = ["contacts_latex"]


def contacts_latex(ctx: RenderContext) -> str:
    """The section of ctx's contacts (empty without the contact functions)."""
    contacts = contacts_of(ctx)
    if not contacts:
        return ""
    table = [(latex_text(c.name), latex_text(c.frame), c.kind, c.rows) for c in contacts]
    built = {f.name for f in ctx.functions}
    names = [n for n in ("contact_jacobian", "contact_drift", "contact_error") if n in built]
    anchors = {
        s: f"a_{{{k // ANCHOR_SIZE + 1},{k % ANCHOR_SIZE + 1}}}"
        for k, s in enumerate(anchor_symbols(len(contacts)))
    }
    return (
        environment()
        .get_template("latex/contacts.tex.j2")
        .render(
            contacts=table,
            kkt="contact_jacobian" in built,
            baumgarte="contact_error" in built,
            blocks=function_blocks(ctx, names, anchors),
        )
    )
