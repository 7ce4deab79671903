"""A user's names spelled for generated code and LaTeX (symdyn.model.names), and a fuzz test of
frame and link names through the C, CasADi, NumPy and LaTeX targets.

The fuzz test writes URDFs whose fixed links (frames) carry hypothesis' names: random unicode,
punctuation, every target's keywords (C `int`, Python `lambda`, MATLAB `end`, CasADi `jac`),
leading digits, LaTeX's special characters and commands. Each URDF loads and generates, or is
refused with one SymdynError line, within a time bound; what is generated compiles as C (syntax
only, the strict flags), as Python, builds its CasADi functions, and its LaTeX holds no command of
the user's. Derandomized (the same cases every run), SYMDYN_FUZZ_NAMES cases (default 20, about
20 s); a longer hunt: SYMDYN_FUZZ_NAMES=500 python -m pytest -q tests/test_names.py
"""

from __future__ import annotations

import hashlib
import os
import re
import subprocess
import tempfile
import warnings
from xml.sax.saxutils import quoteattr

import pytest
from cbuild import STRICT_FLAGS, compilers
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from robots import raw_example
from texbuild import ESCAPES, commands
from timebound import within

from symdyn.codegen import generate, render
from symdyn.errors import SymdynError
from symdyn.model.names import MAX_IDENTIFIER, comment_text, identifier, identifiers, latex_text, short_name
from symdyn.parsers import robot_from_data
from symdyn.parsers.urdf import urdf_from_bytes

#: CasADi's rule for a function name (casadi/core/function_internal.cpp)
CASADI_NAME = re.compile(r"[A-Za-z](_?[A-Za-z0-9])*\Z")
MATLAB_NAME = re.compile(r"[A-Za-z][A-Za-z0-9_]*\Z")
KEYWORDS = ["int", "for", "lambda", "None", "class", "end", "function", "jac", "hess", "null", "com"]
LATEX = ["\\input{x}", "\\immediate\\write18{ls}", "$x^2$", "a&b", "#1", "50%", "{}", "~", "\\\\", "_"]


def test_identifiers_of_the_issue_cases():
    """tool_, my__tool, 1st, cam.-x and names in other scripts: valid in every target at once."""
    cases = {
        "tool_": "tool",
        "my__tool": "my_tool",
        "1st": "frame_1st",
        "cam.-x": "cam_x",
        "Greifer-Spitze-ü": "Greifer_Spitze_u",
        "Ångström": "Angstrom",
        "工具": "frame",
        "": "frame",
        "panda_link8": "panda_link8",
    }
    assert {name: identifier(name) for name in cases} == cases
    for name in ["x" * 250, "é" * 250, "_".join(["ab"] * 200)]:
        ident = identifier(name)
        assert len(ident) <= MAX_IDENTIFIER and CASADI_NAME.match(ident), ident
        assert ident[-9:] == "_" + hashlib.sha256(name.encode()).hexdigest()[:8]
    assert identifier("x" * 250) != identifier("x" * 251)


def test_identifiers_are_distinct_and_deterministic():
    names = ["tip.x", "tip-x", "tip_x", "tip x", "com", "工具", "道具", "1st", "frame_1st"]
    got = identifiers(names, reserved=("com",))
    assert len(set(got.values())) == len(names)
    assert got["tip_x"] == "tip_x" and got["frame_1st"] == "frame_1st"  # own identifiers stay
    for name, ident in got.items():
        assert CASADI_NAME.match(ident) and MATLAB_NAME.match(ident) and ident.isidentifier(), ident
        assert ident == identifier(name) or ident.startswith(identifier(name)[:40] + "_"), (name, ident)
    assert identifiers(names, reserved=("com",)) == got
    assert identifiers(["com"], reserved=("com",))["com"] != "com"


def test_short_name_keeps_short_names_and_cuts_long_ones():
    assert short_name("panda") == "panda"
    long = "r" * 250
    assert len(short_name(long)) == MAX_IDENTIFIER and short_name(long) != short_name(long + "s")


HOSTILE = ["a\n\\immediate\\write18{touch x}\nb", "\\input /etc/passwd", *LATEX, "ü*/"]


@pytest.mark.parametrize("name", HOSTILE)
def test_latex_and_comment_text_run_nothing(name):
    """One line; every backslash is an escape of symdyn's (\\_ \\# \\% \\& \\{ \\} \\$); in a
    comment no newline, backslash, quote or comment end."""
    tex = latex_text(name)
    assert "\n" not in tex and not re.search(r"\\[^_#%&{}$]", tex), tex
    assert not re.search(r"(?<!\\)[#%&{}$^~]", tex), tex
    text = comment_text(name)
    assert text.isascii() and not re.search(r"[\n\\'\"%*]", text), text


def test_a_robot_name_of_250_characters_makes_files_the_file_system_takes(tmp_path):
    """The robot's name is cut (with its hash) in code and file names, and the header says so."""
    name = "r" * 250
    robot = robot_from_data(raw_example("roger_arm_values") | {"name": name})
    with within(60):
        paths = generate(
            robot, ("c", "casadi", "python", "jax", "torch", "latex"), tmp_path, functions=("kinematics",)
        )
    named = [p for p in paths if p.name != "CMakeLists.txt"]  # the C target's build file has a fixed name
    assert named and len(named) == len(paths) - 1
    assert all(len(p.name.encode()) <= 200 and p.name.startswith(short_name(name)) for p in named)
    assert f"add_library({short_name(name)}_dynamics" in (tmp_path / "CMakeLists.txt").read_text()
    header = (tmp_path / f"{short_name(name)}_dynamics.h").read_text()
    assert f"Robot '{name}' is {short_name(name)} in code and file names." in header


# --------------------------------------------------------------------------- fuzz

FUZZ_EXAMPLES = int(os.environ.get("SYMDYN_FUZZ_NAMES", "20"))
TIME_BOUND = 20


def _urdf(names: list[str]) -> bytes:
    """A one-joint arm with each name a fixed link (a frame) on it, 1 apart along z."""
    links = "".join(f"<link name={quoteattr(n)}/>" for n in names)
    joints = "".join(
        f'<joint name="fixed{i}" type="fixed"><parent link="arm"/><child link={quoteattr(n)}/>'
        f'<origin xyz="0 0 {i + 1}"/></joint>'
        for i, n in enumerate(names)
    )
    return (
        '<robot name="fuzz"><link name="base"/><link name="arm"><inertial><mass value="1"/>'
        '<origin xyz="0.5 0 0"/><inertia ixx="0.1" iyy="0.1" izz="0.1" ixy="0" ixz="0" iyz="0"/>'
        '</inertial></link><joint name="j" type="revolute"><parent link="base"/><child link="arm"/>'
        '<axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="1" velocity="1"/></joint>'
        f"{links}{joints}</robot>"
    ).encode()


#: characters XML 1.0 allows in an attribute (no control character but tab and newline)
_UNICODE = st.characters(exclude_categories=("Cc", "Cs"), include_characters="\n\t")
_ASCII = st.characters(codec="ascii", exclude_categories=("Cc",), include_characters="\n")
NAMES = st.one_of(
    st.text(_UNICODE, min_size=1, max_size=30),
    st.text(_ASCII, min_size=1, max_size=12),
    st.sampled_from(KEYWORDS + LATEX + ["tool_", "my__tool", "1st", "cam.-x", "x" * 250]),
    st.builds(lambda d, s: d + s, st.sampled_from("0123456789"), st.text("abc_.-", max_size=6)),
)


_PLAIN_COMMANDS: set[str] = set()


def _plain_commands() -> set[str]:
    """The LaTeX commands symdyn writes for frames with plain names, and its escapes."""
    if not _PLAIN_COMMANDS:
        robot = urdf_from_bytes(_urdf(["tool", "camera"]), "plain.urdf", "-", None, None)
        tex = render(robot, targets=("latex",), functions=("kinematics",))["fuzz_dynamics.tex"]
        _PLAIN_COMMANDS.update(commands(tex) | ESCAPES)
    return _PLAIN_COMMANDS


def _check_files(files: dict, folder: str) -> None:
    """C compiles (syntax), the Python modules compile, CasADi builds every function, LaTeX holds
    only symdyn's commands."""
    assert all(len(name.encode()) <= 200 for name in files), list(files)
    casadi = pytest.importorskip("casadi")
    namespace: dict = {"__name__": "fuzz_casadi"}
    exec(compile(files["fuzz_casadi.py"], "fuzz_casadi.py", "exec"), namespace)
    built = namespace["functions"]()
    assert all(isinstance(f, casadi.Function) for f in built.values())
    compile(files["fuzz_numpy.py"], "fuzz_numpy.py", "exec")
    assert commands(files["fuzz_dynamics.tex"]) <= _plain_commands()
    if compilers():
        for name in ("fuzz_dynamics.h", "fuzz_dynamics.c"):
            with open(os.path.join(folder, name), "w", encoding="utf-8") as f:
                f.write(files[name])
        cmd = [compilers()[0], *STRICT_FLAGS, "-fsyntax-only", os.path.join(folder, "fuzz_dynamics.c")]
        done = subprocess.run(cmd, capture_output=True, text=True, timeout=60)
        assert done.returncode == 0, done.stderr[-2000:]


@settings(
    max_examples=FUZZ_EXAMPLES,
    derandomize=True,
    deadline=None,
    suppress_health_check=list(HealthCheck),
    database=None,
)
@given(st.lists(NAMES, min_size=1, max_size=4, unique=True))
def test_fuzz_frame_and_link_names(names):
    with tempfile.TemporaryDirectory() as folder, within(TIME_BOUND), warnings.catch_warnings():
        warnings.simplefilter("ignore")
        try:
            robot = urdf_from_bytes(_urdf(names), "fuzz.urdf", "-", None, None)
            files = render(robot, targets=("c", "casadi", "python", "latex"), functions=("kinematics",))
        except SymdynError as e:
            assert "\n" not in str(e).strip(), str(e)
            return
        _check_files(files, folder)
    poses = [name for name in files if name.endswith("_pose.casadi")]
    assert len(poses) == len(set(poses)) == len(names) + 2  # the arm and the base are frames too
