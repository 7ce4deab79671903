"""Checking textbook answers (`symdyn check`) against the derivation.

The reference answers are the lecture's closed forms (slides 17-18) in
examples/answers/roger_arm_answers.yaml; wrong answers are made from them by hand.
"""

from __future__ import annotations

from pathlib import Path

import pytest
import sympy as sp
import yaml
from timebound import refused, within

import symdyn.apps.checking.check as check_module
from symdyn import cli
from symdyn.apps.checking.check import check_answers, load_answers
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
    assert sp.expand(parsed["M"][2, 2] - m2 * l2**2) == 0
    assert sp.expand(parsed["G"][(2,)] - m2 * g * l2 * sp.sin(q1 + q2)) == 0


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
    assert lines[0] == "M[2,2]: expected l2**2*m2, got l1**2*m2; answer - symdyn = l1**2*m2 - l2**2*m2"
    assert lines[1].startswith("V[2]: expected ")
    assert lines[1].endswith("got -l1*l2*m2*qd1**2*sin(q2); answer - symdyn = -2*l1*l2*m2*qd1**2*sin(q2)")
    got, diff = lines[2].split("; answer - symdyn = ")
    assert got.startswith("G[1]: expected ") and "cos(q1)" in got
    want = sp.sympify("(m1 + m2)*g*l1*(cos(q1) - sin(q1))")
    assert sp.expand(sp.sympify(diff) - want) == 0
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
        ({"M": [[None, None], [None, None]]}, "no answer entry given: every entry is null (not checked)"),
        ({"M": [None, None], "G": None}, "no answer entry given"),
        ({"M": [[None, None]]}, "list of 2 rows of 2 entries (null for a row or entry not checked)"),
        ({"M[3,1]": "0"}, "no such entry: M has the entries M[i,j], i and j in 1..2"),
        ({"G[1,1]": "0"}, "no such entry: G has the entries G[i], i in 1..2"),
        ({"M": [[None, None], [None, 0]], "M[2,2]": "0"}, "field 'M[2,2]': entry given twice"),
        ({"M[x]": "0"}, "unknown key(s) M[x]"),
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


#: M[2,2] of the lecture's arm (slide 18), right and wrong, as a student who derived only it
M22, M22_WRONG = "m2*l2**2", "m2*l2"


@pytest.mark.parametrize(
    "answers",
    [{"M": [[None, None], [None, M22]]}, {"M": [None, [None, M22]]}, {"M[2,2]": M22}, {"M[2, 2]": M22}],
    ids=["nulls", "null row", "entry key", "entry key with a space"],
)
def test_one_entry_checked(roger, answers):
    report = check_answers(roger, answers)
    assert report.ok and [r.label for r in report.results] == ["M[2,2]"] and report.entries == 4
    assert (
        report.summary()
        == "roger_arm: 1 of 4 entries of M checked (the others null); it matches (all symbolically)"
    )


def test_one_entry_wrong(roger, tmp_path, capsys):
    report = check_answers(roger, {"M[2,2]": M22_WRONG, "G": [None, "m2*g*l2*sin(q1 + q2)"]})
    assert not report.ok and [r.label for r in report.differing] == ["M[2,2]"]
    assert (
        report.summary() == "roger_arm: 2 of 6 entries of M, G checked (the others null); 1 differs (M[2,2])"
    )
    answers = tmp_path / "one.yaml"
    answers.write_text(f"M:\n  - [null, null]\n  - [null, {M22_WRONG}]\n")
    assert run_cli(["check", ROGER, answers]) == 1
    out = capsys.readouterr().out
    assert out == (
        "M[2,2]: expected l2**2*m2, got l2*m2; answer - symdyn = -l2**2*m2 + l2*m2\n"
        "roger_arm: 1 of 4 entries of M checked (the others null); 1 differs (M[2,2])\n"
    )


def test_a_differing_entry_is_shown_as_derive_prints_it(roger, tmp_path, capsys):
    """A new user's case: a uniform bar's M[1,2] answered with l2**2*m2/3 + l1*l2*m2/2*cos(q2) but
    written wrongly; symdyn's entry is printed as `symdyn derive` prints M[1,2], and the difference
    is the one worked out by hand."""
    answers = tmp_path / "bar.yaml"
    answers.write_text('M[1,2]: "l2**2*m2/3 + l1*l2*m2/2*cos(q2)"\n')
    assert run_cli(["derive", ROGER]) == 0
    derived = dict(line.split(" = ", 1) for line in capsys.readouterr().out.splitlines() if " = " in line)
    assert run_cli(["check", ROGER, answers]) == 1
    line = capsys.readouterr().out.splitlines()[0]
    assert line == (
        f"M[1,2]: expected {derived['M[1,2]']}, got l1*l2*m2*cos(q2)/2 + l2**2*m2/3; "
        "answer - symdyn = -l1*l2*m2*cos(q2)/2 - 2*l2**2*m2/3"
    )


def test_an_answer_m_that_is_not_symmetric_is_flagged(roger):
    """M = M^T: an answer whose M[1,2] and M[2,1] differ gets a note with their difference, and a
    symmetric answer none."""
    wrong = {"M": [[None, "m2*l2**2 + m2*l1*l2*cos(q2)"], ["m2*l2**2 + m2*l1*l2*sin(q2)", None]]}
    report = check_answers(roger, wrong)
    assert report.notes == [
        "the answer's M is not symmetric: M[1,2] - M[2,1] = -l1*l2*m2*sin(q2) + l1*l2*m2*cos(q2) "
        "(every M is symmetric: M = M^T)"
    ]
    assert "note: the answer's M is not symmetric" in report.text()
    wrong["M"][1][0] = wrong["M"][0][1]
    assert check_answers(roger, wrong).notes == []


def test_no_entry_at_all(roger, tmp_path, capsys):
    answers = tmp_path / "none.yaml"
    answers.write_text("M: [[null, null], [null, null]]\nG: [null, null]\n")
    assert run_cli(["check", ROGER, answers]) == 1
    assert capsys.readouterr().err == (
        f"symdyn: error: {answers}: no answer entry given: "
        "every entry is null (not checked); give at least one\n"
    )


def test_steps_with_null_entries():
    """Craig's omega_2 = (0, 0, qd1 + qd2) (example 6.6), its third entry alone, right and wrong."""
    craig = load_robot(EXAMPLES / "craig_two_link.yaml")
    report = check_answers(craig, {"steps": {2: {"omega": [None, None, "qd1 + qd2"]}}})
    assert report.ok and [r.label for r in report.results] == ["omega_2[3]"]
    assert (
        report.summary()
        == "craig_two_link: 1 of 3 entries of 1 step checked (the others null); it matches (all symbolically)"
    )
    report = check_answers(
        craig, {"steps": {2: {"omega": [None, None, "qd1 - qd2"], "f": None}}, "M[1,1]": None}
    )
    assert not report.ok and report.first_step.startswith("omega_2 (outward iteration, link 2")
    assert report.summary().endswith(
        "1 of 10 entries of 2 steps, M checked (the others null); 1 differs (omega_2[3])"
    )
    with pytest.raises(SymdynError, match="no answer entry given"):
        check_answers(craig, {"steps": {2: {"omega": None}}})
    with pytest.raises(SymdynError, match="no answer entry given"):
        check_answers(craig, {"steps": {1: None}})


def test_one_entry_at_a_state(roger):
    """M[2,2] = m2 l2^2 (slide 18) at m2 = 2, l2 = 0.5: 0.5, whatever q."""
    at = {"q": [0.3, -1.2], "m1": 1.0, "m2": 2.0, "l1": 0.7, "l2": 0.5, "g": 9.81}
    report = check_answers(roger, {"at": at, "M": [[None, None], [None, 0.5]]})
    assert report.ok and [r.label for r in report.results] == ["M[2,2]"]
    assert (
        report.summary()
        == "roger_arm: 1 of 4 entries of M checked (the others null); it matches (at the given state)"
    )
    assert not check_answers(roger, {"at": at, "M[2,2]": 0.25}).ok


def test_samples_out_of_range_are_one_line(capsys):
    """Before: `check --samples 1e9` was refused by argparse as a spelling (and 1000000000 ended in an
    internal MemoryError); now any whole number is read and one out of 1..MAX_SAMPLES is refused
    before the robot is derived."""
    robot, answers = EXAMPLES / "roger_arm.yaml", EXAMPLES / "answers" / "roger_arm_answers.yaml"
    for samples in ("1e9", "1000000000", "0", "-3"):
        line = refused(capsys, "check", robot, answers, "--samples", samples, seconds=5)
        assert line == f"symdyn: error: --samples {int(float(samples))}: must be from 1 to 100,000"
    with within(5), pytest.raises(SymdynError, match="samples must be a whole number from 1 to 100,000"):
        check_answers(load_robot(robot), answers, samples=10**9)


# -- issue 34: answers bounded like robot files ---------------------------------------------------


@pytest.mark.parametrize(
    "entry, message",
    [
        # each exponent within 64, the product 65 * 65 * 47,905 terms once expanded: it hung
        (
            "sin(q1)**64*cos(q2)**64*(q1+q2+m1+m2)**64",
            "would expand to 47,905 terms, more than the limit of 1,000",
        ),
        ("**".join(["q1"] * 99), "calls and powers are nested more than 20 deep"),  # RecursionError
        ("(q1+q2+m1+m2+l1+l2)**-64", "would expand to 11,238,513 terms"),  # SymPy expands denominators
    ],
)
def test_answers_that_would_expand_or_recurse_without_bound_are_refused(tmp_path, capsys, entry, message):
    from timebound import refused

    path = tmp_path / "answers.yaml"
    path.write_text(yaml.safe_dump({"G[1]": entry}))
    line = refused(capsys, "check", ROGER, path, seconds=10)
    assert line.startswith(f"symdyn: error: {path}: field 'G[1]': ") and message in line


@pytest.mark.parametrize(
    "text, message",
    [
        ("M: " + "[" * 100_000 + "]" * 100_000 + "\n", "invalid YAML: nested too deeply"),
        ("G: &a [x]\nM: &b [*a, *a, *a, *a, *a, *a, *a, *a, *a]\n" + "".join(
            f"k{i}: &c{i} [{', '.join([f'*c{i - 1}' if i else '*b'] * 9)}]\n" for i in range(8)
        ), "the document expands to more than 100,000 nodes"),
        ("G[1]: 1\nG[1]: 2\n", "duplicate key 'G[1]'"),
    ],
)  # fmt: skip
def test_answer_files_are_read_as_robot_files_are(tmp_path, capsys, text, message):
    """The answers file went to yaml.safe_load: deep nesting was a RecursionError, aliases unbounded."""
    from timebound import refused

    path = tmp_path / "answers.yaml"
    path.write_text(text)
    assert message in refused(capsys, "check", ROGER, path, seconds=10)


def test_a_long_answer_within_the_bound_is_still_checked(roger):
    """The lecture's G[1] plus a sum of 150 terms written out (refused before as nested 150 levels deep)."""
    g1 = "(m1 + m2)*g*l1*sin(q1) + m2*g*l2*sin(q1 + q2)"
    padding = " + ".join(f"{i}*m1 - {i}*m1" for i in range(75))
    report = check_answers(roger, {"G": [f"{g1} + {padding}", None]})
    assert report.ok and [r.status for r in report.results] == ["symbolic"]
