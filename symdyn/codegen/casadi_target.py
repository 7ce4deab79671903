"""The CasADi target: a standalone Python module of SX graphs, plus one serialised file per function.

For a robot NAME, `render` returns
* `NAME_casadi.py`: imports only casadi (and math when pi appears); its
  `functions()` returns {name: casadi.Function} for the seven functions of
  docs/generated-code.md, each with the inputs of its FunctionSpec (q, qd, qdd or tau, p;
  p of size k, possibly 0), named so, and one output named like the spec
  (M and C n x n, vectors n x 1). Every function body is the eliminated
  straight-line code, one Python statement per temporary
  (`x12 = x3*x7 + ca.sin(q[1])`), so the SX graph shares what the CSE shared;
* `NAME_<function>.casadi` (bytes): each function as written by
  `casadi.Function.save`, readable with `casadi.Function.load`. They are made
  by executing the rendered module text (symdyn's own output, never user
  input) in a fresh namespace, so the files and the module cannot disagree.

The printer (`CasadiPrinter`) is a small tree printer over SymPy expressions:
sin/cos/tan/sqrt/sign/Abs map to casadi (ca.sin, ...), integer powers up to
simplify.MAX_UNROLLED_POWER become multiplications (as the operation counts
assume), rationals and floats become float literals with full precision (repr),
pi becomes math.pi. Inputs print as indexed vector elements (q[0], p[2]): a
parameter's name never becomes a Python name, so no file can shadow one.
"""

from __future__ import annotations

import os
import re
import tempfile
from dataclasses import replace

import sympy as sp

from ..errors import SymdynError
from ..symbolic.simplify import MAX_UNROLLED_POWER
from .functions import FunctionSpec
from .render import RenderContext, environment, header_lines

__all__ = ["render", "CasadiPrinter", "module_name"]

# Precedences of printed Python expressions (higher binds tighter).
_ATOM = 100
_POW = 60
_MUL = 50
_NEG = 45  # unary minus: safe as an Add term, parenthesised as a factor or operand
_ADD = 40

_FUNCTIONS = {
    sp.sin: "ca.sin",
    sp.cos: "ca.cos",
    sp.tan: "ca.tan",
    sp.asin: "ca.asin",
    sp.acos: "ca.acos",
    sp.atan: "ca.atan",
    sp.atan2: "ca.atan2",
    sp.sinh: "ca.sinh",
    sp.cosh: "ca.cosh",
    sp.tanh: "ca.tanh",
    sp.exp: "ca.exp",
    sp.log: "ca.log",
    sp.sign: "ca.sign",
    sp.Abs: "ca.fabs",
}


class CasadiPrinter:
    """Print SymPy expressions as Python over casadi SX values.

    `names` maps every symbol that may appear (input elements, temporaries) to
    its Python spelling; any other symbol is an internal error. `uses_math`
    records whether a `math.` constant was printed.
    """

    def __init__(self, names: dict[sp.Symbol, str]) -> None:
        self.names = names
        self.uses_math = False

    def doprint(self, expr) -> str:
        return self._print(sp.sympify(expr))[0]

    # -- helpers -----------------------------------------------------------
    def _wrap(self, expr, min_prec: int) -> str:
        """Print `expr`, parenthesised unless it binds at least as tightly as min_prec."""
        text, prec = self._print(expr)
        return text if prec >= min_prec else f"({text})"

    @staticmethod
    def _float(value) -> str:
        return repr(float(value))

    def _number(self, e: sp.Number) -> tuple[str, int]:
        if e.is_Integer:
            text = str(int(e))
        elif e.is_Rational or e.is_Float:
            text = self._float(e)
        else:
            raise SymdynError(f"casadi target: cannot print the number {e}")
        if text in ("inf", "-inf", "nan"):
            raise SymdynError(f"casadi target: non-finite number {e} in an expression")
        return text, (_NEG if text.startswith("-") else _ATOM)

    def _product(self, factors, coeff=None) -> tuple[str, int]:
        """The product of `factors` (after a numeric coefficient, if any), as one Python term."""
        printed = [] if coeff is None else [self._number(coeff)]
        printed += [self._print(f) for f in factors]
        if len(printed) == 1:
            return printed[0]
        return "*".join(t if p >= _MUL else f"({t})" for t, p in printed), _MUL

    def _power(self, base, k: int) -> tuple[str, int]:
        """base**k for a positive integer k (unrolled when small)."""
        if k == 1:
            return self._print(base)
        b = self._wrap(base, _POW + 1)
        if k <= MAX_UNROLLED_POWER:
            return "*".join([b] * k), _MUL
        return f"{b}**{k}", _POW

    # -- the tree ----------------------------------------------------------
    def _print(self, e) -> tuple[str, int]:
        if e.is_Symbol:
            try:
                return self.names[e], _ATOM
            except KeyError:
                raise SymdynError(f"casadi target: unexpected symbol '{e}' in generated code") from None
        if e is sp.pi:
            self.uses_math = True
            return "math.pi", _ATOM
        if e is sp.E:
            self.uses_math = True
            return "math.e", _ATOM
        if e.is_Number:
            return self._number(e)
        if e.is_Add:
            return self._add(e)
        if e.is_Mul:
            return self._mul(e)
        if e.is_Pow:
            return self._pow(e)
        if e.is_Function and e.func in _FUNCTIONS:
            args = ", ".join(self._print(a)[0] for a in e.args)
            return f"{_FUNCTIONS[e.func]}({args})", _ATOM
        raise SymdynError(f"casadi target: cannot print {type(e).__name__} ({e})")

    def _add(self, e: sp.Add) -> tuple[str, int]:
        out = []
        for k, term in enumerate(e.args):
            negative = term.as_coeff_Mul()[0].is_negative
            if k == 0:
                out.append(self._wrap(term, _ADD) if not negative else self._print(term)[0])
            elif negative:
                out.append(" - " + self._wrap(-term, _ADD + 1))
            else:
                out.append(" + " + self._wrap(term, _ADD))
        return "".join(out), _ADD

    def _mul(self, e: sp.Mul) -> tuple[str, int]:
        coeff, factors = e.as_coeff_mul()
        if coeff.is_negative:
            text, prec = self._mul_positive(-coeff, factors)
            return "-" + (text if prec >= _MUL else f"({text})"), _NEG
        return self._mul_positive(coeff, factors)

    def _mul_positive(self, coeff: sp.Number, factors) -> tuple[str, int]:
        num, den = [], []
        for f in factors:
            if f.is_Pow and f.exp.is_Number and f.exp.is_negative:
                den.append(f.base if f.exp == -1 else sp.Pow(f.base, -f.exp, evaluate=False))
            else:
                num.append(f)
        if num or coeff != 1:
            numerator, prec = self._product(num, None if coeff == 1 else coeff)
        else:
            numerator, prec = "1", _ATOM
        if not den:
            return numerator, prec
        if prec < _MUL:
            numerator = f"({numerator})"
        text, prec = self._product(den)
        denominator = text if prec > _MUL else f"({text})"
        return f"{numerator}/{denominator}", _MUL

    def _pow(self, e: sp.Pow) -> tuple[str, int]:
        base, exp = e.base, e.exp
        if exp == sp.S.Half:
            return f"ca.sqrt({self._print(base)[0]})", _ATOM
        if exp == -sp.S.Half:
            return f"1/ca.sqrt({self._print(base)[0]})", _MUL
        if exp.is_Integer and exp > 0:
            return self._power(base, int(exp))
        if exp.is_Integer and exp < 0:
            text, prec = self._power(base, int(-exp))
            return f"1/{text if prec > _MUL else f'({text})'}", _MUL
        b = self._wrap(base, _POW + 1)
        x = self._wrap(exp, _POW + 1)
        return f"{b}**{x}", _POW


def module_name(ctx: RenderContext) -> str:
    return f"{ctx.name}_casadi"


def _docstring(text: str) -> str:
    return text.replace("\\", "\\\\").replace('"""', '\\"\\"\\"')


def _function_view(spec: FunctionSpec) -> tuple[dict, bool]:
    """What the template needs for one function: inputs, statements, output entries."""
    names: dict[sp.Symbol, str] = {}
    for inp in spec.inputs:
        for i, s in enumerate(inp.symbols):
            names[s] = f"{inp.name}[{i}]"
    for x, _ in spec.temporaries:
        if x in names:
            raise SymdynError(f"casadi target: temporary '{x}' has the name of an input symbol")
        names[x] = str(x)
    printer = CasadiPrinter(names)
    statements = [f"{x} = {printer.doprint(e)}" for x, e in spec.temporaries]
    rows, cols = spec.shape
    entries = []
    for k, e in enumerate(spec.outputs):
        e = sp.sympify(e)
        if e == 0:
            continue
        index = f"{k // cols}, {k % cols}" if cols > 1 else f"{k}"
        entries.append((index, printer.doprint(e)))
    signature = ", ".join(f"{inp.name}[{len(inp.symbols)}]" for inp in spec.inputs)
    shape = f"{rows}x{cols}" if cols > 1 else f"{rows}"
    doc = [
        f"casadi.Function {spec.name}({signature}) -> {spec.output}[{shape}].",
        "",
        _docstring(re.sub(r",? row-major( n x n)?", "", spec.doc)) + ".",
    ]
    if spec.temporaries:
        o = spec.ops
        doc.append(
            f"{len(spec.temporaries)} temporaries; {o.total} operations ({o.mul} mul, {o.add} add, "
            f"{o.div} div, {o.trig} trig, {o.other} other)."
        )
    if spec.output in {inp.name for inp in spec.inputs} | {str(x) for x, _ in spec.temporaries}:
        raise SymdynError(f"casadi target: output name '{spec.output}' of {spec.name} is taken")
    view = {
        "name": spec.name,
        "builder": f"build_{spec.name}",
        "doc": doc,
        "inputs": [(inp.name, len(inp.symbols)) for inp in spec.inputs],
        "statements": statements,
        "output": spec.output,
        "rows": rows,
        "cols": cols,
        "entries": entries,
    }
    return view, printer.uses_math


def render_module(ctx: RenderContext) -> str:
    """The text of NAME_casadi.py."""
    params = [str(p) for p in ctx.dynamics.params]
    views, uses_math = [], False
    for spec in ctx.functions:
        view, m = _function_view(spec)
        views.append(view)
        uses_math = uses_math or m
    template = environment().get_template("casadi/module.py.j2")
    return template.render(
        header=header_lines(ctx),
        name=ctx.name,
        module=module_name(ctx),
        n=ctx.robot.n,
        params=params,
        params_tuple="(" + ", ".join(f'"{p}"' for p in params) + ("," if len(params) == 1 else "") + ")",
        functions=views,
        uses_math=uses_math,
    )


def serialise(text: str, ctx: RenderContext) -> dict[str, bytes]:
    """Execute the module text in a fresh namespace and save every function with casadi."""
    namespace: dict = {"__name__": module_name(ctx)}
    exec(compile(text, f"<{module_name(ctx)}.py>", "exec"), namespace)  # our own generated text
    functions = namespace["functions"]()
    files: dict[str, bytes] = {}
    with tempfile.TemporaryDirectory(prefix="symdyn-casadi-") as tmp:
        for spec in ctx.functions:
            path = os.path.join(tmp, f"{spec.name}.casadi")
            functions[spec.name].save(path)
            with open(path, "rb") as fh:
                files[f"{ctx.name}_{spec.name}.casadi"] = fh.read()
    return files


def render(ctx: RenderContext) -> dict[str, str | bytes]:
    """NAME_casadi.py and one NAME_<function>.casadi per function. CasADi's SX is double only,
    so --precision float does not apply here (the header says double)."""
    text = render_module(replace(ctx, precision="double"))
    files: dict[str, str | bytes] = {f"{module_name(ctx)}.py": text}
    files.update(serialise(text, ctx))
    return files
