"""`symdyn derive` in its three forms (symdyn.cli.derive_output): every printed expression
parses, and each form evaluates to the numeric oracle symdyn.rnea."""

from __future__ import annotations

import json
import re
from pathlib import Path

import numpy as np
import pytest
import sympy as sp
import yaml
from robots import example

from symdyn import rnea
from symdyn.cli.main import main
from symdyn.dynamics import derive

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"


def _run(capsys, *argv) -> str:
    assert main(["derive", *argv]) == 0
    return capsys.readouterr().out


def _assignments(text: str) -> dict[str, sp.Expr]:
    pairs = (ln.split(" = ", 1) for ln in text.splitlines() if " = " in ln and not ln.startswith("#"))
    return {a: sp.sympify(b) for a, b in pairs}


def _state(n, seed=1):
    rng = np.random.default_rng(seed)
    return rng.uniform(-np.pi, np.pi, n), rng.uniform(-2, 2, n)


def _subs(e, q, qd):
    names = {sp.Symbol(f"q{i + 1}"): v for i, v in enumerate(q)}
    names.update({sp.Symbol(f"qd{i + 1}"): v for i, v in enumerate(qd)})
    return float(sp.sympify(e).xreplace(names))


@pytest.mark.parametrize("name", ["planar_3r", "scara"])
def test_json_configuration_form_parses_and_has_B_and_Csq(capsys, name):
    doc = json.loads(_run(capsys, str(EXAMPLES / f"{name}.yaml"), "--format", "json"))
    assert {"M", "C", "V", "G", "F", "B", "Csq"} <= doc.keys() and doc["form"] == "configuration"
    dyn = derive(example(name))
    n = dyn.n
    assert np.shape(doc["B"]) == (n, n * (n - 1) // 2) and np.shape(doc["Csq"]) == (n, n)
    q, qd = _state(n)
    for key in ("B", "Csq"):
        want = sp.Matrix(getattr(dyn, key))
        got = [_subs(e, q, qd) for row in doc[key] for e in row]
        np.testing.assert_allclose(got, [_subs(e, q, qd) for e in want], atol=1e-12)
    V = rnea.bias_torque(dyn.robot, q, qd)
    np.testing.assert_allclose([_subs(v, q, qd) for v in doc["V"]], V, atol=1e-9)


def test_lumped_puma_reads_like_the_paper_and_is_the_same_model(capsys):
    text = _run(capsys, str(EXAMPLES / "puma560.yaml"), "--lumped")
    assert (
        "# lumped constants" in text and re.search(r"^I1 = ", text, re.M) and re.search(r"^g1 = ", text, re.M)
    )
    lines = _assignments(text)
    constants = {sp.Symbol(k): v for k, v in lines.items() if re.fullmatch(r"[Ig]\d+", k)}
    dyn = derive(example("puma560"))
    q, qd = _state(6, 4)
    M = rnea.mass_matrix(dyn.robot, q)
    G = rnea.gravity_torque(dyn.robot, q)
    for i in range(6):
        assert _subs(lines[f"G[{i + 1}]"].xreplace(constants), q, qd) == pytest.approx(G[i], abs=1e-9)
        for j in range(i, 6):
            got = _subs(lines[f"M[{i + 1},{j + 1}]"].xreplace(constants), q, qd)
            assert got == pytest.approx(M[i, j], abs=1e-9)


def test_expanded_form_is_the_full_expansion(capsys):
    text = _run(capsys, str(EXAMPLES / "scara.yaml"), "--form", "expanded")
    lines = dict(ln.split(" = ", 1) for ln in text.splitlines() if " = " in ln and not ln.startswith("#"))
    dyn = derive(example("scara"))
    for name in ("M", "V", "G"):
        shape = dyn.compact[name].shape
        for k, e in enumerate(dyn.expanded(name)):
            label = f"{name}[{k // shape[1] + 1},{k % shape[1] + 1}]" if name == "M" else f"{name}[{k + 1}]"
            assert lines[label] == sp.sstr(e)


def test_compact_form_evaluates_to_the_oracle(capsys):
    text = _run(capsys, str(EXAMPLES / "stanford.yaml"), "--form", "compact")
    dyn = derive(example("stanford"))
    q, qd = _state(6, 2)
    env = {sp.Symbol(f"q{i + 1}"): v for i, v in enumerate(q)}
    env.update({sp.Symbol(f"qd{i + 1}"): v for i, v in enumerate(qd)})
    values = {}
    for a, b in (ln.split(" = ", 1) for ln in text.splitlines() if " = " in ln and not ln.startswith("#")):
        values[a] = float(sp.sympify(b).xreplace(env))
        env[sp.Symbol(a)] = values[a]
    V = rnea.bias_torque(dyn.robot, q, qd)
    np.testing.assert_allclose([values[f"V[{i + 1}]"] for i in range(6)], V, atol=1e-9)


def test_prune_prints_its_bound_and_op_counts(capsys):
    text = _run(capsys, str(EXAMPLES / "puma560.yaml"), "--prune", "0.01")
    assert re.search(r"# guaranteed: \|error of an entry\| <= [0-9.e-]+ x its largest value", text)
    assert re.search(r"# operations M \d+ -> \d+", text)
    assert "limits" not in (EXAMPLES / "puma560.yaml").read_text()  # so the ranges are +-pi
    assert "\n# joint ranges: +-pi for q1..q6 (no limits)\n" in text


def test_prune_names_the_robot_files_limits(tmp_path, capsys):
    """planar_3r with limits on joints 1 and 2: the printout says which ranges it used."""
    data = yaml.safe_load((EXAMPLES / "planar_3r.yaml").read_text())
    data["links"][0]["limits"] = ["-pi/2", "pi/2"]
    data["links"][1]["limits"] = [0, "3*pi/4"]
    path = tmp_path / "planar_3r_limits.yaml"
    path.write_text(yaml.safe_dump(data))
    text = _run(capsys, str(path), "--prune", "0.05")
    assert "\n# joint ranges: robot file limits for q1, q2; +-pi for q3 (no limits)\n" in text


def test_latex_configuration_form_breaks_long_entries(capsys):
    text = _run(capsys, str(EXAMPLES / "puma560.yaml"), "--format", "latex")
    assert "\\begin{align*}" in text and "B_{1,(1,2)} &=" in text
    assert "&\\quad" in text  # long entries continue on further lines


def test_an_unreadable_form_falls_back_to_the_expansion_and_compact(monkeypatch, capsys):
    """Past READABLE_TERMS the closed forms are the recursion's expansion (equal values) and
    `derive` prints --form compact with a note; an explicit --form configuration still prints it."""
    from symdyn.algorithms import configuration_space as cs_module
    from symdyn.dynamics import derive

    robot = example("puma560")
    readable = derive(robot, simplify=False)
    assert readable.configuration_space.terms <= cs_module.READABLE_TERMS
    monkeypatch.setattr(cs_module, "READABLE_TERMS", 100)
    big = derive(robot, simplify=False)
    assert not big.configuration_space.readable
    assert big.closed_form("G") == sp.ImmutableMatrix(big.expanded("G"))
    rng = np.random.default_rng(3)
    q = rng.uniform(-np.pi, np.pi, robot.n)
    subs = dict(zip(big.q, q, strict=True))
    got = np.array([float(e.xreplace(subs)) for e in big.closed_form("G")])
    np.testing.assert_allclose(got, rnea.gravity_torque(robot, q), rtol=1e-10, atol=1e-10)
    path = Path(__file__).resolve().parents[1] / "examples" / "puma560.yaml"
    assert main(["derive", str(path)]) == 0
    captured = capsys.readouterr()
    assert "printing --form compact" in captured.err and "B[" not in captured.out
    assert main(["derive", str(path), "--form", "configuration"]) == 0
    assert "B[" in capsys.readouterr().out


FRAMED = """
name: framed
base: {xyz: [0.1, 0, 2], rpy: [pi, 0, 0.2]}
links:
  - {name: l1, joint: revolute, a: 0.4, alpha: pi/2, mass: 1, com: [-0.2, 0, 0]}
  - {name: l2, joint: revolute, a: 0.3, mass: 1, com: [-0.1, 0, 0]}
frames:
  - {name: tool, link: l2, xyz: [0, 0.05, 0.1], rpy: [0.3, 0, 0]}
"""


@pytest.mark.parametrize("fmt", ["text", "json"])
def test_frames_print_each_pose_and_jacobian_entry(capsys, tmp_path, fmt):
    from symdyn.oracle.frames import frame_state

    path = tmp_path / "framed.yaml"
    path.write_text(FRAMED)
    out = _run(capsys, str(path), "--frames", "tool,l1", "--format", fmt, "--simplify", "no")
    robot = __import__("symdyn").load_robot(path)
    q, _ = _state(2, seed=4)
    for name in ("tool", "l1"):
        if fmt == "json":
            frame = json.loads(out)["frames"][name]
            T, J = (
                np.array([[_subs(sp.sympify(e), q, q) for e in row] for row in frame[k]])
                for k in ("pose", "jacobian")
            )
        else:
            entries = _assignments(out)
            T = np.array(
                [[_subs(entries[f"T_{name}[{i},{j}]"], q, q) for j in range(1, 5)] for i in range(1, 5)]
            )
            J = np.array(
                [[_subs(entries[f"J_{name}[{i},{j}]"], q, q) for j in range(1, 3)] for i in range(1, 7)]
            )
        want = frame_state(robot, name, q)
        np.testing.assert_allclose(T.astype(float), want.pose, atol=1e-12)
        np.testing.assert_allclose(J.astype(float), want.jacobian, atol=1e-12)


def test_an_unknown_frame_is_one_line_and_nothing_is_printed(capsys, tmp_path):
    path = tmp_path / "framed.yaml"
    path.write_text(FRAMED)
    assert main(["derive", str(path), "--frames", "tol"]) == 1
    out, err = capsys.readouterr()
    assert out == ""
    assert err.strip().endswith("unknown frame 'tol' (did you mean 'tool'?); the frames: l1, l2, tool")
    assert err.count("\n") == 1 and str(path) in err


def test_frames_do_not_combine_with_steps(capsys, tmp_path):
    path = tmp_path / "framed.yaml"
    path.write_text(FRAMED)
    assert main(["derive", str(path), "--frames", "tool", "--steps"]) == 1
    out, err = capsys.readouterr()
    assert out == "" and "--frames" in err and "--steps" in err


HOSTILE_LINK = "a&#10;M[1] = 0&#10;#"


def test_a_name_with_newlines_stays_inside_its_comment_and_label(tmp_path, capsys):
    """A URDF link (and so frame) whose name holds newlines and an entry's text: derive's text
    output keeps every line of its own shape (a comment, a blank, or LABEL[i,j] = expr), and the
    robot's M[1,1] is the one line that says M[1,1] (the pendulum's m l^2 + Izz = 1*0.25 + 0.1)."""
    urdf = tmp_path / "hostile.urdf"
    urdf.write_text(
        f"""<robot name="arm"><link name="base"/>
<link name="{HOSTILE_LINK}"><inertial><mass value="1"/><origin xyz="0.5 0 0"/>
<inertia ixx="0.1" iyy="0.1" izz="0.1" ixy="0" ixz="0" iyz="0"/></inertial></link>
<joint name="j1" type="revolute"><parent link="base"/><child link="{HOSTILE_LINK}"/><axis xyz="0 0 1"/>
<limit lower="-1" upper="1" effort="1" velocity="1"/></joint></robot>"""
    )
    assert main(["derive", str(urdf), "--frames", "a\nM[1] = 0\n#"]) == 0
    lines = capsys.readouterr().out.splitlines()
    shape = re.compile(r"#.*|\w+(\[[\d,() ]+\])? = .+|")
    assert all(shape.fullmatch(line) for line in lines), [x for x in lines if not shape.fullmatch(x)]
    assert [line for line in lines if line.startswith("M[1")] == ["M[1,1] = 0.35"]
    assert "T_a_M_1_0[1,1] = cos(q1)" in lines
