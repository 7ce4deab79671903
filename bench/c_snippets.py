"""The C text every timing harness of bench/ shares, so that all of them time alike.

A harness is one C file that a bench script writes with str.format: its own state arrays, its
`run_bench(b, it)` (ns per call of benchmark b over `it` calls, each call on the next state) and
its `check` output, around these pieces (inserted as format arguments, so their braces are
single):

    C_PRELUDE        headers, the volatile sink, now_ns() and LOOP(CALL, SINK)
    c_run_bench      run_bench() from one LOOP(...) per benchmark
    C_PRINT_OUT      print_out(): one `check LABEL K v1 v2 ...` line at full precision
    C_MAIN_HEAD      main's declarations and its usage line
    c_read_states    the part of main that reads the states file argv[1]
    C_TIME_MAIN      the end of main: calibration, interleaved repetitions, `time` lines

The harness defines K (states), NB (benchmarks), MAXREPS and LABELS[NB] itself. Used by
bench/c_harness.py (bench/run.py), bench/frames_harness.py, bench/derivatives.py,
bench/closed_loops.py, bench/floating.py and bench/floating_centroidal.py; parsed by
c_harness.parse_harness.
"""

from __future__ import annotations

__all__ = [
    "C_PRELUDE",
    "C_PRINT_OUT",
    "C_MAIN_HEAD",
    "C_TIME_MAIN",
    "c_run_bench",
    "c_read_states",
    "skeleton",
    "JOINT_STATES",
    "CPU_CLOCK",
]

#: the C defining the thread's CPU clock for C_PRELUDE (before it)
CPU_CLOCK = "#define BENCH_CLOCK CLOCK_THREAD_CPUTIME_ID /* CPU time: not other processes' slices */"
#: the states of a fixed-base robot: q, qd, qdd and tau, N doubles each
JOINT_STATES = (("Q", "N"), ("QD", "N"), ("QDD", "N"), ("TAU", "N"))

#: Headers, the sink, a clock in ns, and LOOP(CALL, SINK): `it` calls of CALL on the states
#: k = 0, 1, ... (cycling, so that the state changes every call), each adding one output element
#: SINK to the volatile sink so that no call can be optimised away. The clock is the wall clock
#: unless the harness defines BENCH_CLOCK first (as bench/pinocchio_model.hpp: the floating benches
#: use CLOCK_THREAD_CPUTIME_ID, which does not count other processes' scheduler slices).
C_PRELUDE = r"""#define _POSIX_C_SOURCE 199309L
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#ifndef BENCH_CLOCK
#define BENCH_CLOCK CLOCK_MONOTONIC
#endif

static volatile double sink;

static double now_ns(void)
{
    struct timespec t;
    clock_gettime(BENCH_CLOCK, &t);
    return 1e9 * (double)t.tv_sec + (double)t.tv_nsec;
}

#define LOOP(CALL, SINK)                                                                  \
    {                                                                                     \
        long i_;                                                                          \
        int k = 0;                                                                        \
        for (i_ = 0; i_ < it; ++i_) {                                                     \
            CALL;                                                                         \
            sink += (SINK);                                                               \
            if (++k == K) k = 0;                                                          \
        }                                                                                 \
    }                                                                                     \
    break
"""

#: the C helper that prints one output of a check state: "check LABEL K v1 v2 ..." (full precision)
C_PRINT_OUT = r"""static void print_out(const char *label, int k, const double *a, int len)
{
    int i;
    printf("check %s %d", label, k);
    for (i = 0; i < len; ++i) printf(" %.17g", a[i]);
    printf("\n");
}"""

#: The start of main(argc, argv): what C_TIME_MAIN and c_read_states need, and the usage line.
C_MAIN_HEAD = r"""    static double ns[NB][MAXREPS];
    long iters[NB];
    FILE *f;
    int k, b, r, reps;
    double target_ns;
    if (argc < 3) {
        fprintf(stderr, "usage: %s STATES check NCHECK | STATES time REPS TARGET_MS\n", argv[0]);
        return 2;
    }
"""

#: The end of main that times the NB benchmarks of run_bench(b, it) with REPS and TARGET_MS from
#: argv[3], argv[4] and prints `time LABEL ITERATIONS NS...` lines.
C_TIME_MAIN = r"""    reps = argc > 3 ? atoi(argv[3]) : 11;
    if (reps < 1) reps = 1;
    if (reps > MAXREPS) reps = MAXREPS;
    target_ns = 1e6 * (argc > 4 ? atof(argv[4]) : 10.0);
    /* calibrate (this also warms up): iterations per repetition for ~target_ns */
    for (b = 0; b < NB; ++b) {
        long it = 64;
        double t;
        while ((t = run_bench(b, it) * (double)it) < 0.25 * target_ns) it *= 2;
        iters[b] = (long)(target_ns / (t / (double)it)) + 1;
        run_bench(b, iters[b]);
    }
    /* repetitions interleaved across the functions, so a change of machine load during the run
       falls on all of them alike */
    for (r = 0; r < reps; ++r)
        for (b = 0; b < NB; ++b) ns[b][r] = run_bench(b, iters[b]);
    for (b = 0; b < NB; ++b) {
        printf("time %s %ld", LABELS[b], iters[b]);
        for (r = 0; r < reps; ++r) printf(" %.3f", ns[b][r]);
        printf("\n");
    }
    return 0;
"""


def c_run_bench(loops: list[str]) -> str:
    """run_bench(b, it): ns per call of benchmark b, whose loop is `loops[b]` (a LOOP(...))."""
    cases = "\n".join(f"    case {b}: {loop};" for b, loop in enumerate(loops))
    return f"""/* ns per call of benchmark b over `it` calls */
static double run_bench(int b, long it)
{{
    double s = now_ns();
    switch (b) {{
{cases}
    default: return -1.0;
    }}
    return (now_ns() - s) / (double)it;
}}"""


def c_read_states(*fields: tuple[str, str]) -> str:
    """The part of main that reads K states from the file argv[1] (needs `FILE *f`, `int k`).

    Each state is, in order, the arrays `fields` = (name, length): state k fills name[k][0:length]
    from `length` native doubles.
    """
    join = "\n            || "
    reads = join.join(f"fread({a}[k], sizeof(double), {size}, f) != {size}" for a, size in fields)
    return f"""    f = fopen(argv[1], "rb");
    if (!f) {{
        perror(argv[1]);
        return 2;
    }}
    for (k = 0; k < K; ++k) {{
        if ({reads}) {{
            fprintf(stderr, "short states file\\n");
            return 2;
        }}
    }}
    fclose(f);
"""


def skeleton(loops: list[str], *fields: tuple[str, str]) -> dict[str, str]:
    """The shared pieces as HARNESS.format's keyword arguments: prelude, run_bench (from `loops`),
    print_out, main_head, read_states (of `fields`) and time_main."""
    return {
        "prelude": C_PRELUDE,
        "run_bench": c_run_bench(loops),
        "print_out": C_PRINT_OUT,
        "main_head": C_MAIN_HEAD,
        "read_states": c_read_states(*fields),
        "time_main": C_TIME_MAIN,
    }
