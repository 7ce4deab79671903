"""The derivation's steps (symdyn.apps.checking.steps) as text, LaTeX or JSON, for `symdyn derive --steps`."""

from __future__ import annotations

import json

import sympy as sp

from ...model.names import comment_text
from .steps import Step, Steps

__all__ = ["steps_text", "steps_latex", "steps_json", "STEP_FORMATS", "STEP_LABELS"]

#: how each quantity is printed (text) and typeset (LaTeX, with {i} for the link number)
STEP_LABELS = {
    "omega": ("omega", r"\omega_{{{i}}}"),
    "omegadot": ("omegadot", r"\dot{{\omega}}_{{{i}}}"),
    "vdot": ("vdot", r"\dot{{v}}_{{{i}}}"),
    "vdotC": ("vdotC", r"\dot{{v}}_{{C_{i}}}"),
    "F": ("F", r"F_{{{i}}}"),
    "N": ("N", r"N_{{{i}}}"),
    "f": ("f", r"f_{{{i}}}"),
    "n": ("n", r"n_{{{i}}}"),
    "tau": ("tau", r"\tau_{{{i}}}"),
    "T": ("T", r"T_{{{i}}}"),
    "U": ("U", r"U_{{{i}}}"),
    "dL_dqd": ("dL/dqd", r"\frac{{\partial L}}{{\partial \dot{{q}}_{{{i}}}}}"),
    "ddt_dL_dqd": ("d/dt dL/dqd", r"\frac{{d}}{{dt}} \frac{{\partial L}}{{\partial \dot{{q}}_{{{i}}}}}"),
    "dL_dq": ("dL/dq", r"\frac{{\partial L}}{{\partial q_{{{i}}}}}"),
}
_HEADINGS = {
    "outward": "outward iteration, link {i}",
    "inward": "inward iteration, link {i}",
    "energy": "energies of link {i}",
    "joint": "Lagrange's equation, joint {i}",
}


def _title(steps: Steps) -> str:
    how = "numbers at the given state" if steps.numeric else "symbolic"
    if steps.method == "newton-euler":
        what = "Newton-Euler iterations (Craig (2005), sec. 6.5)"
    else:
        what = "Lagrangian (Spong et al. (2006), sec. 7.2): L = sum_i (T_i - U_i)"
    return f"{steps.robot.name}: {what}, {how}"


def _groups(steps: Steps):
    """(phase, link, the steps of that phase and link), in order of computation."""
    out: list[tuple[str, int, list[Step]]] = []
    for s in steps.steps:
        if out and out[-1][0] == s.phase and out[-1][1] == s.link:
            out[-1][2].append(s)
        else:
            out.append((s.phase, s.link, [s]))
    return out


def _entry_text(e: sp.Expr) -> str:
    """A number to 10 significant digits, an expression as SymPy prints it."""
    return f"{float(e):.10g}" if e.is_number else sp.sstr(e)


def _value_text(s: Step) -> str:
    entries = [_entry_text(e) for e in s.value]
    return entries[0] if len(entries) == 1 else "[" + ", ".join(entries) + "]"


def steps_text(steps: Steps) -> str:
    """One line per quantity, `NAME_i = value`, under a heading per link and phase."""
    lines = [f"# {_title(steps)}"]
    if steps.method == "newton-euler":
        lines.append("# vectors of link i in its body frame {i}; tau_i includes motor and friction terms")
    for phase, i, group in _groups(steps):
        frame = f" (frame {group[0].frame})" if group[0].frame else ""
        lines += ["", f"## {_HEADINGS[phase].format(i=i)}{frame}"]
        lines += [f"{STEP_LABELS[s.name][0]}_{i} = {_value_text(s)}" for s in group]
    return "\n".join(lines) + "\n"


def steps_latex(steps: Steps) -> str:
    """A LaTeX fragment: one align* environment per link and phase, vectors as bmatrix columns."""
    names = {}
    for k in range(1, steps.robot.n + 1):
        names.update({sp.Symbol(f"q{k}"): f"q_{{{k}}}", sp.Symbol(f"qd{k}"): f"\\dot{{q}}_{{{k}}}"})
        names[sp.Symbol(f"qdd{k}")] = f"\\ddot{{q}}_{{{k}}}"
    out = [f"% {comment_text(_title(steps))}"]
    for phase, i, group in _groups(steps):
        frame = f" (frame {group[0].frame})" if group[0].frame else ""
        out.append(f"% {comment_text(_HEADINGS[phase].format(i=i) + frame)}")
        out.append("\\begin{align*}")
        rows = []
        for s in group:
            value = s.value if len(s.value) > 1 else s.value[0]
            rows.append(f"{STEP_LABELS[s.name][1].format(i=i)} &= {sp.latex(value, symbol_names=names)}")
        out.append(" \\\\\n".join(rows))
        out.append("\\end{align*}")
    return "\n".join(out) + "\n"


def steps_json(steps: Steps) -> str:
    """{"robot", "method", "numeric", "steps": [{"link", "quantity", "phase", "frame", "value"}]}."""
    doc = {
        "robot": steps.robot.name,
        "method": steps.method,
        "numeric": steps.numeric,
        "steps": [
            {
                "link": s.link,
                "quantity": s.name,
                "phase": s.phase,
                "frame": s.frame,
                "value": [_json_entry(e, steps.numeric) for e in s.value],
            }
            for s in steps.steps
        ],
    }
    return json.dumps(doc, indent=2) + "\n"


def _json_entry(e: sp.Expr, numeric: bool):
    if numeric and not e.free_symbols:
        return float(e)
    return sp.sstr(e)


STEP_FORMATS = {"text": steps_text, "latex": steps_latex, "json": steps_json}
