"""Speed benchmark of issue 4: symdyn's generated C against the CasADi route and Pinocchio.

    python bench/run.py                # full run (about 10 minutes on 2 cores; Pinocchio's
                                       # harness is compiled once and cached)
    python bench/run.py --quick        # fewer robots and repetitions
    python bench/run.py --markdown     # the same table in Markdown

One table (one row per robot and generated function): generation time of
`symdyn generate --target c` (wall and CPU, fresh process), operation counts,
ns per call of symdyn's C (all seven functions), the CasADi route (an RNEA/CRBA
traced in casadi.SX, bench/casadi_route.py: its casadi.Function called from
Python, and its CodeGenerator C), the NumPy RNEA (symdyn.rnea), and Pinocchio's
C++ (bench/pinocchio_harness.cpp, when the `pin` and `cmeel-eigen` wheels are
installed), with ratio columns. Under the table: notes, the correctness checks
(every timed function is first compared with symdyn.rnea at random states; a
mismatch stops the run) and one PASS/FAIL line per target of the issue.
Progress goes to stderr; the table, notes and verdicts go to stdout and to
bench/results/run.txt (or run.md with --markdown); every number to
bench/results/run.json. See bench/README_run.md.
"""

from __future__ import annotations

import argparse
import hashlib
import json
import os
import platform
import re
import resource
import shutil
import statistics
import subprocess
import sys
import sysconfig
import tempfile
import time
import warnings
from dataclasses import asdict, dataclass, field
from pathlib import Path

import numpy as np

BENCH = Path(__file__).resolve().parent
ROOT = BENCH.parent
RESULTS = BENCH / "results"
sys.path.insert(0, str(BENCH))

import casadi_route  # noqa: E402
import chains  # noqa: E402

from symdyn.codegen import FUNCTION_NAMES  # noqa: E402

C_COMPILER = "gcc"
CXX_COMPILER = "g++"
FLAGS = ("-O3", "-march=native")  # the same for symdyn's C, the CasADi route's C and the harness
CXX_EXTRA = ("-std=c++17", "-DNDEBUG")  # Pinocchio: a release build (Eigen assertions off)
PIN_DEFINES = (  # what pinocchio's CMake target pinocchio_headers adds
    "-DBOOST_MPL_LIMIT_LIST_SIZE=30",
    "-DBOOST_MPL_LIMIT_VECTOR_SIZE=30",
    "-DBOOST_MPL_CFG_NO_PREPROCESSED_HEADERS",
    "-DBOOST_FUSION_INVOKE_MAX_ARITY=12",
)
FUNCTIONS = FUNCTION_NAMES
SHORT = {
    "inverse_dynamics": "tau",
    "mass_matrix": "M",
    "coriolis_matrix": "C",
    "coriolis": "V",
    "gravity": "G",
    "friction": "F",
    "forward_dynamics": "FD",
}
CASADI_FUNCTIONS = casadi_route.FUNCTIONS  # inverse_dynamics, mass_matrix, gravity
PINOCCHIO = {  # symdyn function -> the Pinocchio algorithm timed against it
    "inverse_dynamics": "rnea",
    "mass_matrix": "crba",
    "gravity": "gravity",
    "coriolis_matrix": "coriolis_matrix",
    "forward_dynamics": "aba",
}
PINOCCHIO_NAMES = {
    "rnea": "rnea",
    "crba": "crba",
    "gravity": "computeGeneralizedGravity",
    "coriolis_matrix": "computeCoriolisMatrix",
    "aba": "aba",
}
EXAMPLES = ROOT / "examples"
ROBOTS = {  # name -> robot file (chains are written by bench/chains.py)
    "roger_arm_values": EXAMPLES / "roger_arm_values.yaml",
    "puma560": EXAMPLES / "puma560.yaml",
    "stanford": EXAMPLES / "stanford.yaml",
    "panda": EXAMPLES / "panda.yaml",
    "chain_9": chains.chain_file(9),
    "chain_12": chains.chain_file(12),
}
URDF_TIPS: dict[Path, str] = {}  # URDF file -> the tip link of its chain


def _panda_urdf() -> Path | None:
    """The Franka Panda URDF that example-robot-data (the test extra) ships, if installed."""
    try:
        from importlib.metadata import PackageNotFoundError, distribution

        share = "cmeel.prefix/share/example-robot-data/robots"
        robots = distribution("example-robot-data").locate_file(share)
    except (ImportError, PackageNotFoundError):
        return None
    path = Path(str(robots)) / "panda_description" / "urdf" / "panda.urdf"
    return path if path.is_file() else None


if (_urdf := _panda_urdf()) is not None:  # the same arm as panda.yaml, through the URDF loader
    ROBOTS["panda_urdf"] = _urdf
    URDF_TIPS[_urdf] = "panda_hand"
QUICK_ROBOTS = ("roger_arm_values", "puma560", "panda")
ARMS = ("puma560", "stanford", "panda")  # the "6-7 joint arms with numeric parameters"
NSTATES = 256  # pre-generated random states, cycled through (a power of two)
NCHECK = 4  # states at which every compiled function is checked against symdyn.rnea
CHECK_TOL = 1e-9  # relative (to max(1, |reference|)) error allowed
SEED = 20240604


def log(msg: str) -> None:
    print(msg, file=sys.stderr, flush=True)


# --------------------------------------------------------------------------- data


@dataclass
class Row:
    name: str
    n: int = 0
    file: str = ""
    gen_wall: float = float("nan")
    gen_cpu: float = float("nan")
    ops: dict = field(default_factory=dict)  # function -> {total, mul, add, div, trig, other}
    casadi_ops: dict = field(default_factory=dict)  # function -> flops() dict
    c_ns: dict = field(default_factory=dict)  # symdyn C: function -> ns/call (median)
    cr_c_ns: dict = field(default_factory=dict)  # CasADi route C
    cr_py_us: dict = field(default_factory=dict)  # casadi.Function called from Python
    pin_ns: dict = field(default_factory=dict)  # Pinocchio algorithm -> ns/call
    numpy_us: float = float("nan")  # symdyn.rnea.rnea single call
    numpy_batch_us: float = float("nan")  # per state, batch of 1000
    checks: dict = field(default_factory=dict)  # what -> max relative error
    samples: dict = field(default_factory=dict)  # harness label -> ns per call of every repetition
    notes: list = field(default_factory=list)


# --------------------------------------------------------------------------- helpers


def run(cmd, **kw) -> subprocess.CompletedProcess:
    proc = subprocess.run([str(c) for c in cmd], capture_output=True, text=True, **kw)
    if proc.returncode != 0:
        raise RuntimeError(f"{' '.join(map(str, cmd))}\nexit {proc.returncode}\n{proc.stdout}\n{proc.stderr}")
    return proc


def pin_to_one_core() -> str:
    """Pin this process (and so every child) to one CPU; returns a description."""
    if not hasattr(os, "sched_setaffinity"):
        return "not pinned (no os.sched_setaffinity)"
    cpus = sorted(os.sched_getaffinity(0))
    cpu = cpus[-1]
    try:
        os.sched_setaffinity(0, {cpu})
    except OSError as exc:
        return f"not pinned ({exc})"
    return f"pinned to CPU {cpu} of {len(cpus)}"


def machine() -> str:
    model = platform.processor() or platform.machine()
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                model = line.split(":", 1)[1].strip()
                break
    except OSError:
        pass
    return f"{model}, {os.cpu_count()} CPUs, {platform.system()} {platform.release()}"


def compiler_version(cc: str) -> str:
    try:
        return run([cc, "--version"]).stdout.splitlines()[0]
    except (RuntimeError, OSError):
        return f"{cc}: not found"


def load_average() -> str:
    try:
        return " ".join(f"{x:.2f}" for x in os.getloadavg())
    except OSError:
        return "?"


def source_digest() -> str:
    """A short hash of symdyn's source and templates (to notice edits during a run)."""
    import symdyn

    h = hashlib.sha256()
    pkg = Path(symdyn.__file__).resolve().parent
    for base in (pkg, ROOT / "templates"):
        for f in sorted(base.rglob("*")):
            if f.is_file() and f.suffix in (".py", ".j2"):
                h.update(str(f.relative_to(base)).encode() + f.read_bytes())
    return h.hexdigest()[:12]


def symdyn_command() -> list[str]:
    exe = Path(sys.executable).with_name("symdyn")
    if exe.exists():
        return [str(exe)]
    return [sys.executable, "-c", "import sys; from symdyn.cli.main import main; sys.exit(main())"]


def load(path: Path):
    from symdyn.parsers import load as load_any

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # implausible-but-published inertia (PUMA link 1)
        return load_any(path, tip=URDF_TIPS.get(path))


# --------------------------------------------------------------------------- generation


_OPS = re.compile(
    r"\((\d+) operations: (\d+) multiplications, (\d+) additions, (\d+) divisions, "
    r"(\d+) trigonometric calls, (\d+) other calls\) \*/\s*\nvoid (\w+)\("
)


def op_counts(c_text: str, name: str, robot=None) -> dict:
    """Per function {total, mul, add, div, trig, other}: the counts printed in NAME_dynamics.c.

    These are symdyn's own OpCount (the cost comment above every function). If the
    comments cannot be read, the counts come from symdyn.codegen.context(robot).
    """
    out = {}
    for m in _OPS.finditer(c_text):
        fn = m.group(7)[len(name) + 1 :]
        total, mul, add, div, trig, other = map(int, m.groups()[:6])
        out[fn] = dict(total=total, mul=mul, add=add, div=div, trig=trig, other=other)
    if set(out) >= set(FUNCTIONS) or robot is None:
        return out
    from symdyn.codegen import context

    for spec in context(robot).functions:
        o = spec.ops
        out[spec.name] = dict(total=o.total, mul=o.mul, add=o.add, div=o.div, trig=o.trig, other=o.other)
    return out


def generate(path: Path, out_dir: Path) -> tuple[float, float]:
    """`symdyn generate PATH --target c --out OUT_DIR` in a fresh process: (wall s, CPU s)."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    t0 = time.perf_counter()
    tip = ["--tip", URDF_TIPS[path]] if path in URDF_TIPS else []
    run([*symdyn_command(), "generate", path, "--target", "c", "--out", out_dir, "--force", *tip])
    wall = time.perf_counter() - t0
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    return wall, cpu


def generate_best(path: Path, out_dir: Path, runs: int) -> tuple[float, float, object, dict]:
    """`generate` `runs` times (fastest wall and CPU kept), then load the robot and read op_counts.

    Returns (wall s, CPU s, robot, op counts of OUT_DIR/NAME_dynamics.c).
    """
    times = [generate(path, out_dir) for _ in range(runs)]
    wall, cpu = min(w for w, _ in times), min(c for _, c in times)
    robot = load(path)
    ops = op_counts((out_dir / f"{robot.name}_dynamics.c").read_text(), robot.name, robot)
    return wall, cpu, robot, ops


# --------------------------------------------------------------------------- states


def make_states(robot, rng) -> dict[str, np.ndarray]:
    n = robot.n
    return {
        "q": rng.uniform(-np.pi, np.pi, (NSTATES, n)),
        "qd": rng.uniform(-2, 2, (NSTATES, n)),
        "qdd": rng.uniform(-5, 5, (NSTATES, n)),
        "tau": rng.uniform(-20, 20, (NSTATES, n)),
    }


def write_states(states, path: Path) -> None:
    """Binary doubles, state by state: q[n] qd[n] qdd[n] tau[n]."""
    block = np.stack([states[k] for k in ("q", "qd", "qdd", "tau")], axis=1)  # (K, 4, n)
    path.write_bytes(np.ascontiguousarray(block, dtype="<f8").tobytes())


def references(robot, states, k: int) -> dict[str, np.ndarray]:
    """symdyn.rnea's numbers at state k, for every function (and the frictionless Pinocchio ones)."""
    from symdyn import rnea as oracle

    q, qd, qdd, tau = (states[x][k] for x in ("q", "qd", "qdd", "tau"))
    z = np.zeros_like(q)
    M = oracle.mass_matrix(robot, q)
    h0 = oracle.rnea(robot, q, qd, z, friction=False)
    return {
        "inverse_dynamics": oracle.rnea(robot, q, qd, qdd),
        "mass_matrix": M,
        "coriolis": oracle.bias_torque(robot, q, qd),
        "gravity": oracle.gravity_torque(robot, q),
        "friction": oracle.friction_torque(robot, qd),
        "forward_dynamics": oracle.forward_dynamics(robot, q, qd, tau),
        # Pinocchio has no joint friction: its references leave friction out.
        "rnea_nofriction": oracle.rnea(robot, q, qd, qdd, friction=False),
        "aba_nofriction": np.linalg.solve(M, tau - h0),
    }


def rel_err(got, want) -> float:
    want = np.asarray(want, dtype=float)
    got = np.asarray(got, dtype=float).reshape(want.shape)
    return float(np.max(np.abs(got - want)) / max(1.0, float(np.max(np.abs(want)))))


# --------------------------------------------------------------------------- the C harness

HARNESS = r"""/* Timing harness for {name}: written by bench/run.py, do not edit. */
#define _POSIX_C_SOURCE 199309L
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include "{prefix}_dynamics.h"
#include "cr_{name}.h"

#define N {n}
#define K {nstates}
#define MAXREPS 1000
#define NB 10

static double Q[K][N], QD[K][N], QDD[K][N], TAU[K][N];
static double OUT[N * N];
static volatile double sink;
static const double *P = NULL; /* numeric robot: no free parameters */
static const casadi_real *cr_arg[64];
static casadi_real *cr_res[64];
static casadi_int *cr_iw;
static casadi_real *cr_w;

static const char *LABELS[NB] = {{
    "inverse_dynamics", "cr_inverse_dynamics", "mass_matrix", "cr_mass_matrix", "gravity",
    "cr_gravity", "coriolis_matrix", "coriolis", "friction", "forward_dynamics"}};

static double now_ns(void)
{{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return 1e9 * (double)t.tv_sec + (double)t.tv_nsec;
}}

static void cr_work(int (*work)(casadi_int *, casadi_int *, casadi_int *, casadi_int *),
                    casadi_int *sz_iw, casadi_int *sz_w)
{{
    casadi_int a, r, i, w;
    work(&a, &r, &i, &w);
    if (a > 64 || r > 64) {{
        fprintf(stderr, "casadi work sizes too large\n");
        exit(2);
    }}
    if (i > *sz_iw) *sz_iw = i;
    if (w > *sz_w) *sz_w = w;
}}

#define CR(FN, ...)                                                                       \
    do {{                                                                                  \
        const casadi_real *a_[] = {{__VA_ARGS__}};                                         \
        memcpy(cr_arg, a_, sizeof a_);                                                    \
        cr_res[0] = OUT;                                                                  \
        FN(cr_arg, cr_res, cr_iw, cr_w, 0);                                               \
    }} while (0)

/* IT calls of CALL on states k = 0, 1, ... (cycling: the state changes every call), one output
   element per call into the volatile sink. */
#define LOOP(OUTLEN, CALL)                                                                \
    {{                                                                                     \
        long i_;                                                                          \
        int k = 0;                                                                        \
        for (i_ = 0; i_ < it; ++i_) {{                                                     \
            CALL;                                                                         \
            sink += OUT[k % (OUTLEN)];                                                    \
            if (++k == K) k = 0;                                                          \
        }}                                                                                 \
    }}                                                                                     \
    break

/* ns per call of benchmark b over `it` calls */
static double run_bench(int b, long it)
{{
    double s = now_ns();
    switch (b) {{
    case 0: LOOP(N, {prefix}_inverse_dynamics(Q[k], QD[k], QDD[k], P, OUT));
    case 1: LOOP(N, CR(cr_{prefix}_inverse_dynamics, Q[k], QD[k], QDD[k]));
    case 2: LOOP(N * N, {prefix}_mass_matrix(Q[k], P, OUT));
    case 3: LOOP(N * N, CR(cr_{prefix}_mass_matrix, Q[k]));
    case 4: LOOP(N, {prefix}_gravity(Q[k], P, OUT));
    case 5: LOOP(N, CR(cr_{prefix}_gravity, Q[k]));
    case 6: LOOP(N * N, {prefix}_coriolis_matrix(Q[k], QD[k], P, OUT));
    case 7: LOOP(N, {prefix}_coriolis(Q[k], QD[k], P, OUT));
    case 8: LOOP(N, {prefix}_friction(QD[k], P, OUT));
    case 9: LOOP(N, {prefix}_forward_dynamics(Q[k], QD[k], TAU[k], P, OUT));
    default: return -1.0;
    }}
    return (now_ns() - s) / (double)it;
}}

static void print_out(const char *label, int k, int len)
{{
    int i;
    printf("check %s %d", label, k);
    for (i = 0; i < len; ++i) printf(" %.17g", OUT[i]);
    printf("\n");
}}

int main(int argc, char **argv)
{{
    static double ns[NB][MAXREPS];
    long iters[NB];
    FILE *f;
    int k, b, r, reps;
    double target_ns;
    casadi_int sz_iw = 1, sz_w = 1;
    if (argc < 3) {{
        fprintf(stderr, "usage: %s STATES check NCHECK | STATES time REPS TARGET_MS\n", argv[0]);
        return 2;
    }}
    f = fopen(argv[1], "rb");
    if (!f) {{
        perror(argv[1]);
        return 2;
    }}
    for (k = 0; k < K; ++k) {{
        if (fread(Q[k], sizeof(double), N, f) != N || fread(QD[k], sizeof(double), N, f) != N
            || fread(QDD[k], sizeof(double), N, f) != N || fread(TAU[k], sizeof(double), N, f) != N) {{
            fprintf(stderr, "short states file\n");
            return 2;
        }}
    }}
    fclose(f);
    cr_work(cr_{prefix}_inverse_dynamics_work, &sz_iw, &sz_w);
    cr_work(cr_{prefix}_mass_matrix_work, &sz_iw, &sz_w);
    cr_work(cr_{prefix}_gravity_work, &sz_iw, &sz_w);
    cr_iw = malloc(sizeof(casadi_int) * (size_t)sz_iw);
    cr_w = malloc(sizeof(casadi_real) * (size_t)sz_w);

    if (strcmp(argv[2], "check") == 0) {{
        int ncheck = argc > 3 ? atoi(argv[3]) : 4;
        for (k = 0; k < ncheck && k < K; ++k) {{
            {prefix}_inverse_dynamics(Q[k], QD[k], QDD[k], P, OUT); print_out("inverse_dynamics", k, N);
            {prefix}_mass_matrix(Q[k], P, OUT); print_out("mass_matrix", k, N * N);
            {prefix}_coriolis_matrix(Q[k], QD[k], P, OUT); print_out("coriolis_matrix", k, N * N);
            {prefix}_coriolis(Q[k], QD[k], P, OUT); print_out("coriolis", k, N);
            {prefix}_gravity(Q[k], P, OUT); print_out("gravity", k, N);
            {prefix}_friction(QD[k], P, OUT); print_out("friction", k, N);
            {prefix}_forward_dynamics(Q[k], QD[k], TAU[k], P, OUT); print_out("forward_dynamics", k, N);
            CR(cr_{prefix}_inverse_dynamics, Q[k], QD[k], QDD[k]); print_out("cr_inverse_dynamics", k, N);
            CR(cr_{prefix}_mass_matrix, Q[k]); print_out("cr_mass_matrix", k, N * N);
            CR(cr_{prefix}_gravity, Q[k]); print_out("cr_gravity", k, N);
        }}
        return 0;
    }}
    reps = argc > 3 ? atoi(argv[3]) : 11;
    if (reps < 1) reps = 1;
    if (reps > MAXREPS) reps = MAXREPS;
    target_ns = 1e6 * (argc > 4 ? atof(argv[4]) : 10.0);
    /* calibrate (this also warms up): iterations per repetition for ~target_ns */
    for (b = 0; b < NB; ++b) {{
        long it = 64;
        double t;
        while ((t = run_bench(b, it) * (double)it) < 0.25 * target_ns) it *= 2;
        iters[b] = (long)(target_ns / (t / (double)it)) + 1;
        run_bench(b, iters[b]);
    }}
    /* repetitions interleaved across the functions, so a change of machine load during the run
       falls on all of them alike */
    for (r = 0; r < reps; ++r)
        for (b = 0; b < NB; ++b) ns[b][r] = run_bench(b, iters[b]);
    for (b = 0; b < NB; ++b) {{
        printf("time %s %ld", LABELS[b], iters[b]);
        for (r = 0; r < reps; ++r) printf(" %.3f", ns[b][r]);
        printf("\n");
    }}
    return 0;
}}
"""


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
    casadi_route.write_c(fns, f"cr_{row.name}", work)
    harness = work / f"bench_{row.name}.c"
    harness.write_text(HARNESS.format(name=row.name, prefix=robot.name, n=robot.n, nstates=NSTATES))
    exe = work / f"bench_{row.name}"
    sources = [harness, gen_dir / f"{robot.name}_dynamics.c", work / f"cr_{row.name}.c"]
    t0 = time.perf_counter()
    run([C_COMPILER, *FLAGS, "-I", gen_dir, "-I", work, "-o", exe, *sources, "-lm"])
    row.notes.append(f"C build {time.perf_counter() - t0:.1f} s")
    return exe


def check_c(row: Row, robot, exe: Path, states_file: Path, states, refs: list[dict]) -> None:
    """Compare the harness's outputs at the first NCHECK states with `refs` (see `references`)."""
    checks, _ = parse_harness(run([exe, states_file, "check", NCHECK]).stdout)
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


# --------------------------------------------------------------------------- Python-side timings


def time_python(fn, args_list, reps: int, budget_s: float) -> float:
    """Median over `reps` repetitions of the seconds per call, cycling through args_list."""
    fn(*args_list[0])  # warm-up (and caches)
    t0 = time.perf_counter()
    calls = 0
    while time.perf_counter() - t0 < 0.05:
        fn(*args_list[calls % len(args_list)])
        calls += 1
    per = (time.perf_counter() - t0) / calls
    count = max(3, int(budget_s / reps / per))
    out = []
    for _ in range(reps):
        t = time.perf_counter()
        for i in range(count):
            fn(*args_list[i % len(args_list)])
        out.append((time.perf_counter() - t) / count)
    return statistics.median(out)


def time_numpy_and_casadi(row: Row, robot, fns, states, reps: int, budget_s: float) -> None:
    from symdyn.rnea import rnea

    m = min(NSTATES, 64)
    q, qd, qdd = (states[x] for x in ("q", "qd", "qdd"))
    single = [(robot, q[i], qd[i], qdd[i]) for i in range(m)]
    row.numpy_us = 1e6 * time_python(rnea, single, reps, budget_s)
    B = 1000
    idx = np.arange(B) % NSTATES
    batch = [(robot, q[idx], qd[idx], qdd[idx])]
    row.numpy_batch_us = 1e6 * time_python(rnea, batch, reps, budget_s) / B
    argsets = {
        "inverse_dynamics": [(q[i], qd[i], qdd[i]) for i in range(m)],
        "mass_matrix": [(q[i],) for i in range(m)],
        "gravity": [(q[i],) for i in range(m)],
    }
    for fn in CASADI_FUNCTIONS:
        row.cr_py_us[fn] = 1e6 * time_python(fns[fn], argsets[fn], reps, budget_s)


# --------------------------------------------------------------------------- Pinocchio


def pinocchio_prefix() -> tuple[Path | None, str]:
    """The cmeel prefix holding pinocchio's and Eigen's headers, and a note."""
    try:
        from importlib.metadata import PackageNotFoundError, version

        try:
            pin_version = version("pin")
        except PackageNotFoundError:
            return None, "the `pin` package is not installed (pip install 'symdyn[bench]')"
    except ImportError:  # pragma: no cover
        return None, "importlib.metadata missing"
    candidates = []
    for key in ("purelib", "platlib"):
        candidates.append(Path(sysconfig.get_paths()[key]) / "cmeel.prefix")
    for prefix in dict.fromkeys(candidates):
        if (prefix / "include" / "pinocchio").is_dir():
            if (
                not (prefix / "include" / "eigen3" / "Eigen").is_dir()
                and not Path("/usr/include/eigen3").is_dir()
            ):
                return None, f"pin {pin_version} found but no Eigen headers (pip install cmeel-eigen)"
            return prefix, f"pin {pin_version}"
    return (
        None,
        f"pin {pin_version} installed but its headers (cmeel.prefix/include/pinocchio) were not found",
    )


def build_pinocchio(prefix: Path, build_dir: Path) -> tuple[Path, str]:
    """Compile bench/pinocchio_harness.cpp (cached by source, flags, compiler and headers)."""
    src = BENCH / "pinocchio_harness.cpp"
    inc = prefix / "include"
    eigen = inc / "eigen3" if (inc / "eigen3" / "Eigen").is_dir() else Path("/usr/include/eigen3")
    cmd_flags = [*FLAGS, *CXX_EXTRA, *PIN_DEFINES, "-I", str(inc), "-I", str(eigen)]
    config = (inc / "pinocchio" / "config.hpp").read_bytes()
    key = hashlib.sha256(
        src.read_bytes() + config + " ".join(cmd_flags).encode() + compiler_version(CXX_COMPILER).encode()
    ).hexdigest()[:16]
    exe = build_dir / f"pinocchio_harness_{key}"
    if exe.exists():
        return exe, "cached build"
    build_dir.mkdir(parents=True, exist_ok=True)
    log(f"compiling the Pinocchio harness (several minutes, cached afterwards in {build_dir}) ...")
    t0 = time.perf_counter()
    tmp = exe.with_suffix(".tmp")
    # -w: GCC 12 prints false -Wstringop-overread warnings from Eigen's AVX-512 code
    run([CXX_COMPILER, *cmd_flags, "-w", "-o", tmp, src])
    tmp.rename(exe)
    return exe, f"compiled in {time.perf_counter() - t0:.0f} s"


def pinocchio_model_text(robot, states, refs: list[dict]) -> str:
    """The MODEL.txt of bench/pinocchio_harness.cpp, with symdyn.rnea's reference numbers `refs`."""
    m = casadi_route.robot_arrays(robot)
    lines = [f"n {m.n}", "gravity " + " ".join(repr(float(x)) for x in m.gravity)]
    for i in range(m.n):
        I = m.inertia[i]
        vals = [
            *m.axis[i],
            *m.R0[i].ravel(),
            *m.p0[i],
            m.mass[i],
            *m.com[i],
            I[0, 0],
            I[0, 1],
            I[0, 2],
            I[1, 1],
            I[1, 2],
            I[2, 2],
            m.reflected[i],
        ]
        lines.append(f"joint {'R' if m.revolute[i] else 'P'} " + " ".join(repr(float(v)) for v in vals))
    lines.append(f"nstates {NSTATES}")
    for k in range(NSTATES):
        vec = np.concatenate([states[x][k] for x in ("q", "qd", "qdd", "tau")])
        lines.append(" ".join(repr(float(v)) for v in vec))
    lines.append(f"ncheck {NCHECK}")
    for k in range(NCHECK):
        ref = refs[k]
        vec = np.concatenate(
            [
                ref["rnea_nofriction"],
                ref["mass_matrix"].ravel(),
                ref["gravity"],
                ref["coriolis"],
                ref["aba_nofriction"],
            ]
        )
        lines.append(f"{k} " + " ".join(repr(float(v)) for v in vec))
    return "\n".join(lines) + "\n"


def check_pinocchio(row: Row, robot, exe: Path, work: Path, states, refs: list[dict]) -> list:
    """Write MODEL.txt, run the harness once (it checks, then times briefly); the command to time."""
    model = work / f"pinocchio_{row.name}.txt"
    model.write_text(pinocchio_model_text(robot, states, refs))
    checks, _ = parse_harness(run([exe, model, 1, 0.1]).stdout)
    row.checks.update({f"Pinocchio {k}": v for k, v in checks.items() if isinstance(v, float)})
    bad = {k: v for k, v in checks.items() if isinstance(v, float) and not v <= CHECK_TOL}
    if bad or not checks:
        raise SystemExit(f"{row.name}: Pinocchio's model disagrees with symdyn.rnea: {bad or 'no output'}")
    return [exe, model]


# --------------------------------------------------------------------------- one robot


def bench_robot(name: str, path: Path, work: Path, opts, pin_exe: Path | None) -> Row:
    row = Row(name=name, file=str(path.relative_to(ROOT)) if path.is_relative_to(ROOT) else str(path))
    gen_dir = work / f"gen_{name}"
    log(f"[{name}] symdyn generate --target c ...")
    row.gen_wall, row.gen_cpu, robot, row.ops = generate_best(path, gen_dir, opts.gen_runs)
    row.n = robot.n
    if robot.params:
        row.notes.append("free parameters: not timed")
        return row

    log(f"[{name}] CasADi route: trace, verify, count ...")
    t0 = time.perf_counter()
    fns = casadi_route.casadi_functions(robot)
    row.notes.append(f"CasADi trace {time.perf_counter() - t0:.2f} s")
    err = casadi_route.verify(robot, fns)
    row.checks["CasADi route (casadi.Function)"] = err
    if not err <= CHECK_TOL:
        raise SystemExit(f"{name}: the CasADi route disagrees with symdyn.rnea ({err:.2e})")
    row.casadi_ops = {fn: casadi_route.flops(fns[fn]) for fn in CASADI_FUNCTIONS}

    log(f"[{name}] compile and check the C ...")
    states = make_states(robot, np.random.default_rng(SEED + robot.n))
    states_file = work / f"states_{name}.bin"
    write_states(states, states_file)
    exe = build_c(row, robot, gen_dir, work, fns)
    refs = [references(robot, states, k) for k in range(NCHECK)]  # symdyn.rnea, shared by both checks
    check_c(row, robot, exe, states_file, states, refs)
    pin_cmd = None
    if pin_exe is not None:
        log(f"[{name}] check Pinocchio ...")
        pin_cmd = check_pinocchio(row, robot, pin_exe, work, states, refs)
    log(f"[{name}] time the C" + (" and Pinocchio" if pin_cmd else "") + " ...")
    time_compiled(row, [exe, states_file, "time"], pin_cmd, opts)

    log(f"[{name}] NumPy RNEA and casadi.Function from Python ...")
    time_numpy_and_casadi(row, robot, fns, states, opts.py_reps, opts.py_budget)
    return row


# --------------------------------------------------------------------------- output


def fmt(x, digits: int = 1) -> str:
    if x is None or (isinstance(x, float) and not np.isfinite(x)):
        return "-"
    if isinstance(x, int):
        return f"{x:,}"
    if abs(x) >= 1000:
        return f"{x:,.0f}"
    return f"{x:.{digits}f}"


def ratio(a, b) -> str:
    if a is None or b is None or not np.isfinite(a) or not np.isfinite(b) or b == 0:
        return "-"
    return f"{a / b:.2f}x"


COLUMNS = (
    ("robot", "robot"),
    ("n", "n"),
    ("gen", "gen s wall/cpu"),
    ("function", "function"),
    ("ops", "ops"),
    ("cr_ops", "CasADi ops"),
    ("ops_ratio", "ops sd/CasADi"),
    ("c_ns", "symdyn C ns"),
    ("cr_c_ns", "CasADi C ns"),
    ("cr_ratio", "sd/CasADi-C"),
    ("pin_ns", "Pinocchio ns"),
    ("pin_ratio", "sd/Pin"),
    ("cr_py", "CasADi py us"),
    ("np1", "NumPy us"),
    ("npb", "NumPy batch us/state"),
)


def table_rows(rows: list[Row]) -> list[dict]:
    out = []
    for row in rows:
        for j, fn in enumerate(FUNCTIONS):
            ops = row.ops.get(fn, {}).get("total")
            cro = row.casadi_ops.get(fn, {}).get("total")
            c = row.c_ns.get(fn)
            crc = row.cr_c_ns.get(fn)
            pin_alg = PINOCCHIO.get(fn)
            pin = row.pin_ns.get(pin_alg) if pin_alg else None
            out.append(
                {
                    "robot": row.name if j == 0 else "",
                    "n": str(row.n) if j == 0 else "",
                    "gen": f"{row.gen_wall:.2f}/{row.gen_cpu:.2f}" if j == 0 else "",
                    "function": f"{fn} ({SHORT[fn]})",
                    "ops": fmt(ops),
                    "cr_ops": fmt(cro) if cro else "",
                    "ops_ratio": ratio(ops, cro) if cro else "",
                    "c_ns": fmt(c),
                    "cr_c_ns": fmt(crc) if crc is not None else "",
                    "cr_ratio": ratio(c, crc) if crc is not None else "",
                    "pin_ns": (fmt(pin) + f" ({PINOCCHIO_NAMES[pin_alg]})") if pin is not None else "",
                    "pin_ratio": ratio(c, pin) if pin is not None else "",
                    "cr_py": fmt(row.cr_py_us.get(fn)) if fn in row.cr_py_us else "",
                    "np1": fmt(row.numpy_us) if fn == "inverse_dynamics" and row.c_ns else "",
                    "npb": fmt(row.numpy_batch_us, 2) if fn == "inverse_dynamics" and row.c_ns else "",
                }
            )
    return out


def render_table(rows: list[Row], markdown: bool) -> str:
    data = table_rows(rows)
    keys = [k for k, _ in COLUMNS]
    heads = [h for _, h in COLUMNS]
    if markdown:
        lines = ["| " + " | ".join(heads) + " |"]
        lines.append("|" + "|".join("---" if k in ("robot", "function") else "---:" for k in keys) + "|")
        for d in data:
            lines.append("| " + " | ".join(d[k] for k in keys) + " |")
        return "\n".join(lines)
    widths = [max(len(h), *(len(d[k]) for d in data)) for k, h in zip(keys, heads, strict=True)]
    left = {"robot", "function", "pin_ns"}

    def line(cells):
        return "  ".join(
            c.ljust(w) if k in left else c.rjust(w) for k, c, w in zip(keys, cells, widths, strict=True)
        ).rstrip()

    out = [line(heads), line(["-" * w for w in widths])]
    for i, d in enumerate(data):
        if i and d["robot"]:
            out.append("")
        out.append(line([d[k] for k in keys]))
    return "\n".join(out)


def verdict(ok: bool | None) -> str:
    return "SKIP" if ok is None else ("PASS" if ok else "FAIL")


def targets(rows: dict[str, Row], sym: Row | None, have_pin: bool) -> list[str]:
    lines = []
    arms = [rows[a] for a in ARMS if a in rows]
    for fn in CASADI_FUNCTIONS:
        for r in arms:
            c, cr = r.c_ns.get(fn), r.cr_c_ns.get(fn)
            best = min(r.samples[fn]) / min(r.samples["cr_" + fn])
            ops, cro = r.ops[fn]["total"], r.casadi_ops[fn]["total"]
            lines.append(
                f"{verdict(c < cr)}  {r.name} {fn}: faster than the CasADi route's C: "
                f"{c:.1f} ns vs {cr:.1f} ns = {c / cr:.2f}x (< 1x; fastest repetitions {best:.2f}x)"
            )
            lines.append(
                f"{verdict(c <= 0.8 * cr)}  {r.name} {fn}: goal 0.8x the CasADi route's time: {c / cr:.2f}x"
            )
            lines.append(
                f"{verdict(ops <= 0.8 * cro)}  {r.name} {fn}: goal 0.8x the CasADi route's flops: "
                f"{ops} ops vs {cro} = {ops / cro:.2f}x"
            )
    for fn, alg in (("coriolis_matrix", "coriolis_matrix"), ("forward_dynamics", "aba")):
        for r in arms:
            c, p = r.c_ns.get(fn), r.pin_ns.get(alg)
            if not have_pin or p is None:
                lines.append(f"SKIP  {r.name} {fn} <= 0.5x Pinocchio's {PINOCCHIO_NAMES[alg]}: no Pinocchio")
                continue
            best = min(r.samples[fn]) / min(r.samples["pin_" + alg])
            lines.append(
                f"{verdict(c <= 0.5 * p)}  {r.name} {fn} <= 0.5x Pinocchio's {PINOCCHIO_NAMES[alg]}: "
                f"{c:.1f} ns vs {p:.1f} ns = {c / p:.2f}x (fastest repetitions {best:.2f}x)"
            )
    for r in arms:
        lines.append(
            f"{verdict(r.gen_wall < 3.0)}  {r.name}: symdyn generate --target c (7 functions) < 3 s: "
            f"{r.gen_wall:.2f} s wall ({r.gen_cpu:.2f} s CPU)"
        )
    if sym is not None:
        lines.append(
            f"{verdict(sym.gen_wall < 5.0)}  puma560, all 60 inertial parameters symbolic: generate < 5 s: "
            f"{sym.gen_wall:.2f} s wall ({sym.gen_cpu:.2f} s CPU)"
        )
        tau = sym.ops["inverse_dynamics"]["total"]
        lines.append(
            f"{verdict(tau <= 800)}  puma560, all inertial parameters symbolic: tau <= 800 operations: {tau}"
        )
    for r in [*arms, *([sym] if sym else [])]:
        C, V = r.ops["coriolis_matrix"]["total"], r.ops["coriolis"]["total"]
        lines.append(
            f"{verdict(C <= 3 * V)}  {r.name}: Coriolis matrix <= 3x the operations of V: "
            f"{C} vs {V} = {C / V:.2f}x"
        )
    return lines


# --------------------------------------------------------------------------- main


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--quick", action="store_true", help="fewer robots and repetitions")
    ap.add_argument("--markdown", action="store_true", help="print the table in Markdown")
    ap.add_argument("--robots", nargs="+", choices=list(ROBOTS), help="only these robots")
    ap.add_argument("--no-pinocchio", action="store_true", help="skip Pinocchio even if installed")
    ap.add_argument("--reps", type=int, help="timing repetitions per C/C++ function (default 60, quick 12)")
    ap.add_argument("--rounds", type=int, help="alternating C / Pinocchio rounds (default 4, quick 2)")
    ap.add_argument("--gen-runs", type=int, help="generation runs per robot, best kept (default 2, quick 1)")
    ap.add_argument("--target-ms", type=float, help="length of one repetition in ms (default 2)")
    ap.add_argument(
        "--build-dir", type=Path, default=RESULTS / "build", help="cache of the Pinocchio harness"
    )
    ap.add_argument("--keep", type=Path, help="keep the generated and compiled files in this directory")
    opts = ap.parse_args(argv)
    opts.reps = opts.reps or (12 if opts.quick else 60)
    opts.rounds = opts.rounds or (2 if opts.quick else 4)
    opts.gen_runs = opts.gen_runs or (1 if opts.quick else 2)
    opts.target_ms = opts.target_ms or 2.0
    opts.py_reps = 3 if opts.quick else 5
    opts.py_budget = 0.15 if opts.quick else 0.5
    names = opts.robots or (QUICK_ROBOTS if opts.quick else tuple(ROBOTS))

    t_start = time.perf_counter()
    load_before = load_average()
    digest_before = source_digest()
    pinned = pin_to_one_core()
    robot_files = chains.write_robot_files()
    RESULTS.mkdir(parents=True, exist_ok=True)

    pin_exe, pin_note = None, "Pinocchio skipped (--no-pinocchio)"
    if not opts.no_pinocchio:
        prefix, pin_note = pinocchio_prefix()
        if prefix is not None:
            try:
                pin_exe, how = build_pinocchio(prefix, opts.build_dir)
                pin_note += f", headers {prefix / 'include'}; harness {how}"
            except (RuntimeError, OSError) as exc:
                pin_note += f": the harness did not compile, Pinocchio columns skipped ({str(exc)[:400]})"
                pin_exe = None
        else:
            pin_note += "; Pinocchio columns skipped"

    if opts.keep:
        opts.keep.mkdir(parents=True, exist_ok=True)
        work_ctx = None
        work = opts.keep
    else:
        work_ctx = tempfile.TemporaryDirectory(prefix="symdyn_bench_")
        work = Path(work_ctx.name)
    rows: list[Row] = []
    try:
        for name in names:
            rows.append(bench_robot(name, ROBOTS[name], work, opts, pin_exe))
        sym = bench_robot("puma560_symbolic", robot_files["puma560_symbolic"], work, opts, None)
    finally:
        if work_ctx is not None:
            work_ctx.cleanup()

    import casadi

    import symdyn

    notes = [
        f"machine: {machine()}; load average {load_before} at the start, {load_average()} at the end; "
        f"timing process {pinned}",
        f"C: {compiler_version(C_COMPILER)}, flags {' '.join(FLAGS)} for symdyn's C, the CasADi route's C "
        "and the harness (separate translation units, no LTO)",
        f"C++: {compiler_version(CXX_COMPILER)}, flags {' '.join(FLAGS + CXX_EXTRA)} (header-only Pinocchio)",
        f"Pinocchio: {pin_note}",
        f"symdyn {getattr(symdyn, '__version__', '?')}, casadi {casadi.__version__}, numpy {np.__version__}, "
        f"Python {platform.python_version()}",
        f"ns/call: median of {opts.reps} repetitions of ~{opts.target_ms:g} ms each (after calibration and "
        f"warm-up), cycling through {NSTATES} random states (state changes every call), one output element "
        "per call into a volatile sink; repetitions interleaved across the functions of one harness, and "
        f"the C and Pinocchio harnesses run in {opts.rounds} alternating rounds",
        "gen s: `symdyn generate ROBOT --target c` in a fresh process (import, load, derive, render, "
        f"write), wall / CPU (user+sys) seconds, best of {opts.gen_runs} run(s)",
        "ops: symdyn's OpCount per function (NAME_dynamics.c); CasADi ops: the same categories counted "
        "over the traced SX algorithm (add/sub, mul/sq, div, sin/cos, others; negations not counted, "
        "as symdyn does not count unary minus)",
        "friction: INCLUDED on both symdyn's and the CasADi route's inverse dynamics (viscous qd + "
        "coulomb sign(qd)); Pinocchio's rnea and aba have no joint friction (its model gets the reflected "
        "rotor inertia as `armature`), so for puma560 (the one timed robot with friction) Pinocchio "
        "does 2n multiplications, 2n additions and n signs less",
        "the Targets lines judge the medians; 'fastest repetitions' is the ratio of the minima over all "
        "repetitions, a view less sensitive to the load of a shared machine",
        "Pinocchio crba fills the upper triangle only; symdyn's mass_matrix and the CasADi route write "
        "all n*n entries",
        "NumPy us: symdyn.rnea.rnea, one state per call; batch: one call on 1000 states, divided by 1000",
        "CasADi py us: the casadi.Function called from Python with NumPy arguments",
        "puma560_symbolic: bench/chains/puma560_symbolic.yaml (examples/puma560.yaml with all 60 inertial "
        "parameters free, no motor inertia, no friction); generated, not timed",
    ]
    worst = {}
    for r in rows:
        for k, v in r.checks.items():
            kind = k.split(" ")[0]
            worst[kind] = max(worst.get(kind, 0.0), v)
    check_line = (
        "checks against symdyn.rnea (max relative error over all robots, "
        f"{NCHECK} states each for C/C++, 5 for casadi.Function): "
        + ", ".join(f"{k} {v:.1e}" for k, v in sorted(worst.items()))
        + f"; tolerance {CHECK_TOL:g}: all passed"
    )
    per_robot = [f"{r.name}: " + "; ".join(r.notes) for r in rows if r.notes]
    digest_after = source_digest()
    if digest_after == digest_before:
        notes.append(f"symdyn source digest {digest_before} (unchanged during the run)")
    else:
        notes.append(
            f"WARNING: symdyn's source changed during the run ({digest_before} -> {digest_after}): "
            "rows may have generated code from different versions; run again"
        )
    verdicts = targets({r.name: r for r in rows}, sym, pin_exe is not None)
    total = time.perf_counter() - t_start

    nparams = len(load(robot_files["puma560_symbolic"]).params)
    extra = [
        *per_robot,
        f"puma560_symbolic: {sym.n} joints, {nparams} free parameters, generation {sym.gen_wall:.2f} s wall "
        f"/ {sym.gen_cpu:.2f} s CPU, ops "
        + ", ".join(f"{SHORT[f]} {sym.ops[f]['total']}" for f in FUNCTIONS),
        f"whole run: {total:.0f} s",
    ]

    def report(markdown: bool) -> str:
        bullet = "- " if markdown else ""
        text = [render_table([*rows, sym], markdown), ""]
        text.append("**Notes**" if markdown else "Notes:")
        text += [bullet + n for n in [*notes, check_line, *extra]]
        text += ["", "**Targets**" if markdown else "Targets:"]
        text += ["```", *verdicts, "```"] if markdown else verdicts
        return "\n".join(text) + "\n"

    print(report(opts.markdown), end="")
    stem = "run" + ("_quick" if opts.quick else "") + ("_partial" if opts.robots else "")
    (RESULTS / f"{stem}.txt").write_text(report(False))
    (RESULTS / f"{stem}.md").write_text(report(True))
    payload = {
        "rows": [asdict(r) for r in rows],
        "puma560_symbolic": asdict(sym),
        "notes": notes,
        "targets": verdicts,
        "seconds": total,
    }
    (RESULTS / f"{stem}.json").write_text(json.dumps(payload, indent=1, default=str))
    return 0


if __name__ == "__main__":
    shutil.which(C_COMPILER) or sys.exit(f"{C_COMPILER} not found")
    sys.exit(main())
