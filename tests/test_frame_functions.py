"""The generated frame functions (symdyn.codegen.frame_functions: the kinematics and
operational_space groups) in C, NumPy, CasADi, MATLAB/Octave and LaTeX, against the numeric
oracle symdyn.oracle.frames (pose, Jacobians, drift, centre of mass) and, for Lambda and mu + p,
NumPy formulas over the oracle's M (symdyn.rnea.mass_matrix), h = V + G + F (symdyn.rnea at
qdd = 0), J and Jdot qd. One derivation per robot (cached), one Octave run for every robot."""

from __future__ import annotations

import ctypes
import dataclasses
import importlib.util
import re
import shutil
import subprocess
import warnings
from functools import cache
from pathlib import Path

import numpy as np
import pytest
from cbuild import SANITIZE_FLAGS, STRICT_FLAGS, compile_shared, compilers, header_macros, write_files
from robots import example, random_state, raw_example, y_robot

import symdyn
from symdyn.algorithms.operational_space import TASK_AXES
from symdyn.codegen import c as c_target
from symdyn.codegen import casadi as casadi_target
from symdyn.codegen import context
from symdyn.codegen import latex as latex_target
from symdyn.codegen import matlab as matlab_target
from symdyn.codegen import python as numpy_target
from symdyn.codegen.frame_functions import choose_frames, identifier
from symdyn.errors import SymdynError
from symdyn.model.frames import Frame
from symdyn.oracle.frames import center_of_mass, frame_state
from symdyn.regenerate import example_robot_data_folder
from symdyn.rnea import mass_matrix, rnea
from symdyn.spatial.transform import Transform

TOL = 1e-9
GROUPS = ("kinematics", "operational_space")
#: robot -> (frames given, task axes): the Panda (a URDF with merged fixed links), the Y-tree
#: (default frames: its leaves) and a product-of-exponentials robot (its end effector)
CASES = {
    "panda": (["panda_hand", "panda_link8"], None),
    "ytree": (None, "x,y"),
    "mr_ur5": (None, None),
}
STATES = 2
OCTAVE = shutil.which("octave-cli")


@cache
def robot(name: str):
    if name == "ytree":
        return y_robot()
    if name == "mr_ur5":
        return example(name)
    folder = example_robot_data_folder()
    if folder is None:
        pytest.skip("example-robot-data is not installed")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return symdyn.load_urdf(folder / "panda_description/urdf/panda.urdf")


@cache
def ctx(name: str):
    frames, axes = CASES[name]
    return context(robot(name), functions=GROUPS, frames=frames, task_axes=axes)


@cache
def files(name: str, target) -> dict:
    return target.render(ctx(name))


@cache
def states(name: str) -> list:
    rng = np.random.default_rng(22)
    r = robot(name)
    return [random_state(r, rng)[:2] for _ in range(STATES)]


@cache
def expected(name: str, s: int) -> dict[str, np.ndarray]:
    """Every generated function's outputs by the oracle at state s."""
    r, c = robot(name), ctx(name)
    q, qd = states(name)[s]
    rows = [TASK_AXES.index(a) for a in (CASES[name][1] or ",".join(TASK_AXES)).split(",")]
    M = mass_matrix(r, q)
    h = rnea(r, q, qd, np.zeros(r.n))
    out = {}
    for frame, ident, _ in c.frames:
        st = frame_state(r, frame, q, qd)
        J, drift = st.jacobian[rows], st.drift[rows]
        L = np.linalg.inv(J @ np.linalg.solve(M, J.T))
        out |= {
            f"{ident}_pose": st.pose,
            f"{ident}_jacobian": st.jacobian,
            f"{ident}_jacobian_local": st.jacobian_local,
            f"{ident}_jacobian_dot_qd": st.drift,
            f"{ident}_operational_space_inertia": L,
            f"{ident}_operational_space_bias": L @ (J @ np.linalg.solve(M, h) - drift),
        }
    com, Jc, a = center_of_mass(r, q, qd)
    return out | {"com": com, "com_jacobian": Jc, "com_jacobian_dot_qd": a}


def _inputs(name: str, s: int) -> dict[str, np.ndarray]:
    q, qd = states(name)[s]
    return {"q": q, "qd": qd, "p": np.zeros(0)}


def _check(name: str, fname: str, s: int, got, where: str) -> None:
    want = expected(name, s)[fname]
    scale = max(1.0, float(np.abs(want).max()))
    np.testing.assert_allclose(
        np.reshape(got, want.shape), want, atol=TOL * scale, err_msg=f"{where}: {fname}"
    )


def test_every_function_is_generated_for_the_chosen_frames():
    for name in CASES:
        c = ctx(name)
        r = robot(name)
        frames = CASES[name][0]
        if frames is None:  # the default: the leaf links, then Robot.frames
            children = {p for p in r.parents}
            frames = [lk.name for i, lk in enumerate(r.links) if i not in children] + [
                f.name for f in r.frames
            ]
        assert [f for f, _, _ in c.frames] == frames
        assert sorted(f.name for f in c.functions) == sorted(expected(name, 0))


@pytest.mark.parametrize("name", CASES)
def test_numpy_and_casadi_agree_with_the_oracle(name, tmp_path):
    ((file, text),) = files(name, numpy_target).items()
    (tmp_path / file).write_text(text)
    spec = importlib.util.spec_from_file_location(f"frames_{name}", tmp_path / file)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    casadi_files = files(name, casadi_target)
    ca = pytest.importorskip("casadi")
    text = casadi_files[f"{ctx(name).name}_casadi.py"]
    namespace: dict = {}
    exec(compile(text, "casadi_module", "exec"), namespace)
    built = namespace["functions"]()
    for s in range(STATES):
        values = _inputs(name, s)
        for f in ctx(name).functions:
            args = [values[i.name] for i in f.inputs if i.name != "p"]
            _check(name, f.name, s, getattr(module, f.name)(*args), "numpy")
            fn = built[f.name]
            got = fn.call({fn.name_in(i): values[fn.name_in(i)] for i in range(fn.n_in())})[fn.name_out(0)]
            _check(name, f.name, s, np.asarray(ca.DM(got).full()), "casadi")


def _c_call(lib, c_name: str, spec, values: dict, real=ctypes.c_double) -> np.ndarray:
    ptr = ctypes.POINTER(real)
    args = [np.ascontiguousarray(values[i.name], dtype=np.float64) for i in spec.inputs]
    ((result),) = spec.results
    out = np.full(result.size, np.nan)
    f = getattr(lib, c_name)
    f.argtypes = [ptr] * (len(args) + 1)
    f.restype = None
    f(*[a.ctypes.data_as(ptr) for a in args], out.ctypes.data_as(ptr))
    return out


@pytest.mark.skipif(not compilers(), reason="no C compiler")
@pytest.mark.parametrize("name", CASES)
def test_c_compiles_with_werror_and_agrees_with_the_oracle(name, tmp_path):
    c = ctx(name)
    rendered = files(name, c_target)
    header = rendered[f"{c.name}_dynamics.h"]
    macros = header_macros(header)
    assert macros[f"{c.name}_NFRAMES"] == str(len(c.frames))
    for frame, ident, _ in c.frames:  # the table: name, identifier, link
        assert any(
            frame in line and ident in line for line in header.splitlines() if line.startswith(" *   ")
        )
    paths = write_files(rendered, tmp_path)
    lib = ctypes.CDLL(str(compile_shared([p for p in paths if p.suffix == ".c"], tmp_path / "lib.so")))
    for s in range(STATES):
        for f in c.functions:
            _check(name, f.name, s, _c_call(lib, f"{c.name}_{f.name}", f, _inputs(name, s)), "C")


@pytest.mark.skipif(not compilers(), reason="no C compiler")
def test_c_under_address_and_undefined_behaviour_sanitizers(tmp_path):
    c = ctx("ytree")
    paths = write_files(files("ytree", c_target), tmp_path)
    main = tmp_path / "main.c"
    calls = []
    for f in c.functions:
        args = ", ".join(f"{i.name}_in" for i in f.inputs)
        size = f.results[0].size
        calls.append(f"{{ double out[{size}]; {c.name}_{f.name}({args}, out); s += out[{size - 1}]; }}")
    n = robot("ytree").n
    main.write_text(
        f'#include <stdio.h>\n#include "{c.name}_dynamics.h"\n'
        "int main(void) {\n"
        f"  double q_in[{n}], qd_in[{n}], p_in[1] = {{0.0}}, s = 0.0;\n"
        f"  for (int i = 0; i < {n}; ++i) {{ q_in[i] = 0.1 * (i + 1); qd_in[i] = 0.2 - 0.1 * i; }}\n"
        + "\n".join("  " + call for call in calls)
        + '\n  printf("%g\\n", s);\n  return 0;\n}\n'
    )
    sources = [p for p in paths if p.suffix == ".c"] + [main]
    from cbuild import compile_program

    exe = compile_program(sources, tmp_path / "run", flags=(*STRICT_FLAGS, *SANITIZE_FLAGS))
    done = subprocess.run([str(exe)], capture_output=True, text=True, timeout=60)
    assert done.returncode == 0 and np.isfinite(float(done.stdout)), done.stderr[-2000:]


def _numbers(values) -> str:
    return "[" + " ".join(f"{float(v):.17g}" for v in np.ravel(values)) + "]"


@pytest.mark.skipif(OCTAVE is None, reason="GNU Octave (octave-cli) is not installed")
def test_matlab_in_octave_agrees_with_the_oracle(tmp_path):
    lines, calls = ["1;"], []
    for name in CASES:
        folder = tmp_path / name
        write_files(files(name, matlab_target), folder)
        lines.append(f"addpath('{folder}');")
        for s in range(STATES):
            values = _inputs(name, s)
            for f in ctx(name).functions:
                args = ", ".join(_numbers(values[i.name]) for i in f.inputs)
                lines.append(f"o = {ctx(name).name}_{f.name}({args});")
                lines.append(f"fprintf('@ {name} {f.name} {s}'); fprintf(' %.17g', o.'); fprintf('\\n');")
                calls.append((name, f.name, s))
    (tmp_path / "run_all.m").write_text("\n".join(lines) + "\n")
    done = subprocess.run(
        [OCTAVE, "--no-gui", "--quiet", "--norc", "--no-history", "run_all.m"],
        capture_output=True,
        text=True,
        timeout=300,
        cwd=tmp_path,
    )
    results = {}
    for line in done.stdout.splitlines():
        if line.startswith("@ "):
            _, name, fname, s, *nums = line.split()
            results[(name, fname, int(s))] = np.array([float(x) for x in nums])
    assert sorted(results) == sorted(calls), done.stdout[-2000:] + done.stderr[-2000:]
    for (name, fname, s), got in results.items():
        _check(name, fname, s, got, "octave")


def test_latex_lists_every_frame_function():
    c = ctx("ytree")
    ((_, text),) = files("ytree", latex_target).items()
    assert "\\section*{Frames}" in text
    for f in c.functions:
        assert f"\\paragraph{{\\texttt{{{f.name.replace('_', chr(92) + '_')}}}}}" in text
    assert text.count("\\begin{align*}") >= len(c.functions)


# --------------------------------------------------------------------------- compile


def test_compile_exposes_the_frame_functions():
    r = example("mr_ur5")
    fast = symdyn.compile(r)
    q, qd = states("mr_ur5")[0]
    st = frame_state(r, "end_effector", q, qd)
    np.testing.assert_allclose(fast.frame_pose("end_effector", q), st.pose, atol=TOL)
    np.testing.assert_allclose(fast.frame_jacobian("end_effector", q), st.jacobian, atol=TOL)
    np.testing.assert_allclose(fast.frame_jacobian("end_effector", q, "local"), st.jacobian_local, atol=TOL)
    np.testing.assert_allclose(fast.frame_jacobian_dot_qd("end_effector", q, qd), st.drift, atol=TOL)
    com, Jc, a = center_of_mass(r, q, qd)
    np.testing.assert_allclose(fast.com(q), com, atol=TOL)
    np.testing.assert_allclose(fast.com_jacobian(q), Jc, atol=TOL)
    np.testing.assert_allclose(fast.com_jacobian_dot_qd(q, qd), a, atol=TOL)
    M, h = mass_matrix(r, q), rnea(r, q, qd, np.zeros(r.n))
    J, drift = st.jacobian[:3], st.drift[:3]
    L = np.linalg.inv(J @ np.linalg.solve(M, J.T))
    np.testing.assert_allclose(fast.operational_space_inertia("end_effector", q, axes="x,y,z"), L, rtol=1e-9)
    got = fast.operational_space_bias("end_effector", q, qd, axes="x,y,z")
    np.testing.assert_allclose(got, L @ (J @ np.linalg.solve(M, h) - drift), rtol=1e-8, atol=1e-9)
    with pytest.raises(SymdynError, match="unknown frame 'end_efector'.*did you mean 'end_effector'"):
        fast.frame_pose("end_efector", q)
    with pytest.raises(SymdynError, match="unknown axis w"):
        fast.operational_space_inertia("end_effector", q, axes="x,w")


# --------------------------------------------------------------------------- bad input


def test_identifiers_are_valid_everywhere_and_distinct():
    """Every target's identifier from a frame name; two names meeting in one identifier (or a
    name becoming `com`) keep distinct ones, the changed name taking a hash of itself."""
    assert identifier("tool-0.tip") == "tool_0_tip"
    assert identifier("3rd") == "frame_3rd"
    data = raw_example("roger_arm") | {
        "frames": [
            {"name": "tip.x", "link": "forearm", "xyz": [0.1, 0, 0]},
            {"name": "tip-x", "link": "forearm", "xyz": [0.2, 0, 0]},
            {"name": "tip_x", "link": "forearm", "xyz": [0.3, 0, 0]},
            {"name": "com", "link": "forearm", "xyz": [0.4, 0, 0]},
        ]
    }
    r = symdyn.parsers.robot_from_data(data)
    idents = dict((name, ident) for name, ident, _ in choose_frames(r).frames)
    assert idents["tip_x"] == "tip_x" and idents["tip.x"] != idents["tip-x"]
    assert {idents["tip.x"][:6], idents["tip-x"][:6], idents["com"][:4]} == {"tip_x_", "com_"}
    assert len({idents["tip.x"], idents["tip-x"], idents["com"]}) == 3
    assert [f[1] for f in choose_frames(r, "forearm,tip.x").frames] == ["forearm", "tip_x"]
    assert choose_frames(r, "tip.x,tip-x").frames == choose_frames(r, "tip.x,tip-x").frames


def _cli(*args: str):
    return subprocess.run(
        [str(Path(__import__("sys").executable).parent / "symdyn"), *args],
        capture_output=True,
        text=True,
        timeout=120,
    )


@pytest.mark.parametrize(
    ("extra", "message"),
    [
        (["--frames", "forarm"], "unknown frame 'forarm' (did you mean 'forearm'?)"),
        (["--task-axes", "x,q"], "--task-axes: unknown axis q"),
    ],
)
def test_bad_frames_and_task_axes_write_nothing(tmp_path, extra, message):
    out = tmp_path / "out"
    robot_file = Path(__file__).parents[1] / "examples" / "roger_arm.yaml"
    done = _cli("generate", str(robot_file), "--out", str(out), "--functions", *GROUPS, *extra)
    assert done.returncode == 1 and message in done.stderr, done.stderr
    assert len(done.stderr.strip().splitlines()) == 1 and "Traceback" not in done.stderr
    assert not out.exists()


def test_frames_without_a_frame_group_is_an_error():
    with pytest.raises(SymdynError, match="name them in --functions"):
        context(example("roger_arm"), functions=("dynamics",), frames="forearm")


@pytest.mark.skipif(not compilers(), reason="no C compiler")
def test_a_frame_name_reaches_generated_code_only_sanitised(tmp_path):
    """A frame named with comment ends, quotes, a backslash and a newline: C compiles under -Werror,
    the NumPy module imports, and the name appears in no file but as its `?` spelling."""
    name = 'tip*/ "1%\\\nx'  # robot files refuse such names; a Robot built in Python may have them
    base = example("roger_arm")
    r = dataclasses.replace(base, frames=(Frame(name, 1, base.links[1].frame),))
    rendered = symdyn.codegen.render(
        r, targets=("c", "python", "matlab", "latex"), functions=GROUPS, frames=[name], task_axes="x,y"
    )
    assert "def tip_1_x_pose(" in rendered["roger_arm_numpy.py"]
    for file, text in rendered.items():
        assert "*/ " not in text.replace("/* ", "").replace(" */", "") and name not in text, file
    paths = write_files(rendered, tmp_path)
    compile_shared([p for p in paths if p.suffix == ".c"], tmp_path / "lib.so")
    spec = importlib.util.spec_from_file_location("odd_frame", tmp_path / "roger_arm_numpy.py")
    spec.loader.exec_module(importlib.util.module_from_spec(spec))


#: the names of issue 34 (item 7) that CasADi refused, a name in another script, one of 250
#: characters, and two names meeting in one identifier
ODD_NAMES = ["tool_", "my__tool", "1st", "cam.-x", "Greifer-ü", "工具", "x" * 250, "tip.x", "tip-x"]


@pytest.mark.skipif(not compilers(), reason="no C compiler")
def test_odd_frame_names_work_in_every_target(tmp_path):
    """Each name through C (compiled, -Werror), NumPy (imported), CasADi (functions built),
    MATLAB (file names are function names) and LaTeX; the poses of every frame equal the oracle's,
    and every file name fits the file system with room to spare."""
    base = example("roger_arm_values")
    frames = tuple(
        Frame(name, 1, Transform.from_translation([0.1 * k, 0.02, 0])) for k, name in enumerate(ODD_NAMES)
    )
    r = dataclasses.replace(base, frames=frames)
    c = context(r, functions=("kinematics",), frames=ODD_NAMES)
    idents = [ident for _, ident, _ in c.frames]
    assert len(set(idents)) == len(ODD_NAMES) and idents[:5] == [
        "tool",
        "my_tool",
        "frame_1st",
        "cam_x",
        "Greifer_u",
    ]
    rendered = {
        **c_target.render(c),
        **numpy_target.render(c),
        **casadi_target.render(c),
        **latex_target.render(c),
    }
    assert all(len(name.encode()) <= 200 for name in rendered)
    header = rendered["roger_arm_values_dynamics.h"]
    assert "Frame 'tool_' is tool in function names." in header
    paths = write_files(rendered, tmp_path)
    lib = ctypes.CDLL(str(compile_shared([p for p in paths if p.suffix == ".c"], tmp_path / "lib.so")))
    spec = importlib.util.spec_from_file_location("odd_names", tmp_path / "roger_arm_values_numpy.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    namespace: dict = {}
    exec(compile(rendered["roger_arm_values_casadi.py"], "casadi_module", "exec"), namespace)
    built = namespace["functions"]() if importlib.util.find_spec("casadi") else {}
    q = np.array([0.3, -0.7])
    for name, ident in zip(ODD_NAMES, idents, strict=True):
        want = frame_state(r, name, q).pose
        f = next(f for f in c.functions if f.name == f"{ident}_pose")
        got = _c_call(lib, f"roger_arm_values_{ident}_pose", f, {"q": q, "p": np.zeros(0)})
        np.testing.assert_allclose(got.reshape(4, 4), want, atol=1e-12, err_msg=name)
        np.testing.assert_allclose(getattr(module, f"{ident}_pose")(q), want, atol=1e-12, err_msg=name)
        if built:
            np.testing.assert_allclose(
                np.asarray(built[f"{ident}_pose"](q, [])), want, atol=1e-12, err_msg=name
            )
    with pytest.raises(SymdynError, match="longer than 63 characters.*shorten the robot's name or frame"):
        matlab_target.render(c)
    short = context(r, functions=("kinematics",), frames=ODD_NAMES[:6])
    assert all(
        re.fullmatch(r"[A-Za-z]\w{0,62}\.m", n) for n in matlab_target.render(short) if n.endswith(".m")
    )
