"""No live LaTeX from names (issue 34, item 3): hostile link, frame and robot names through every
LaTeX path (derive --format latex in each form, with --frames and --lumped; derive --steps;
generate --target latex; Dynamics._repr_latex_).

The oracle is the same robot with plain names: the hostile output may hold only the commands the
plain one holds, and symdyn's escapes (\\_ \\# \\% \\& \\{ \\} \\$); no line starts inside a name
(the newline of `a<newline>\\immediate\\write18{...}<newline>b` stays escaped); and with pdflatex
installed, each output typesets with \\write18 allowed while running nothing (no file appears) and
\\inputs nothing (the file `secret.tex` that `\\input secret` would read stops TeX with an error).
"""

from __future__ import annotations

import contextlib
import dataclasses
import io
import re
import warnings
from pathlib import Path

import pytest
from texbuild import ESCAPES, TEX, commands, typeset, uncommented
from timebound import within

from symdyn.cli.main import main
from symdyn.codegen import render
from symdyn.dynamics import derive
from symdyn.parsers import load_urdf

DATA = Path(__file__).parent / "data" / "urdf"
WRITE = "a\n\\immediate\\write18{touch pwned}\nb"
INPUT = "\\input secret"
SPECIALS = "$x^2$ & #1 % {~} \\\\ ü工具"
PLAIN = {WRITE: "forearm_link", INPUT: "upper_link", SPECIALS: "tool_frame"}


def _urdf(tmp_path: Path, names: dict[str, str], file: str) -> Path:
    """tests/data/urdf/two_link.urdf with upper, lower and a fixed tool link under the given names."""
    text = (DATA / "two_link.urdf").read_text()
    tool = (
        '<link name="tool"/><joint name="tool_joint" type="fixed"><parent link="lower"/>'
        '<child link="tool"/><origin xyz="0.5 0 0"/></joint></robot>'
    )
    text = text.replace("</robot>", tool)
    for old, new in (("upper", names[INPUT]), ("lower", names[WRITE]), ("tool", names[SPECIALS])):
        quoted = new.replace("&", "&amp;").replace("\n", "&#10;").replace('"', "&quot;")
        text = text.replace(f'"{old}"', f'"{quoted}"')
    path = tmp_path / file
    path.write_text(text, encoding="utf-8")
    return path


def _outputs(path: Path) -> dict[str, str]:
    """What every LaTeX path prints for the robot file `path` (whose frames are PLAIN's values
    or keys), by name."""
    frames = ",".join(n for n in load_urdf(path).frame_names if n != "base")
    runs = {
        "configuration": ["derive", path, "--format", "latex", "--frames", frames, "--lumped"],
        "compact": ["derive", path, "--format", "latex", "--form", "compact", "--frames", frames],
        "product": ["derive", path, "--format", "latex", "--form", "product", "--lumped"],
        "steps": ["derive", path, "--format", "latex", "--steps"],
    }
    out = {}
    for name, args in runs.items():
        printed = io.StringIO()
        with within(60), contextlib.redirect_stdout(printed):
            assert main([str(a) for a in args]) == 0
        out[name] = printed.getvalue()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        robot = load_urdf(path)
        (tex,) = render(robot, targets=("latex",), functions=("all",)).values()
    out["generate"] = tex
    return out


@pytest.fixture(scope="module")
def both(tmp_path_factory) -> tuple[dict[str, str], dict[str, str]]:
    """(what each LaTeX path prints for the hostile names, for the plain names)."""
    folder = tmp_path_factory.mktemp("names")
    hostile = _outputs(_urdf(folder, {k: k for k in PLAIN}, "hostile.urdf"))
    return hostile, _outputs(_urdf(folder, PLAIN, "plain.urdf"))


def test_hostile_names_reach_every_latex_path_escaped(both):
    hostile, plain = both
    for path, tex in hostile.items():
        extra = commands(tex) - commands(plain[path]) - ESCAPES
        assert not extra, (path, extra)
        assert not re.search(r"^\s*[?\\]?(immediate|b\b|input)", tex, re.M), path
        read = uncommented(tex)
        assert "\\input" not in read and "\\write" not in read and "\\immediate" not in read, path
    assert "a??immediate?write18?touch pwned??b" in hostile["generate"]
    assert "?input secret" in hostile["configuration"]  # as the comment above the frame's block


@pytest.mark.skipif(TEX is None, reason="no pdflatex/latexmk")
def test_hostile_names_typeset_and_run_nothing(both, tmp_path):
    hostile, _ = both
    for path, tex in hostile.items():
        folder = tmp_path / path
        folder.mkdir()
        (folder / "secret.tex").write_text("\\errmessage{secret was read}\n")
        done = typeset(folder, {f"{path}.tex": tex}, shell_escape=True)
        assert done.returncode == 0, (path, done.stdout[-3000:])
        assert not (folder / "pwned").exists() and "secret was read" not in done.stdout, path


def test_a_robot_name_built_in_python_is_escaped_too():
    """A Robot made in Python is not checked like a file's name: _repr_latex_ and the fragment
    of derive --format latex escape it all the same."""
    from symdyn.codegen.latex import dynamics_latex

    robot = load_urdf(DATA / "two_link.urdf")
    dyn = derive(dataclasses.replace(robot, name=WRITE))
    for tex in (dyn._repr_latex_(), dynamics_latex(dyn)):
        assert "\\immediate" not in tex and "\\write" not in tex
        assert not re.search(r"^\s*[?\\]?immediate|^b\b", tex, re.M)
