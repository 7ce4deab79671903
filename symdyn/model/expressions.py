"""The safe expression parser for robot description files.

Every number in a robot file may instead be an expression over named
parameters ("l1/2", "m2*l2**2", "pi/2"). The text is parsed with
``ast.parse(text, mode="eval")`` and the syntax tree is walked against a
whitelist, building the SymPy objects directly: numbers, names, ``+ - * / **``,
unary ``+``/``-``, parentheses, and calls of ``sin``, ``cos``, ``tan``, ``sqrt``
with one positional argument; ``pi`` is the constant. Nothing from the file is
ever passed to ``eval``, ``exec`` or ``sympify``, so loading a file never
executes code from it.

Limits that keep a hostile file from hanging the loader: text at most
2000 characters, nesting depth at most 100 (a chain such as a + b - c + ... or a*b/c*... counts
as one level, however long), calls and powers nested at most 20 deep inside each other
(SymPy recurses several frames per level of sin(sin(...)) or x**x**...), integer literals at most 30
digits, and the bounds of `symdyn.model.bounded` on the result (exponents at most 64 in
absolute value once SymPy has merged powers of powers, numeric powers of at most 4096 bits,
256 bits under a root, numbers at most 1e150 in absolute value, at most 100 terms once expanded,
1000 for an answer of `symdyn check`). Division by zero, non-finite and non-real results are errors.
"""

from __future__ import annotations

import ast
import math
import re
from collections.abc import Callable

import sympy as sp

from ..errors import SymdynError
from ..symbolic import float_zero as _float_zero  # noqa: F401  (SymPy's Float.is_zero, fast)
from .bounded import MAX_EXPANDED_TERMS, MAX_EXPONENT, check_bounded, check_expansion, check_power

__all__ = [
    "parse_expression",
    "parse_expression_names",
    "free_symbols_in_order",
    "check_parameter_name",
    "is_c_identifier",
    "C_KEYWORDS",
    "RESERVED_NAMES",
    "MAX_TEXT_LENGTH",
    "MAX_DEPTH",
    "MAX_CALL_DEPTH",
    "MAX_EXPONENT",
    "MAX_INT_DIGITS",
]

MAX_TEXT_LENGTH = 2000
MAX_DEPTH = 100
MAX_CALL_DEPTH = 20
MAX_INT_DIGITS = 30

_FUNCTIONS: dict[str, Callable[[sp.Expr], sp.Expr]] = {
    "sin": sp.sin,
    "cos": sp.cos,
    "tan": sp.tan,
    "sqrt": sp.sqrt,
}
_CONSTANTS = {"pi": sp.pi}

#: Names that can never be parameters: the whitelisted functions and constants.
RESERVED_NAMES = frozenset(_FUNCTIONS) | frozenset(_CONSTANTS)

_IDENTIFIER = re.compile(r"[A-Za-z_][A-Za-z0-9_]*\Z")
_JOINT_SYMBOL = re.compile(r"(q|qd|qdd|tau)[0-9]+\Z")
#: The joint symbols that allow_joint_symbols=True lets through (answer files of `symdyn check`).
_ANSWER_JOINT_SYMBOL = re.compile(r"(q|qd|qdd)[1-9][0-9]*\Z")

#: C keywords (C89 to C23): they cannot name a robot or a parameter of generated C.
C_KEYWORDS = frozenset(
    """
    auto break case char const continue default do double else enum extern float for
    goto if inline int long register restrict return short signed sizeof static struct
    switch typedef union unsigned void volatile while _Bool _Complex _Imaginary _Alignas
    _Alignof _Atomic _Generic _Noreturn _Static_assert _Thread_local alignas alignof bool
    constexpr false nullptr static_assert thread_local true typeof typeof_unqual _BitInt
    _Decimal32 _Decimal64 _Decimal128
    """.split()  # noqa: SIM905
)

_BINOPS = {
    ast.Add: "+",
    ast.Sub: "-",
    ast.Mult: "*",
    ast.Div: "/",
    ast.Pow: "**",
}
#: the operators whose left-nested chains (a + b - c + ...) are built in one loop, as one level
_CHAINS = {"+": ("+", "-"), "-": ("+", "-"), "*": ("*", "/"), "/": ("*", "/")}

_DESCRIBE = {
    ast.Attribute: "attribute access",
    ast.Subscript: "subscript",
    ast.Lambda: "lambda",
    ast.ListComp: "list comprehension",
    ast.SetComp: "set comprehension",
    ast.DictComp: "dict comprehension",
    ast.GeneratorExp: "generator expression",
    ast.List: "list",
    ast.Tuple: "tuple",
    ast.Set: "set",
    ast.Dict: "dict",
    ast.IfExp: "conditional expression",
    ast.Compare: "comparison",
    ast.BoolOp: "boolean operator",
    ast.NamedExpr: "assignment expression",
    ast.Starred: "starred expression",
    ast.JoinedStr: "f-string",
    ast.Await: "await",
    ast.Yield: "yield",
    ast.YieldFrom: "yield",
    ast.Slice: "slice",
}


def is_c_identifier(name: object) -> bool:
    """True for a string matching [A-Za-z_][A-Za-z0-9_]* that is not a C keyword."""
    return isinstance(name, str) and bool(_IDENTIFIER.match(name)) and name not in C_KEYWORDS


def _name_problem(name: str) -> str | None:
    """Why `name` cannot be a parameter, or None if it can."""
    if not _IDENTIFIER.match(name):
        return (
            f"'{name}' is not a valid parameter name (letters, digits and underscores, "
            "not starting with a digit)"
        )
    if _JOINT_SYMBOL.match(name):
        return f"'{name}' is reserved for joint symbols (q<k>, qd<k>, qdd<k>, tau<k>)"
    if name in RESERVED_NAMES:
        return f"'{name}' is reserved (the built-in {'constant' if name == 'pi' else 'function'})"
    if name in C_KEYWORDS:
        return f"'{name}' is a C keyword and cannot name a parameter"
    if name.startswith("_"):
        return f"'{name}' starts with an underscore: such names are reserved for symdyn's intermediates"
    return None


def check_parameter_name(
    name: object,
    *,
    file: str | None = None,
    link_index: int | None = None,
    link_name: str | None = None,
    field: str | None = None,
) -> str:
    """Return `name` if it can name a parameter, else raise SymdynError saying why."""
    if not isinstance(name, str):
        raise SymdynError(
            f"parameter name must be a string, not {type(name).__name__} {name!r}",
            file=file,
            link_index=link_index,
            link_name=link_name,
            field=field,
        )
    problem = _name_problem(name)
    if problem:
        raise SymdynError(problem, file=file, link_index=link_index, link_name=link_name, field=field)
    return name


class _Builder:
    """Walks a whitelisted Python expression tree and builds SymPy objects."""

    def __init__(
        self, text: str, fail: Callable[[str], SymdynError], allow_joint_symbols: bool = False
    ) -> None:
        self.text = text
        self.fail = fail
        self.allow_joint_symbols = allow_joint_symbols
        self.names: list[str] = []

    def _segment(self, node: ast.AST) -> str:
        return _short(ast.get_source_segment(self.text, node) or "")

    def _refuse(self, node: ast.AST, what: str | None = None) -> SymdynError:
        if what is None:
            what = _DESCRIBE.get(type(node), f"'{type(node).__name__}' construct")
        seg = self._segment(node)
        where = f" (in '{seg}')" if seg else ""
        return self.fail(
            f"{what} is not allowed in an expression{where}; allowed are numbers, names, "
            "+ - * / **, parentheses, sin, cos, tan, sqrt and pi"
        )

    def build(self, node: ast.AST, depth: int = 0, calls: int = 0) -> sp.Expr:
        """The SymPy object of `node`, `depth` levels and `calls` calls or powers deep."""
        if depth > MAX_DEPTH:
            raise self.fail(f"expression is nested more than {MAX_DEPTH} levels deep")
        if calls > MAX_CALL_DEPTH:
            raise self.fail(f"calls and powers are nested more than {MAX_CALL_DEPTH} deep inside each other")
        if isinstance(node, ast.Constant):
            return self._constant(node)
        if isinstance(node, ast.Name):
            return self._name(node)
        if isinstance(node, ast.UnaryOp):
            if isinstance(node.op, ast.USub):
                return -self.build(node.operand, depth + 1, calls)
            if isinstance(node.op, ast.UAdd):
                return self.build(node.operand, depth + 1, calls)
            op = {ast.Not: "'not'", ast.Invert: "'~'"}.get(type(node.op), "unary operator")
            raise self._refuse(node, f"operator {op}")
        if isinstance(node, ast.BinOp):
            return self._binop(node, depth, calls)
        if isinstance(node, ast.Call):
            return self._call(node, depth, calls)
        raise self._refuse(node)

    def _constant(self, node: ast.Constant) -> sp.Expr:
        v = node.value
        if isinstance(v, bool) or not isinstance(v, (int, float)):
            what = {str: "string", bytes: "bytes", complex: "complex number"}.get(type(v), "constant")
            raise self._refuse(node, what)
        return _number(v, self.fail)

    def _name(self, node: ast.Name) -> sp.Expr:
        name = node.id
        if name in _CONSTANTS:
            return _CONSTANTS[name]
        if name in _FUNCTIONS:
            raise self.fail(f"function '{name}' used without an argument")
        if self.allow_joint_symbols and _ANSWER_JOINT_SYMBOL.match(name):
            self.names.append(name)
            return sp.Symbol(name)
        problem = _name_problem(name)
        if problem:
            raise self.fail(problem)
        self.names.append(name)
        return sp.Symbol(name)

    def _operator(self, node: ast.BinOp) -> str:
        """The operator of `node` (+ - * / **), or refuse it."""
        op = _BINOPS.get(type(node.op))
        if op is None:
            sym = {
                ast.BitXor: "'^' (use ** for powers)",
                ast.FloorDiv: "'//'",
                ast.Mod: "'%'",
                ast.MatMult: "'@'",
                ast.LShift: "'<<'",
                ast.RShift: "'>>'",
                ast.BitAnd: "'&'",
                ast.BitOr: "'|'",
            }.get(type(node.op), "binary operator")
            raise self._refuse(node, f"operator {sym}")
        return op

    def _binop(self, node: ast.BinOp, depth: int, calls: int) -> sp.Expr:
        op = self._operator(node)
        if op == "**":
            left = self.build(node.left, depth + 1, calls + 1)
            return self._power(node, left, self.build(node.right, depth + 1, calls + 1))
        # a left-nested chain a + b - c + ... (or a * b / c ...) is one level, built in a loop
        chain = [node]
        while isinstance(chain[-1].left, ast.BinOp) and self._operator(chain[-1].left) in _CHAINS[op]:
            chain.append(chain[-1].left)
        out = self.build(chain[-1].left, depth + 1, calls)
        for link in reversed(chain):
            right = self.build(link.right, depth + 1, calls)
            out = self._apply(link, self._operator(link), out, right)
        return out

    def _apply(self, node: ast.BinOp, op: str, left: sp.Expr, right: sp.Expr) -> sp.Expr:
        if op == "+":
            return left + right
        if op == "-":
            return left - right
        if op == "*":
            return left * right
        if right.is_zero:
            raise self.fail(f"division by zero in '{self._segment(node)}'")
        return left / right

    def _power(self, node: ast.AST, base: sp.Expr, exponent: sp.Expr) -> sp.Expr:
        check_power(base, exponent, self.fail, self._segment(node))
        return base**exponent

    def _call(self, node: ast.Call, depth: int, calls: int) -> sp.Expr:
        func = node.func
        if not isinstance(func, ast.Name) or func.id not in _FUNCTIONS:
            name = self._segment(func) or type(func).__name__
            raise self._refuse(node, f"call of '{name}'")
        if node.keywords:
            raise self._refuse(node, f"keyword argument in call of '{func.id}'")
        if len(node.args) != 1 or isinstance(node.args[0], ast.Starred):
            seg = self._segment(node)
            raise self.fail(f"'{func.id}' takes exactly one positional argument (in '{seg}')")
        arg = self.build(node.args[0], depth + 1, calls + 1)
        if func.id == "sqrt":
            return self._power(node, arg, sp.S.Half)
        return _FUNCTIONS[func.id](arg)


def _number(v: int | float, fail: Callable[[str], SymdynError]) -> sp.Expr:
    if isinstance(v, int):
        if abs(v) >= 10**MAX_INT_DIGITS:
            raise fail(f"integer has more than {MAX_INT_DIGITS} digits")
        return sp.Integer(v)
    if not math.isfinite(v):
        raise fail(f"number {v} is not finite")
    return sp.Float(v)


def _fail_factory(
    file: str | None,
    link_index: int | None,
    link_name: str | None,
    field: str | None,
) -> Callable[[str], SymdynError]:
    def fail(message: str) -> SymdynError:
        return SymdynError(message, file=file, link_index=link_index, link_name=link_name, field=field)

    return fail


def parse_expression_names(
    value: object,
    *,
    file: str | None = None,
    link_index: int | None = None,
    link_name: str | None = None,
    field: str | None = None,
    allow_joint_symbols: bool = False,
    max_terms: int = MAX_EXPANDED_TERMS,
) -> tuple[sp.Expr, tuple[str, ...]]:
    """Parse like `parse_expression`; also return the parameter names in textual order.

    The names are those written in the text (left to right, first appearance,
    without repeats), even if they cancel in the result ("x - x").
    With allow_joint_symbols=True the joint symbols q<k>, qd<k>, qdd<k> (k >= 1) are
    accepted as names too (answer files of `symdyn check`); robot files never pass it.
    max_terms: the most terms the expression may expand to (symdyn.model.bounded.expanded_terms).
    """
    fail = _fail_factory(file, link_index, link_name, field)
    if isinstance(value, bool):
        raise fail(f"expected a number or an expression, not the boolean {value}")
    if isinstance(value, (int, float)):
        expr = _number(value, fail)
        check_bounded(expr, fail)
        return expr, ()
    if not isinstance(value, str):
        kind = "null" if value is None else type(value).__name__
        raise fail(f"expected a number or an expression, not a {kind}")
    if len(value) > MAX_TEXT_LENGTH:
        raise fail(f"expression is longer than {MAX_TEXT_LENGTH} characters")
    text = " ".join(value.split("\n")).strip()
    if not text:
        raise fail("empty expression")
    try:
        tree = ast.parse(text, mode="eval")
    except SyntaxError as exc:
        detail = exc.msg if exc.msg else "invalid syntax"
        raise fail(f"cannot parse expression '{_short(text)}': {detail}") from None
    except (RecursionError, MemoryError, ValueError):
        raise fail(f"cannot parse expression '{_short(text)}'") from None
    builder = _Builder(text, fail, allow_joint_symbols)
    expr = builder.build(tree.body)
    check_bounded(expr, fail)
    check_expansion(expr, fail, max_terms)
    if expr.has(sp.zoo, sp.oo, -sp.oo, sp.nan):
        raise fail(f"expression '{_short(text)}' is not finite ({expr})")
    if expr.has(sp.I):
        raise fail(f"expression '{_short(text)}' is not real ({expr})")
    return expr, tuple(dict.fromkeys(builder.names))


def parse_expression(
    value: object,
    *,
    file: str | None = None,
    link_index: int | None = None,
    link_name: str | None = None,
    field: str | None = None,
    allow_joint_symbols: bool = False,
    max_terms: int = MAX_EXPANDED_TERMS,
) -> sp.Expr:
    """Parse a number (int/float from YAML) or an expression string into a SymPy expression.

    Integers stay exact (sympy.Integer), floats become sympy.Float; names become
    plain ``sympy.Symbol``s, ``pi`` is ``sympy.pi``. Anything outside the
    whitelist raises SymdynError naming the location and the offending construct.
    """
    expr, _ = parse_expression_names(
        value,
        file=file,
        link_index=link_index,
        link_name=link_name,
        field=field,
        allow_joint_symbols=allow_joint_symbols,
        max_terms=max_terms,
    )
    return expr


def free_symbols_in_order(value: object) -> tuple[sp.Symbol, ...]:
    """The parameter symbols of an expression in order of first textual appearance."""
    _, names = parse_expression_names(value)
    return tuple(sp.Symbol(n) for n in names)


def _short(text: str) -> str:
    return text if len(text) <= 60 else text[:57] + "..."
