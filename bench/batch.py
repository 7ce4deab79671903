"""Speed of the SIMD batch wrappers (issue 26): NAME_batch against the scalar function in a C loop.

    python bench/batch.py            # 100,000 states; identify on a one-million-sample log
    python bench/batch.py --quick    # 10,000 states; 100,000 samples

Part 1: the Panda's inverse dynamics, M and forward dynamics. A C harness links NAME_dynamics.c
and NAME_batch.c compiled with symdyn.compile's own flags (symdyn.apps.compilation.build: COMPILE_FLAGS and
-march=native unless $SYMDYN_MARCH says otherwise) and times, over the same states, the scalar
function called once per state in a C loop and one call of NAME_batch (the best of 15 rounds,
interleaved); it also checks that both give the same bits. Then the batch through Python
(symdyn.compile's method: output arrays allocated per call, and out= reusing one) with threads=1
and threads=2, over the same number of states and over ten times as many.
Part 2: `symdyn identify` on a million-sample log of the Panda, stage by stage and end to end
(bench/identify.py).
The table goes to stdout and to bench/results/batch.txt.
"""

from __future__ import annotations

import argparse
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))

from identify import identify_part  # noqa: E402
from identify import lines as identify_lines  # noqa: E402
from machine import RESULTS, load_averages, log, machine, project_path  # noqa: E402

import symdyn  # noqa: E402
from symdyn.apps.compilation.build import COMPILE_FLAGS, arch_flags, find_compiler  # noqa: E402
from symdyn.codegen import c as c_target  # noqa: E402
from symdyn.codegen import context  # noqa: E402
from symdyn.codegen.c.runtime import render_runtime  # noqa: E402

ROOT = Path(__file__).resolve().parent.parent
FUNCTIONS = ("inverse_dynamics", "mass_matrix", "forward_dynamics")
ROUNDS = 15

HARNESS = r"""
#define _POSIX_C_SOURCE 199309L
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include "panda_dynamics.h"
typedef const double *in;
void panda_inverse_dynamics_batch(long, in, in, in, in, double *);
void panda_mass_matrix_batch(long, in, in, double *);
void panda_forward_dynamics_batch(long, in, in, in, in, double *);
int panda_batch_width(void);
#define N panda_NDOF
static double now(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}
int main(int argc, char **argv)
{
    const long count = atol(argv[1]);
    double *q = malloc(sizeof(double) * count * N), *qd = malloc(sizeof(double) * count * N);
    double *u = malloc(sizeof(double) * count * N);
    double *a = malloc(sizeof(double) * count * N * N), *b = malloc(sizeof(double) * count * N * N);
    double best[3][2] = {{1e30, 1e30}, {1e30, 1e30}, {1e30, 1e30}};
    unsigned long long s = 2026;
    long i;
    int r, f, same[3] = {1, 1, 1};
    (void)argc;
    for (i = 0; i < count * N; ++i) { /* uniform in [-2, 2) from a 64-bit LCG */
        s = s * 6364136223846793005ULL + 1442695040888963407ULL;
        q[i] = 4.0 * (double)(s >> 11) / 9007199254740992.0 - 2.0;
        s = s * 6364136223846793005ULL + 1442695040888963407ULL;
        qd[i] = 4.0 * (double)(s >> 11) / 9007199254740992.0 - 2.0;
        s = s * 6364136223846793005ULL + 1442695040888963407ULL;
        u[i] = 4.0 * (double)(s >> 11) / 9007199254740992.0 - 2.0;
    }
    for (r = 0; r < ROUNDS; ++r) {
        for (f = 0; f < 3; ++f) {
            const long size = f == 1 ? N * N : N;
            double t0, t1, t2;
            t0 = now();
            for (i = 0; i < count; ++i) {
                if (f == 0) panda_inverse_dynamics(q + i * N, qd + i * N, u + i * N, NULL, a + i * size);
                else if (f == 1) panda_mass_matrix(q + i * N, NULL, a + i * size);
                else panda_forward_dynamics(q + i * N, qd + i * N, u + i * N, NULL, a + i * size);
            }
            t1 = now();
            if (f == 0) panda_inverse_dynamics_batch(count, q, qd, u, NULL, b);
            else if (f == 1) panda_mass_matrix_batch(count, q, NULL, b);
            else panda_forward_dynamics_batch(count, q, qd, u, NULL, b);
            t2 = now();
            if (t1 - t0 < best[f][0]) best[f][0] = t1 - t0;
            if (t2 - t1 < best[f][1]) best[f][1] = t2 - t1;
            same[f] = same[f] && memcmp(a, b, sizeof(double) * count * size) == 0;
        }
    }
    printf("%d\n", panda_batch_width());
    for (f = 0; f < 3; ++f) {
        printf("%.3f %.3f %d\n", 1e9 * best[f][0] / count, 1e9 * best[f][1] / count, same[f]);
    }
    return 0;
}
"""


def c_part(count: int, folder: Path) -> tuple[int, list[tuple[str, float, float, bool]], list[str]]:
    """(W, [(function, scalar ns/state, batch ns/state, same bits)], flags) from the C harness."""
    robot = symdyn.load_robot(ROOT / "examples" / "panda.yaml")
    ctx = context(robot, functions=("dynamics",))
    files = {**c_target.render(ctx), **render_runtime(ctx), "main.c": HARNESS}
    for name, text in files.items():
        (folder / name).write_text(text, encoding="utf-8")
    compiler = find_compiler()
    flags = [f for f in COMPILE_FLAGS if f not in ("-shared", "-fPIC")] + list(arch_flags())
    objects = []
    jobs = []
    for name in ("panda_dynamics.c", "panda_batch.c"):
        objects.append(name[:-2] + ".o")
        jobs.append(subprocess.Popen([*compiler, *flags, "-c", name, "-o", objects[-1]], cwd=folder))
    assert all(job.wait() == 0 for job in jobs)
    harness = [*compiler, *flags, f"-DROUNDS={ROUNDS}", "main.c", *objects, "-o", "harness", "-lm"]
    subprocess.run(harness, cwd=folder, check=True)
    out = subprocess.run([str(folder / "harness"), str(count)], capture_output=True, text=True, check=True)
    lines = out.stdout.split("\n")
    rows = []
    for name, line in zip(FUNCTIONS, lines[1:4], strict=True):
        scalar, batch, same = line.split()
        rows.append((name, float(scalar), float(batch), same == "1"))
    return int(lines[0]), rows, flags


def python_part(count: int) -> dict[str, dict[tuple[int, bool], float]]:
    """ns per state of symdyn.compile's batch methods, {(threads, out=): ns} for threads 1 and 2,
    each with a fresh output array and with out= (one array reused); best of 5, interleaved."""
    robot = symdyn.load_robot(ROOT / "examples" / "panda.yaml")
    fast = symdyn.compile(robot)
    rng = np.random.default_rng(7)
    q, qd, u = (rng.uniform(-2, 2, (count, robot.n)) for _ in range(3))
    T, M = np.empty((count, robot.n)), np.empty((count, robot.n, robot.n))
    calls = {
        "inverse_dynamics": lambda t, o: fast.inverse_dynamics(q, qd, u, threads=t, out=T if o else None),
        "mass_matrix": lambda t, o: fast.mass_matrix(q, threads=t, out=M if o else None),
        "forward_dynamics": lambda t, o: fast.forward_dynamics(q, qd, u, threads=t, out=T if o else None),
    }
    result = {}
    for name, call in calls.items():
        best = {(t, o): float("inf") for t in (1, 2) for o in (False, True)}
        for _ in range(5):
            for key in best:
                t0 = time.perf_counter()
                call(*key)
                best[key] = min(best[key], 1e9 * (time.perf_counter() - t0) / count)
        result[name] = best
    return result


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true")
    args = parser.parse_args()
    count, samples = (10_000, 100_000) if args.quick else (100_000, 1_000_000)
    lines = [f"# bench/batch.py: {machine()}; load averages at the start {load_averages()}", ""]
    with tempfile.TemporaryDirectory(prefix="symdyn-batch-") as tmp:
        log("C harness")
        width, rows, flags = c_part(count, Path(tmp))
        log("Python methods")
        py = python_part(count)
        big = python_part(10 * count)
        log("identify")
        ident = identify_part(samples, Path(tmp))
    lines += [
        f"Panda, {count:,} states, flags {' '.join(flags)}; W = {width} doubles per instruction",
        "",
        f"{'function':<18}  {'scalar C loop ns':>16}  {'batch ns':>8}  {'batch/scalar':>12}"
        f"  {'same bits':>9}  {'Python batch ns':>15}  {'with out= ns':>12}  {'threads=2 ns':>12}",
        "-" * 118,
    ]
    for name, scalar, batch, same in rows:
        b = py[name]
        lines.append(
            f"{name:<18}  {scalar:>16.1f}  {batch:>8.1f}  {batch / scalar:>11.2f}x"
            f"  {'yes' if same else 'NO':>9}  {b[1, False]:>15.1f}  {b[1, True]:>12.1f}  {b[2, False]:>12.1f}"
        )
    lines += [
        "",
        f"threads through Python at {10 * count:,} states, ns per state (best of 5), a fresh output"
        " array / out= (one reused):",
    ]
    for name, b in big.items():
        lines.append(
            f"  {name:<18} threads=1 {b[1, False]:7.1f} / {b[1, True]:7.1f}  threads=2 {b[2, False]:7.1f} /"
            f" {b[2, True]:7.1f}  ratio {b[2, False] / b[1, False]:.2f} / {b[2, True] / b[1, True]:.2f}"
        )
    target = all(batch / scalar <= 0.4 for _, scalar, batch, _ in rows)
    lines += [
        "",
        f"target batch <= 0.4x scalar per state: {'PASS' if target else 'FAIL'} "
        f"({', '.join(f'{n} {b / s:.2f}x' for n, s, b, _ in rows)})",
        "",
        *identify_lines(samples, ident),
    ]
    lines += ["", f"# load averages at the end {load_averages()}"]
    text = "\n".join(lines) + "\n"
    print(text, end="")
    out = RESULTS / "batch.txt"
    out.write_text(text, encoding="utf-8")
    log(f"wrote {project_path(out)}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
