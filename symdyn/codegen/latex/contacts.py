"""The contacts in the LaTeX target: the contact Jacobian Jc and the drift gamma
(symdyn.codegen.contact_functions' contact_jacobian and contact_drift), each as the definitions x_k
it needs and its entries, after the list of contacts and the KKT system the constrained and
impulse dynamics solve (symdyn.algorithms.contact_dynamics)."""

from __future__ import annotations

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
    return (
        environment()
        .get_template("latex/contacts.tex.j2")
        .render(contacts=table, blocks=function_blocks(ctx, ["contact_jacobian", "contact_drift"]))
    )
