"""The MATLAB/Octave target (NAME_<function>.m) run in GNU Octave against the C target.

The files of several example robots (free parameters, motors and friction, a prismatic joint,
a product-of-exponentials robot) are written to a temporary folder, and one octave-cli process
for the whole module calls every generated function at random states, printing the outputs
to 17 significant digits. The seven functions must equal the C target's (compiled with the
strict flags, tests/cbuild.py) and every function (other families included) the NumPy
target's, to a relative 1e-12; the same run leaves p out for a robot without parameters and
passes wrong input sizes. Then: the header and the operation counts are those of the other
targets, p may be left out for a robot without parameters, a wrong input size is one error,
and names MATLAB cannot take are refused.
"""

from __future__ import annotations

import importlib
import importlib.util
import re
import shutil
import subprocess
from functools import cache
from pathlib import Path

import numpy as np
import pytest
import sympy as sp
from cbuild import build_dynamics, compilers
from robots import (
    ASYMMETRIC_PARAMS,
    assert_close,
    asymmetric_friction,
    example,
    example_context,
    friction_closed_form,
    friction_states,
    random_params,
    random_state,
)

from symdyn.codegen import c as c_backend
from symdyn.codegen import matlab as matlab_backend
from symdyn.codegen import python as python_backend
from symdyn.codegen import render
from symdyn.codegen.matlab import MatlabPrinter
from symdyn.codegen.render import header_lines
from symdyn.errors import SymdynError
from symdyn.oracle.regressor import regressor
from symdyn.parsers import robot_from_data

rn = importlib.import_module("symdyn.rnea")  # the module (symdyn.rnea is also the function)

ROBOTS = ("roger_arm", "puma560", "planar_prismatic_modified", "mr_ur5", "scara")
STATES = 3
OCTAVE = shutil.which("octave-cli")
pytestmark = pytest.mark.skipif(OCTAVE is None, reason="GNU Octave (octave-cli) is not installed")


def _context(name: str):
    """symdyn.codegen.context of the example robot, derived once per test process (tests/robots.py):
    the MATLAB, C and NumPy files compared here are all rendered from it."""
    return example_context(name)


def _numbers(values) -> str:
    return "[" + " ".join(f"{float(v):.17g}" for v in np.ravel(values)) + "]"


@pytest.fixture(scope="module")
def octave(tmp_path_factory):
    """(robot, function, state) -> the outputs Octave returned (row-major, flattened), and the
    inputs used: one octave-cli run for every robot, function and state."""
    root = tmp_path_factory.mktemp("matlab")
    rng = np.random.default_rng(1414)
    lines, calls = ["1;"], {}
    for name in ROBOTS:
        folder = root / name
        folder.mkdir()
        for file, text in matlab_backend.render(_context(name)).items():
            (folder / file).write_text(text)
        lines.append(f"addpath('{folder}');")
        robot = example(name)
        for s in range(STATES):
            q, qd, qdd = random_state(robot, rng)
            values = {
                "q": q,
                "qd": qd,
                "qdd": qdd,
                "tau": rng.uniform(-5, 5, robot.n),
                "p": random_params(robot, rng),
                "F": rng.normal(size=6),  # the end-effector wrench of tip_wrench_torque (PoE robots)
            }
            for spec in _context(name).functions:
                args = [values[i.name] for i in spec.inputs]
                calls[(name, spec.name, s)] = (spec, values)
                outs = ", ".join(f"o{k}" for k in range(len(spec.results)))
                lines.append(f"[{outs}] = {name}_{spec.name}({', '.join(_numbers(a) for a in args)});")
                for k in range(len(spec.results)):
                    lines.append(
                        f"fprintf('@ {name} {spec.name} {s} {k}'); fprintf(' %.17g', o{k}.'); fprintf('\\n');"
                    )
    lines.append(EXTRA_CALLS)  # p left out, wrong sizes: in the same Octave run
    script = root / "run_all.m"
    script.write_text("\n".join(lines) + "\n")
    done = subprocess.run(
        [OCTAVE, "--no-gui", "--quiet", "--norc", "--no-history", str(script)],
        capture_output=True,
        text=True,
        timeout=300,
        cwd=root,
    )
    assert "error:" not in done.stdout, done.stdout[-2000:] + done.stderr[-2000:]
    results: dict = {}
    for line in done.stdout.splitlines():
        if line.startswith("@ "):
            _, robot, fname, s, k, *nums = line.split()
            results.setdefault((robot, fname, int(s)), {})[int(k)] = np.array([float(x) for x in nums])
    assert len(results) == len(calls), done.stderr[-2000:]
    extra = [line[2:] for line in done.stdout.splitlines() if line.startswith("# ")]
    return root, results, calls, extra


@cache
def _c_library(name: str, folder: str):
    return build_dynamics(c_backend.render(_context(name)), folder, name)


def _numpy_module(name: str, folder: Path):
    files = python_backend.render(_context(name))
    ((file, text),) = files.items()
    path = folder / file
    path.write_text(text)
    spec = importlib.util.spec_from_file_location(f"matlab_cmp_{name}", path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


@pytest.mark.skipif(not compilers(), reason="no C compiler")
@pytest.mark.parametrize("name", ROBOTS)
def test_octave_equals_the_c_and_numpy_targets(octave, name, tmp_path):
    root, results, calls, _ = octave
    lib = _c_library(name, str(tmp_path))
    module = _numpy_module(name, tmp_path)
    for (robot, fname, s), (spec, values) in calls.items():
        if robot != name:
            continue
        got = results[(robot, fname, s)]
        args = [values[i.name] for i in spec.inputs]
        want = getattr(module, fname)(*args)
        want = want if isinstance(want, tuple) else (want,)
        for k, out in enumerate(spec.results):
            assert_close(got[k], np.ravel(want[k]), 1e-12, f"{name} {fname} {out.name} vs NumPy")
        if hasattr(lib, fname):
            assert_close(got[0], np.ravel(getattr(lib, fname)(*args)), 1e-12, f"{name} {fname} vs C")


def test_header_op_counts_and_one_file_per_function():
    ctx = _context("puma560")
    files = render(example("puma560"), targets=("matlab",))
    assert sorted(files) == sorted(f"puma560_{f.name}.m" for f in ctx.functions)
    head = header_lines(ctx)
    for spec in ctx.functions:
        text = files[f"puma560_{spec.name}.m"]
        outs = [r.name for r in spec.results]
        signature = f"{outs[0] if len(outs) == 1 else '[' + ', '.join(outs) + ']'} = puma560_{spec.name}("
        assert text.startswith(f"function {signature}")
        comments = [line[1:].strip() for line in text.splitlines() if line.startswith("%")]
        assert all(line.strip() in comments for line in head)
        assert spec.ops.summary() in text
    assert "p: the 0 free parameters, or [] (or left out): the robot has none" in files["puma560_gravity.m"]


#: Octave statements run after the comparisons: p left out for a robot without parameters, and
#: wrong input sizes; each prints one line starting with "# ".
EXTRA_CALLS = """
g = puma560_gravity(zeros(1, 6)); fprintf('# %d\\n', numel(g));
try
  puma560_gravity([1 2 3]);
catch err
  fprintf('# %s\\n', err.message);
end
try
  roger_arm_gravity([0 0], [1 2]);
catch err
  fprintf('# %s\\n', err.message);
end
"""


def test_p_left_out_and_wrong_sizes(octave):
    *_, extra = octave
    assert extra == [
        "6",
        "puma560_gravity: q must have 6 entries, got 3",
        "roger_arm_gravity: p must have 5 entries, got 2",
    ]


def test_printer_spells_matlab():
    x, y = sp.symbols("x y")
    p = MatlabPrinter({x: "x", y: "y"})
    assert p.doprint(sp.sign(x)) == "sign(x)"
    assert p.doprint(sp.Abs(x) + x**3) == "x*x*x + abs(x)"
    assert p.doprint(x**y) == "x^y"
    assert p.doprint(2 * (x + 1) ** y) == "2.0*(1.0 + x)^y"
    assert p.doprint((x**y) ** sp.Rational(3, 7)) == "(x^y)^0.42857142857142855"
    assert p.doprint(sp.sqrt(x) / y**2) == "sqrt(x)/(y*y)"
    assert p.doprint(-x * sp.cos(y)) == "-x*cos(y)"


@pytest.mark.parametrize(
    "name,precision,message",
    [
        ("a" * 50, "double", "longer than 63"),
        ("arm", "float", "double precision only"),
    ],
)
def test_names_and_precision_matlab_cannot_take(name, precision, message):
    robot = robot_from_data({"name": name, "links": [{"joint": "revolute", "mass": 1, "com": [1, 0, 0]}]})
    with pytest.raises(SymdynError, match=message):
        render(robot, targets=("matlab",), precision=precision)


def test_a_parameter_named_like_a_matlab_word_is_renamed():
    robot = robot_from_data(
        {"name": "arm", "links": [{"joint": "revolute", "mass": "end", "com": ["zeros", 0, 0]}]}
    )
    text = render(robot, targets=("matlab",))["arm_mass_matrix.m"]
    assert re.search(r"^end_ = p\(1\);$", text, re.MULTILINE) and re.search(
        r"^zeros_ = p\(2\);$", text, re.MULTILINE
    )


def test_direction_dependent_friction_in_octave(tmp_path):
    """double(qd > 0) and double(qd < 0) in Octave: friction, inverse and forward dynamics and the
    regressor equal the oracle (friction the hand-written closed form) at rates of both signs and 0."""
    robot = asymmetric_friction()
    for file, text in render(robot, targets=("matlab",)).items():
        (tmp_path / file).write_text(text)
    p = [ASYMMETRIC_PARAMS[str(s)] for s in robot.params]
    states = list(zip(*friction_states(), strict=True))
    calls = {
        "friction": lambda q, qd, qdd, tau: (qd, p),
        "inverse_dynamics": lambda q, qd, qdd, tau: (q, qd, qdd, p),
        "forward_dynamics": lambda q, qd, qdd, tau: (q, qd, tau, p),
        "regressor": lambda q, qd, qdd, tau: (q, qd, qdd, p),
    }
    lines = ["1;", f"addpath('{tmp_path}');"]
    for s, state in enumerate(states):
        for fname, args in calls.items():
            call = f"{robot.name}_{fname}({', '.join(_numbers(a) for a in args(*state))})"
            lines.append(f"o = {call}; fprintf('@ {fname} {s}'); fprintf(' %.17g', o.'); fprintf('\\n');")
    (tmp_path / "run.m").write_text("\n".join(lines) + "\n")
    done = subprocess.run(
        [OCTAVE, "--no-gui", "--quiet", "--norc", "--no-history", str(tmp_path / "run.m")],
        capture_output=True,
        text=True,
        timeout=120,
        cwd=tmp_path,
    )
    got = {}
    for line in done.stdout.splitlines():
        if line.startswith("@ "):
            _, fname, s, *nums = line.split()
            got[(fname, int(s))] = np.array([float(x) for x in nums])
    assert len(got) == len(states) * len(calls), done.stdout[-2000:] + done.stderr[-2000:]
    for s, (q, qd, qdd, tau) in enumerate(states):
        want = {
            "friction": friction_closed_form(qd),
            "inverse_dynamics": rn.rnea(robot, q, qd, qdd, ASYMMETRIC_PARAMS),
            "forward_dynamics": rn.forward_dynamics(robot, q, qd, tau, ASYMMETRIC_PARAMS),
            "regressor": regressor(robot, q, qd, qdd, ASYMMETRIC_PARAMS),
        }
        for fname, w in want.items():
            assert_close(got[(fname, s)], np.ravel(w), 1e-10, f"{fname} at state {s}")
