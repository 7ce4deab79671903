"""The C that symdyn.compile adds (NAME_batch.c, symdyn_step.c, symdyn_csv.c) under the C contract's flags.

The files compile with -std=c99 -Wall -Wextra -Wpedantic -Werror (gcc and clang when installed),
and a small program runs the stepping loop (RK4, a torque table and the computed-torque law) and
a batch wrapper under -fsanitize=address,undefined; its numbers must be those of symdyn.simulate.
Another runs the CSV writer under the sanitizers on awkward doubles; its text must be Python's "%.17g".
"""

from __future__ import annotations

import os
import subprocess
from pathlib import Path

import numpy as np
import pytest
from cbuild import SANITIZE_FLAGS, compile_program, compile_shared, compilers, write_files

import symdyn
from symdyn.apps.simulation.control import ComputedTorque, Reference, track
from symdyn.apps.simulation.csv_format import csv_text
from symdyn.apps.simulation.simulate import simulate
from symdyn.codegen import c as c_target
from symdyn.codegen import context
from symdyn.codegen.c.runtime import render_runtime

pytestmark = pytest.mark.skipif(not compilers(), reason="needs a C compiler")

STEPS, H = 50, 2e-3

# A driver: 50 RK4 steps of planar_3r from q0 under a constant torque table, then under the
# computed-torque law with a reference table given on stdin, then one batch of mass matrices.
DRIVER = r"""
#include <stdio.h>
#include "planar_3r_dynamics.h"
typedef void (*fn4)(const double *, const double *, const double *, const double *, double *);
typedef void (*fn2)(const double *, const double *, double *);
long symdyn_simulate(int, int, long, long, const double *, fn4, const double *, const double *, fn4, fn2,
    const double *, const double *, const double *, const double *, double *, double *, double *, double *);
void planar_3r_mass_matrix_batch(long, const double *, const double *, double *);
#define N 3
#define STEPS 50
static double Q[(STEPS + 1) * N], QD[(STEPS + 1) * N], U[(STEPS + 1) * N], W[12 * N];
static double table[(3 * STEPS + 1) * N], ref[(3 * STEPS + 1) * 3 * N], h[STEPS];
int main(void)
{
    const double Kp[9] = {100, 0, 0, 0, 100, 0, 0, 0, 100}, Kd[9] = {20, 0, 0, 0, 20, 0, 0, 0, 20};
    double qs[2 * N] = {0.1, 0.2, 0.3, -0.4, 0.5, 0.6}, M[2 * N * N];
    long k, i;
    for (k = 0; k < STEPS; ++k) h[k] = 2e-3;
    for (i = 0; i < (3 * STEPS + 1) * N; ++i) table[i] = 0.5;
    for (i = 0; i < (3 * STEPS + 1) * 3 * N; ++i) {
        if (scanf("%lf", &ref[i]) != 1) return 2;
    }
    for (i = 0; i < N; ++i) { Q[i] = 0.1 * (i + 1); QD[i] = 0.0; }
    if (symdyn_simulate(N, 0, 0, STEPS, h, planar_3r_forward_dynamics, NULL, table, NULL, NULL, NULL, NULL,
                        NULL, NULL, Q, QD, U, W) != -1) return 3;
    for (i = 0; i < N; ++i) printf("%.17g ", Q[STEPS * N + i]);
    printf("\n");
    for (i = 0; i < N; ++i) { Q[i] = ref[i]; QD[i] = ref[N + i]; }
    if (symdyn_simulate(N, 0, 0, STEPS, h, planar_3r_forward_dynamics, NULL, NULL, planar_3r_inverse_dynamics,
                        NULL, NULL, ref, Kp, Kd, Q, QD, U, W) != -1) return 4;
    for (i = 0; i < N; ++i) printf("%.17g ", Q[STEPS * N + i]);
    printf("\n");
    planar_3r_mass_matrix_batch(2, qs, NULL, M);
    for (i = 0; i < 2 * N * N; ++i) printf("%.17g ", M[i]);
    printf("\n");
    return 0;
}
"""


@pytest.fixture(scope="module")
def files():
    robot = symdyn.load_robot(Path(__file__).resolve().parent.parent / "examples" / "planar_3r.yaml")
    ctx = context(robot)
    return robot, {**c_target.render(ctx), **render_runtime(ctx)}


@pytest.mark.parametrize("compiler", compilers())
def test_runtime_compiles_with_warnings_as_errors(files, compiler, tmp_path):
    _, sources = files
    paths = write_files(sources, tmp_path)
    compile_shared([p for p in paths if p.suffix == ".c"], tmp_path / "lib.so", compiler=compiler)


def test_stepping_loop_under_sanitizers_equals_simulate(files, tmp_path):
    robot, sources = files
    paths = write_files({**sources, "main.c": DRIVER}, tmp_path)
    exe = compile_program([p for p in paths if p.suffix == ".c"], tmp_path / "driver", extra=SANITIZE_FLAGS)
    reference = Reference(["0.3*sin(2*t)", "0.2*cos(t)", "t/4"])
    t = np.arange(STEPS + 1) * H
    rows = np.empty(3 * STEPS + 1)
    rows[0:-1:3], rows[1:-1:3], rows[2:-1:3], rows[-1] = t[:-1], t[:-1] + H / 2, t[:-1] + H, t[-1]
    table = np.concatenate(reference(rows), axis=1)
    env = dict(os.environ, ASAN_OPTIONS="detect_leaks=1", UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1")
    stdin = " ".join(f"{x:.17g}" for x in table.ravel())
    proc = subprocess.run([str(exe)], input=stdin, capture_output=True, text=True, env=env, timeout=60)
    assert proc.returncode == 0 and "runtime error" not in proc.stderr, proc.stderr
    lines = [np.array([float(x) for x in line.split()]) for line in proc.stdout.splitlines()]
    duration = STEPS * H
    free = simulate(robot, [0.1, 0.2, 0.3], duration=duration, dt=H, tau=[0.5] * 3)
    np.testing.assert_allclose(lines[0], free.q[-1], rtol=1e-12, atol=1e-12)
    tracked = track(robot, reference, ComputedTorque(robot, 100, 20), duration=duration, dt=H)
    np.testing.assert_allclose(lines[1], tracked.q[-1], rtol=1e-12, atol=1e-12)
    plant = symdyn.compile(robot)
    M = plant.module.mass_matrix(np.array([[0.1, 0.2, 0.3], [-0.4, 0.5, 0.6]]))
    np.testing.assert_allclose(lines[2], M.ravel(), rtol=1e-12, atol=1e-12)


# A driver of the CSV writer: doubles as bit patterns (hexadecimal, one a line) on stdin, one row of
# COLS values per line of CSV on stdout.
CSV_DRIVER = r"""
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
long symdyn_csv(long rows, int cols, const double x[], char out[]);
#define COLS 4
int main(void)
{
    static double x[4096];
    static char out[4096 * 25];
    unsigned long long bits;
    long count = 0, n;
    while (count < 4096 && scanf("%llx", &bits) == 1) {
        memcpy(&x[count++], &bits, sizeof bits);
    }
    n = symdyn_csv(count / COLS, COLS, x, out);
    fwrite(out, 1, (size_t)n, stdout);
    return 0;
}
"""


def test_csv_writer_under_sanitizers_equals_python(files, tmp_path):
    """Python's "%.17g" (tests/test_csv_format.py has the long lists): here the bounds and shifts."""
    _, sources = files
    paths = write_files({"symdyn_csv.c": sources["symdyn_csv.c"], "main.c": CSV_DRIVER}, tmp_path)
    exe = compile_program(paths, tmp_path / "csv", extra=SANITIZE_FLAGS)
    rng = np.random.default_rng(3)
    values = [0.0, -0.0, 0.1, -1e-300, 1e300, 5e-324, 1.7976931348623157e308, float("nan"), -float("inf")]
    values += [2.0**53, 2.0**127, 2.0**128, 1e16, 1e17, 9.9999999999999984e16, 1e-5, 9.9999999999999991e-5]
    values += [float(f"1e{k}") for k in range(-30, 40)] + list(rng.standard_normal(1000) * 1e3)
    values += list(rng.integers(0, 2**64, 2000, dtype=np.uint64).view(np.float64))
    values = np.resize(np.array(values), (len(values) // 4, 4))
    stdin = "\n".join(f"{b:x}" for b in values.ravel().view(np.uint64))
    env = dict(os.environ, UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1")
    proc = subprocess.run([str(exe)], input=stdin, capture_output=True, text=True, env=env, timeout=60)
    assert proc.returncode == 0 and "runtime error" not in proc.stderr, proc.stderr
    assert proc.stdout == csv_text([], values)[1:]  # without the (empty) header line
