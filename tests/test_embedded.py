"""The generated C on a microcontroller: cross-compiled for ARM Cortex-M, run under QEMU.

The seven functions of the PUMA 560, the Panda and Solo-12 on its floating base, in float and
double, compiled by arm-none-eabi-gcc for the Cortex-M4F (single-precision FPU) and the
Cortex-M7 (double-precision FPU) at -Os and -O2 with the embedded strict flags
(tests/embedded.WARNINGS, -Werror); a float object calls no double-precision helper of libgcc
(__aeabi_d*) and no double function of libm. A harness (tests/embedded.py) runs every function
at 100 states under QEMU (mps2-an386, mps2-an500) and its outputs are compared with the host's
double results from the numeric oracle symdyn.rnea (C qd with the oracle's V).

Tolerances. Norm-wise, relative to the largest entry of the oracle's output (a matrix's or
vector's), with u the unit roundoff of the precision (2^-24 for float, 2^-53 for double):
every function but forward dynamics within 2^8 u (hundreds of roundings along the longest
chains of the generated code, each of the size of the largest term, rarely aligned), forward
dynamics within 2^8 u times the condition number of M at that state (the solve of M qdd = b
amplifies the errors of M and b by up to cond(M)).

What runs (about 40 s of CPU on one core, cold cache; the budget of the file is 60 s): the
PUMA's and the Panda's whole matrix (2 cores x -Os/-O2 x float/double: 16 builds of 0.2 to
1.5 s each), QEMU on the M4F at -Os in float and double for each robot (the double through
the M4F's software double-precision calls, the slowest path), and the M7 at -O2 in double (its
double-precision FPU). Solo-12's file is 430 KB of C: gcc's pre-RA instruction scheduler and
register allocator take 30 to 64 s per build at -O2 and 17 s at -Os in double on the M4F, so
by default it is built at -Os in float for the M4F and in double for the M7 (5 and 8 s) and
both are run under QEMU; SYMDYN_EMBEDDED_FULL=1 builds its other six cells too.
"""

from __future__ import annotations

import dataclasses
import os
import re
import shutil
import subprocess
import warnings
from functools import cache
from pathlib import Path

import numpy as np
import pytest
from cbuild import STRICT_FLAGS, write_files
from embedded import (
    CPUS,
    available,
    cross_compile,
    host_results,
    link_bare,
    link_harness,
    random_states,
    relative_errors,
    run_harness,
    undefined_symbols,
)
from robots import derived
from timebound import refused

import symdyn
from symdyn.codegen import c as c_backend
from symdyn.codegen import context
from symdyn.codegen.c.config import MATH_CALLS
from symdyn.codegen.functions import build_functions
from symdyn.codegen.render import RenderContext
from symdyn.regenerate import example_robot_data_folder
from symdyn.rnea import mass_matrix

pytestmark = pytest.mark.skipif(not available(), reason="arm-none-eabi-gcc and qemu-system-arm are needed")

ROBOTS = ("puma560", "panda", "solo12")
PRECISIONS = ("float", "double")
OPTS = ("-Os", "-O2")
STATES = 100
UNIT_ROUNDOFF = {"float": 2.0**-24, "double": 2.0**-53}
#: the norm-wise error bound in units of the unit roundoff (see the module's docstring)
ROUNDINGS = 2.0**8
FULL = os.environ.get("SYMDYN_EMBEDDED_FULL", "") not in ("", "0")
#: the cells run under QEMU: (robot, core, -O level, precision)
QEMU_CELLS = [(r, "m4f", "-Os", p) for r in ("puma560", "panda") for p in PRECISIONS]
QEMU_CELLS += [(r, "m7", "-O2", "double") for r in ("puma560", "panda")]
QEMU_CELLS += [("solo12", "m4f", "-Os", "float"), ("solo12", "m7", "-Os", "double")]
COMPILE_CELLS = [
    (r, cpu, opt, p)
    for r in ROBOTS
    for cpu in CPUS
    for opt in OPTS
    for p in PRECISIONS
    if (r, cpu, opt, p) not in QEMU_CELLS and (r != "solo12" or FULL)
]

#: libm's double-precision functions of the generated code, which a float object must not call
DOUBLE_LIBM = set(MATH_CALLS.values()) | {"sqrt", "pow", "exp", "log", "atan2"}


def _robot_file(name: str) -> symdyn.Robot:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return symdyn.load_robot(Path(__file__).resolve().parents[1] / "examples" / f"{name}.yaml")


@cache
def _robot(name: str) -> symdyn.Robot:
    if name == "solo12":
        folder = example_robot_data_folder()
        if folder is None:
            pytest.skip("example-robot-data is not installed")
        return symdyn.load_urdf(folder / "solo_description/robots/solo12.urdf", floating=True)
    return _robot_file(name)


@pytest.fixture(scope="module")
def rendered(tmp_path_factory):
    """(robot, precision, freestanding) -> the folder of its C target's files (the seven
    functions only), each robot derived once."""
    contexts: dict[str, RenderContext] = {}
    folders: dict[tuple[str, str, bool], Path] = {}

    def get(robot: str, precision: str, freestanding: bool = False) -> Path:
        if robot not in contexts:
            if robot == "solo12":
                contexts[robot] = context(_robot(robot), functions=("dynamics",))
            else:
                dyn = derived(robot, "newton-euler")  # shared with the other test files
                contexts[robot] = RenderContext(dyn.robot, dyn, tuple(build_functions(dyn, ("dynamics",))))
        key = (robot, precision, freestanding)
        if key not in folders:
            ctx = dataclasses.replace(contexts[robot], precision=precision, freestanding=freestanding)
            folders[key] = tmp_path_factory.mktemp(f"{robot}-{precision}{'-free' * freestanding}")
            write_files(c_backend.render(ctx), folders[key])
        return folders[key]

    return get


@pytest.fixture(scope="module")
def compiled(tmp_path_factory):
    """(folder of `rendered`, core, -O level) -> its objects (cross_compile), each compiled once
    per module: the QEMU cells, the freestanding checks and the instruction count share the
    Panda's and the PUMA's -Os builds for the M4F. The objects are only read (linked, nm)."""
    objects: dict[tuple[Path, str, str], list[Path]] = {}

    def get(folder: Path, cpu: str, opt: str) -> list[Path]:
        key = (folder, cpu, opt)
        if key not in objects:
            objects[key] = cross_compile(folder, cpu, opt, tmp_path_factory.mktemp(f"{folder.name}-{cpu}"))
        return objects[key]

    return get


def _check_object(objects, precision: str) -> None:
    """A float object calls no double helper of libgcc and no double function of libm."""
    undefined = undefined_symbols(objects)
    if precision == "float":
        assert not {s for s in undefined if s.startswith("__aeabi_d")}, undefined
        assert not undefined & DOUBLE_LIBM, undefined


@pytest.mark.parametrize("robot,cpu,opt,precision", COMPILE_CELLS)
def test_cross_compiles(rendered, tmp_path, robot, cpu, opt, precision):
    """Warning-free with the embedded strict flags; no double arithmetic in a float object."""
    objects = cross_compile(rendered(robot, precision), cpu, opt, tmp_path)
    _check_object(objects, precision)


def _compare(objects: list[Path], folder: Path, build: Path, robot: str, cpu: str, opt: str, precision: str):
    """Every function of the C in `folder` (its `objects`) at 100 states on the emulated core,
    within the stated tolerances of the host's double results (see the module's docstring)."""
    r = _robot(robot)
    _check_object(objects, precision)
    name = next(folder.glob("*_dynamics.h")).name.removesuffix("_dynamics.h")
    elf = link_harness(folder, objects, cpu, name, precision, r.nq, r.nv, build)
    states = random_states(r, STATES)
    got = run_harness(elf, cpu, states, precision, r.nv)
    want = host_results(r, states)
    bound = ROUNDINGS * UNIT_ROUNDOFF[precision]
    for f, error in relative_errors(r, states, got, want).items():
        allowed = bound * (want["cond"] if f == "forward_dynamics" else 1.0)
        worst = int(np.argmax(error / allowed))
        assert np.all(error <= allowed), (
            f"{robot} {cpu} {opt} {precision} {f}: relative error {error[worst]:.3g} at state {worst} "
            f"(allowed {np.broadcast_to(allowed, error.shape)[worst]:.3g})"
        )


@pytest.mark.parametrize("robot,cpu,opt,precision", QEMU_CELLS)
def test_runs_under_qemu(rendered, compiled, tmp_path, robot, cpu, opt, precision):
    """Every function at 100 states on the emulated core, within the stated tolerances of the
    host's double results (see the module's docstring)."""
    folder = rendered(robot, precision)
    _compare(compiled(folder, cpu, opt), folder, tmp_path, robot, cpu, opt, precision)


# --------------------------------------------------------------------------- --freestanding


@pytest.mark.parametrize("precision", PRECISIONS)
def test_freestanding_runs_under_qemu(rendered, compiled, tmp_path, precision):
    """--freestanding: no header of the C library in the files, and the same tolerances on the
    M4F (the float file with symdyn's own sinf and cosf, the double one with its own sin and cos)."""
    folder = rendered("puma560", precision, True)
    for path in folder.iterdir():
        text = path.read_text()
        assert "#include <" not in text, path.name
    assert "its own" in (folder / "puma560_dynamics.h").read_text()
    _compare(compiled(folder, "m4f", "-Os"), folder, tmp_path, "puma560", "m4f", "-Os", precision)


@pytest.mark.parametrize("robot", ROBOTS)
def test_freestanding_float_needs_nothing(rendered, compiled, tmp_path, robot):
    """A freestanding float object has no undefined symbol (no libm, no libgcc, no memset for the
    zeros of a floating base's M), so it links with -nostdlib."""
    objects = compiled(rendered(robot, "float", True), "m4f", "-Os")
    assert undefined_symbols(objects) == set()
    name = next(rendered(robot, "float", True).glob("*_dynamics.h")).name.removesuffix("_dynamics.h")
    link_bare(objects, "m4f", f"{name}_inverse_dynamics", tmp_path)


SWEEP = r"""
#include <math.h>
#include <stdio.h>
#include "puma560_dynamics.c"
/* max |error| of puma560_sincos over 2^20 floats evenly in [-8, 8] and 2^20 pseudo-random floats
   in [-8192, 8192], against the double sine and cosine of the same float */
int main(void)
{
    static float x[1024], s[1024], c[1024];
    double worst = 0.0;
    unsigned long long state = 38;
    long i;
    int k;
    for (i = 0; i < 2048; ++i) {
        for (k = 0; k < 1024; ++k) {
            state = state * 6364136223846793005ULL + 1442695040888963407ULL;
            x[k] = i < 1024 ? (float)(-8.0 + 16.0 * (double)(i * 1024 + k) / 1048576.0)
                            : (float)((double)(state >> 11) / 9007199254740992.0 * 16384.0 - 8192.0);
        }
        puma560_sincos(1024, x, s, c);
        for (k = 0; k < 1024; ++k) {
            double es = fabs((double)s[k] - sin((double)x[k])), ec = fabs((double)c[k] - cos((double)x[k]));
            worst = es > worst ? es : worst;
            worst = ec > worst ? ec : worst;
        }
    }
    printf("%.17g\n", worst);
    return 0;
}
"""


def test_freestanding_sincos_error_bound(rendered, tmp_path):
    """The float sine and cosine of a freestanding file keep the bound its header states
    (symdyn.codegen.c.sincos.FREESTANDING_ERROR: 1e-7 absolute for |x| <= 8192), on the host's
    IEEE single precision (the M4F's FPU rounds the same way)."""
    folder = rendered("puma560", "float", True)
    (tmp_path / "sweep.c").write_text(SWEEP)
    exe = tmp_path / "sweep"
    cmd = [
        "gcc",
        "-std=c99",
        "-O2",
        "-ffp-contract=off",
        f"-I{folder}",
        str(tmp_path / "sweep.c"),
        "-o",
        str(exe),
    ]
    subprocess.run([*cmd, "-lm"], check=True, capture_output=True)
    worst = float(subprocess.run([str(exe)], check=True, capture_output=True, text=True).stdout)
    assert 0 < worst <= 1e-7


def test_freestanding_refused_where_it_cannot_hold(capsys, tmp_path):
    """--freestanding without the C target, or with a function that needs more of <math.h> than
    sine and cosine (a floating robot's configuration group: sqrt, atan2), is one line of error
    and no file."""
    examples = Path(__file__).resolve().parents[1] / "examples"
    line = refused(
        capsys,
        "generate",
        examples / "roger_arm.yaml",
        "--target",
        "casadi",
        "--freestanding",
        "--out",
        tmp_path / "a",
    )
    assert "option of the C target" in line
    arm = Path(__file__).parent / "data" / "floating_arm.yaml"
    args = ("--target", "c", "--functions", "configuration", "--freestanding", "--out", tmp_path / "b")
    line = refused(capsys, "generate", arm, *args, seconds=60)
    assert "--freestanding" in line and "sqrt" in line
    assert not (tmp_path / "a").exists() and not (tmp_path / "b").exists()


# --------------------------------------------------------------------------- CMakeLists.txt

APP = r"""
#include <stdio.h>
#include "roger_arm_values_dynamics.h"
int main(void)
{
    const float q[2] = {0.3f, -0.7f};
    float M[4];
    roger_arm_values_mass_matrix(q, NULL, M);
    printf("%.9g %.9g %.9g %.9g\n", (double)M[0], (double)M[1], (double)M[2], (double)M[3]);
    return 0;
}
"""


@pytest.mark.skipif(shutil.which("cmake") is None, reason="cmake is not installed")
def test_cmake_builds_the_library(tmp_path):
    """The C target's CMakeLists.txt, added to a parent project with add_subdirectory, builds a static
    library (host gcc, the strict flags) that a program links; its M is the oracle's. Asking for
    the other precision stops the configuration with the command that regenerates the files."""
    robot = _robot_file("roger_arm_values")
    symdyn.generate(robot, targets=("c",), out_dir=tmp_path / "dyn", precision="float")
    (tmp_path / "main.c").write_text(APP)
    (tmp_path / "CMakeLists.txt").write_text(
        "cmake_minimum_required(VERSION 3.13)\nproject(app C)\nadd_subdirectory(dyn)\n"
        "add_executable(app main.c)\ntarget_link_libraries(app PRIVATE roger_arm_values_dynamics)\n"
    )
    flags = "-DCMAKE_C_FLAGS=" + " ".join(STRICT_FLAGS[1:])
    configure = ["cmake", "-S", str(tmp_path), "-B", str(tmp_path / "build"), flags]
    subprocess.run(configure, check=True, capture_output=True)
    subprocess.run(["cmake", "--build", str(tmp_path / "build")], check=True, capture_output=True)
    out = subprocess.run([str(tmp_path / "build" / "app")], check=True, capture_output=True, text=True)
    got = np.array(out.stdout.split(), dtype=float)
    np.testing.assert_allclose(got, mass_matrix(robot, [0.3, -0.7]).ravel(), rtol=1e-6)
    wrong = ["cmake", "-S", str(tmp_path), "-B", str(tmp_path / "b2"), "-Droger_arm_values_PRECISION=double"]
    proc = subprocess.run(wrong, capture_output=True, text=True)
    assert proc.returncode != 0 and "--precision double" in proc.stderr.replace("\n", " ")


def test_a_users_cmakelists_is_never_overwritten(capsys, tmp_path):
    """The C target's CMakeLists.txt has a fixed name: generating into a project's own folder stops
    with one line of error, and the project's file and the folder stay as they were."""
    (tmp_path / "CMakeLists.txt").write_text("project(mine)\n")
    robot = Path(__file__).resolve().parents[1] / "examples" / "roger_arm.yaml"
    line = refused(capsys, "generate", robot, "--target", "c", "--out", tmp_path)
    assert "CMakeLists.txt" in line and "not generated by symdyn" in line
    assert (tmp_path / "CMakeLists.txt").read_text() == "project(mine)\n"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["CMakeLists.txt"]


# --------------------------------------------------------------------------- instructions per call

#: the static count of a call and QEMU's may differ by the harness's part of the window: setting up
#: the arguments (the Panda's inverse dynamics: four pointers and a NULL) and the call (bench/embedded.py
#: measured +5 for it, -1 to -3 for the others)
COUNT_MARGIN = 8


def test_inverse_dynamics_is_branch_free_and_its_count_is_qemus(rendered, compiled, tmp_path):
    """The Panda's float inverse dynamics on the M4F at -Os has no branch but its calls and its
    return (with newlib's sinf and cosf, and freestanding), so one call runs each instruction once:
    freestanding, its static count (its own instructions, plus NAME_sincos's one loop once per
    angle) is QEMU's -icount count within COUNT_MARGIN."""
    from embedded import instructions, loop_count, static_count

    _, callees, broken = static_count(
        compiled(rendered("panda", "float"), "m4f", "-Os")[0], "panda_inverse_dynamics"
    )
    assert not broken and sorted(set(callees)) == ["cosf", "sinf"], (broken, callees)
    folder = rendered("panda", "float", True)
    objects = compiled(folder, "m4f", "-Os")
    count, callees, broken = static_count(objects[0], "panda_inverse_dynamics")
    assert not broken and len(callees) == 1 and callees[0].startswith("panda_sincos"), (broken, callees)
    count += loop_count(objects[0], callees[0], 6)  # the Panda's six angles, q2 to q7
    x = random_states(_robot("panda"), 1, seed=1)[0]
    calls = {"inverse_dynamics": "panda_inverse_dynamics(in, in + 7, in + 14, NULL, out)"}
    measured = instructions(folder, objects, "panda_dynamics.h", calls, x, tmp_path / "t")
    assert abs(measured["inverse_dynamics"] - count) <= COUNT_MARGIN, (count, measured)


# --------------------------------------------------------------------------- --precision both

APP_BOTH = r"""
#include <stdio.h>
#include "roger_arm_values_dynamics.h"
int main(void)
{
    const roger_arm_values_real q[2] = {(roger_arm_values_real)0.3, (roger_arm_values_real)-0.7};
    roger_arm_values_real M[4];
    roger_arm_values_mass_matrix(q, NULL, M);
    printf("%d %.17g %.17g %.17g %.17g\n", (int)sizeof M[0], (double)M[0], (double)M[1], (double)M[2],
           (double)M[3]);
    return 0;
}
"""


@pytest.mark.skipif(shutil.which("cmake") is None, reason="cmake is not installed")
def test_cmake_switches_the_precision(tmp_path):
    """--precision both: one set of files that CMake's NAME_PRECISION compiles in float or in
    double (host gcc, the strict flags with -Wdouble-promotion and -Wconversion), each M the
    oracle's to its precision; the float build also cross-compiles for the M4F with the embedded
    flags and no double arithmetic."""
    robot = _robot_file("roger_arm_values")
    symdyn.generate(robot, targets=("c",), out_dir=tmp_path / "dyn", precision="both")
    (tmp_path / "main.c").write_text(APP_BOTH)
    (tmp_path / "CMakeLists.txt").write_text(
        "cmake_minimum_required(VERSION 3.13)\nproject(app C)\nadd_subdirectory(dyn)\n"
        "add_executable(app main.c)\ntarget_link_libraries(app PRIVATE roger_arm_values_dynamics)\n"
    )
    flags = "-DCMAKE_C_FLAGS=" + " ".join((*STRICT_FLAGS[1:], "-Wdouble-promotion", "-Wconversion"))
    want = mass_matrix(robot, [0.3, -0.7]).ravel()
    for precision, size, rtol in (("float", 4, 1e-6), ("double", 8, 1e-13)):
        build = tmp_path / precision
        define = f"-Droger_arm_values_PRECISION={precision}"
        subprocess.run(
            ["cmake", "-S", str(tmp_path), "-B", str(build), flags, define], check=True, capture_output=True
        )
        proc = subprocess.run(["cmake", "--build", str(build)], capture_output=True, text=True)
        assert proc.returncode == 0 and "warning" not in proc.stdout + proc.stderr, proc.stdout + proc.stderr
        out = subprocess.run([str(build / "app")], check=True, capture_output=True, text=True).stdout.split()
        assert int(out[0]) == size
        np.testing.assert_allclose(np.array(out[1:], dtype=float), want, rtol=rtol)
    objects = cross_compile(
        tmp_path / "dyn", "m4f", "-Os", tmp_path / "arm", extra=("-Droger_arm_values_USE_FLOAT",)
    )
    _check_object(objects, "float")
    wrong = ["cmake", "-S", str(tmp_path), "-B", str(tmp_path / "b2"), "-Droger_arm_values_PRECISION=half"]
    proc = subprocess.run(wrong, capture_output=True, text=True)
    assert proc.returncode != 0 and "float or double" in proc.stderr


def test_precision_both_is_the_c_targets(capsys, tmp_path):
    """--precision both with another target than C is one line of error and no file."""
    robot = Path(__file__).resolve().parents[1] / "examples" / "roger_arm.yaml"
    for targets in (("--target", "casadi"), ()):
        line = refused(capsys, "generate", robot, *targets, "--precision", "both", "--out", tmp_path / "a")
        assert "--precision both" in line and "--target c" in line
    assert not (tmp_path / "a").exists()


def test_precision_both_macros_are_no_parameters_name(tmp_path):
    """A free parameter named as a macro of --precision both (NAME_real, NAME_USE_FLOAT) gets
    another local name, so that the macro cannot replace it: the files compile in float and double."""
    text = (Path(__file__).resolve().parents[1] / "examples" / "roger_arm.yaml").read_text()
    text = re.sub(r"\bg\b", "roger_arm_real", re.sub(r"\bm1\b", "roger_arm_USE_FLOAT", text))
    (tmp_path / "roger_arm.yaml").write_text(text)
    symdyn.generate(tmp_path / "roger_arm.yaml", targets=("c",), out_dir=tmp_path / "dyn", precision="both")
    source = (tmp_path / "dyn" / "roger_arm_dynamics.c").read_text()
    assert "const float roger_arm_real " not in source and "const float roger_arm_real_ " in source
    for define in ((), ("-Droger_arm_USE_FLOAT",)):
        cross_compile(tmp_path / "dyn", "m4f", "-Os", tmp_path / "o", extra=define)  # a warning fails
