"""The LaTeX backend's notation (symdyn.codegen.latex.notation): abbreviations, legend, line breaks.

The fragments as a whole are read back and checked against the lecture and the
oracle in tests/test_latex_target.py; here the notation's rules one by one.
"""

from __future__ import annotations

from types import SimpleNamespace

import sympy as sp

from symdyn.codegen.latex.notation import LINE_WIDTH, DynamicsLatexPrinter, Notation, width


def _notation(n: int) -> Notation:
    q = sp.symbols(f"q1:{n + 1}")
    dyn = SimpleNamespace(
        n=n,
        q=list(q),
        qd=list(sp.symbols(f"qd1:{n + 1}")),
        qdd=list(sp.symbols(f"qdd1:{n + 1}")),
        params=(sp.Symbol("m1"), sp.Symbol("l2")),
    )
    return Notation(dyn)


def test_abbreviations_only_for_sums_of_distinct_joints():
    nt = _notation(3)
    q1, q2, q3 = sp.symbols("q1:4")
    assert nt.latex(nt.prepare(sp.sin(q1 + q2) * sp.cos(q3))) in ("c_{3} s_{12}", "s_{12} c_{3}")
    for e in (sp.sin(2 * q1), sp.sin(q1 - q2), sp.cos(q1 + 1)):
        text = nt.latex(nt.prepare(e))
        assert "s_{" not in text and "c_{" not in text, text
    # the legend defines exactly the abbreviations used, fewest joints first
    nt.prepare(sp.cos(q2) + sp.sin(q2) + sp.sin(q1 + q2 + q3))
    legend = nt.legend()
    assert sorted((s, f, tuple(a)) for s, f, a in legend) == sorted(
        [
            ("s_{2}", "sin", ("q_{2}",)),
            ("c_{2}", "cos", ("q_{2}",)),
            ("c_{3}", "cos", ("q_{3}",)),
            ("s_{12}", "sin", ("q_{1}", "q_{2}")),
            ("s_{123}", "sin", ("q_{1}", "q_{2}", "q_{3}")),
        ]
    )
    assert [len(a) for _, _, a in legend] == sorted(len(a) for _, _, a in legend)


def test_indices_take_commas_from_ten_joints():
    nt = _notation(10)
    q = sp.symbols("q1:11")
    assert nt.latex(nt.prepare(sp.sin(q[0] + q[9]))) == "s_{1,10}"
    assert nt.label("M", 0, 9) == "M_{1,10}"
    assert _notation(3).label("M", 0, 2) == "M_{13}"


def test_long_sums_break_at_top_level_signs():
    nt = _notation(3)
    q1, q2, q3 = sp.symbols("q1:4")
    m1, l2 = sp.symbols("m1 l2")
    long = sum(sp.Symbol(f"a{k}") * l2 * sp.sin(q1 + q2) * sp.cos(q3) * q1 for k in range(12))
    lines = nt.lines(nt.prepare(long))
    assert len(lines) > 1
    assert all(width(line) <= LINE_WIDTH for line in lines)
    assert " ".join(lines).replace("  ", " ") == "".join(nt.printer.terms(nt.prepare(long))).replace(
        "  ", " "
    )
    assert nt.lines(nt.prepare(m1 * q1)) == [nt.latex(nt.prepare(m1 * q1))]


def test_heaviside_prints_as_an_iverson_bracket():
    """Direction-dependent Coulomb friction: H(qd) with H(0) = 0 as [qd > 0], H(-qd) as [qd < 0]."""
    qd1 = sp.Symbol("qd1")
    printer = DynamicsLatexPrinter({qd1: r"\dot{q}_{1}"})
    assert printer.doprint(sp.Heaviside(qd1, 0)) == r"\left[\dot{q}_{1} > 0\right]"
    assert printer.doprint(sp.Heaviside(-qd1, 0)) == r"\left[\dot{q}_{1} < 0\right]"
