"""The LaTeX backend's notation and printer: how each symbol of the equations of motion is spelled.

Symbols read like a textbook: q_{1}, \\dot{q}_{1}, \\ddot{q}_{1}, parameters with
subscripts (m1 -> m_{1}) and the abbreviations s_{1} = sin q1, c_{1} = cos q1,
s_{12} = sin(q1 + q2). An abbreviation is used exactly when the argument is a sum
of distinct joint coordinates, each with coefficient +1 (indices joined with
commas from ten joints on); any other argument prints as \\sin(...). A parameter
whose LaTeX would look like a joint, an abbreviation or a definition x_{k} is
spelled out upright (\\mathrm{s1}). Float rounding residues of numeric robots (a
term of a sum below 1e-12 of the largest) are not printed.

`Notation` also breaks a long entry into displayed lines at its top-level + and -;
the displays around them (align*, bmatrix) are spelled in templates/latex/.
"""

from __future__ import annotations

import re

import sympy as sp
from sympy.printing.latex import LatexPrinter

from ...dynamics import Dynamics
from ...model.names import latex_text
from ...symbolic.simplify import chop_float_noise
from ..printing import step_comparison

__all__ = ["DynamicsLatexPrinter", "Notation", "width", "LINE_WIDTH", "MATRIX_WIDTH"]

#: Estimated visible width (characters) of one displayed line and of a bmatrix row.
LINE_WIDTH = 56
MATRIX_WIDTH = 60

# LaTeX spellings reserved for the notation; a parameter printing like one is spelled out.
_RESERVED_LATEX = re.compile(r"(q|s|c|x|\\tau)(_\{.*\})?\Z|\\dot|\\ddot")


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

    def _print_Heaviside(self, expr, exp=None) -> str:
        """H(x) with H(0) = 0 as the Iverson bracket [x > 0] (H(-x) as [x < 0])."""
        x, op = step_comparison(expr)
        tex = f"\\left[{self._print(x)} {op} 0\\right]"
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


def width(tex: str) -> int:
    """A rough estimate of the printed width of LaTeX math, in characters."""
    t = re.sub(r"\\(left|right)\b", "", tex)
    t = re.sub(r"\\operatorname\{([^{}]*)\}", r"\1", t)
    t = re.sub(r"\\(dot|ddot|frac|cdot|quad|qquad|mathrm)\b", "", t)
    t = re.sub(r"\\[A-Za-z]+", "x", t)  # a Greek letter or a function name
    operators = len(re.findall(r" [-+=] ", t))
    t = re.sub(r"[{}_^\s]", "", t)
    return len(t) + 2 * operators


class Notation:
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
                tex = f"\\mathrm{{{latex_text(s.name)}}}"
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

    def legend(self) -> list[tuple[str, str, list[str]]]:
        """(s_{12}, "sin", [q_{1}, q_{2}]) for every abbreviation used, in a fixed order."""
        out = []
        for ph, (kind, idx) in sorted(self.trig.items(), key=lambda kv: (len(kv[1][1]), kv[1][1], kv[1][0])):
            out.append((self.names[ph], "sin" if kind == "s" else "cos", [f"q_{{{i}}}" for i in idx]))
        return out

    # -- printing -----------------------------------------------------------------------
    def latex(self, expr: sp.Expr) -> str:
        return self.printer.doprint(expr)

    def lines(self, expr: sp.Expr, expand: bool = True) -> list[str]:
        """The entry broken into displayed lines at its top-level + and - (none when short).

        A long product with a sum inside (a (b + c)) is multiplied out first, so it can break
        (unless `expand` is False: a factored form stays factored).
        """
        if expand and not expr.is_Add and width(self.latex(expr)) > LINE_WIDTH and expr.has(sp.Add):
            expanded = sp.expand(expr)
            expr = expanded if expanded.is_Add else expr
        terms = self.printer.terms(expr) if expand else self._pieces(expr)
        lines, current = [], ""
        for t in terms:
            if current and width(current + t) > LINE_WIDTH:
                lines.append(current)
                current = t.lstrip()
            else:
                current += t
        lines.append(current)
        return lines

    def _pieces(self, expr: sp.Expr) -> list[str]:
        """The terms of expr, each with its sign (as `DynamicsLatexPrinter.terms`), a long
        product with a sum inside opened up: a \\bigl(b + c\\bigr) as the pieces
        "a \\bigl(b", " + c\\bigr)" (recursively), so a factored entry can break inside its
        parentheses (\\bigl( and \\bigr) may stand on different lines of an align*)."""
        terms = self.printer._as_ordered_terms(expr, order=None) if expr.is_Add else [expr]
        out: list[str] = []
        for k, term in enumerate(terms):
            negative = term.could_extract_minus_sign()
            pieces = self._factor_pieces(-term if negative else term)
            sign = ("- " if k == 0 else " - ") if negative else ("" if k == 0 else " + ")
            out += [sign + pieces[0], *pieces[1:]]
        return out

    def _factor_pieces(self, term: sp.Expr) -> list[str]:
        text = self.printer._print(term)
        sums = [f for f in term.args if f.is_Add] if term.is_Mul else []
        if width(text) <= LINE_WIDTH or not sums:
            return [text]
        inner = max(sums, key=lambda f: width(self.latex(f)))
        rest = sp.Mul(*[f for f in term.args if f is not inner])
        pieces = self._pieces(inner)
        head = "" if rest == 1 else self.printer._print(rest) + " "
        pieces[0] = f"{head}\\bigl({pieces[0]}"
        pieces[-1] += "\\bigr)"
        return pieces

    def label(self, name: str, i: int, j: int | None = None) -> str:
        return f"{name}_{{{i + 1}}}" if j is None else f"{name}_{{{i + 1}{self.sep}{j + 1}}}"
