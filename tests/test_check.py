"""Checking textbook answers (`symdyn check`) against the derivation.

The reference answers are the lecture's closed forms (slides 17-18) in
examples/answers/roger_arm_answers.yaml; wrong answers are made from them by hand.
"""

from __future__ import annotations

from pathlib import Path

import pytest
import sympy as sp
import yaml

import symdyn.apps.check as check_module
from symdyn import cli
from symdyn.apps.check import check_answers, load_answers
from symdyn.errors import SymdynError
from symdyn.parsers import load_robot

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"
ROGER = EXAMPLES / "roger_arm.yaml"
ANSWERS = EXAMPLES / "answers" / "roger_arm_answers.yaml"


@pytest.fixture(scope="module")
def roger():
    return load_robot(ROGER)


@pytest.fixture(scope="module")
def answers() -> dict:
    return yaml.safe_load(ANSWERS.read_text())


def run_cli(argv, monkeypatch=None) -> int:
    """The symdyn command in-process (symdyn.cli.main, which registers simulate/analyze/check)."""
    return cli.main([str(a) for a in argv])


def test_answers_file_holds_the_lecture(roger):
    m1, m2, l1, l2, g, q1, q2 = sp.symbols("m1 m2 l1 l2 g q1 q2")
    parsed = load_answers(ANSWERS, roger)
    assert set(parsed) == {"M", "V", "G"}
    assert sp.expand(parsed["M"][1, 1] - m2 * l2**2) == 0
    assert sp.expand(parsed["G"][1] - m2 * g * l2 * sp.sin(q1 + q2)) == 0


@pytest.mark.parametrize("method", ["newton-euler", "lagrange"])
def test_lecture_answers_match(roger, method):
    report = check_answers(roger, ANSWERS, method=method)
    assert report.ok and len(report.results) == 8
    assert all(r.status == "symbolic" for r in report.results)
    assert report.summary() == "roger_arm: all 8 entries of M, V, G match (all symbolically)"


def test_values_of_the_robot_file_are_substituted():
    report = check_answers(load_robot(EXAMPLES / "roger_arm_values.yaml"), ANSWERS)
    assert report.ok


def test_wrong_answers_are_caught(roger, answers, tmp_path, monkeypatch, capsys):
    wrong = yaml.safe_load(yaml.safe_dump(answers))
    wrong["M"][1][1] = "m2*l1**2"  # l1 for l2
    wrong["G"][0] = "(m1 + m2)*g*l1*cos(q1) + m2*g*l2*sin(q1 + q2)"  # cos for sin
    wrong["V"][1] = "-m2*l1*l2*sin(q2)*qd1**2"  # sign
    path = tmp_path / "wrong.yaml"
    path.write_text(yaml.safe_dump(wrong))
    assert run_cli(["check", ROGER, path], monkeypatch) == 1
    lines = capsys.readouterr().out.splitlines()
    assert lines[0] == "M[2,2]: expected l2**2*m2, got l1**2*m2"
    assert lines[1].startswith("V[2]: expected ") and lines[1].endswith("got -l1*l2*m2*qd1**2*sin(q2)")
    assert lines[2].startswith("G[1]: expected ") and "cos(q1)" in lines[2]
    assert lines[3] == "roger_arm: 3 of 8 entries of M, V, G differ (M[2,2], V[2], G[1])"
    assert len(lines) == 4


def test_cli_good_answers_exit_0(monkeypatch, capsys):
    assert run_cli(["check", ROGER, ANSWERS, "--verbose"], monkeypatch) == 0
    out = capsys.readouterr().out
    assert "M[1,2]: matches (symbolic)" in out and out.rstrip().endswith("match (all symbolically)")


def test_equal_but_differently_written_answers_match(roger):
    report = check_answers(
        roger,
        {
            "M": [
                [
                    "(m1+m2)*l1**2 + m2*l2**2 + 2*m2*l1*l2*(cos(q2/2)**2 - sin(q2/2)**2)",
                    "m2*l2*(l2 + l1*cos(q2))",
                ],
                ["m2*l2**2 + m2*l1*l2*cos(q2)", "m2*l2**2"],
            ],
            "tau": [
                "((m1 + m2)*l1**2 + m2*l2**2 + 2*m2*l1*l2*cos(q2))*qdd1 + (m2*l2**2 + m2*l1*l2*cos(q2))*qdd2"
                " - m2*l1*l2*sin(q2)*(qd2**2 + 2*qd1*qd2) + (m1 + m2)*g*l1*sin(q1) + m2*g*l2*sin(q1 + q2)",
                "(m2*l2**2 + m2*l1*l2*cos(q2))*qdd1 + m2*l2**2*qdd2 + m2*l1*l2*sin(q2)*qd1**2"
                " + m2*g*l2*(sin(q1)*cos(q2) + cos(q1)*sin(q2))",
            ],
            "C": [["-m2*l1*l2*sin(q2)*qd2", "-m2*l1*l2*sin(q2)*(qd1 + qd2)"], ["m2*l1*l2*sin(q2)*qd1", 0]],
            "F": [0, 0],
        },
    )
    assert report.ok, report.text()


def test_numeric_comparison_when_simplification_is_inconclusive(roger, answers, monkeypatch):
    monkeypatch.setattr(check_module, "_symbolic_zero", lambda diff: False)
    alt = {
        "M": [
            ["m2*l2**2 + 2*m2*l1*l2*(1 - 2*sin(q2/2)**2) + (m1 + m2)*l1**2", answers["M"][0][1]],
            answers["M"][1],
        ]
    }
    report = check_answers(roger, alt, samples=8)
    assert report.ok
    assert report.results[0].status == "numeric"
    assert "1 numerically at 8 random points" in report.summary()


def test_one_joint_robot_accepts_scalars():
    eye = load_robot(EXAMPLES / "roger_eye.yaml")
    assert check_answers(eye, {"M": "m*l**2", "G": "m*g*l*sin(q1)", "V": 0}).ok
    assert not check_answers(eye, {"G": "m*g*l*cos(q1)"}).ok


@pytest.mark.parametrize(
    "answers, message",
    [
        ({"M": [[1, 2]]}, "list of 2 rows of 2 entries"),
        ({"G": ["0"]}, "list of 2 entries"),
        ({"X": [0, 0]}, "unknown key"),
        ({}, "no answers"),
        ({"G": ["c2", 0]}, "unknown name(s) c2"),
        ({"G": ["q3", 0]}, "unknown name(s) q3"),
        ({"G": ["__import__('os').system('true')", 0]}, "not allowed"),
        ({"G": ["m1.__class__", 0]}, "attribute access"),
        ({"G": ["Q1", 0]}, "Q1"),  # reserved (placeholder fallback) or unknown (parser flag)
        ({"G": [[0], 0]}, "expected one expression"),
    ],
)
def test_bad_answers(roger, answers, message):
    with pytest.raises(SymdynError) as info:
        check_answers(roger, answers)
    assert message in str(info.value)


def test_cli_bad_file_one_line(tmp_path, monkeypatch, capsys):
    bad = tmp_path / "bad.yaml"
    bad.write_text("M: [[1, 2], [3\n")
    assert run_cli(["check", ROGER, bad], monkeypatch) == 1
    err = capsys.readouterr().err
    assert err.startswith("symdyn: error: ") and "invalid YAML" in err and err.count("\n") == 1
    assert run_cli(["check", ROGER, tmp_path / "missing.yaml"], monkeypatch) == 1
    assert capsys.readouterr().err.startswith("symdyn: error: ")
