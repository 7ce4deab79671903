"""The `symdyn` command: derive output, generate, and bad input through the real entry point."""

from __future__ import annotations

import importlib
import json
import os
import re
import subprocess
import sys
from pathlib import Path

import pytest
import sympy as sp

from symdyn.cli.main import COMMANDS, build_parser, main

ROOT = Path(__file__).resolve().parents[1]
EXAMPLES = ROOT / "examples"
BAD = ROOT / "tests" / "data" / "bad"


def run(*args: str, cwd: Path | None = None) -> subprocess.CompletedProcess:
    """Run `python -m symdyn.cli.main ...` exactly as the console script would."""
    env = dict(os.environ, PYTHONPATH=str(ROOT))
    return subprocess.run(
        [sys.executable, "-m", "symdyn.cli", *args],
        capture_output=True,
        text=True,
        cwd=cwd or ROOT,
        env=env,
        timeout=300,
    )


def lecture_roger_arm():
    m1, m2, l1, l2, g, q1, q2, qd1, qd2 = sp.symbols("m1 m2 l1 l2 g q1 q2 qd1 qd2")
    c2, s2 = sp.cos(q2), sp.sin(q2)
    M = sp.Matrix(
        [
            [m2 * l2**2 + 2 * m2 * l1 * l2 * c2 + (m1 + m2) * l1**2, m2 * l2**2 + m2 * l1 * l2 * c2],
            [m2 * l2**2 + m2 * l1 * l2 * c2, m2 * l2**2],
        ]
    )
    V = sp.Matrix([-m2 * l1 * l2 * s2 * (qd2**2 + 2 * qd1 * qd2), m2 * l1 * l2 * s2 * qd1**2])
    G = sp.Matrix(
        [(m1 + m2) * g * l1 * sp.sin(q1) + m2 * g * l2 * sp.sin(q1 + q2), m2 * g * l2 * sp.sin(q1 + q2)]
    )
    return M, V, G


@pytest.mark.parametrize("method", ["newton-euler", "lagrange"])
def test_derive_json_reproduces_the_lecture(method):
    out = run("derive", str(EXAMPLES / "roger_arm.yaml"), "--method", method, "--format", "json")
    assert out.returncode == 0, out.stderr
    doc = json.loads(out.stdout)
    assert doc["q"] == ["q1", "q2"] and doc["params"] == sorted(doc["params"], key=doc["params"].index)
    M, V, G = lecture_roger_arm()
    got_M = sp.Matrix(doc["M"]).applyfunc(sp.sympify)
    assert sp.simplify(got_M - M) == sp.zeros(2, 2)
    assert sp.simplify(sp.Matrix([sp.sympify(v) for v in doc["V"]]) - V) == sp.zeros(2, 1)
    assert sp.simplify(sp.Matrix([sp.sympify(v) for v in doc["G"]]) - G) == sp.zeros(2, 1)


def test_derive_text_names_entries_one_based():
    out = run("derive", str(EXAMPLES / "roger_eye.yaml"))
    assert out.returncode == 0, out.stderr
    lines = dict(line.split(" = ", 1) for line in out.stdout.splitlines() if " = " in line)
    m, g, l, q1 = sp.symbols("m g l q1")
    assert sp.simplify(sp.sympify(lines["M[1,1]"]) - m * l**2) == 0
    assert sp.simplify(sp.sympify(lines["G[1]"]) - m * g * l * sp.sin(q1)) == 0
    assert "B[" not in out.stdout and "Csq[" not in out.stdout  # one joint: no velocity terms
    out = run("derive", str(EXAMPLES / "roger_eye.yaml"), "--form", "expanded")
    lines = dict(line.split(" = ", 1) for line in out.stdout.splitlines() if " = " in line)
    assert sp.sympify(lines["V[1]"]) == 0


BAD_FILES = sorted(p.name for p in BAD.glob("*.yaml"))


@pytest.mark.parametrize("name", BAD_FILES)
def test_bad_input_gives_one_line_and_nonzero_exit(name, tmp_path, capsys):
    """In-process through main() (the console script's function): one line, exit 1, no output."""
    assert main(["derive", str(BAD / name)]) == 1
    out, err = capsys.readouterr()
    err_lines = [line for line in err.splitlines() if line.startswith("symdyn: error:")]
    assert len(err_lines) == 1, err
    assert "Traceback" not in err
    assert name in err_lines[0]
    assert out == ""
    # generate: the same refusal, and nothing is written
    target = tmp_path / "out"
    assert main(["generate", str(BAD / name), "--target", "c", "--out", str(target)]) == 1
    assert "Traceback" not in capsys.readouterr().err
    assert not target.exists()


@pytest.mark.parametrize("name", ["python_code.yaml", "non_psd_inertia.yaml", "bad_yaml.yaml"])
def test_bad_input_through_the_installed_entry_point(name):
    out = run("derive", str(BAD / name))
    assert out.returncode == 1, (out.stdout, out.stderr)
    assert out.stderr.count("symdyn: error:") == 1 and "Traceback" not in out.stderr
    assert out.stdout == ""


def test_error_names_link_and_field():
    out = run("derive", str(BAD / "non_psd_inertia.yaml"))
    assert out.returncode == 1
    assert "link " in out.stderr and "field 'inertia" in out.stderr


def test_python_code_in_an_expression_is_refused_and_not_executed(tmp_path):
    marker = Path("/tmp/symdyn_pwned")
    marker.unlink(missing_ok=True)
    out = run("derive", str(BAD / "python_code.yaml"))
    assert out.returncode == 1
    assert "field 'mass'" in out.stderr
    assert not marker.exists()


def test_warnings_are_one_line_each():
    out = run("derive", str(ROOT / "tests" / "data" / "good" / "warn_triangle.yaml"), "--format", "json")
    assert out.returncode == 0, out.stderr
    warns = [line for line in out.stderr.splitlines() if line]
    assert len(warns) == 1 and warns[0].startswith("symdyn: warning: ")
    assert "warn_triangle.yaml" in warns[0] and "link 1" in warns[0] and "triangle" in warns[0]


def test_missing_file_and_bad_option():
    out = run("derive", "no/such/robot.yaml")
    assert out.returncode == 1 and "no/such/robot.yaml" in out.stderr and "Traceback" not in out.stderr
    out = run("derive", str(EXAMPLES / "roger_arm.yaml"), "--method", "kane")
    assert out.returncode == 2 and "Traceback" not in out.stderr


def test_generate_writes_every_target_and_refuses_foreign_files(tmp_path):
    out_dir = tmp_path / "gen"
    args = ["generate", str(EXAMPLES / "roger_arm.yaml"), "--out", str(out_dir)]
    targets = ["--target", "c", "--target", "casadi", "--target", "python", "--target", "latex"]
    first = run(*args, *targets)
    assert first.returncode == 0, first.stderr
    names = sorted(p.name for p in out_dir.iterdir())
    assert "roger_arm_dynamics.h" in names and "roger_arm_dynamics.c" in names
    assert "roger_arm_casadi.py" in names and "roger_arm_mass_matrix.casadi" in names
    assert "roger_arm_numpy.py" in names and "roger_arm_dynamics.tex" in names
    assert not [n for n in names if n.endswith(".tmp") or n.startswith(".")]
    before = {p.name: p.read_bytes() for p in out_dir.iterdir()}
    # regenerating over our own files is allowed and byte-identical
    again = run(*args, *targets)
    assert again.returncode == 0, again.stderr
    assert {p.name: p.read_bytes() for p in out_dir.iterdir()} == before
    # a file symdyn did not write is never overwritten without --force
    (out_dir / "roger_arm_dynamics.c").write_text("/* my own controller */\n")
    refused = run(*args, "--target", "c")
    assert refused.returncode == 1 and "--force" in refused.stderr
    assert (out_dir / "roger_arm_dynamics.c").read_text() == "/* my own controller */\n"
    assert (out_dir / "roger_arm_dynamics.h").read_bytes() == before["roger_arm_dynamics.h"]
    forced = run(*args, "--target", "c", "--force")
    assert forced.returncode == 0
    assert (out_dir / "roger_arm_dynamics.c").read_bytes() == before["roger_arm_dynamics.c"]


def test_generate_default_targets_are_c_and_casadi(tmp_path):
    out = run("generate", str(EXAMPLES / "roger_eye.yaml"), "--out", str(tmp_path))
    assert out.returncode == 0, out.stderr
    names = {p.name for p in tmp_path.iterdir()}
    assert {"roger_eye_dynamics.c", "roger_eye_dynamics.h", "roger_eye_casadi.py"} <= names
    assert not any(n.endswith(".tex") or n.endswith("_numpy.py") for n in names)


def _declared(header: Path) -> list[str]:
    return re.findall(r"^void (\w+)\(", header.read_text(), re.M)


def test_generate_builds_the_dynamics_group_unless_told_all(tmp_path, capsys):
    """Without --functions: the seven functions of tau = M qdd + V + G + F and forward dynamics;
    --functions all: every function generated/ holds (written by symdyn.regenerate, which leaves
    the frame groups out but for the Panda), then the kinematics of the default frame (forearm,
    the leaf link; its operational space is singular at every q, so left out with a warning), then
    the centroidal functions (com once, in the kinematics group)."""
    robot = str(EXAMPLES / "roger_arm.yaml")
    assert main(["generate", robot, "--target", "c", "--out", str(tmp_path / "default")]) == 0
    assert (
        main(["generate", robot, "--target", "c", "--functions", "all", "--out", str(tmp_path / "all")]) == 0
    )
    seven = ("inverse_dynamics", "mass_matrix", "coriolis_matrix", "coriolis", "gravity", "friction")
    seven += ("forward_dynamics",)
    assert _declared(tmp_path / "default" / "roger_arm_dynamics.h") == [f"roger_arm_{n}" for n in seven]
    committed = _declared(ROOT / "generated" / "roger_arm" / "roger_arm_dynamics.h")
    assert len(committed) > len(seven) and "roger_arm_regressor" in committed
    kinematics = [f"forearm_{s}" for s in ("pose", "jacobian", "jacobian_local", "jacobian_dot_qd")]
    kinematics += ["com", "com_jacobian", "com_jacobian_dot_qd"]
    kinematics += ["centroidal_momentum_matrix", "centroidal_momentum_drift", "total_mass"]
    assert _declared(tmp_path / "all" / "roger_arm_dynamics.h") == committed + [
        f"roger_arm_{n}" for n in kinematics
    ]
    with pytest.raises(SystemExit) as refused:
        main(["generate", robot, "--functions", "dynamic", "--out", str(tmp_path / "x")])
    assert refused.value.code == 2
    assert "invalid choice" in capsys.readouterr().err


def _subcommands(parser):
    return next(a for a in parser._actions if a.__class__.__name__ == "_SubParsersAction").choices


#: A valid command line of each subcommand (its required arguments), for the parsing comparison.
VALID = {
    "derive": ["robot.yaml"],
    "generate": ["robot.yaml", "--out", "out"],
    "simulate": ["robot.yaml", "--duration", "1", "--dt", "0.1", "--out", "a.csv"],
    "analyze": ["robot.yaml", "--q", "0", "--torque-limits", "1"],
    "check": ["robot.yaml", "answers.yaml"],
    "cache": [],
    "identify": ["robot.yaml", "data.csv"],
    "excite": ["robot.yaml", "--out", "e.csv"],
    "draw": ["robot.yaml", "--out", "robot.svg"],
}


@pytest.mark.parametrize("name", list(COMMANDS))
def test_a_subcommand_built_alone_is_the_one_of_the_whole_parser(name, monkeypatch):
    """main builds only the named subcommand's options: the same help, usage and parse as the whole parser."""
    monkeypatch.setenv("COLUMNS", "100")
    full, alone = build_parser(), build_parser(name)
    assert list(_subcommands(full)) == list(COMMANDS) and list(_subcommands(alone)) == [name]
    assert alone.format_usage() == full.format_usage()
    assert _subcommands(alone)[name].format_help() == _subcommands(full)[name].format_help()
    assert vars(alone.parse_args([name, *VALID[name]])) == vars(full.parse_args([name, *VALID[name]]))


def test_symdyn_help_lists_every_subcommand():
    out = run("--help")
    assert out.returncode == 0
    assert re.findall(r"^    (\w+) ", out.stdout, re.MULTILINE) == list(COMMANDS)


def test_main_builds_the_named_subcommand_only(monkeypatch, capsys):
    cli_main = importlib.import_module("symdyn.cli.main")  # the module (symdyn.cli.main is also the function)

    built = []
    real = cli_main.build_parser
    monkeypatch.setattr(cli_main, "build_parser", lambda command=None: built.append(command) or real(command))
    assert main(["cache"]) == 0
    with pytest.raises(SystemExit):
        main(["no-such-command"])
    assert built == ["cache", None]  # an unknown word: the whole parser, whose error lists the commands
    assert "invalid choice" in capsys.readouterr().err


def test_messages_quoting_user_text_stay_one_line(tmp_path, capsys):
    """A file name with a newline and a terminal escape is printed escaped: one line, no control
    character reaching the terminal."""
    bad = tmp_path / "bad\nname\x1b[2J.yaml"
    bad.write_text("links: [")
    assert main(["derive", str(bad)]) == 1
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "\x1b" not in err and "bad\\nname\\x1b[2J.yaml" in err, err
