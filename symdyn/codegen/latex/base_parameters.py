"""The base parameters in LaTeX: each pi_b,k as its combination of the standard parameters.

Standard parameters print as m_{i}, (mx)_{i}, I_{xx,i}, I_{a,i} (reflected rotor inertia),
f_{v,i} and f_{c,i} (viscous and Coulomb friction); a base parameter that regroups others gets
the superscript R (Khalil and Dombre (2002), sec. 12.3). The display itself is spelled in
templates/latex/base_parameters.tex.j2; long combinations are broken at their + and -.
"""

from __future__ import annotations

import re

import sympy as sp

from ...dynamics import Dynamics
from ..render import environment
from .notation import DynamicsLatexPrinter, Notation

__all__ = ["parameter_latex", "base_parameters_latex"]

_NAME = re.compile(r"(m|mx|my|mz|Ixx|Ixy|Iyy|Ixz|Iyz|Izz|Ia|fv|fcp|fcn|fc)(\d+)(R?)\Z")


def parameter_latex(name: str) -> str:
    """m1 -> m_{1}, mx1 -> (mx)_{1}, Izz2 -> I_{zz,2}, Ia1 -> I_{a,1}, fv1 -> f_{v,1},
    fcp1 -> f_{c+,1}, fcn1 -> f_{c-,1},
    Izz1R -> I_{zz,1}^{R}."""
    match = _NAME.match(name)
    assert match, name
    head, index, regrouped = match.groups()
    if head == "m":
        tex = f"m_{{{index}}}"
    elif head.startswith("m"):
        tex = f"(m{head[1]})_{{{index}}}"
    else:
        sub = {"cp": "c+", "cn": "c-"}.get(head[1:], head[1:])
        tex = f"{head[0]}_{{{sub},{index}}}"
    return tex + ("^{R}" if regrouped else "")


def base_parameters_latex(dyn: Dynamics) -> str:
    """The section of NAME_dynamics.tex that defines the base parameters (tau = Y_b pi_b)."""
    names = dict(Notation(dyn).names)
    base = dyn.base_parameters
    symbols = {s for _, e in base for s in e.free_symbols}
    names.update({s: parameter_latex(str(s)) for s in symbols if _NAME.match(str(s))})
    printer = DynamicsLatexPrinter(names)
    rows = []
    for k, (name, expr) in enumerate(base):
        terms = printer.terms(sp.expand(expr))
        lines = [""]
        for t in terms:
            if len(lines[-1]) > 60:
                lines.append("")
            lines[-1] += t
        rows.append((f"\\pi_{{b,{k + 1}}} = {parameter_latex(name)}", [ln.strip() for ln in lines]))
    return environment().get_template("latex/base_parameters.tex.j2").render(count=len(base), rows=rows)
