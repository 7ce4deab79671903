"""The safe expression parser: the whitelist builds the right SymPy, everything else is refused."""

from __future__ import annotations

import ast
import time
from pathlib import Path

import pytest
import sympy as sp
from hypothesis import given, settings
from hypothesis import strategies as st

from symdyn.errors import SymdynError
from symdyn.model.expressions import (
    check_parameter_name,
    free_symbols_in_order,
    parse_expression,
    parse_expression_names,
)

x, y, z, l1, m2, l2 = sp.symbols("x y z l1 m2 l2")


@pytest.mark.parametrize(
    "text, expected",
    [
        (3, sp.Integer(3)),
        (-7, sp.Integer(-7)),
        (2.5, sp.Float(2.5)),
        ("3", sp.Integer(3)),
        ("1/2", sp.Rational(1, 2)),
        ("l1/2", sp.Mul(sp.Rational(1, 2), l1)),
        ("m2*l2**2", sp.Mul(m2, sp.Pow(l2, 2))),
        ("pi/2", sp.pi / 2),
        ("-pi/2", -sp.pi / 2),
        ("+x", x),
        ("(x + y) * z", sp.Mul(sp.Add(x, y), z)),
        ("x - y", sp.Add(x, sp.Mul(-1, y))),
        ("x**-2", sp.Pow(x, -2)),
        ("2**0.5", sp.Float(2) ** sp.Float(0.5)),
        ("sin(x) + cos(y)", sp.Add(sp.sin(x), sp.cos(y))),
        ("tan(x/3)", sp.tan(x / 3)),
        ("sqrt(2)/2", sp.sqrt(2) / 2),
        ("sqrt(x**2 + y**2)", sp.sqrt(x**2 + y**2)),
        ("cos(pi/2)", sp.Integer(0)),
        ("sin(pi/6)", sp.Rational(1, 2)),
        ("1e-3", sp.Float(0.001)),
        ("  x\n + y ", x + y),
        ("((((x))))", x),
    ],
)
def test_whitelist_builds_the_right_sympy(text, expected):
    got = parse_expression(text)
    assert got == expected
    assert sp.simplify(got - expected) == 0


def test_integers_stay_exact_and_floats_are_floats():
    assert isinstance(parse_expression(3), sp.Integer)
    assert isinstance(parse_expression("12/4"), sp.Integer)
    assert parse_expression("1/3") == sp.Rational(1, 3)
    assert isinstance(parse_expression(0.1), sp.Float)
    assert float(parse_expression(0.1)) == 0.1
    assert parse_expression("10**30") == sp.Integer(10) ** 30


def test_names_are_plain_symbols():
    e = parse_expression("m_1 * Lx")
    assert e.free_symbols == {sp.Symbol("m_1"), sp.Symbol("Lx")}
    assert all(s.assumptions0 == sp.Symbol("t").assumptions0 for s in e.free_symbols)


def test_free_symbols_in_textual_order():
    assert free_symbols_in_order("b + a - b*c + sin(z)") == sp.symbols("b a c z")
    assert free_symbols_in_order("l2**2*m2 + m1*l1") == sp.symbols("l2 m2 m1 l1")
    # a name counts where it is written, even if it cancels
    expr, names = parse_expression_names("x - x + y")
    assert expr == y
    assert names == ("x", "y")
    assert free_symbols_in_order(3.5) == ()


_SEVEN = (x, y, z, l1, m2, l2, sp.Symbol("w"))


@st.composite
def _trees(draw, depth=0):
    """A random whitelisted expression as (text, the same built with SymPy operators)."""
    if depth > 3 or draw(st.booleans()):
        if draw(st.booleans()):
            n = draw(st.integers(-50, 50))
            return (f"({n})", sp.Integer(n))
        s = draw(st.sampled_from(_SEVEN))
        return (str(s), s)
    kind = draw(st.sampled_from(["+", "-", "*", "/", "**", "sin", "cos", "sqrt", "neg"]))
    a_text, a = draw(_trees(depth + 1))
    if kind in ("sin", "cos"):
        fn = {"sin": sp.sin, "cos": sp.cos}[kind]
        return (f"{kind}({a_text})", fn(a))
    if kind == "sqrt":  # of a positive argument: the result stays real
        return (f"sqrt(({a_text})**2 + 1)", sp.sqrt(a**2 + 1))
    if kind == "neg":
        return (f"-({a_text})", -a)
    if kind == "**":
        k = draw(st.integers(0, 4))
        return (f"({a_text})**{k}", a**k)
    b_text, b = draw(_trees(depth + 1))
    if kind == "/":
        b = b**2 + 1  # never zero
        b_text = f"(({b_text})**2 + 1)"
    op = {"+": sp.Add, "-": lambda p, q: p - q, "*": sp.Mul, "/": lambda p, q: p / q}[kind]
    return (f"({a_text}) {kind} ({b_text})", op(a, b))


@settings(max_examples=60, deadline=None)
@given(_trees())
def test_random_whitelisted_expressions_match_sympy(tree):
    text, expected = tree
    assert parse_expression(text) == expected


REFUSED = [
    ("().__class__", "attribute"),
    ("open('f')", "call of 'open'"),
    ("lambda: 1", "lambda"),
    ("[1,2]", "list"),
    ("(1, 2)", "tuple"),
    ("{1: 2}", "dict"),
    ("x if y else z", "conditional"),
    ("a.b", "attribute"),
    ("f(x)", "call of 'f'"),
    ("x[0]", "subscript"),
    ("[i for i in x]", "comprehension"),
    ("sin(x=1)", "keyword"),
    ("sqrt(x, y)", "one positional argument"),
    ("sin(*x)", "one positional argument"),
    ("sin", "without an argument"),
    ("'text'", "string"),
    ("1j", "complex"),
    ("True", "constant"),
    ("None", "constant"),
    ("x < y", "comparison"),
    ("x and y", "boolean"),
    ("x ^ 2", "use ** for powers"),
    ("x // 2", "'//'"),
    ("x % 2", "'%'"),
    ("~x", "'~'"),
    ("(y := 2)", "assignment"),
    ("f'{x}'", "f-string"),
    ("x = 1", "cannot parse"),
    ("x +", "cannot parse"),
    ("", "empty"),
    ("1/0", "division by zero"),
    ("x/(2 - 2)", "division by zero"),
    ("0**-1", "division by zero"),
    ("tan(pi/2)", "not finite"),
    ("sqrt(-1)", "not real"),
    ("q1", "reserved for joint symbols"),
    ("2*qd2", "reserved for joint symbols"),
    ("qdd3 + 1", "reserved for joint symbols"),
    ("int * 2", "C keyword"),
    ("__x", "reserved"),
    ("_m", "underscore"),  # symdyn's intermediates are named _<hint><k>
    ("tau2", "joint symbols"),  # forward_dynamics takes tau1..taun
    ("1" * 31, "more than 30 digits"),
    ("x" * 2001, "longer than 2000"),
    ("-" * 150 + "1", "nested more than 100"),
]


@pytest.mark.parametrize("text, reason", REFUSED)
def test_refused_with_the_field_and_the_construct(text, reason):
    with pytest.raises(SymdynError) as info:
        parse_expression(text, file="arm.yaml", link_index=2, link_name="elbow", field="mass")
    err = info.value
    assert reason in str(err)
    assert (err.file, err.link_index, err.link_name, err.field) == ("arm.yaml", 2, "elbow", "mass")
    assert str(err).startswith("arm.yaml: link 2 (elbow): field 'mass': ")


@pytest.mark.parametrize("value", [True, False, None, [1, 2], {"a": 1}, float("inf"), float("nan")])
def test_non_numbers_from_yaml_are_refused(value):
    with pytest.raises(SymdynError, match="field 'a'"):
        parse_expression(value, field="a")


def test_python_code_is_never_executed(tmp_path):
    target = tmp_path / "pwned"
    payloads = [
        f"__import__('os').system('touch {target}')",
        f"open('{target}', 'w')",
        f"[c for c in ().__class__.__base__.__subclasses__()][0]('touch {target}')",
        f"(lambda: __import__('os').system('touch {target}'))()",
        f"exec(\"open('{target}','w')\")",
        f"eval(\"open('{target}','w')\")",
    ]
    for payload in payloads:
        with pytest.raises(SymdynError):
            parse_expression(payload, field="mass")
    assert not target.exists()


def test_the_parser_and_loaders_never_evaluate_text():
    """No call of eval/exec/compile/sympify/parse_expr anywhere in the parser or the loaders."""
    root = Path(__file__).parents[1] / "symdyn"
    files = [root / "model" / "expressions.py", *sorted((root / "parsers").glob("*.py"))]
    assert any(f.name == "robot_file.py" for f in files) and any(f.name == "urdf.py" for f in files)
    for path in files:
        for node in ast.walk(ast.parse(path.read_text())):
            if not isinstance(node, ast.Call):
                continue
            f = node.func
            where = f"{path.name}:{node.lineno}"
            if isinstance(f, ast.Name):
                assert f.id not in {"eval", "exec", "compile", "__import__", "sympify"}, where
            elif isinstance(f, ast.Attribute):
                assert f.attr not in {"parse_expr", "S", "literal_eval"}, where
                if f.attr == "sympify":  # only in its strict form, which refuses strings
                    assert any(
                        k.arg == "strict" and getattr(k.value, "value", None) is True for k in node.keywords
                    ), where


@pytest.mark.parametrize(
    "text",
    [
        "10**10**10",
        "2**10**10",
        "9**99",
        "2**-65",
        "(10**30)**64",
        "((9**64)**64)**64",
        "sqrt(" + "*".join(["999999999999999999999999999989"] * 60) + " + 1)",
        "(" + "*".join(["999999999999999999999999999989"] * 30) + ")**(1/3)",
    ],
)
def test_huge_powers_are_refused_quickly(text):
    t0 = time.perf_counter()
    with pytest.raises(SymdynError, match="exponent|too large"):
        parse_expression(text, field="a")
    assert time.perf_counter() - t0 < 0.5


def test_exponent_limit_is_inclusive_and_symbolic_exponents_are_allowed():
    assert parse_expression("2**64") == sp.Integer(2) ** 64
    assert parse_expression("x**-64") == x**-64
    assert parse_expression("x**y") == x**y


@pytest.mark.parametrize(
    "name, reason",
    [
        ("q1", "reserved for joint symbols"),
        ("qd12", "reserved for joint symbols"),
        ("qdd3", "reserved for joint symbols"),
        ("pi", "reserved"),
        ("sin", "reserved"),
        ("sqrt", "reserved"),
        ("1abc", "not a valid parameter name"),
        ("a-b", "not a valid parameter name"),
        ("m 1", "not a valid parameter name"),
        ("double", "C keyword"),
        (3, "must be a string"),
    ],
)
def test_parameter_names(name, reason):
    with pytest.raises(SymdynError, match=reason) as info:
        check_parameter_name(name, file="f.yaml", field=f"parameters.{name}")
    assert info.value.field == f"parameters.{name}"


@pytest.mark.parametrize("name", ["q", "qd", "q1a", "qx1", "Q1", "m_1", "theta0", "l1"])
def test_valid_parameter_names(name):
    assert check_parameter_name(name) == name
    assert parse_expression(name) == sp.Symbol(name)


# -- issue 34: the size of what gets expanded, nesting, hostile literals --------------------------

from timebound import refused, within  # noqa: E402

from symdyn.model.bounded import MAX_ANSWER_TERMS, MAX_EXPANDED_TERMS, expanded_terms  # noqa: E402


def _sympy_terms(text: str) -> int:
    """The terms of the expression expanded by SymPy, sines and cosines of sums as exponentials."""
    e = parse_expression(text, max_terms=10**6).rewrite(sp.exp)
    return len(sp.Add.make_args(sp.expand(e)))


@pytest.mark.parametrize(
    "text", ["(a+b+c)**3", "(a+b)**2*(c+d)", "(a+b+c+d)**5", "(x+y)**-3", "sin(x)**6", "(a+b)*(a-b)"]
)
def test_the_expansion_estimate_bounds_what_sympy_expands(text):
    """An upper bound, and the multinomial count where no terms cancel: C(t + k - 1, k) for (a+b+c)**3."""
    assert expanded_terms(parse_expression(text), 10**6, SymdynError) >= _sympy_terms(text)
    for exact in ("(a+b+c)**3", "(a+b+c+d)**5"):
        assert expanded_terms(parse_expression(exact), 100, SymdynError) == _sympy_terms(exact)
    assert _sympy_terms("(a+b+c)**3") == 10


def test_a_product_of_capped_powers_is_refused_naming_the_field_and_the_limit():
    """Each exponent is within 64, but the product would expand to 47,905**2 terms (it hung)."""
    with within(3), pytest.raises(SymdynError) as info:
        parse_expression("(a+b+c+d)**64*(e+f+g+h)**64", file="f.yaml", field="com.x")
    message = str(info.value)
    assert message.startswith("f.yaml: field 'com.x': '(a + b + c + d)**64' would expand to 47,905 terms")
    assert f"limit of {MAX_EXPANDED_TERMS}" in message
    with within(3), pytest.raises(SymdynError, match=f"limit of {MAX_ANSWER_TERMS:,}"):
        parse_expression(
            "sin(q1)**64*cos(q2)**64*(q1+q2+m1+m2)**64", allow_joint_symbols=True, max_terms=MAX_ANSWER_TERMS
        )


def test_a_robot_file_with_a_product_of_capped_powers_is_refused_in_one_line(tmp_path, capsys):
    text = (Path(__file__).resolve().parents[1] / "examples" / "roger_arm.yaml").read_text()
    path = tmp_path / "com.yaml"
    path.write_text(text.replace("com: [0, 0, 0]", "com: ['(a+b+c+d)**64*(e+f+g+h)**64', 0, 0]", 1))
    line = refused(capsys, "derive", path, seconds=10)
    assert f"{path}: link 1 (upper_arm): field 'com.x': " in line and "limit of 100" in line


def test_a_parameter_value_that_completes_a_large_expansion_is_refused():
    """x: a+b+c+d and mass: x**64 pass each on its own; substituted they are (a+b+c+d)**64."""
    data = {
        "name": "t",
        "parameters": {"x": "a+b+c+d"},
        "links": [
            {"name": "l", "joint": "revolute", "a": 1, "alpha": 0, "d": 0, "theta": 0, "mass": "x**64",
             "com": [0, 0, 0], "inertia": {"ixx": 0, "iyy": 0, "izz": 0, "ixy": 0, "ixz": 0, "iyz": 0}}
        ],
    }  # fmt: skip
    from symdyn.parsers.robot_file import robot_from_data

    with within(5), pytest.raises(SymdynError, match=r"field 'mass'.*47,905 terms.*after substituting"):
        robot_from_data(data, "f.yaml")


def test_a_long_sum_is_one_level_of_nesting():
    """150 terms written out were refused as nested 150 levels deep; a chain is one level."""
    names = sp.symbols("v0:150")
    assert parse_expression(" + ".join(map(str, names))) == sp.Add(*names)
    assert parse_expression(" * ".join(map(str, names[:40])) + " / v149") == sp.Mul(*names[:40]) / names[149]
    assert parse_expression("v1 - v2 + v3 - v4") == names[1] - names[2] + names[3] - names[4]


@pytest.mark.parametrize(
    "text",
    [
        "**".join(["x"] * 99),  # x**x**...: SymPy's recursion broke `check` after 21 s
        "sin(" * 99 + "x" + ")" * 99,
        "tan(" * 30 + "x" + ")" * 30,
        "sqrt(" * 25 + "x" + ")" * 25,
        "(" * 30 + "x" + "**y)" * 30,
    ],
)
def test_calls_and_powers_nested_deeply_are_refused(text):
    with within(2), pytest.raises(SymdynError, match="calls and powers are nested more than 20 deep"):
        parse_expression(text, field="mass")


@pytest.mark.parametrize(
    "text, message",
    [
        ("x+" * 500_000 + "x", "longer than 2000 characters"),
        ("١٢٣", r"invalid character '١' \(U\+0661\)"),
        ("x²", "invalid character"),
        ("1e400", "not finite"),
        ("0**-1", "division by zero"),
        ("10**10**10", "exponent 10000000000"),
        ("x/(y-y)", "division by zero"),
    ],
)
def test_hostile_literals_are_refused_quickly(text, message):
    """The same parser reads robot files and check's answers (allow_joint_symbols)."""
    for answer in (False, True):
        with within(2), pytest.raises(SymdynError, match=message):
            parse_expression(text, field="mass", allow_joint_symbols=answer)
