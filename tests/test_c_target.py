"""The C target (docs/generated-code.md) compiled with gcc and judged by the numeric oracle.

Every example robot is derived once, rendered in double and float precision,
compiled warning-free with the strict flags (-Werror) and loaded with ctypes
(tests/cbuild.py): unoptimised (cbuild.TEST_OPT), and two robots also at -O2, where
gcc finds the warnings that need its flow analysis (test_optimised_strict_build). All
seven functions are compared with symdyn.rnea at random states; a sanitised driver
program exercises them with exact-size heap arrays and a NULL p. Derivations run in this
process while gcc compiles in worker threads.
"""

from __future__ import annotations

import contextlib
import dataclasses
import importlib
import os
import re
import subprocess
import sys
import warnings
import zlib
from concurrent.futures import Future, ThreadPoolExecutor
from pathlib import Path

import numpy as np
import pytest
from cbuild import (
    SANITIZE_FLAGS,
    STRICT_FLAGS,
    TEST_OPT,
    CDynamics,
    compile_program,
    compile_shared,
    compilers,
    header_macros,
    write_files,
)
from robots import example_context, regressor_oracle

import symdyn.codegen
from symdyn.codegen import c as c_backend
from symdyn.codegen.render import RenderContext
from symdyn.parsers import load_robot, robot_from_data

oracle = importlib.import_module("symdyn.rnea")  # the module (symdyn.rnea is also the function)

ROOT = Path(__file__).resolve().parent.parent
EXAMPLES = ROOT / "examples"
ROBOTS = sorted(p.stem for p in EXAMPLES.glob("*.yaml"))
PRECISIONS = ("double", "float")
TOLERANCE = {"double": 1e-9, "float": 1e-4}
STATES = 50
FUNCTIONS = symdyn.codegen.FUNCTION_NAMES


def _load(path: Path):
    with warnings.catch_warnings():  # published PUMA data is implausible (a warning, not an error)
        warnings.simplefilter("ignore")
        return load_robot(path)


class Builds:
    """Each robot derived, rendered and compiled at most once per (precision, compiler)."""

    def __init__(self, root: Path):
        self.root = root
        self.pool = ThreadPoolExecutor(max_workers=2)
        self._ctx: dict[str, RenderContext] = {}
        self._files: dict[tuple[str, str], dict[str, str]] = {}
        self._futures: dict[tuple[str, str, str, str], Future] = {}
        self._libs: dict[tuple[str, str, str, str], CDynamics] = {}

    def context(self, robot: str) -> RenderContext:
        if robot not in self._ctx:
            self._ctx[robot] = example_context(robot)  # derived once per test process (tests/robots.py)
        return self._ctx[robot]

    def files(self, robot: str, precision: str = "double") -> dict[str, str]:
        key = (robot, precision)
        if key not in self._files:
            ctx = dataclasses.replace(self.context(robot), precision=precision)
            self._files[key] = c_backend.render(ctx)
        return self._files[key]

    def directory(self, robot: str, precision: str) -> Path:
        d = self.root / f"{robot}_{precision}"
        if not d.exists():
            write_files(self.files(robot, precision), d)
        return d

    def submit(
        self, robot: str, precision: str = "double", compiler: str = "gcc", opt: str = TEST_OPT
    ) -> Future:
        key = (robot, precision, compiler, opt)
        if key not in self._futures:
            d = self.directory(robot, precision)
            self._futures[key] = self.pool.submit(
                compile_shared,
                [d / f"{robot}_dynamics.c"],
                d / f"lib{robot}_{compiler}{opt}.so",
                compiler,
                opt,
            )
        return self._futures[key]

    def library(
        self, robot: str, precision: str = "double", compiler: str = "gcc", opt: str = TEST_OPT
    ) -> CDynamics:
        key = (robot, precision, compiler, opt)
        if key not in self._libs:
            path = self.submit(robot, precision, compiler, opt).result()
            ctx = self.context(robot)
            self._libs[key] = CDynamics(path, robot, ctx.robot.n, len(ctx.dynamics.params), precision)
        return self._libs[key]


@pytest.fixture(scope="module")
def builds(request, tmp_path_factory):
    b = Builds(tmp_path_factory.mktemp("c_target"))
    # start compiling everything the selected tests of this module will need
    wanted: dict[tuple[str, str], None] = {}
    for item in request.session.items:
        params = getattr(getattr(item, "callspec", None), "params", {})
        if getattr(item, "module", None) is request.module and params.get("robot") in ROBOTS:
            opt = "-O2" if item.originalname == "test_optimised_strict_build" else TEST_OPT
            wanted[(params["robot"], params.get("precision", "double"), opt)] = None
    for robot, precision, opt in wanted:
        for compiler in compilers():
            with contextlib.suppress(Exception):  # reported by the tests that need this robot
                b.submit(robot, precision, compiler, opt)
    yield b
    b.pool.shutdown(wait=True, cancel_futures=True)


def _states(ctx: RenderContext, count: int, precision: str):
    """Random q, qd, qdd, tau (N, n) and parameters, exactly representable in `precision`."""
    robot = ctx.robot
    rng = np.random.default_rng(zlib.crc32(robot.name.encode()))
    revolute = oracle.numeric_model(robot, {str(p): 1.0 for p in ctx.dynamics.params} or None).revolute
    n = robot.n
    span = np.where(revolute, np.pi, 0.5)
    q = rng.uniform(-1, 1, (count, n)) * span
    qd = rng.uniform(-2, 2, (count, n))
    qd[0] = 0.0  # sign(0) = 0 in the Coulomb term
    qdd = rng.uniform(-3, 3, (count, n))
    p = rng.uniform(0.5, 2.0, len(ctx.dynamics.params))
    if precision == "float":
        q, qd, qdd, p = (x.astype(np.float32).astype(float) for x in (q, qd, qdd, p))
    params = {str(s): v for s, v in zip(ctx.dynamics.params, p, strict=True)} or None
    tau = oracle.rnea(robot, q, qd, qdd, params)
    if precision == "float":
        tau = tau.astype(np.float32).astype(float)
    return q, qd, qdd, tau, p, params


def _assert_close(got, want, tol: float, what: str) -> None:
    got, want = np.asarray(got, float), np.asarray(want, float)
    axes = tuple(range(1, want.ndim))
    err = np.sqrt(np.sum((got - want) ** 2, axis=axes))
    scale = np.maximum(1.0, np.sqrt(np.sum(want**2, axis=axes)))
    worst = int(np.argmax(err / scale))
    assert np.all(err <= tol * scale), (
        f"{what}: relative error {err[worst] / scale[worst]:.3g} > {tol:g} at state {worst}: "
        f"got {got[worst]}, want {want[worst]}"
    )


# --- the header ----------------------------------------------------------------------


@pytest.mark.parametrize("robot", ROBOTS)
def test_header_macros_and_docs(builds, robot):
    ctx = builds.context(robot)
    header = builds.files(robot)[f"{robot}_dynamics.h"]
    macros = header_macros(header)
    params = [str(p) for p in ctx.dynamics.params]
    assert macros[f"{robot}_NDOF"] == str(ctx.robot.n)
    assert macros[f"{robot}_NPARAM"] == str(len(params))
    index = {
        name[len(f"{robot}_P_") :]: int(v) for name, v in macros.items() if name.startswith(f"{robot}_P_")
    }
    assert index == {name: k for k, name in enumerate(params)}
    upper = robot.upper()
    if upper != robot:
        assert macros[f"{upper}_NDOF"] == str(ctx.robot.n)
        assert macros[f"{upper}_NPARAM"] == str(len(params))
        for k, name in enumerate(params):
            assert macros[f"{upper}_P_{name.upper()}"] == str(k)
    assert header.startswith("/*\n * Generated by symdyn ")
    assert f"#ifndef {upper}_DYNAMICS_H" in header and 'extern "C" {' in header
    for spec in ctx.functions:
        assert f"void {robot}_{spec.name}(" in header
        assert f"Cost per call: {spec.ops.total} operations" in header
    assert "row-major" in header
    source = builds.files(robot)[f"{robot}_dynamics.c"]
    if not params:
        assert not re.search(r"\bp\[[^\]]", source)  # p may be NULL: never read
    assert "pow(" not in source


def test_signatures_are_the_contract(builds):
    header = builds.files("roger_arm")["roger_arm_dynamics.h"]
    expected = [
        "void roger_arm_inverse_dynamics(const double q[], const double qd[], const double qdd[], "
        "const double p[], double tau[]);",
        "void roger_arm_mass_matrix(const double q[], const double p[], double M[]);",
        "void roger_arm_coriolis_matrix(const double q[], const double qd[], const double p[], double C[]);",
        "void roger_arm_coriolis(const double q[], const double qd[], const double p[], double V[]);",
        "void roger_arm_gravity(const double q[], const double p[], double G[]);",
        "void roger_arm_friction(const double qd[], const double p[], double F[]);",
        "void roger_arm_forward_dynamics(const double q[], const double qd[], const double tau[], "
        "const double p[], double qdd[]);",
    ]
    for line in expected:
        assert line in header


# --- against the oracle ---------------------------------------------------------------


@pytest.mark.parametrize("precision", PRECISIONS)
@pytest.mark.parametrize("robot", ROBOTS)
def test_functions_match_rnea(builds, robot, precision):
    ctx = builds.context(robot)
    r = ctx.robot
    q, qd, qdd, tau, p, params = _states(ctx, STATES, precision)
    tol = TOLERANCE[precision]
    want = {
        "inverse_dynamics": oracle.rnea(r, q, qd, qdd, params),
        "mass_matrix": oracle.mass_matrix(r, q, params),
        "coriolis": oracle.bias_torque(r, q, qd, params),
        "gravity": oracle.gravity_torque(r, q, params),
        "friction": oracle.friction_torque(r, qd, params),
        "forward_dynamics": oracle.forward_dynamics(r, q, qd, tau, params),
    }
    pv = p if len(p) else None
    for compiler in compilers():
        lib = builds.library(robot, precision, compiler)
        got = {
            "inverse_dynamics": [lib.inverse_dynamics(*x, pv) for x in zip(q, qd, qdd, strict=True)],
            "mass_matrix": [lib.mass_matrix(x, pv) for x in q],
            "coriolis": [lib.coriolis(*x, pv) for x in zip(q, qd, strict=True)],
            "gravity": [lib.gravity(x, pv) for x in q],
            "friction": [lib.friction(x, pv) for x in qd],
            "forward_dynamics": [lib.forward_dynamics(*x, pv) for x in zip(q, qd, tau, strict=True)],
        }
        C = np.array([lib.coriolis_matrix(*x, pv) for x in zip(q, qd, strict=True)])
        got["C qd"] = np.einsum("nij,nj->ni", C, qd)
        want["C qd"] = want["coriolis"]
        for name in want:
            _assert_close(got[name], want[name], tol, f"{robot} {precision} {compiler} {name}")


#: robots compiled at -O2 too: a 6R arm with friction and motors, and one with a prismatic joint
OPTIMISED = ("puma560", "stanford")


@pytest.mark.parametrize("precision", PRECISIONS)
@pytest.mark.parametrize("robot", OPTIMISED)
def test_optimised_strict_build(builds, robot, precision):
    """The C contract's strict flags at -O2, where gcc's flow analysis adds warnings that the
    unoptimised builds of the other tests (cbuild.TEST_OPT) cannot give: still no warning, and the
    optimised library computes what the oracle does (every function group is in the one file)."""
    ctx = builds.context(robot)
    r = ctx.robot
    q, qd, qdd, tau, p, params = _states(ctx, 10, precision)
    pv = p if len(p) else None
    tol = TOLERANCE[precision]
    for compiler in compilers():
        lib = builds.library(robot, precision, compiler, "-O2")
        got = {
            "inverse_dynamics": [lib.inverse_dynamics(*x, pv) for x in zip(q, qd, qdd, strict=True)],
            "mass_matrix": [lib.mass_matrix(x, pv) for x in q],
            "forward_dynamics": [lib.forward_dynamics(*x, pv) for x in zip(q, qd, tau, strict=True)],
        }
        want = {
            "inverse_dynamics": oracle.rnea(r, q, qd, qdd, params),
            "mass_matrix": oracle.mass_matrix(r, q, params),
            "forward_dynamics": oracle.forward_dynamics(r, q, qd, tau, params),
        }
        for name in want:
            _assert_close(got[name], want[name], tol, f"{robot} {precision} {compiler} -O2 {name}")


@pytest.mark.parametrize("robot", ROBOTS)
def test_coriolis_matrix_makes_mdot_minus_2c_skew(builds, robot):
    ctx = builds.context(robot)
    lib = builds.library(robot)
    q, qd, _, _, p, _ = _states(ctx, 10, "double")
    pv = p if len(p) else None
    h = 1e-6
    for qi, qdi in zip(q, qd, strict=True):
        Mdot = (lib.mass_matrix(qi + h * qdi, pv) - lib.mass_matrix(qi - h * qdi, pv)) / (2 * h)
        N = Mdot - 2 * lib.coriolis_matrix(qi, qdi, pv)
        scale = max(1.0, np.linalg.norm(lib.mass_matrix(qi, pv)) * np.linalg.norm(qdi))
        assert np.linalg.norm(N + N.T) <= 1e-6 * scale, f"{robot}: dM/dt - 2C not skew at q={qi}"


# --- a sanitised C program ------------------------------------------------------------


def _c_array(name: str, values) -> str:
    return f"static const double {name}[] = {{{', '.join(repr(float(v)) for v in values)}}};"


def _driver(robot: str, q, qd, qdd, tau, p, params: list[str]) -> str:
    n = len(q)
    calls = {
        "inverse_dynamics": ("q", "qd", "qdd"),
        "mass_matrix": ("q",),
        "coriolis_matrix": ("q", "qd"),
        "coriolis": ("q", "qd"),
        "gravity": ("q",),
        "friction": ("qd",),
        "forward_dynamics": ("q", "qd", "tau"),
        "regressor": ("q", "qd", "qdd"),
        "base_regressor": ("q", "qd", "qdd"),
    }
    sizes = {"regressor": f"n * {robot}_NSTD", "base_regressor": f"n * {robot}_NBASE"}
    lines = [
        "#include <stdio.h>",
        "#include <stdlib.h>",
        "#include <string.h>",
        f'#include "{robot}_dynamics.h"',
        "",
        "static double *copy(const double *src, size_t count)",
        "{",
        "    double *a = malloc(count * sizeof *a);",
        "    if (a == NULL) exit(2);",
        "    memcpy(a, src, count * sizeof *a);",
        "    return a;",
        "}",
        "",
        "static void show(const char *what, const double *a, size_t count)",
        "{",
        "    size_t i;",
        '    printf("%s", what);',
        '    for (i = 0; i < count; ++i) printf(" %.17g", a[i]);',
        '    printf("\\n");',
        "}",
        "",
        _c_array("q0", q),
        _c_array("qd0", qd),
        _c_array("qdd0", qdd),
        _c_array("tau0", tau),
    ]
    if params:
        lines.append(_c_array("p0", p))
    lines += [
        "",
        "int main(void)",
        "{",
        f"    const size_t n = {robot}_NDOF;",
        "    double *q = copy(q0, n), *qd = copy(qd0, n), *qdd = copy(qdd0, n), *tau = copy(tau0, n);",
        f"    double *p = {'copy(p0, ' + robot + '_NPARAM)' if params else 'NULL'};",
        f'    printf("NDOF %d\\nNPARAM %d\\n", {robot}_NDOF, {robot}_NPARAM);',
    ]
    lines += [f'    printf("P_{name} %d\\n", {robot}_P_{name});' for name in params]
    for fname, args in calls.items():
        size = sizes.get(fname, "n * n" if fname.endswith("matrix") else "n")
        lines += [
            "    {",
            f"        double *out = malloc({size} * sizeof *out);",
            "        if (out == NULL) return 2;",
            f"        {robot}_{fname}({', '.join(args)}, p, out);",
            f'        show("{fname}", out, {size});',
            "        free(out);",
            "    }",
        ]
    lines += [
        "    free(q);",
        "    free(qd);",
        "    free(qdd);",
        "    free(tau);",
        "    free(p);",
        "    return 0;",
        "}",
    ]
    assert n
    return "\n".join(lines) + "\n"


@pytest.mark.parametrize("robot", ["puma560", "roger_arm", "planar_prismatic_modified"])
def test_sanitised_driver(builds, robot, tmp_path):
    ctx = builds.context(robot)
    r = ctx.robot
    q, qd, qdd, tau, p, params = _states(ctx, 2, "double")
    q, qd, qdd, tau = q[1], qd[1], qdd[1], tau[1]
    names = [str(s) for s in ctx.dynamics.params]
    write_files(builds.files(robot), tmp_path)
    (tmp_path / "driver.c").write_text(_driver(robot, q, qd, qdd, tau, p, names))
    exe = compile_program(
        [tmp_path / "driver.c", tmp_path / f"{robot}_dynamics.c"], tmp_path / "driver", extra=SANITIZE_FLAGS
    )
    env = dict(os.environ, ASAN_OPTIONS="detect_leaks=1", UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1")
    proc = subprocess.run([str(exe)], capture_output=True, text=True, env=env, timeout=60)
    assert proc.returncode == 0, proc.stderr
    assert "Sanitizer" not in proc.stderr and "runtime error" not in proc.stderr, proc.stderr
    out = {line.split()[0]: line.split()[1:] for line in proc.stdout.splitlines()}
    assert out["NDOF"] == [str(r.n)] and out["NPARAM"] == [str(len(names))]
    for k, name in enumerate(names):
        assert out[f"P_{name}"] == [str(k)]
    got = {name: np.array([float(v) for v in out[name]]) for name in FUNCTIONS}
    want = {
        "inverse_dynamics": oracle.rnea(r, q, qd, qdd, params),
        "mass_matrix": oracle.mass_matrix(r, q, params).ravel(),  # row-major
        "coriolis_matrix": None,
        "coriolis": oracle.bias_torque(r, q, qd, params),
        "gravity": oracle.gravity_torque(r, q, params),
        "friction": oracle.friction_torque(r, qd, params),
        "forward_dynamics": oracle.forward_dynamics(r, q, qd, tau, params),
    }
    want |= {k: v.ravel() for k, v in regressor_oracle(ctx.dynamics, q, qd, qdd, params).items()}
    want["coriolis_matrix"] = got["coriolis_matrix"]
    _assert_close(got["coriolis_matrix"].reshape(r.n, r.n) @ qd, want["coriolis"], 1e-9, "C qd")
    for name in FUNCTIONS:
        _assert_close(got[name][None], want[name][None], 1e-9, f"{robot} driver {name}")


def test_sanitizers_are_active(tmp_path):
    """The driver test means something only if the sanitizers do report: plant an overflow."""
    (tmp_path / "bad.c").write_text(
        "#include <stdlib.h>\n"
        "int main(void)\n{\n"
        "    volatile int k = 3;\n"
        "    volatile double *a = malloc(3 * sizeof *a);\n"
        "    if (a == NULL) return 2;\n"
        "    a[k] = 1.0;\n"
        "    free((void *)a);\n"
        "    return 0;\n}\n"
    )
    for flags, report in (
        (("-fsanitize=address", "-fno-omit-frame-pointer", "-g"), "AddressSanitizer: heap-buffer-overflow"),
        (SANITIZE_FLAGS, "bad.c:7"),
    ):
        exe = compile_program([tmp_path / "bad.c"], tmp_path / "bad", extra=flags)
        proc = subprocess.run([str(exe)], capture_output=True, text=True, timeout=60)
        assert proc.returncode != 0 and report in proc.stderr, proc.stderr


# --- float precision ---------------------------------------------------------------------

_LITERAL = re.compile(r"(?<![\w.])(\d+\.\d*(?:[eE][+-]?\d+)?|\d+[eE][+-]?\d+)(f?)")


@pytest.mark.parametrize("robot", ["puma560", "scara", "roger_arm"])
def test_float_source_is_all_float(builds, robot):
    for name, text in builds.files(robot, "float").items():
        if not name.endswith((".c", ".h")):  # CMakeLists.txt names both precisions in its option
            continue
        code = [ln for ln in text.splitlines() if not ln.lstrip().startswith(("/*", "*"))]
        body = "\n".join(code)
        assert not re.search(r"\bdouble\b", body), name
        assert not re.search(r"\b(sin|cos|tan|sqrt|fabs|pow)\(", body), name
        for number, suffix in _LITERAL.findall(body):
            assert suffix == "f", f"{name}: literal {number} without f suffix"
    assert "sinf(" in builds.files(robot, "float")[f"{robot}_dynamics.c"]


# --- determinism ---------------------------------------------------------------------------


def test_rendering_is_deterministic(builds):
    robot = _load(EXAMPLES / "scara.yaml")
    first = symdyn.codegen.render(robot, targets=("c",))
    second = symdyn.codegen.render(robot, targets=("c",))
    assert sorted(first) == ["CMakeLists.txt", "scara_dynamics.c", "scara_dynamics.h"]
    assert first == second
    assert first == builds.files("scara", "double")
    assert symdyn.codegen.render(robot, targets=("c",), precision="float") == builds.files("scara", "float")


def test_rendering_does_not_depend_on_hash_seed(tmp_path):
    script = (
        "import sys, warnings; warnings.simplefilter('ignore')\n"
        "from symdyn.parsers import load_robot\n"
        "from symdyn.codegen import render\n"
        "files = render(load_robot(sys.argv[1]), targets=('c',))\n"
        "sys.stdout.write(files['scara_dynamics.c'] + files['scara_dynamics.h'])\n"
    )
    outputs = []
    for seed in ("1", "2"):
        env = dict(os.environ, PYTHONHASHSEED=seed)
        proc = subprocess.run(
            [sys.executable, "-c", script, str(EXAMPLES / "scara.yaml")],
            capture_output=True,
            text=True,
            env=env,
            timeout=120,
        )
        assert proc.returncode == 0, proc.stderr
        outputs.append(proc.stdout)
    assert outputs[0] == outputs[1]


# --- names (the printer has tests/test_c_printer.py) ------------------------------------


def _clash_robot(temporary_like: bool):
    """A two-link arm whose parameter names are C keywords of sorts: argument names, libm
    names, macro names, and (with temporary_like) names of temporaries x<k>."""
    a1, a1_ = ("x0", "x0_") if temporary_like else ("a1", "a1_")
    data = {
        "name": "clash",
        "convention": "standard",
        "gravity": [0, "-g", 0],
        "parameters": {},
        "links": [
            {
                "name": "one",
                "joint": "revolute",
                "a": a1,
                "alpha": 0,
                "d": 0,
                "theta": 0,
                "mass": "M",
                "com": [f"-{a1_}/2", 0, 0],
                "inertia": {"izz": "cosf"},
                "friction": {"viscous": "NAN", "coulomb": "tau"},
                "motor": {"inertia": "y1", "gear_ratio": "clash_NDOF"},
            },
            {
                "name": "two",
                "joint": "revolute",
                "a": "p",
                "alpha": 0,
                "d": 0,
                "theta": 0,
                "mass": "m",
                "com": ["-p/2", 0, 0],
                "inertia": {"izz": "F", "iyy": "F", "ixx": "F"},
            },
        ],
    }
    return robot_from_data(data, source="clash.yaml")


def _check_clash_robot(robot, tmp_path, bad: tuple[str, ...]):
    ctx = symdyn.codegen.context(robot)
    names = c_backend.c_names(ctx)
    local = {str(s): v for s, v in names.locals.items()}
    for name in bad:
        assert local[name] != name
    assert len(set(names.locals.values())) == len(names.locals)
    assert "CLASH_P_M" not in dict(names.aliases)  # m and M would both become CLASH_P_M
    assert "CLASH_P_G" in dict(names.aliases)
    files = c_backend.render(ctx)
    write_files(files, tmp_path)
    macros = header_macros(files["clash_dynamics.h"])
    params = ctx.dynamics.params
    assert [int(macros[f"clash_P_{s}"]) for s in params] == list(range(len(params)))
    library = compile_shared([tmp_path / "clash_dynamics.c"], tmp_path / "libclash.so")
    lib = CDynamics(library, "clash", 2, len(params))
    rng = np.random.default_rng(7)
    p = rng.uniform(0.5, 2.0, len(params))
    values = {str(s): v for s, v in zip(params, p, strict=True)}
    for _ in range(5):
        q, qd, qdd = rng.uniform(-2, 2, (3, 2))
        tau = oracle.rnea(robot, q, qd, qdd, values)
        _assert_close(lib.inverse_dynamics(q, qd, qdd, p)[None], tau[None], 1e-9, "clash tau")
        M = oracle.mass_matrix(robot, q, values)
        _assert_close(lib.mass_matrix(q, p)[None], M[None], 1e-9, "clash M")
        F = oracle.friction_torque(robot, qd, values)
        _assert_close(lib.friction(qd, p)[None], F[None], 1e-9, "clash F")
        _assert_close(lib.forward_dynamics(q, qd, tau, p)[None], qdd[None], 1e-8, "clash qdd")


def test_parameter_names_that_clash_in_c(tmp_path):
    robot = _clash_robot(temporary_like=False)
    _check_clash_robot(robot, tmp_path, ("M", "p", "cosf", "NAN", "tau", "y1", "clash_NDOF", "F"))


def test_parameter_named_like_a_temporary(tmp_path):
    robot = _clash_robot(temporary_like=True)
    _check_clash_robot(robot, tmp_path, ("M", "p", "x0", "cosf", "NAN", "tau", "y1", "clash_NDOF", "F"))


def test_strict_flags_are_the_contract():
    assert STRICT_FLAGS[:4] == ("-std=c99", "-Wall", "-Wextra", "-Wpedantic") and "-Werror" in STRICT_FLAGS
