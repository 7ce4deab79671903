"""The LaTeX target: `NAME_dynamics.tex`, the equations of motion for people who read them.

The file is a fragment for the body of a document (no preamble) that needs
only amsmath. It prints M, V, G, F (and C for up to three joints) of
tau = M(q) qdd + V(q, qd) + G(q) + F(qd) with readable symbols: q_{1},
\\dot{q}_{1}, \\ddot{q}_{1}, parameters with subscripts (m1 -> m_{1}) and the
textbook abbreviations s_{1} = sin q1, c_{1} = cos q1, s_{12} = sin(q1 + q2).
An abbreviation is used exactly when the argument is a sum of distinct joint
coordinates, each with coefficient +1 (indices joined with commas from ten
joints on); any other argument prints as \\sin(...). Every abbreviation used
is defined in the fragment.

Float rounding residues of numeric robots (a term of a sum whose coefficient is
below 1e-12 of the largest one, e.g. 6.9e-18 s_{3} next to 0.048 s_{3}) are
not printed. Two forms:
- closed form (up to three joints): the trigonometrically simplified entries
  (`Dynamics.simplified`), matrices entry by entry in a bmatrix when the rows
  are short, else one equation per entry, long sums broken over lines;
- eliminated form (more joints): the common subexpressions of M, V, G and F
  as one align* list of definitions x_{1}, x_{2}, ... in evaluation order,
  then the entries over them (M by its upper triangle). Definitions that are
  just s_{..} or c_{..} are inlined.

`latex_document_body(dyn)` gives the fragment's body, `dynamics_latex(dyn)`
the text of `symdyn derive --format latex`, and `render(ctx)` the file.
"""

from __future__ import annotations

import dataclasses
import re
from collections.abc import Sequence

import sympy as sp
from sympy.printing.latex import LatexPrinter

from ..dynamics import AUTO_SIMPLIFY_MAX_JOINTS, Dynamics
from ..symbolic.simplify import chop_float_noise, eliminate
from .render import RenderContext, environment, header_lines

__all__ = [
    "render",
    "latex_document_body",
    "dynamics_latex",
    "DynamicsLatexPrinter",
    "file_name",
    "AMSMATH_NOTE",
]

AMSMATH_NOTE = "% A fragment for a document body (\\input it); it needs only \\usepackage{amsmath}."

#: Estimated visible width (characters) of one displayed line and of a bmatrix row.
LINE_WIDTH = 56
MATRIX_WIDTH = 60

# LaTeX spellings reserved for the notation; a parameter printing like one is spelled out.
_RESERVED_LATEX = re.compile(r"(q|s|c|x|\\tau)(_\{.*\})?\Z|\\dot|\\ddot")


def file_name(name: str) -> str:
    return f"{name}_dynamics.tex"


def _escape_text(s: str) -> str:
    return s.replace("_", r"\_")


class DynamicsLatexPrinter(LatexPrinter):
    """SymPy's LaTeX printer over a fixed notation: each known symbol has its LaTeX spelling."""

    def __init__(self, names: dict[sp.Symbol, str]) -> None:
        super().__init__({"mul_symbol": None})
        self._names = names

    def _print_Symbol(self, expr: sp.Symbol, style: str = "plain") -> str:
        name = self._names.get(expr)
        return name if name is not None else super()._print_Symbol(expr, style)

    def _print_sign(self, expr, exp=None) -> str:
        tex = f"\\operatorname{{sgn}}({self._print(expr.args[0])})"
        return f"{tex}^{{{exp}}}" if exp else tex

    def terms(self, expr: sp.Expr) -> list[str]:
        """The printed terms of a sum, each with its sign (' + t' / ' - t'; the first bare)."""
        if not expr.is_Add:
            return [self.doprint(expr)]
        out = []
        for k, term in enumerate(self._as_ordered_terms(expr, order=None)):
            if term.could_extract_minus_sign():
                text = self._print(-term)
                out.append(("- " if k == 0 else " - ") + text)
            else:
                out.append(("" if k == 0 else " + ") + self._print(term))
        return out


def _width(tex: str) -> int:
    """A rough estimate of the printed width of LaTeX math, in characters."""
    t = re.sub(r"\\(left|right)\b", "", tex)
    t = re.sub(r"\\operatorname\{([^{}]*)\}", r"\1", t)
    t = re.sub(r"\\(dot|ddot|frac|cdot|quad|qquad|mathrm)\b", "", t)
    t = re.sub(r"\\[A-Za-z]+", "x", t)  # a Greek letter or a function name
    operators = len(re.findall(r" [-+=] ", t))
    t = re.sub(r"[{}_^\s]", "", t)
    return len(t) + 2 * operators


class _Notation:
    """Symbols, abbreviations and the printer for one robot's equations."""

    def __init__(self, dyn: Dynamics) -> None:
        n = dyn.n
        self.n = n
        self.sep = "," if n >= 10 else ""
        self.index = {q: i + 1 for i, q in enumerate(dyn.q)}
        names: dict[sp.Symbol, str] = {}
        self._joint_sub: dict[sp.Symbol, sp.Symbol] = {}
        # placeholders whose names sort after the parameters: q, then s/c, then qd, then qdd
        for i in range(n):
            for kind, sym, tex in (
                ("1", dyn.q[i], f"q_{{{i + 1}}}"),
                ("3", dyn.qd[i], f"\\dot{{q}}_{{{i + 1}}}"),
                ("4", dyn.qdd[i], f"\\ddot{{q}}_{{{i + 1}}}"),
            ):
                ph = sp.Symbol(f"~{kind}{sym.name[: -len(str(i + 1))]}{i + 1:04d}")
                self._joint_sub[sym] = ph
                names[ph] = tex
        plain = LatexPrinter()
        for s in dyn.params:
            tex = plain.doprint(s)
            if _RESERVED_LATEX.match(tex):
                tex = f"\\mathrm{{{_escape_text(s.name)}}}"
            names[s] = tex
        self.params = [names[s] for s in dyn.params]
        self.names = names
        self.trig: dict[sp.Symbol, tuple[str, tuple[int, ...]]] = {}
        self.printer = DynamicsLatexPrinter(names)

    # -- abbreviations ------------------------------------------------------------------
    def _joint_sum(self, arg: sp.Expr) -> tuple[int, ...] | None:
        idx = []
        for t in sp.Add.make_args(arg):
            if t not in self.index:
                return None
            idx.append(self.index[t])
        return tuple(sorted(idx)) if len(set(idx)) == len(idx) else None

    def _trig_symbol(self, f: sp.Expr) -> sp.Symbol:
        kind = "s" if isinstance(f, sp.sin) else "c"
        idx = self._joint_sum(f.args[0])
        label = self.sep.join(str(i) for i in idx)
        ph = sp.Symbol(f"~2{kind}{'_'.join(f'{i:04d}' for i in idx)}")
        if ph not in self.trig:
            self.trig[ph] = (kind, idx)
            self.names[ph] = f"{kind}_{{{label}}}"
        return ph

    def prepare(self, expr: sp.Expr) -> sp.Expr:
        """expr with sin/cos of joint sums abbreviated and joints on their placeholders."""
        expr = chop_float_noise(sp.sympify(expr))
        if expr.has(sp.sin, sp.cos):
            expr = expr.replace(
                lambda e: isinstance(e, (sp.sin, sp.cos)) and self._joint_sum(e.args[0]) is not None,
                self._trig_symbol,
            )
        return expr.xreplace(self._joint_sub)

    def legend(self) -> list[str]:
        """'s_{12} = \\sin(q_{1} + q_{2})' for every abbreviation used, in a fixed order."""
        out = []
        for ph, (kind, idx) in sorted(self.trig.items(), key=lambda kv: (len(kv[1][1]), kv[1][1], kv[1][0])):
            func = r"\sin" if kind == "s" else r"\cos"
            args = " + ".join(f"q_{{{i}}}" for i in idx)
            out.append(
                f"{self.names[ph]} = {func} {args}" if len(idx) == 1 else f"{self.names[ph]} = {func}({args})"
            )
        return out

    # -- printing -----------------------------------------------------------------------
    def latex(self, expr: sp.Expr) -> str:
        return self.printer.doprint(expr)

    def lines(self, expr: sp.Expr) -> list[str]:
        """The entry broken into displayed lines at its top-level + and - (none when short).

        A long product with a sum inside (a (b + c)) is multiplied out first, so it can break.
        """
        if not expr.is_Add and _width(self.latex(expr)) > LINE_WIDTH and expr.has(sp.Add):
            expanded = sp.expand(expr)
            expr = expanded if expanded.is_Add else expr
        terms = self.printer.terms(expr)
        lines, current = [], ""
        for t in terms:
            if current and _width(current + t) > LINE_WIDTH:
                lines.append(current)
                current = t.lstrip()
            else:
                current += t
        lines.append(current)
        return lines

    def label(self, name: str, i: int, j: int | None = None) -> str:
        return f"{name}_{{{i + 1}}}" if j is None else f"{name}_{{{i + 1}{self.sep}{j + 1}}}"


def _align(rows: Sequence[tuple[str, list[str]]]) -> str:
    """An align* of `label &= line` rows; continuation lines indented under the first."""
    out = []
    for label, lines in rows:
        first, *rest = lines
        out.append(f"  {label} &= {first}")
        out.extend(f"  &\\qquad {line}" for line in rest)
    return "\\begin{align*}\n" + " \\\\\n".join(out) + "\n\\end{align*}"


def _quantity(
    nt: _Notation, name: str, entries: list[sp.Expr], shape: tuple[int, int], symmetric: bool
) -> str:
    """One of M, C, V, G, F: a bmatrix when its rows are short, else one equation per entry."""
    rows, cols = shape
    texts = [nt.latex(e) for e in entries]
    grid = [texts[r * cols : (r + 1) * cols] for r in range(rows)]
    widest = max(sum(_width(t) for t in row) + 3 * (cols - 1) for row in grid)
    if widest <= MATRIX_WIDTH:
        body = " \\\\\n".join("    " + " & ".join(row) for row in grid)
        return f"\\[\n  {name} = \\begin{{bmatrix}}\n{body}\n  \\end{{bmatrix}}\n\\]"
    eqs = []
    for r in range(rows):
        for c in range(cols):
            if symmetric and c < r:
                continue
            label = nt.label(name, r) if cols == 1 else nt.label(name, r, c)
            eqs.append((label, nt.lines(entries[r * cols + c])))
    note = ""
    if symmetric:
        note = (
            f"The matrix ${name}$ is symmetric (${nt.label(name, 1, 0)} = {nt.label(name, 0, 1)}$, \\dots):\n"
        )
    return note + _align(eqs)


_QUANTITY_TEXT = {
    "M": "The mass matrix $M(q)$:",
    "C": r"The Coriolis matrix $C(q, \dot{q})$ (Christoffel symbols, $V = C \dot{q}$):",
    "V": r"The Coriolis and centrifugal torques $V(q, \dot{q})$:",
    "G": "The gravity torques $G(q)$:",
    "F": r"The friction torques $F(\dot{q})$:",
}


def _closed_view(dyn: Dynamics) -> Dynamics:
    """`dyn` with trigonometrically simplified closed forms (a copy unless already so)."""
    return dyn if dyn.simplified else dataclasses.replace(dyn, simplified=True, _closed={})


def _closed_blocks(dyn: Dynamics, nt: _Notation) -> list[tuple[str, str]]:
    dyn = _closed_view(dyn)
    blocks = []
    for name in ("M", "C", "V", "G", "F"):
        m = dyn.closed_form(name)
        entries = [nt.prepare(e) for e in m]
        blocks.append((_QUANTITY_TEXT[name], _quantity(nt, name, entries, m.shape, name == "M")))
    return blocks


def _eliminated_blocks(dyn: Dynamics, nt: _Notation) -> tuple[list[tuple[str, str]], str]:
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
    blocks = [(_QUANTITY_TEXT["M"], _quantity(nt, "M", list(M), (n, n), True))]
    for k, name in enumerate(("V", "G", "F")):
        blocks.append((_QUANTITY_TEXT[name], _quantity(nt, name, rest[k * n : (k + 1) * n], (n, 1), False)))
    defs = ""
    if definitions:
        defs = _align([(nt.names[s], nt.lines(e)) for s, e in definitions])
    return blocks, defs


def latex_document_body(dyn: Dynamics, form: str = "auto") -> str:
    """The LaTeX fragment (without header) for `dyn`.

    form: "closed" (simplified closed forms, with C), "eliminated" (definitions
    x_k then M, V, G, F over them) or "auto": closed up to three joints.
    """
    if form not in ("auto", "closed", "eliminated"):
        raise ValueError(f"unknown form '{form}' (auto, closed or eliminated)")
    closed = dyn.n <= AUTO_SIMPLIFY_MAX_JOINTS if form == "auto" else form == "closed"
    nt = _Notation(dyn)
    if closed:
        blocks, definitions = _closed_blocks(dyn, nt), ""
    else:
        blocks, definitions = _eliminated_blocks(dyn, nt)
    robot = dyn.robot
    return (
        environment()
        .get_template("latex/body.tex.j2")
        .render(
            name=robot.name,
            tex_name=_escape_text(robot.name),
            n=dyn.n,
            joints=", ".join(str(i) for i in range(1, dyn.n + 1)) if dyn.n <= 3 else f"1, \\dots, {dyn.n}",
            method=dyn.method,
            closed=closed,
            params=nt.params,
            legend=nt.legend(),
            definitions=definitions,
            n_definitions=definitions.count("&="),
            blocks=blocks,
        )
    )


def dynamics_latex(dyn: Dynamics) -> str:
    """The text of `symdyn derive --format latex`: the amsmath note and the fragment."""
    return AMSMATH_NOTE + "\n" + latex_document_body(dyn)


def render(ctx: RenderContext) -> dict[str, str]:
    """{NAME_dynamics.tex: fragment} for the robot of `ctx`."""
    text = (
        environment()
        .get_template("latex/dynamics.tex.j2")
        .render(header=header_lines(ctx), note=AMSMATH_NOTE, body=latex_document_body(ctx.dynamics))
    )
    return {file_name(ctx.name): text}
