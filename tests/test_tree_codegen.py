"""Generated code for kinematic trees and mimic joints, in every target, judged by the numeric oracle.

Two real robots of example-robot-data, loaded whole: the Solo-12 legs on a fixed base (4 legs x 3
joints: a tree whose M is block-diagonal) and the Franka Panda with its gripper (7 arm joints, one
finger, the second finger a mimic joint off the chain: 8 coordinates, 9 bodies). Each generated
function (C compiled with -Werror, once under the sanitizers; the NumPy module for one state and a
batch; the CasADi functions; the LaTeX fragment compiled by pdflatex) is compared with
`symdyn.rnea`, which computes on the bodies and projects with S^T independently of the
symbolic derivation.
"""

from __future__ import annotations

import importlib
import importlib.util
import re
import shutil
import subprocess
import sys
import warnings
from pathlib import Path

import numpy as np
import pytest
from cbuild import SANITIZE_FLAGS, STRICT_FLAGS, build_dynamics, compile_program, compilers, write_files

import symdyn
from symdyn.codegen import render
from symdyn.regenerate import (
    EXAMPLES,
    TOOLCHAIN_FILE,
    example_robot,
    example_robot_data_folder,
    read_toolchain,
    versions,
)

rn = importlib.import_module("symdyn.rnea")  # the module (symdyn.rnea is also the function)

FILES = {
    "solo12": "solo_description/robots/solo12.urdf",
    "panda_gripper": "panda_description/urdf/panda.urdf",
}
STATES = 3
TOL = 1e-9
ROOT = Path(__file__).resolve().parents[1]
#: the files of the targets below, of those generated/ holds
TARGET_FILES = re.compile(r"(_dynamics\.(c|h|tex)|_casadi\.py|\.casadi|_numpy\.py|CMakeLists\.txt)\Z")


def _robot(name: str):
    folder = example_robot_data_folder()
    if folder is None:
        pytest.skip("example-robot-data is not installed")
    path = folder / FILES[name]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        robot = symdyn.load_urdf(path)
    return robot


def _committed(name: str) -> dict[str, str | bytes] | None:
    """generated/NAME's files of the targets below, when generated/ holds NAME (the Solo-12 legs:
    the same URDF, named solo12, every group but the named-only ones, as render's default) and
    was written with this toolchain, so that tests/test_generated.py finds them byte-identical
    to a fresh render; else None (then the robot is rendered here)."""
    stamp = ROOT / "generated" / TOOLCHAIN_FILE
    if name not in EXAMPLES or not stamp.is_file() or read_toolchain(stamp.read_text()) != versions():
        return None
    return {
        p.name: p.read_bytes() if p.suffix == ".casadi" else p.read_text(encoding="utf-8")
        for p in sorted((ROOT / "generated" / name).iterdir())
        if TARGET_FILES.search(p.name)
    }


@pytest.fixture(scope="module", params=sorted(FILES))
def generated(request, tmp_path_factory):
    pytest.importorskip("casadi")
    out = tmp_path_factory.mktemp(request.param)
    files = _committed(request.param)
    if files is not None:
        robot = example_robot(ROOT, request.param)
    else:
        robot = _robot(request.param)
        files = render(robot, targets=("c", "casadi", "python", "latex"))
    write_files(files, out)
    return robot, files, out


def _states(robot, seed: int):
    rng = np.random.default_rng(seed)
    for _ in range(STATES):
        yield tuple(rng.uniform(-1, 1, robot.n) for _ in range(4))


def _expected(robot, q, qd, qdd, tau) -> dict[str, np.ndarray]:
    V = rn.bias_torque(robot, q, qd)
    return {
        "inverse_dynamics": rn.rnea(robot, q, qd, qdd),
        "mass_matrix": rn.mass_matrix(robot, q),
        "coriolis": V,
        "gravity": rn.gravity_torque(robot, q),
        "friction": rn.friction_torque(robot, qd),
        "forward_dynamics": rn.forward_dynamics(robot, q, qd, tau),
    }


def _close(a, b) -> None:
    a, b = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
    assert a.shape == b.shape
    assert np.max(np.abs(a - b)) <= TOL * max(1.0, float(np.max(np.abs(b)))), np.max(np.abs(a - b))


def test_the_robots_are_a_tree_and_a_mimic_robot(generated):
    robot = generated[0]
    if robot.name in ("solo", "solo12"):  # rendered here, or generated/solo12's
        assert (robot.n, robot.nb) == (12, 12) and robot.parents.count(-1) == 4
    else:
        assert (robot.n, robot.nb) == (8, 9) and sum(link.mimic is not None for link in robot.links) == 1


@pytest.mark.skipif(not compilers(), reason="no C compiler")
def test_c(generated, tmp_path):
    robot, files, _ = generated
    lib = build_dynamics(files, tmp_path, robot.name)
    assert lib.n == robot.n
    for q, qd, qdd, tau in _states(robot, 1):
        want = _expected(robot, q, qd, qdd, tau)
        _close(lib.inverse_dynamics(q, qd, qdd), want["inverse_dynamics"])
        _close(lib.mass_matrix(q), want["mass_matrix"])
        _close(lib.coriolis(q, qd), want["coriolis"])
        _close(lib.coriolis_matrix(q, qd) @ qd, want["coriolis"])
        _close(lib.gravity(q), want["gravity"])
        _close(lib.friction(qd), want["friction"])
        _close(lib.forward_dynamics(q, qd, tau), want["forward_dynamics"])


@pytest.mark.skipif("gcc" not in compilers(), reason="no gcc")
def test_c_under_the_sanitizers(generated, tmp_path):
    """A driver calls every function; ASan/UBSan abort on any out-of-bounds access or UB."""
    robot, files, out = generated
    name = robot.name
    n = robot.n
    driver = tmp_path / "driver.c"
    driver.write_text(
        f'#include "{name}_dynamics.h"\n#include <stdio.h>\n'
        "int main(void) {\n"
        f"    double q[{n}], qd[{n}], qdd[{n}], tau[{n}], out[{n}], M[{n * n}];\n"
        f"    for (int i = 0; i < {n}; ++i) {{ q[i] = 0.1 * i; qd[i] = 0.2 - 0.05 * i; qdd[i] = 0.3; }}\n"
        f"    {name}_inverse_dynamics(q, qd, qdd, NULL, tau);\n"
        f"    {name}_mass_matrix(q, NULL, M);\n"
        f"    {name}_coriolis_matrix(q, qd, NULL, M);\n"
        f"    {name}_coriolis(q, qd, NULL, out);\n"
        f"    {name}_gravity(q, NULL, out);\n"
        f"    {name}_friction(qd, NULL, out);\n"
        f"    {name}_forward_dynamics(q, qd, tau, NULL, out);\n"
        '    printf("%.17g\\n", out[0]);\n'
        "    return 0;\n}\n"
    )
    exe = compile_program(
        [driver, out / f"{name}_dynamics.c"],
        tmp_path / "driver",
        "gcc",
        flags=(*STRICT_FLAGS, *SANITIZE_FLAGS, f"-I{out}"),
    )
    run = subprocess.run([str(exe)], capture_output=True, text=True, timeout=120, cwd=out)
    assert run.returncode == 0, run.stderr
    assert abs(float(run.stdout) - 0.3) < 1e-9  # forward dynamics of inverse dynamics gives qdd back


def _module(path, label: str):
    spec = importlib.util.spec_from_file_location(f"_symdyn_tree_{label}", path)
    module = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = module
    spec.loader.exec_module(module)
    return module


def test_numpy_one_state_and_a_batch(generated):
    robot, _, out = generated
    mod = _module(out / f"{robot.name}_numpy.py", f"np_{robot.name}")
    states = list(_states(robot, 2))
    batch = [np.array(x) for x in zip(*states, strict=True)]
    got = mod.inverse_dynamics(batch[0], batch[1], batch[2], None)
    for k, (q, qd, qdd, tau) in enumerate(states):
        want = _expected(robot, q, qd, qdd, tau)
        _close(mod.inverse_dynamics(q, qd, qdd, None), want["inverse_dynamics"])
        _close(got[k], want["inverse_dynamics"])
        _close(mod.mass_matrix(q, None), want["mass_matrix"])
        _close(mod.forward_dynamics(q, qd, tau, None), want["forward_dynamics"])


def test_casadi(generated):
    robot, _, out = generated
    functions = _module(out / f"{robot.name}_casadi.py", f"ca_{robot.name}").functions()
    for q, qd, qdd, tau in _states(robot, 3):
        want = _expected(robot, q, qd, qdd, tau)
        p = np.zeros(0)
        _close(np.asarray(functions["inverse_dynamics"](q, qd, qdd, p)).ravel(), want["inverse_dynamics"])
        _close(np.asarray(functions["mass_matrix"](q, p)), want["mass_matrix"])
        _close(np.asarray(functions["gravity"](q, p)).ravel(), want["gravity"])
        _close(np.asarray(functions["forward_dynamics"](q, qd, tau, p)).ravel(), want["forward_dynamics"])


@pytest.mark.skipif(shutil.which("pdflatex") is None, reason="no pdflatex")
def test_latex_compiles(generated, tmp_path):
    robot, files, _ = generated
    (tmp_path / "fragment.tex").write_text(files[f"{robot.name}_dynamics.tex"])
    (tmp_path / "doc.tex").write_text(
        "\\documentclass{article}\n\\usepackage{amsmath}\n\\begin{document}\n"
        "\\input{fragment.tex}\n\\end{document}\n"
    )
    proc = subprocess.run(
        ["pdflatex", "-interaction=nonstopmode", "-halt-on-error", "doc.tex"],
        cwd=tmp_path,
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert proc.returncode == 0, proc.stdout[-3000:]
    assert "Undefined control sequence" not in proc.stdout
