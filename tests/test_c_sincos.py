"""The sines and cosines of generated C (symdyn.codegen.c.sincos, templates/c/sincos.c.j2).

With AVX2 each generated function computes the sines and cosines of all its angles in one call
of the file's helper NAME_sincos; without it, the C library's sin and cos where they are used.
The helper is judged against the C library (at most 1 ulp apart, counted as the number of
doubles between the two results, over a million arguments and the special ones), and the
generated functions compiled with AVX2 against the numeric oracle symdyn.rnea. The tests of
tests/test_c_target.py compile without -mavx2, so they cover the C library's path.
"""

from __future__ import annotations

import dataclasses
import functools
import importlib
import platform
import re
import subprocess
from pathlib import Path

import numpy as np
import pytest
import sympy as sp
from cbuild import (
    SANITIZE_FLAGS,
    STRICT_FLAGS,
    TEST_OPT,
    build_dynamics,
    compile_program,
    compilers,
    write_files,
)
from robots import (
    EXAMPLE_NAMES,
    assert_close,
    example,
    example_context,
    random_params,
    random_state,
    tree_robot,
    y_robot,
)

import symdyn.codegen
from symdyn.codegen import c as c_backend
from symdyn.codegen.c.sincos import BLOCK, gather
from symdyn.model.robot import Mimic

oracle = importlib.import_module("symdyn.rnea")  # the module (symdyn.rnea is also the function)

#: The builds that take the vector path: -O2 and -O3, with and without FMA contraction (-std=c99
#: turns contraction off; -ffp-contract=fast is GNU C's default), and the machine's own CPU.
VECTOR_BUILDS = {
    "O2 avx2": ("-O2", "-mavx2"),
    "O3 avx2 fma": ("-O3", "-mavx2", "-mfma"),
    "O3 avx2 fma contracted": ("-O3", "-mavx2", "-mfma", "-ffp-contract=fast"),
    "O3 native": ("-O3", "-march=native"),
}


def _has_avx2() -> bool:
    """An x86-64 CPU with AVX2 (then the vector path can run here) and gcc to compile it."""
    if platform.machine().lower() not in ("x86_64", "amd64") or "gcc" not in compilers():
        return False
    try:
        cpuinfo = Path("/proc/cpuinfo").read_text()
    except OSError:
        return False
    return any(line.startswith("flags") and " avx2" in line for line in cpuinfo.splitlines())


needs_avx2 = pytest.mark.skipif(not _has_avx2(), reason="needs gcc and an x86-64 CPU with AVX2")


def _mimic_chain():
    """A chain whose third joint follows the first, q3 = 0.3 - 2 q1: angles that are not joints."""
    return tree_robot(
        "mimic3",
        (-1, 0, 1),
        ("revolute", "prismatic", "revolute"),
        31,
        {2: Mimic(0, sp.Float(-2), sp.Float(0.3))},
    )


ROBOTS = {
    "puma560": lambda: example("puma560"),
    "panda": lambda: example("panda"),
    "ytree": y_robot,
    "mimic3": _mimic_chain,
}


# --- gathering the angles ----------------------------------------------------------------


def test_gather_resolves_temporaries_and_drops_dead_ones():
    q1, q2, x0, x1, x2 = sp.symbols("q1 q2 x0 x1 x2")
    a = q1 - sp.Rational(1, 3)
    temporaries = [(x0, a), (x1, sp.sin(x0) * q2), (x2, sp.cos(q2) + sp.cos(a))]
    trig = gather(temporaries, [x1 + x2, sp.sin(q2) * sp.sin(sp.Integer(1))])
    assert trig.angles == (a, q2)  # sin(x0) and cos(q1 - 1/3) share one angle; sin(1) is a constant
    assert trig.calls == {sp.sin(x0): (0, 0), sp.cos(q2): (1, 1), sp.cos(a): (1, 0), sp.sin(q2): (0, 1)}
    assert trig.live == {x1, x2}  # x0 was read only as an angle
    assert trig.size == BLOCK


def test_float_keeps_the_library_calls_and_double_reads_the_arrays():
    """The PUMA's C in double and in float precision, over the session's derivation
    (`_rendered`: symdyn.codegen.render's context, robots.example_context)."""
    _, ctx, files = _rendered("puma560")
    double = files["puma560_dynamics.c"]
    single = c_backend.render(dataclasses.replace(ctx, precision="float"))["puma560_dynamics.c"]
    assert "sincos" not in single and "sinf(" in single
    functions: dict[str, str] = {}  # each function's text with its parts' (symdyn.codegen.c.parts)
    for m in re.finditer(r"^(?:static \w+ )?void puma560_(\w+?)(?:_part\d+)?\(.*?^}", double, re.M | re.S):
        functions[m.group(1)] = functions.get(m.group(1), "") + m.group(0)
    assert len(functions) == len(ctx.functions)
    for body in functions.values():
        assert not re.search(r"\b(sin|cos)\(", body)  # only the macros, which the helper's arrays back
        uses = "puma560_SIN(" in body or "puma560_COS(" in body
        assert body.count("puma560_sincos(") == uses


# --- the helper against the C library ------------------------------------------------------

ACCURACY = r"""
#include <stdint.h>
#include <stdio.h>
#include <string.h>
#include "puma560_dynamics.c"

#ifndef puma560_SINCOS_VECTOR
#error "the vector path is off"
#endif

#define N 4096

static uint64_t state = 88172645463325252u;
static double uniform(void) /* xorshift64, in [-1, 1) */
{
    state ^= state << 13;
    state ^= state >> 7;
    state ^= state << 17;
    return (double)(state >> 11) / 4503599627370496.0 - 1.0;
}

static int64_t ordinal(double y) /* doubles in order: neighbours differ by 1 (+0 and -0 are 0) */
{
    int64_t i;
    memcpy(&i, &y, sizeof i);
    return i < 0 ? -(i & INT64_MAX) : i;
}

static double worst[2], worst_at[2];
static long bad;

static void check(const double *x, int n)
{
    static double s[N], c[N];
    int k;
    puma560_sincos(n, x, s, c);
    for (k = 0; k < n; ++k) {
        const double want[2] = {sin(x[k]), cos(x[k])}, got[2] = {s[k], c[k]};
        int f;
        for (f = 0; f < 2; ++f) {
            if (isnan(want[f])) {
                bad += !isnan(got[f]);
            } else {
                /* |sin|, |cos| <= 1: the ordinals are below 2^62, their difference fits */
                const double d = fabs((double)(ordinal(got[f]) - ordinal(want[f])));
                bad += !(d <= 1.0) || signbit(got[f]) != signbit(want[f]);
                if (d > worst[f]) {
                    worst[f] = d;
                    worst_at[f] = x[k];
                }
            }
        }
    }
}

int main(void)
{
    static const double ranges[] = {1e-300, 1e-9, 1e-4, 0.5, 1.0, 3.2, 10.0, 100.0, 1e4, 823549.0, 1e7};
    static double x[N];
    const double pio2 = 1.5707963267948966;
    int r, t, k, n = 0;
    for (r = 0; r < (int)(sizeof ranges / sizeof ranges[0]); ++r) {
        for (t = 0; t < 24; ++t) {
            for (k = 0; k < N; ++k) {
                x[k] = uniform() * ranges[r];
            }
            check(x, N);
            n += N;
        }
    }
    /* multiples of pi/2 and their neighbours, zeros, infinities, NaN, the libm threshold */
    for (k = 0; k < N / 4 - 4; ++k) {
        const double m = (k - N / 8) * pio2 * (k % 2 ? 1.0 : 1000.0);
        x[3 * k] = m;
        x[3 * k + 1] = nextafter(m, INFINITY);
        x[3 * k + 2] = nextafter(m, -INFINITY);
    }
    k = 3 * (N / 4 - 4);
    x[k++] = 0.0;
    x[k++] = -0.0;
    x[k++] = INFINITY;
    x[k++] = -INFINITY;
    x[k++] = NAN;
    x[k++] = -NAN;
    x[k++] = 823549.6;
    x[k++] = nextafter(823549.6, 0.0);
    x[k++] = -823549.6;
    x[k++] = 524288.0 * pio2;
    x[k++] = 1e22;
    x[k++] = -1.7976931348623157e308;
    x[k++] = 4.9406564584124654e-324;
    x[k++] = -4.9406564584124654e-324;
    x[k++] = 0x1p-27;
    x[k++] = -0x1p-28;
    check(x, k); /* k is not a multiple of 4: the entries past k are finite and unread */
    n += k;
    printf("%d %ld %.1f %.17g %.1f %.17g\n", n, bad, worst[0], worst_at[0], worst[1], worst_at[1]);
    return 0;
}
"""


@pytest.fixture(scope="module")
def puma_files(tmp_path_factory):
    out = tmp_path_factory.mktemp("puma_sincos")
    write_files(_rendered("puma560")[2], out)
    return out


@needs_avx2
@pytest.mark.parametrize("build", sorted(VECTOR_BUILDS))
def test_helper_within_one_ulp_of_the_c_library(puma_files, build, tmp_path):
    (tmp_path / "accuracy.c").write_text(ACCURACY)
    exe = compile_program(
        [tmp_path / "accuracy.c"], tmp_path / "accuracy", "gcc", VECTOR_BUILDS[build][0],
        extra=(*VECTOR_BUILDS[build][1:], f"-I{puma_files}"),
    )  # fmt: skip
    run = subprocess.run([str(exe)], capture_output=True, text=True, timeout=120)
    assert run.returncode == 0, run.stderr
    count, bad, worst_sin, at_sin, worst_cos, at_cos = run.stdout.split()
    assert int(count) > 1_000_000
    assert int(bad) == 0, f"{build}: sin {worst_sin} apart at {at_sin}, cos {worst_cos} apart at {at_cos}"
    assert float(worst_sin) <= 1 and float(worst_cos) <= 1


@needs_avx2
def test_helper_is_vector_code(puma_files, tmp_path):
    """The point of the helper: with -O2 -mavx2 its loop is 4-wide AVX (ymm) code."""
    asm = tmp_path / "puma.s"
    subprocess.run(
        ["gcc", *STRICT_FLAGS, "-O2", "-mavx2", "-S", "-o", str(asm), str(puma_files / "puma560_dynamics.c")],
        check=True,
    )
    text = asm.read_text()
    body = text[text.index("puma560_sincos:") : text.index(".size\tpuma560_sincos")]
    assert re.search(r"\tv(mul|add|sub)pd\t.*%ymm", body), "the helper's loop was not vectorised"


# --- the generated functions with the vector path --------------------------------------------


@functools.cache
def _rendered(name: str):
    """(robot, context, C files), the files rendered from the context: one derivation, for the
    example robots the one of the whole test process (tests/robots.py)."""
    robot = ROBOTS[name]()
    ctx = example_context(name) if name in EXAMPLE_NAMES else symdyn.codegen.context(robot)
    return robot, ctx, c_backend.render(ctx)


#: The optimisation level of each robot's AVX2 build. -O3 (the vector code as it is meant to be
#: compiled: the helper's loop vectorised, `restrict` relied on) for the PUMA and the mimic
#: chain; the Panda and the tree at the suite's TEST_OPT (-O0), still with -mavx2, so still the
#: vector path (the macros reading the helper's arrays, chosen by __AVX2__ alone) over seven
#: joints and over a tree's general axes: their values do not depend on the level (no
#: -ffast-math, cbuild's docstring), the helper's -O2/-O3 builds are judged above, and gcc -O3
#: costs ten seconds on the Panda's file and 3.4 s on the tree's 530 KB (-O0: 0.7 s).
VECTOR_OPT = {"puma560": "-O3", "ytree": TEST_OPT, "mimic3": "-O3", "panda": TEST_OPT}


@needs_avx2
@pytest.mark.parametrize("name", sorted(ROBOTS))
def test_functions_with_the_vector_path_match_rnea(name, tmp_path):
    robot, _, files = _rendered(name)
    lib = build_dynamics(files, tmp_path, robot.name, opt=VECTOR_OPT[name], extra=("-mavx2", "-mfma"))
    rng = np.random.default_rng(15)
    for _ in range(20):
        q, qd, qdd = random_state(robot, rng)
        p = random_params(robot, rng)
        params = {str(s): v for s, v in zip(robot.params, p, strict=True)} or None
        pv = p if len(p) else None
        tau = oracle.rnea(robot, q, qd, qdd, params)
        V = oracle.bias_torque(robot, q, qd, params)
        assert_close(lib.inverse_dynamics(q, qd, qdd, pv), tau, 1e-9, "tau")
        assert_close(lib.mass_matrix(q, pv), oracle.mass_matrix(robot, q, params), 1e-9, "M")
        assert_close(lib.coriolis(q, qd, pv), V, 1e-9, "V")
        assert_close(lib.coriolis_matrix(q, qd, pv) @ qd, V, 1e-9, "C qd")
        assert_close(lib.gravity(q, pv), oracle.gravity_torque(robot, q, params), 1e-9, "G")
        assert_close(lib.forward_dynamics(q, qd, tau, pv), qdd, 1e-8, "qdd")


@needs_avx2
@pytest.mark.parametrize("name", ["mimic3", "puma560"])
def test_functions_with_the_vector_path_under_the_sanitizers(name, tmp_path):
    """Every function of the file once, with -mavx2, under ASan and UBSan (the helper reads and
    writes the padded arrays). Built at the suite's TEST_OPT (-O0): the sanitizers check every
    access unoptimised as well (cbuild's docstring), -O1 does not vectorise the helper's loop
    either, and gcc -O1 with the sanitizers took 9 s of one core on the PUMA's file (-O0: 1.2 s)."""
    robot, ctx, files = _rendered(name)
    out = tmp_path
    write_files(files, out)
    name, n, k = robot.name, robot.n, len(robot.params)
    inputs = {"q": "q", "qd": "qd", "qdd": "qdd", "tau": "qdd", "p": "p"}
    lines = [
        f'#include "{name}_dynamics.h"',
        "#include <stdlib.h>",
        "int main(void) {",
        f"    double q[{n}], qd[{n}], qdd[{n}], p[{k + 1}];",
        "    int i;",
        f"    for (i = 0; i < {n}; ++i) {{ q[i] = 0.4 * i - 1.0; qd[i] = 0.2 - 0.05 * i; qdd[i] = 0.3; }}",
        f"    for (i = 0; i < {k + 1}; ++i) p[i] = 1.0 + 0.1 * i;",
    ]
    for spec in ctx.functions:
        outputs = [f"{r.name}_{spec.name}" for r in spec.results]
        lines += [
            f"    double *{o} = malloc({r.rows * r.cols} * sizeof(double));"
            for o, r in zip(outputs, spec.results, strict=True)
        ]
        lines.append(f"    {name}_{spec.name}({', '.join([inputs[i.name] for i in spec.inputs] + outputs)});")
        lines += [f"    free({o});" for o in outputs]
    driver = tmp_path / "driver.c"
    driver.write_text("\n".join([*lines, "    return 0;", "}", ""]))
    exe = compile_program(
        [driver, out / f"{name}_dynamics.c"], tmp_path / "driver", "gcc", TEST_OPT,
        (*STRICT_FLAGS, *SANITIZE_FLAGS, "-mavx2", f"-I{out}"),
    )  # fmt: skip
    run = subprocess.run([str(exe)], capture_output=True, text=True, timeout=120)
    assert run.returncode == 0 and "runtime error" not in run.stderr, run.stderr
