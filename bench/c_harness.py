"""The compiled harnesses of bench/run.py: symdyn's C and the CasADi route's C, built and timed.

One small C program per robot (`HARNESS`) links symdyn's NAME_dynamics.c and the CasADi
route's CodeGenerator C (separate translation units, compiled with machine.FLAGS, no LTO).
`STATES check K` prints every function's output at the first K states (`check_c` compares
them with symdyn.rnea); `STATES time REPS TARGET_MS` prints ns per call of every repetition,
the repetitions interleaved across the functions. `time_compiled` runs this program and
bench/pin_harness.py's Pinocchio program in alternating rounds and keeps the medians.
"""

from __future__ import annotations

import statistics
import time
from pathlib import Path

import casadi_route
import numpy as np
from c_snippets import JOINT_STATES, skeleton
from machine import C_COMPILER, FLAGS, run
from row import FUNCTIONS, Row
from states import CHECK_TOL, NCHECK, NSTATES, rel_err

import symdyn
from symdyn.model.parameters import numeric_parameters

__all__ = ["HARNESS", "CR_WORK", "parse_harness", "build_harness", "build_c", "check_c", "time_compiled"]

HARNESS = r"""/* Timing harness for {name}: written by bench/c_harness.py (bench/run.py), do not edit. */
{prelude}
#include "{prefix}_dynamics.h"
#include "cr_{name}.h"

#define N {n}
#define K {nstates}
#define MAXREPS 1000
#define NB 12

static double Q[K][N], QD[K][N], QDD[K][N], TAU[K][N];
static double OUT[N * N + N * {prefix}_NSTD]; /* the largest output: M or Y */
static const double *P = NULL; /* numeric robot: no free parameters */
static const casadi_real *cr_arg[64];
static casadi_real *cr_res[64];

static const char *LABELS[NB] = {{
    "inverse_dynamics", "cr_inverse_dynamics", "mass_matrix", "cr_mass_matrix", "gravity",
    "cr_gravity", "coriolis_matrix", "coriolis", "friction", "forward_dynamics", "regressor",
    "base_regressor"}};

{cr_work}

#define CR(FN, ...)                                                                       \
    do {{                                                                                  \
        const casadi_real *a_[] = {{__VA_ARGS__}};                                         \
        memcpy(cr_arg, a_, sizeof a_);                                                    \
        cr_res[0] = OUT;                                                                  \
        FN(cr_arg, cr_res, cr_iw, cr_w, 0);                                               \
    }} while (0)

{run_bench}

{print_out}

int main(int argc, char **argv)
{{
{main_head}    casadi_int sz_iw = 1, sz_w = 1;
{read_states}{cr_workspace}
    if (strcmp(argv[2], "check") == 0) {{
        int ncheck = argc > 3 ? atoi(argv[3]) : 4;
        for (k = 0; k < ncheck && k < K; ++k) {{
            {prefix}_inverse_dynamics(Q[k], QD[k], QDD[k], P, OUT); print_out("inverse_dynamics", k, OUT, N);
            {prefix}_mass_matrix(Q[k], P, OUT); print_out("mass_matrix", k, OUT, N * N);
            {prefix}_coriolis_matrix(Q[k], QD[k], P, OUT); print_out("coriolis_matrix", k, OUT, N * N);
            {prefix}_coriolis(Q[k], QD[k], P, OUT); print_out("coriolis", k, OUT, N);
            {prefix}_gravity(Q[k], P, OUT); print_out("gravity", k, OUT, N);
            {prefix}_friction(QD[k], P, OUT); print_out("friction", k, OUT, N);
            {prefix}_forward_dynamics(Q[k], QD[k], TAU[k], P, OUT); print_out("forward_dynamics", k, OUT, N);
            {prefix}_regressor(Q[k], QD[k], QDD[k], P, OUT);
            print_out("regressor", k, OUT, N * {prefix}_NSTD);
            {prefix}_base_regressor(Q[k], QD[k], QDD[k], P, OUT);
            print_out("base_regressor", k, OUT, N * {prefix}_NBASE);
            CR(cr_{prefix}_inverse_dynamics, Q[k], QD[k], QDD[k]);
            print_out("cr_inverse_dynamics", k, OUT, N);
            CR(cr_{prefix}_mass_matrix, Q[k]); print_out("cr_mass_matrix", k, OUT, N * N);
            CR(cr_{prefix}_gravity, Q[k]); print_out("cr_gravity", k, OUT, N);
        }}
        return 0;
    }}
{time_main}}}
"""


#: The CasADi functions' work space, shared by every harness (`{cr_work}` of a template): their
#: integer and real work arrays, sized by `cr_work` over the functions used (`cr_workspace`).
CR_WORK = r"""static casadi_int *cr_iw;
static casadi_real *cr_w;

static void cr_work(int (*work)(casadi_int *, casadi_int *, casadi_int *, casadi_int *),
                    casadi_int *sz_iw, casadi_int *sz_w)
{
    casadi_int a, r, i, w;
    work(&a, &r, &i, &w);
    if (a > 64 || r > 64) {
        fprintf(stderr, "casadi work sizes too large\n");
        exit(2);
    }
    if (i > *sz_iw) *sz_iw = i;
    if (w > *sz_w) *sz_w = w;
}"""


def cr_workspace(functions: list[str]) -> str:
    """main's lines that size and allocate CR_WORK's arrays for the CasADi `functions` (their C
    names; sz_iw and sz_w declared before)."""
    sizes = "".join(f"    cr_work({f}_work, &sz_iw, &sz_w);\n" for f in functions)
    return (
        sizes + "    cr_iw = malloc(sizeof(casadi_int) * (size_t)sz_iw);\n"
        "    cr_w = malloc(sizeof(casadi_real) * (size_t)sz_w);\n"
    )


def build_harness(
    template: str, loops, fns: dict, cr_name: str, stem: str, robot, work: Path, gen_dir: Path, **fields
):
    """Write the CasADi route's C of `fns` as `cr_name`.c and `template` filled in (the robot, the
    states, the timing `loops`, the CasADi work space of every function of `fns`, `fields`) as
    `stem`.c, and compile them with symdyn's NAME_dynamics.c (machine.FLAGS).

    Returns:
        (the program, the seconds the compiler took).
    """
    casadi_route.write_c(fns, cr_name, work)
    harness = work / f"{stem}.c"
    harness.write_text(
        template.format(
            prefix=robot.name,
            n=robot.n,
            nstates=NSTATES,
            cr_work=CR_WORK,
            cr_workspace=cr_workspace([f.name() for f in fns.values()]),
            **fields,
            **skeleton([loop.format(p=robot.name) for loop in loops], *JOINT_STATES),
        )
    )
    exe = work / stem
    sources = [harness, gen_dir / f"{robot.name}_dynamics.c", work / f"{cr_name}.c"]
    t0 = time.perf_counter()
    run([C_COMPILER, *FLAGS, "-I", gen_dir, "-I", work, "-o", exe, *sources, "-lm"])
    return exe, time.perf_counter() - t0


LOOPS = (  # run_bench's benchmarks in LABELS order: LOOP(call, one output element)
    "LOOP({p}_inverse_dynamics(Q[k], QD[k], QDD[k], P, OUT), OUT[k % N])",
    "LOOP(CR(cr_{p}_inverse_dynamics, Q[k], QD[k], QDD[k]), OUT[k % N])",
    "LOOP({p}_mass_matrix(Q[k], P, OUT), OUT[k % (N * N)])",
    "LOOP(CR(cr_{p}_mass_matrix, Q[k]), OUT[k % (N * N)])",
    "LOOP({p}_gravity(Q[k], P, OUT), OUT[k % N])",
    "LOOP(CR(cr_{p}_gravity, Q[k]), OUT[k % N])",
    "LOOP({p}_coriolis_matrix(Q[k], QD[k], P, OUT), OUT[k % (N * N)])",
    "LOOP({p}_coriolis(Q[k], QD[k], P, OUT), OUT[k % N])",
    "LOOP({p}_friction(QD[k], P, OUT), OUT[k % N])",
    "LOOP({p}_forward_dynamics(Q[k], QD[k], TAU[k], P, OUT), OUT[k % N])",
    "LOOP({p}_regressor(Q[k], QD[k], QDD[k], P, OUT), OUT[k % (N * {p}_NSTD)])",
    "LOOP({p}_base_regressor(Q[k], QD[k], QDD[k], P, OUT), OUT[k % (N * {p}_NBASE)])",
)


def parse_harness(text: str) -> tuple[dict, dict]:
    """('check' lines -> {label: {k: values} or max error}, 'time' lines -> {label: [ns per rep]})."""
    checks: dict = {}
    times: dict = {}
    for line in text.splitlines():
        parts = line.split()
        if not parts:
            continue
        if parts[0] == "check" and len(parts) > 3:
            checks.setdefault(parts[1], {})[int(parts[2])] = np.array([float(x) for x in parts[3:]])
        elif parts[0] == "check" and len(parts) == 3:
            checks[parts[1]] = float(parts[2])
        elif parts[0] == "time":
            times[parts[1]] = [float(x) for x in parts[3:]]
    return checks, times


def build_c(row: Row, robot, gen_dir: Path, work: Path, fns) -> Path:
    """Write the CasADi route's C and the harness; compile all three with FLAGS."""
    exe, seconds = build_harness(
        HARNESS, LOOPS, fns, f"cr_{row.name}", f"bench_{row.name}", robot, work, gen_dir, name=row.name
    )
    row.notes.append(f"C build {seconds:.1f} s")
    return exe


def check_c(row: Row, robot, exe: Path, states_file: Path, states, refs: list[dict]) -> None:
    """Compare the harness's outputs at the first NCHECK states with `refs` (see `references`)."""
    checks, _ = parse_harness(run([exe, states_file, "check", NCHECK]).stdout)
    pi_b = symdyn.derive(robot, simplify=False).linear_compact()[1].matrix() @ numeric_parameters(robot)
    worst: dict[str, float] = {}
    for k in range(NCHECK):
        ref = refs[k]
        qd = states["qd"][k]
        n = robot.n
        got = {fn: checks[fn][k] for fn in FUNCTIONS}
        errs = {
            "inverse_dynamics": rel_err(got["inverse_dynamics"], ref["inverse_dynamics"]),
            "mass_matrix": rel_err(got["mass_matrix"], ref["mass_matrix"]),
            # C itself is not unique; C qd = V is what the oracle can judge.
            "coriolis_matrix": rel_err(got["coriolis_matrix"].reshape(n, n) @ qd, ref["coriolis"]),
            "coriolis": rel_err(got["coriolis"], ref["coriolis"]),
            "gravity": rel_err(got["gravity"], ref["gravity"]),
            "friction": rel_err(got["friction"], ref["friction"]),
            "forward_dynamics": rel_err(got["forward_dynamics"], ref["forward_dynamics"]),
            "regressor": rel_err(got["regressor"], ref["regressor"]),
            # Y_b pi_b, pi_b = K pi the base parameters' values (symdyn.algorithms.base_parameters)
            "base_regressor": rel_err(got["base_regressor"].reshape(n, -1) @ pi_b, ref["inverse_dynamics"]),
            "cr_inverse_dynamics": rel_err(checks["cr_inverse_dynamics"][k], ref["inverse_dynamics"]),
            "cr_mass_matrix": rel_err(checks["cr_mass_matrix"][k], ref["mass_matrix"].T.ravel()),
            "cr_gravity": rel_err(checks["cr_gravity"][k], ref["gravity"]),
        }
        for key, e in errs.items():
            worst[key] = max(worst.get(key, 0.0), e)
    row.checks.update({f"C {k}": v for k, v in worst.items()})
    bad = {k: v for k, v in worst.items() if not v <= CHECK_TOL}
    if bad:
        raise SystemExit(f"{row.name}: compiled code disagrees with symdyn.rnea: {bad}")


def time_compiled(row: Row, c_cmd: list, pin_cmd: list | None, opts) -> None:
    """Time the C harness and (if given) the Pinocchio harness in alternating rounds.

    Each harness interleaves its functions repetition by repetition; running the two
    programs in `opts.rounds` alternating rounds of reps/rounds repetitions spreads any
    change of machine load over both. The median is over all repetitions of all rounds.
    """
    samples: dict[str, list[float]] = {}
    per_round = max(1, -(-opts.reps // opts.rounds))
    for _ in range(opts.rounds):
        for cmd, prefix in ((c_cmd, ""), (pin_cmd, "pin_")):
            if cmd is None:
                continue
            _, times = parse_harness(run([*cmd, per_round, opts.target_ms]).stdout)
            for label, values in times.items():
                samples.setdefault(prefix + label, []).extend(values)
    row.samples = samples
    for label, values in samples.items():
        med = statistics.median(values)
        if label.startswith("pin_"):
            row.pin_ns[label[4:]] = med
        elif label.startswith("cr_"):
            row.cr_c_ns[label[3:]] = med
        else:
            row.c_ns[label] = med
