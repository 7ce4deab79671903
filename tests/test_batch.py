"""The SIMD batch wrappers (templates/c/batch.c.j2, symdyn.codegen.c.vector) and their calling.

NAME_batch evaluates W states per instruction: the function's body over vectors of W lanes, each
lane performing the scalar function's operations in its order, the sines and cosines by the vector
twin of NAME_sincos. So a batch must equal the scalar function state by state, bit for bit (both
compiled with -ffp-contract=off, as symdyn.compile does), for every batch size, a multiple of W or
not: on the Panda (inverse dynamics, M, forward dynamics, under -march=native and with AVX2 alone)
and a tree robot with friction (whose sign and step go through the lane helpers), in double and
float, and with the scalar fallback (no AVX); the angles' sines in calls of one, two and three
angles (Roger's arm). States include angles the vector sine sends to the
C library (|q| >= 2^19 pi/2), tiny ones and -0. Every build uses the C contract's -Werror flags;
one runs the batch path under -fsanitize=address,undefined. Through symdyn.compile: no copy of
C-contiguous float64 arrays, and threads= giving the one-thread result bit for bit.
"""

from __future__ import annotations

import ctypes
import dataclasses
import os
import platform
import re
import subprocess
from pathlib import Path

import numpy as np
import pytest
from cbuild import SANITIZE_FLAGS, STRICT_FLAGS, TEST_OPT, compile_program, compilers, write_files
from robots import example, y_robot

import symdyn
from symdyn.apps.compilation import build, calling
from symdyn.apps.compilation.calling import batch_layout, load_library
from symdyn.codegen import c as c_target
from symdyn.codegen import context
from symdyn.codegen.c import parts
from symdyn.codegen.c.runtime import function_table, render_runtime
from symdyn.errors import SymdynError

pytestmark = pytest.mark.skipif("gcc" not in compilers(), reason="needs gcc")

#: unoptimised, as tests/cbuild.py's builds (the values do not depend on the level without
#: -ffast-math; symdyn.compile's -O2 -march=native library is checked by the last tests)
BASE = (TEST_OPT, "-ffp-contract=off", "-shared", "-fPIC")
X86 = platform.machine().lower() in ("x86_64", "amd64")


def _cpu_flags() -> set[str]:
    try:
        text = Path("/proc/cpuinfo").read_text()
    except OSError:
        return set()
    flags = [line.split(":")[1].split() for line in text.splitlines() if line.startswith("flags")]
    return set(flags[0]) if flags else set()


CPU = _cpu_flags()
#: name -> (flags, W expected); the vector builds only where this CPU can run them
BUILDS = {"scalar": (("-mno-avx",), 1)} if X86 else {}
if {"avx2", "fma"} <= CPU:
    BUILDS["avx2"] = (("-mavx2", "-mfma"), 4)
if {"avx2", "avx512f"} <= CPU:
    BUILDS["native"] = (("-march=native",), 8)
#: AVX without AVX2 (W = 4, the C library's sine lane by lane), at -O3 where gcc looks hardest for
#: values read before they are set; built for Roger's arm only
AVX_ONLY = {"avx": (("-mavx", "-O3"), 4)} if X86 and "avx" in CPU else {}
ALL_BUILDS = {**BUILDS, **AVX_ONLY}


def _build_all(ctx, folder: Path, names, extra=()) -> dict:
    """Compile the robot's C and batch wrappers (every file of each: NAME_dynamics*.c, NAME_batch*.c)
    once per build of `names`, with the flags `extra` too, all at once; load each."""
    files = {**c_target.render(ctx), **render_runtime(ctx)}
    paths = write_files(files, folder)
    sources = [str(p) for p in paths if re.fullmatch(r".*_(dynamics|batch)(_\d+)?\.c", p.name)]
    jobs = {}
    for name in names:
        flags, _ = ALL_BUILDS[name]
        cmd = ["gcc", *STRICT_FLAGS, *BASE, *flags, *extra, "-o", str(folder / f"{name}.so"), *sources, "-lm"]
        jobs[name] = subprocess.Popen(cmd, stderr=subprocess.PIPE, text=True)
    table = function_table(ctx)
    libs = {}
    for name, job in jobs.items():
        assert job.wait() == 0, job.stderr.read()
        width = f"{ctx.name}_batch_width"
        ffi, lib = load_library(folder / f"{name}.so", table, width, ctx.precision)
        libs[name] = (ffi, lib, int(getattr(lib, width)()))
    return {
        "table": {f["name"]: f for f in table},
        "libs": libs,
        "batch": files[f"{ctx.name}_batch.c"],
        "files": files,
    }


@pytest.fixture(scope="module")
def panda(tmp_path_factory):
    ctx = context(example("panda"), functions=("dynamics",))
    return _build_all(ctx, tmp_path_factory.mktemp("panda"), [b for b in BUILDS if b != "scalar"])


@pytest.fixture(scope="module")
def tree(tmp_path_factory):
    """The tree robot's context (derived once: float only prints it otherwise) and its builds: the
    dynamics and the regressors (vectorised too: 3.7 and 5.5 operations per output value)."""
    ctx = context(y_robot(), functions=("dynamics", "regressor"))
    builds = {}
    for precision in ("double", "float"):
        ctx_p = dataclasses.replace(ctx, precision=precision)
        builds[precision] = _build_all(ctx_p, tmp_path_factory.mktemp(f"tree-{precision}"), list(BUILDS))
    return ctx, builds


def _states(n: int, count: int, rng) -> np.ndarray:
    """`count` random states of n values, with awkward angles in some lanes: beyond 2^19 pi/2
    (the C library's range), below 2^-27 (sin x = x), -0, exact multiples of pi/2."""
    x = rng.uniform(-4.0, 4.0, (count, n))
    awkward = [1e6, -3e7, 1e-30, -0.0, 0.0, np.pi / 2, -np.pi, 823549.7, 2.0**-28]
    for k, value in enumerate(awkward):
        x[(3 * k + 1) % count, k % n] = value
    return x


def _check(build: dict, name: str, function: str, count: int, rng, dtype=np.float64, params=None) -> int:
    """NAME_batch over `count` states against NAME state by state: the same bits (p NULL, or
    `params` for a robot with free parameters). Returns W."""
    ffi, lib, width = build["libs"][name]
    f = build["table"][function]
    inputs = [(n, s) for n, s in f["inputs"] if n != "p"]
    with_p = len(inputs) != len(f["inputs"])
    real = "float" if dtype == np.float32 else "double"
    arrays = [_states(s, count, rng).astype(dtype) for _, s in inputs]
    sizes = [rows * cols for _, rows, cols, _ in f["outputs"]]
    batch = [np.full((count, s), np.nan, dtype) for s in sizes]
    buf = ffi.from_buffer
    p = ([ffi.NULL] if params is None else [buf(f"{real}[]", params)]) if with_p else []
    getattr(lib, f["c_name"] + "_batch")(
        count, *[buf(f"{real}[]", a) for a in arrays], *p, *[buf(f"{real}[]", o) for o in batch]
    )
    one = [np.full((count, s), np.nan, dtype) for s in sizes]
    single = getattr(lib, f["c_name"])
    for i in range(count):
        single(*[buf(f"{real}[]", a[i]) for a in arrays], *p, *[buf(f"{real}[]", o[i]) for o in one])
    for got, want in zip(batch, one, strict=True):
        assert got.tobytes() == want.tobytes(), f"{name} {function} count={count}"
    return width


def _sizes(width: int) -> list[int]:
    return sorted({1, max(width - 1, 1), width, width + 1, 2 * width + 3, 1000})


@pytest.mark.parametrize("name", [b for b in BUILDS if b != "scalar"])
def test_panda_batches_equal_the_scalar_functions_bit_for_bit(panda, name):
    rng = np.random.default_rng(26)
    width = panda["libs"][name][2]
    assert width == BUILDS[name][1]
    assert "panda_simd_sincos3(" in panda["batch"] and "panda_simd_sincos2(" not in panda["batch"]
    for function in ("inverse_dynamics", "mass_matrix", "forward_dynamics"):
        assert f"static void panda_simd_{function}(" in panda["batch"]  # a vector body, not the loop
        for count in _sizes(width):
            _check(panda, name, function, count, rng)


ROGER_BUILDS = [b for b in BUILDS if b != "scalar"] + list(AVX_ONLY)
#: a name holding the words the templates once substituted (VD, VU, VI, SELECT, ABS)
HOSTILE_NAME = "VIPER_SELECT_ABS_VU_VD"


@pytest.fixture(scope="module")
def roger(tmp_path_factory):
    robot = dataclasses.replace(example("roger_arm_values"), name=HOSTILE_NAME)
    ctx = context(robot, functions=("dynamics",))
    return _build_all(ctx, tmp_path_factory.mktemp("roger"), ROGER_BUILDS)


@pytest.mark.parametrize("name", ROGER_BUILDS)
def test_sines_of_one_and_of_two_angles_per_call(roger, name):
    """Roger's arm, named with capitals that once broke the templates' substitutions: its
    functions' angles come in calls of NAME_simd_sincosK with K = 1 and 2 (the Panda's six in two
    calls of three, the tree's in calls of 2 and 3), each bit for bit, with AVX2, AVX-512 and AVX
    alone (the C library's sine; -O3)."""
    assert (
        f"{HOSTILE_NAME}_simd_sincos1(" in roger["batch"]
        and f"{HOSTILE_NAME}_simd_sincos2(" in roger["batch"]
    )
    assert roger["libs"][name][2] == ALL_BUILDS[name][1]
    rng = np.random.default_rng(7)
    width = roger["libs"][name][2]
    for function in roger["table"]:
        for count in _sizes(width):
            _check(roger, name, function, count, rng)


@pytest.mark.parametrize("name", list(BUILDS))
def test_tree_batches_equal_the_scalar_functions_bit_for_bit(tree, name):
    """Every function of the dynamics and regressor groups, friction's sign and step included;
    float too (W doubled), and the scalar fallback (W = 1) without AVX."""
    _, builds = tree
    assert "ytree_simd_sincos_lanes(q" in builds["float"]["batch"]  # sinf and cosf in one lane loop
    assert "static void ytree_simd_base_regressor(" in builds["double"]["batch"]
    rng = np.random.default_rng(5)
    for precision, dtype in (("double", np.float64), ("float", np.float32)):
        build_ = builds[precision]
        width = build_["libs"][name][2]
        assert width == BUILDS[name][1] * (2 if precision == "float" and width > 1 else 1)
        for function in build_["table"]:
            for count in _sizes(width):
                _check(build_, name, function, count, rng, dtype)


DRIVER = r"""
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "ytree_dynamics.h"
typedef const double *in;
void ytree_inverse_dynamics_batch(long, in, in, in, in, double *);
void ytree_mass_matrix_batch(long, in, in, double *);
void ytree_forward_dynamics_batch(long, in, in, in, in, double *);
int ytree_batch_width(void);
#define N ytree_NDOF
int main(void)
{
    const long count = 2 * ytree_batch_width() + 3;
    double *q = malloc(sizeof(double) * count * N), *qd = malloc(sizeof(double) * count * N);
    double *u = malloc(sizeof(double) * count * N), *out = malloc(sizeof(double) * count * N * N);
    double one[N * N];
    long i, bad = 0;
    for (i = 0; i < count * N; ++i) {
        q[i] = 0.37 * (double)(i % 11) - 1.5; qd[i] = 0.11 * (double)(i % 7); u[i] = 0.5 - 0.05 * (double)i;
    }
    q[3] = 1e7;
    ytree_inverse_dynamics_batch(count, q, qd, u, NULL, out);
    for (i = 0; i < count; ++i) {
        ytree_inverse_dynamics(q + i * N, qd + i * N, u + i * N, NULL, one);
        bad += memcmp(one, out + i * N, sizeof(double) * N) != 0;
    }
    ytree_forward_dynamics_batch(count, q, qd, u, NULL, out);
    for (i = 0; i < count; ++i) {
        ytree_forward_dynamics(q + i * N, qd + i * N, u + i * N, NULL, one);
        bad += memcmp(one, out + i * N, sizeof(double) * N) != 0;
    }
    ytree_mass_matrix_batch(count, q, NULL, out);
    for (i = 0; i < count; ++i) {
        ytree_mass_matrix(q + i * N, NULL, one);
        bad += memcmp(one, out + i * N * N, sizeof(double) * N * N) != 0;
    }
    printf("%d %ld\n", ytree_batch_width(), bad);
    free(q); free(qd); free(u); free(out);
    return 0;
}
"""


@pytest.mark.parametrize("name", [b for b in BUILDS if b != "scalar"])
def test_the_vector_path_under_sanitizers(tree, tmp_path, name):
    """count = 2W + 3 states in buffers of exactly that size: no read or write outside them (the
    inputs' last rows are read under a mask), no undefined behaviour; W = 4 and, where the CPU has
    AVX-512, W = 8."""
    ctx, _ = tree
    flags, width = BUILDS[name]
    files = {**c_target.render(ctx), **render_runtime(ctx), "main.c": DRIVER}
    paths = [p for p in write_files(files, tmp_path) if p.suffix == ".c" and "symdyn_" not in p.name]
    exe = compile_program(paths, tmp_path / "driver", extra=(*SANITIZE_FLAGS, *flags))
    env = dict(os.environ, ASAN_OPTIONS="detect_leaks=1", UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1")
    proc = subprocess.run([str(exe)], capture_output=True, text=True, env=env, timeout=60)
    assert proc.returncode == 0 and "runtime error" not in proc.stderr, proc.stderr
    assert proc.stdout.split() == [str(width), "0"]


@pytest.fixture(scope="module")
def compiled():
    """planar_3r through symdyn.compile with its default flags (-O2 -march=native; the suite's
    conftest.py builds at -O0 without -march otherwise)."""
    robot = example("planar_3r")
    with pytest.MonkeyPatch.context() as mp:
        mp.delenv(build.ARCH_ENV, raising=False)
        mp.delenv(build.OPT_ENV, raising=False)
        return robot, symdyn.compile(robot)


def test_compiled_batches_without_copies_and_with_threads(compiled, monkeypatch):
    robot, fast = compiled
    monkeypatch.delenv(build.ARCH_ENV, raising=False)  # symdyn.compile's default flags, as `compiled`
    monkeypatch.delenv(build.OPT_ENV, raising=False)
    n = robot.n
    rng = np.random.default_rng(3)
    q, qd, qdd = (rng.uniform(-2, 2, (1001, n)) for _ in range(3))
    # the batch's own layout is passed as it is; other arrays are copied into it
    assert np.shares_memory(batch_layout(q, (1001,), n, 1001), q)
    assert np.shares_memory(batch_layout(q.reshape(7, 143, n), (7, 143), n, 1001), q)
    for other in (np.asfortranarray(q), q.astype(np.float32), q[::2], q[0]):
        lead = other.shape[:-1] if other.ndim > 1 else (1001,)
        count = int(np.prod(lead))
        flat = batch_layout(other, lead, n, count)
        assert not np.shares_memory(flat, other) and flat.flags.c_contiguous and flat.shape == (count, n)
    one = fast.inverse_dynamics(q, qd, qdd)
    assert np.array_equal(one, np.array([fast.inverse_dynamics(*s) for s in zip(q, qd, qdd, strict=True)]))
    oracle = symdyn.rnea(robot, q[:5], qd[:5], qdd[:5])
    np.testing.assert_allclose(one[:5], oracle, rtol=1e-10, atol=1e-10)
    monkeypatch.setattr(calling, "MIN_STATES_PER_THREAD", 16)  # 1001 states in up to 63 chunks
    for threads in (2, 3, 64):
        assert fast.inverse_dynamics(q, qd, qdd, threads=threads).tobytes() == one.tobytes()
        M = fast.mass_matrix(q, threads=threads)
        assert M.tobytes() == fast.mass_matrix(q).tobytes()
    M = np.full((1001, n, n), np.nan)  # out=: filled in place, the same bits, threads or not
    assert fast.mass_matrix(q, out=M, threads=3) is M and M.tobytes() == fast.mass_matrix(q).tobytes()
    tau = np.empty(n)
    assert fast.inverse_dynamics(q[0], qd[0], qdd[0], out=tau) is tau and np.array_equal(tau, one[0])
    for bad, message in (
        (np.empty((1001, n, n), dtype=np.float32), "C-contiguous float64 array of shape"),
        (np.empty((1000, n, n)), r"shape \(1001, 3, 3\), got float64 \(1000, 3, 3\)"),
        (np.empty((n, n, 1001)).T, "C-contiguous"),
        ((M, M), r"takes 1 array\(s\), got 2"),
    ):
        with pytest.raises(SymdynError, match=message):
            fast.mass_matrix(q, out=bad)
    with pytest.raises(SymdynError, match="share no memory with the inputs"):
        fast.inverse_dynamics(q, qd, qdd, out=q)
    threaded = symdyn.compile(robot, threads=2)
    assert threaded.threads == 2 and threaded.forward_dynamics(q, qd, qdd).tobytes() == (
        fast.forward_dynamics(q, qd, qdd).tobytes()
    )
    assert fast.batch_width == (8 if "avx512f" in CPU else 4 if "avx" in CPU else 1)
    for bad in (0, -1, 1.5, True, "2"):
        with pytest.raises(SymdynError, match="threads must be a whole number"):
            fast.inverse_dynamics(q, qd, qdd, threads=bad)
    with pytest.raises(SymdynError, match="threads must be a whole number"):
        symdyn.compile(robot, threads=0)


def test_the_cache_key_holds_the_flags_and_the_machine(monkeypatch):
    """-O2 -march=native by default, with the CPU's fingerprint in the key; $SYMDYN_MARCH another
    target (no fingerprint then: the library runs on any machine of that target), or none;
    $SYMDYN_OPT another optimisation level, in place of -O2."""
    from symdyn.apps.compilation.entry import build_options

    monkeypatch.delenv(build.ARCH_ENV, raising=False)
    monkeypatch.delenv(build.OPT_ENV, raising=False)
    native = build_options("newton-euler")
    assert "-march=native" in native["flags"] and native["machine"] == build.machine_fingerprint()
    assert "-ffp-contract=off" in native["flags"]
    assert [f for f in native["flags"] if f.startswith("-O")] == ["-O2"] and native["opt"] == "-O2"
    for level in build.OPT_LEVELS:
        monkeypatch.setenv(build.OPT_ENV, f" {level} ")
        options = build_options("newton-euler")
        assert [f for f in options["flags"] if f.startswith("-O")] == [f"-O{level}"] == [options["opt"]]
    for bad in ("-O3", "fast", "2 -fno-strict-aliasing", "4"):
        monkeypatch.setenv(build.OPT_ENV, bad)
        with pytest.raises(SymdynError, match=r"^\$SYMDYN_OPT=.* is not an optimisation level"):
            build_options("newton-euler")
    monkeypatch.delenv(build.OPT_ENV)
    monkeypatch.setenv(build.ARCH_ENV, "x86-64-v3")
    portable = build_options("newton-euler")
    assert "-march=x86-64-v3" in portable["flags"] and portable["machine"] is None
    monkeypatch.setenv(build.ARCH_ENV, "none")
    assert not any(f.startswith("-march") for f in build_options("newton-euler")["flags"])
    monkeypatch.setenv(build.ARCH_ENV, "native; rm -rf /")
    with pytest.raises(SymdynError, match="SYMDYN_MARCH"):
        build_options("newton-euler")


#: the widest vector build this CPU runs (the parts' test builds only it)
WIDEST = [b for b in BUILDS if b != "scalar"][-1:]


@pytest.fixture(scope="module")
def roger_in_parts(tmp_path_factory):
    """Roger's arm, fully symbolic (temporaries of the parameters alone: scalars in the vector
    body), with every function of more than 6 statements cut into parts of about 4, scalar and
    vector bodies alike (symdyn.codegen.c.vector_parts); the widest vector build."""
    ctx = context(example("roger_arm"), functions=("dynamics",))
    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(parts, "PART_ABOVE", 6)
        mp.setattr(parts, "PART_STATEMENTS", 4)
        mp.setattr(parts, "LIVE_ABOVE", 0)
        return ctx, _build_all(ctx, tmp_path_factory.mktemp("roger-parts"), WIDEST)


@pytest.mark.skipif(not WIDEST, reason="needs AVX2")
def test_vector_bodies_in_parts_equal_the_scalar_functions_bit_for_bit(roger_in_parts):
    """A large body's vector twin cut into parts (the temporaries a later part reads through a stash
    of vectors, a scalar one in lane 0 of its slot) still computes each lane as the scalar
    function, bit for bit."""
    ctx, build_ = roger_in_parts
    batch = build_["batch"]
    assert "static __attribute__((noinline)) void roger_arm_simd_mass_matrix_part2(" in batch
    assert "roger_arm_simd_stash[" in batch and "][0] = " in batch  # a scalar through the stash
    rng = np.random.default_rng(8)
    params = rng.uniform(0.5, 2.0, len(ctx.robot.params))
    width = BUILDS[WIDEST[0]][1]
    for function in build_["table"]:
        for count in (1, width + 1, 2 * width + 3):
            _check(build_, WIDEST[0], function, count, rng, params=params)


@pytest.mark.skipif(not WIDEST, reason="needs AVX2")
def test_batch_files_of_a_large_robot_equal_the_scalar_functions_bit_for_bit(roger_in_parts, tmp_path):
    """The batch wrappers spread over several files as a large robot's (symdyn.codegen.c.vector_files):
    each block and wrapper defined once, a part in another file than its block hidden and declared
    in NAME_batch_parts.h (-Wmissing-prototypes), the same bytes twice, and every lane still the
    scalar function, bit for bit."""
    ctx, _ = roger_in_parts
    with pytest.MonkeyPatch.context() as mp:
        for name, value in (
            ("PART_ABOVE", 6),
            ("PART_STATEMENTS", 4),
            ("LIVE_ABOVE", 0),
            ("SPLIT_BYTES", 16_000),
        ):
            mp.setattr(parts, name, value)
        spread = _build_all(ctx, tmp_path, WIDEST, ("-Wmissing-prototypes", "-Wmissing-declarations"))
        again = render_runtime(ctx)
    files = spread["files"]
    assert again == {name: text for name, text in files.items() if name in again}  # the same bytes
    batch = sorted(n for n in files if n.startswith("roger_arm_batch"))
    assert len(batch) >= 3 and "roger_arm_batch_parts.h" in batch and "roger_arm_batch_2.c" in batch
    sources = [files[n] for n in batch if n.endswith(".c")]
    for f in ["batch_width", *(f"{name}_batch" for name in spread["table"])]:
        assert sum(len(re.findall(rf"^(?:int|void) roger_arm_{f}\(.*\)$", s, re.M)) for s in sources) == 1, f
    hidden = re.findall(r"roger_arm_SIMD_HIDDEN void (\w+)\(", files["roger_arm_batch_parts.h"])
    assert hidden and all(
        sum(f"roger_arm_SIMD_HIDDEN __attribute__((noinline)) void {h}(" in s for s in sources) == 1
        for h in hidden
    )
    library = ctypes.CDLL(str(tmp_path / f"{WIDEST[0]}.so"))
    assert hasattr(library, "roger_arm_mass_matrix_batch") and not any(hasattr(library, h) for h in hidden)
    rng = np.random.default_rng(9)
    params = rng.uniform(0.5, 2.0, len(ctx.robot.params))
    width = BUILDS[WIDEST[0]][1]
    for function in spread["table"]:
        _check(spread, WIDEST[0], function, 2 * width + 3, rng, params=params)
