"""The LaTeX target (NAME_dynamics.tex): read back and judged against the lecture and the oracle.

The fragment is parsed back with a small reader for the LaTeX the target
prints (sums, juxtaposed products, \\frac, powers, \\left( \\right), s_{..},
c_{..}, x_{k}, \\dot{q}_{i}, \\operatorname{sgn}): for Roger's arm into SymPy,
compared with the lecture's M, V and G (slide 18); for every example
numerically, with the definitions x_k evaluated in order, compared with the
numeric oracle symdyn.rnea at random states. If pdflatex is installed, the
fragments are compiled inside a minimal amsmath document.
"""

from __future__ import annotations

import importlib
import re
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest
import sympy as sp
from robots import (
    derived,
    derived_robot,
    example,
    m1,
    roger_arm_lecture,
    roger_eye_lecture,
)
from sympy.printing.latex import LatexPrinter
from texbuild import TEX, typeset

from symdyn.codegen import latex as latex_backend
from symdyn.codegen import render as render_targets
from symdyn.codegen.latex.base_parameters import base_parameters_latex
from symdyn.dynamics import AUTO_SIMPLIFY_MAX_JOINTS
from symdyn.parsers import robot_from_data

rn = importlib.import_module("symdyn.rnea")  # the module (symdyn.rnea is also the function)
EXAMPLES = Path(__file__).resolve().parent.parent / "examples"
ROBOTS = sorted(p.stem for p in EXAMPLES.glob("*.yaml"))
MAX_BYTES = 300_000


def _dynamics(name: str):
    """Closed forms are simplified up to three joints (the target's closed form)."""
    return derived(name, "newton-euler", example(name).n <= AUTO_SIMPLIFY_MAX_JOINTS)


# --------------------------------------------------------------------------- reading LaTeX back

_TOKEN = re.compile(
    r"""\s+
    | (?P<open>\\left\(|\\bigl\(|\() | (?P<close>\\right\)|\\bigr\)|\))
    | (?P<frac>\\frac) | (?P<cdot>\\cdot) | (?P<sgn>\\operatorname\{sgn\})
    | (?P<func>\\sin|\\cos)(?![A-Za-z])
    | (?P<num>\d+(?:\.\d+)?)
    | (?P<sym>\\d?dot\{q\}_\{[\d,]+\}|\\mathrm\{[^{}]*\}|(?:\\[A-Za-z]+|[A-Za-z])(?:_\{[^{}]*\})?)
    | (?P<op>[-+{}^])
    """,
    re.VERBOSE,
)


class Reader:
    """Recursive descent over the printed LaTeX; leaves come from `symbol` and `number`."""

    def __init__(self, symbol, number, sin, cos, sign):
        self.symbol, self.number, self.sin, self.cos, self.sign = symbol, number, sin, cos, sign

    def __call__(self, tex: str):
        self.tokens = []
        pos = 0
        while pos < len(tex):
            m = _TOKEN.match(tex, pos)
            assert m, f"unreadable LaTeX at {tex[pos : pos + 30]!r}"
            pos = m.end()
            if m.lastgroup:
                self.tokens.append((m.lastgroup, m.group(m.lastgroup)))
        self.k = 0
        value = self.expr()
        assert self.k == len(self.tokens), f"trailing tokens in {tex!r}"
        return value

    def peek(self):
        return self.tokens[self.k] if self.k < len(self.tokens) else (None, None)

    def take(self, kind=None, text=None):
        tok = self.peek()
        assert (kind is None or tok[0] == kind) and (text is None or tok[1] == text), (tok, kind, text)
        self.k += 1
        return tok

    def expr(self):
        sign = 1
        if self.peek() in (("op", "-"), ("op", "+")):
            sign = -1 if self.take()[1] == "-" else 1
        value = self.term() if sign == 1 else -self.term()
        while self.peek() in (("op", "-"), ("op", "+")):
            op = self.take()[1]
            value = value + self.term() if op == "+" else value - self.term()
        return value

    def starts_factor(self) -> bool:
        kind, text = self.peek()
        return kind in ("num", "sym", "open", "frac", "sgn", "func") or (kind, text) == ("op", "{")

    def term(self):
        value = self.factor()
        while self.peek()[0] == "cdot" or self.starts_factor():
            if self.peek()[0] == "cdot":
                self.take()
            value = value * self.factor()
        return value

    def group(self):
        if self.peek() == ("op", "{"):
            self.take()
            value = self.expr()
            self.take("op", "}")
            return value
        return self.primary()

    def factor(self):
        value = self.primary()
        if self.peek() == ("op", "^"):
            self.take()
            exponent = self.group()
            value = value ** int(exponent) if float(exponent) == int(exponent) else value**exponent
        return value

    def primary(self):
        kind, text = self.take()
        if kind == "num":
            return self.number(text)
        if kind == "sym":
            return self.symbol(text)
        if kind == "open":
            value = self.expr()
            self.take("close")
            return value
        if (kind, text) == ("op", "{"):
            value = self.expr()
            self.take("op", "}")
            return value
        if kind == "frac":
            num = self.group()
            return num / self.group()
        if kind == "sgn":
            return self.sign(self.primary())
        if kind == "func":
            return (self.sin if text == r"\sin" else self.cos)(self.group())
        raise AssertionError(f"unexpected {text!r}")


def _abbreviation(name: str):
    """s_{12} -> ('s', (1, 2)); None for other symbols."""
    m = re.fullmatch(r"([sc])_\{([\d,]+)\}", name)
    if not m:
        return None
    digits = m.group(2).split(",") if "," in m.group(2) else list(m.group(2))
    return m.group(1), tuple(int(d) for d in digits)


def _symbolic_reader() -> Reader:
    def symbol(name):
        if name == r"\pi":
            return sp.pi
        abbr = _abbreviation(name)
        if abbr:
            arg = sum(sp.Symbol(f"q{i}") for i in abbr[1])
            return sp.sin(arg) if abbr[0] == "s" else sp.cos(arg)
        m = re.fullmatch(r"(\\d?dot)\{q\}_\{(\d+)\}", name)
        if m:
            return sp.Symbol(("qd" if m.group(1) == r"\dot" else "qdd") + m.group(2))
        return sp.Symbol(re.sub(r"[_{}\\]", "", name))

    return Reader(symbol, sp.Rational, sp.sin, sp.cos, sp.sign)


# --------------------------------------------------------------------------- the printed layout


def _blocks(tex: str) -> tuple[list[tuple[str, str]], dict[str, str]]:
    """(definitions in order as (name, rhs), entries label -> rhs) of a fragment."""
    definitions: list[tuple[str, str]] = []
    entries: dict[str, str] = {}
    for name, body in re.findall(r"(\w) = \\begin\{bmatrix\}\n(.*?)\n  \\end\{bmatrix\}", tex, re.S):
        rows = [r.strip() for r in body.split("\\\\\n")]
        for i, row in enumerate(rows):
            cells = [c.strip() for c in row.split(" & ")]
            for j, cell in enumerate(cells):
                label = f"{name}_{{{i + 1}{j + 1}}}" if name in ("M", "C") else f"{name}_{{{i + 1}}}"
                entries[label] = cell
    for body in re.findall(r"\\begin\{align\*\}\n(.*?)\n\\end\{align\*\}", tex, re.S):
        rows: list[list[str]] = []
        for line in body.split(" \\\\\n"):
            line = line.strip()
            if line.startswith(r"&\qquad "):
                rows[-1][1] += " " + line[len(r"&\qquad ") :]
            else:
                label, rhs = line.split(" &= ", 1)
                rows.append([label, rhs])
        for label, rhs in rows:
            if re.fullmatch(r"x_\{\d+\}", label):
                definitions.append((label, rhs))
            else:
                entries[label] = rhs
    return definitions, entries


def _matrix(entries: dict[str, str], name: str, n: int, read, symmetric: bool = False):
    out = [[None] * n for _ in range(n)]
    for i in range(n):
        for j in range(n):
            key = f"{name}_{{{i + 1}{j + 1}}}"
            if key not in entries and symmetric:
                key = f"{name}_{{{j + 1}{i + 1}}}"
            out[i][j] = read(entries[key])
    return out


def _vector(entries: dict[str, str], name: str, n: int, read):
    return [read(entries[f"{name}_{{{i + 1}}}"]) for i in range(n)]


def _velocity_terms(entries: dict[str, str], read, qd: np.ndarray) -> list:
    """V_k = sum_{i<j} B_{k,(i,j)} qd_i qd_j + sum_i Csq_{k,i} qd_i^2 from the printed nonzero
    entries of B and Csq of the product form (the others are zero)."""
    V = [np.zeros(qd.shape[0]) for _ in range(qd.shape[1])]
    for label, rhs in entries.items():
        b = re.fullmatch(r"B_\{(\d+),\((\d+),(\d+)\)\}", label)
        c = re.fullmatch(r"C\^\{\\mathrm\{sq\}\}_\{(\d+),(\d+)\}", label)
        if b:
            k, i, j = (int(x) - 1 for x in b.groups())
            V[k] = V[k] + read(rhs) * qd[:, i] * qd[:, j]
        elif c:
            k, i = (int(x) - 1 for x in c.groups())
            V[k] = V[k] + read(rhs) * qd[:, i] ** 2
    return V


# --------------------------------------------------------------------------- tests


def test_roger_arm_reads_back_as_the_lecture():
    tex = latex_backend.latex_document_body(_dynamics("roger_arm"))
    _, entries = _blocks(tex)
    read = _symbolic_reader()
    M = sp.Matrix(_matrix(entries, "M", 2, read, symmetric=True))
    V = sp.Matrix(_vector(entries, "V", 2, read))
    G = sp.Matrix(_vector(entries, "G", 2, read))
    M_l, V_l, G_l = roger_arm_lecture()
    for got, want in ((M, M_l), (V, V_l), (G, G_l)):
        diff = (got - want).applyfunc(lambda e: sp.expand(sp.expand_trig(e)))
        assert diff == sp.zeros(*want.shape), diff
    # the printed notation
    assert r"M = \begin{bmatrix}" in tex
    assert r"\dot{q}_{1}" in tex and r"\dot{q}_{2}" in tex
    for symbol in ("m_{1}", "m_{2}", "l_{1}", "l_{2}", "c_{2}", "s_{2}", "s_{12}"):
        assert symbol in tex
    assert r"s_{12} = \sin(q_{1} + q_{2})" in tex and r"c_{2} = \cos q_{2}" in tex
    assert r"\sin" not in tex.split("Abbreviations:")[1].split("\n", 1)[1]  # only in the legend


def test_roger_eye_reads_back_as_the_lecture():
    _, entries = _blocks(latex_backend.latex_document_body(_dynamics("roger_eye")))
    read = _symbolic_reader()
    M_l, V_l, G_l = roger_eye_lecture()
    assert sp.expand(read(entries["M_{11}"]) - M_l[0, 0]) == 0
    assert sp.expand(read(entries["V_{1}"]) - V_l[0]) == 0
    assert sp.expand(read(entries["G_{1}"]) - G_l[0]) == 0


@pytest.mark.parametrize("name", ROBOTS)
def test_every_example_renders_and_reads_back_as_the_oracle(name):
    """Parse M, V, G, F (and C) back, evaluate at random states, compare with the RNEA."""
    dyn = _dynamics(name)
    robot, n = dyn.robot, dyn.n
    tex = latex_backend.dynamics_latex(dyn)
    assert tex.startswith("% ") and "amsmath" in tex.splitlines()[0]
    assert latex_backend.dynamics_latex(dyn) == tex  # deterministic
    assert len(tex.encode()) < MAX_BYTES
    assert "\\documentclass" not in tex and "\\usepackage" not in tex.split("\n", 1)[1]
    assert not re.search(r"~|(?<![\\\w])_\w|qd\d|\bx\d", tex), "internal names leaked"
    assert tex.count("{") == tex.count("}")
    for env in ("align*", "bmatrix"):
        assert tex.count(f"\\begin{{{env}}}") == tex.count(f"\\end{{{env}}}")
    closed = n <= AUTO_SIMPLIFY_MAX_JOINTS
    assert ("C = " in tex or "C_{11} &=" in tex) == closed
    # beyond three joints the product form, but for the Panda (228,647 configuration terms)
    product = "\n% Form: product form, " in tex
    assert product == (not closed and name != "panda")
    assert ("\n% Form: eliminated form (" in tex) == (name == "panda")
    assert (r"x_{1} &=" in tex) == (name == "panda" or (product and bool(dyn.product_form().shared)))

    rng = np.random.default_rng(sum(map(ord, name)))
    S = 3
    q = rng.uniform(-np.pi, np.pi, (S, n))
    qd = rng.uniform(0.3, 1.5, (S, n)) * rng.choice([-1, 1], (S, n))
    p = rng.uniform(0.5, 2.0, len(dyn.params))
    params = {s.name: v for s, v in zip(dyn.params, p, strict=True)} or None
    plain = LatexPrinter()
    env: dict[str, np.ndarray] = {}
    for i in range(n):
        env[f"q_{{{i + 1}}}"] = q[:, i]
        env[f"\\dot{{q}}_{{{i + 1}}}"] = qd[:, i]
    for s, v in zip(dyn.params, p, strict=True):
        env[plain.doprint(s)] = np.full(S, v)

    def symbol(tex_name):
        if tex_name == r"\pi":
            return np.pi
        abbr = _abbreviation(tex_name)
        if abbr:
            arg = sum(q[:, i - 1] for i in abbr[1])
            return np.sin(arg) if abbr[0] == "s" else np.cos(arg)
        return env[tex_name]

    read = Reader(symbol, float, np.sin, np.cos, np.sign)
    definitions, entries = _blocks(tex)
    for label, rhs in definitions:  # in evaluation order: each uses earlier ones only
        assert label not in env
        env[label] = read(rhs) + np.zeros(S)

    def arr(x):
        return np.array([[np.broadcast_to(np.asarray(e, dtype=float), (S,)) for e in row] for row in x])

    M = np.moveaxis(arr(_matrix(entries, "M", n, read, symmetric=True)), -1, 0)
    G, F = (np.moveaxis(arr([_vector(entries, k, n, read)]), -1, 0)[:, 0] for k in ("G", "F"))
    V = _velocity_terms(entries, read, qd) if product else _vector(entries, "V", n, read)
    V = np.moveaxis(arr([V]), -1, 0)[:, 0]
    tol = {"rtol": 1e-8, "atol": 1e-8}
    np.testing.assert_allclose(M, rn.mass_matrix(robot, q, params), **tol)
    np.testing.assert_allclose(V, rn.bias_torque(robot, q, qd, params), **tol)
    np.testing.assert_allclose(G, rn.gravity_torque(robot, q, params), **tol)
    np.testing.assert_allclose(F, rn.friction_torque(robot, qd, params), **tol)
    if closed:
        C = np.moveaxis(arr(_matrix(entries, "C", n, read)), -1, 0)
        np.testing.assert_allclose(np.einsum("sij,sj->si", C, qd), V, **tol)


def test_file_through_the_codegen_entry_point():
    robot = example("roger_arm")
    files = render_targets(robot, targets=("latex",))
    assert list(files) == ["roger_arm_dynamics.tex"]
    text = files["roger_arm_dynamics.tex"]
    assert render_targets(robot, targets=("latex",)) == files  # byte-for-byte deterministic
    lines = text.splitlines()
    assert lines[0].startswith("% Generated by symdyn")
    header = [ln for ln in lines if ln.startswith("% ")]
    assert any("amsmath" in ln for ln in header)
    # the file's body is the fragment of the simplified closed forms, then the base parameters
    dyn = _dynamics("roger_arm")
    assert text.endswith(latex_backend.latex_document_body(dyn) + base_parameters_latex(dyn))


def test_long_entries_break_over_lines():
    tex = latex_backend.latex_document_body(_dynamics("planar_3r"))
    assert r"&\qquad" in tex  # planar_3r's V_1 is longer than a line


def test_parameter_names_like_the_notation_are_spelled_out():
    s1, x1, q1 = sp.symbols("s1 x1 q1")
    dyn = SimpleNamespace(n=1, q=[q1], qd=[sp.Symbol("qd1")], qdd=[sp.Symbol("qdd1")], params=(s1, x1, m1))
    nt = latex_backend.Notation(dyn)
    assert nt.params == [r"\mathrm{s1}", r"\mathrm{x1}", "m_{1}"]
    assert nt.latex(nt.prepare(s1 * sp.sin(q1))) == r"\mathrm{s1} s_{1}"


@pytest.mark.skipif(TEX is None, reason="no pdflatex/latexmk")
@pytest.mark.parametrize("name", ["roger_arm", "planar_3r", "puma560"])
def test_fragment_compiles(name, tmp_path):
    proc = typeset(tmp_path, {f"{name}_dynamics.tex": latex_backend.dynamics_latex(_dynamics(name))})
    assert proc.returncode == 0, proc.stdout[-3000:]
    assert (tmp_path / "doc.pdf").stat().st_size > 0
    assert "Undefined control sequence" not in proc.stdout
    assert "Overfull \\vbox" not in proc.stdout  # every long display breaks across pages


def test_direction_dependent_friction_and_its_base_parameters():
    """F_1 = 0.00148 qd1 + 0.395 [qd1 > 0] - 0.435 [qd1 < 0] as written in the robot file (a planar
    two-link arm, to keep the closed forms short), and the Coulomb magnitudes of each direction as
    base parameters f_{c+,i}, f_{c-,i}."""
    link = {
        "joint": "revolute",
        "a": 0.5,
        "mass": 1,
        "com": [-0.25, 0, 0],
        "inertia": {"ixx": 0.01, "iyy": 0.01, "izz": 0.02},
    }
    friction = ({"viscous": 1.48e-3, "coulomb": [0.395, 0.435]}, {"viscous": 0.2, "coulomb": 0.3})
    data = {
        "name": "two",
        "links": [dict(link, name=f"l{i + 1}", friction=f) for i, f in enumerate(friction)],
    }
    dyn = derived_robot(robot_from_data(data), "newton-euler", None)
    tex = latex_backend.latex_document_body(dyn) + base_parameters_latex(dyn)
    coulomb = r"0.435 \left[\dot{q}_{1} < 0\right] + 0.395 \left[\dot{q}_{1} > 0\right]"
    assert r"0.00148 \dot{q}_{1} - " + coulomb in tex
    assert r"0.3 \operatorname{sgn}(\dot{q}_{2})" in tex
    for name in ("f_{c+,1}", "f_{c-,1}", "f_{c,2}"):
        assert f"= {name} &= {name}" in tex, name
