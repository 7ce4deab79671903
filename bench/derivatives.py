"""The derivative part of bench/run.py (issue 13): symdyn's derivative C against Pinocchio and CasADi.

For each of the arms (bench/robots.py ARMS: PUMA 560, Stanford, Panda), in the same run as the
other functions:

* symdyn's generated C: NAME_inverse_dynamics_derivatives, NAME_forward_dynamics_derivatives,
  NAME_mass_matrix_inverse (and NAME_linearize, which has no counterpart);
* the CasADi route (bench/casadi_route_derivatives.py): CasADi's Jacobians of the traced RNEA, of
  qdd = solve(M, tau - bias), and solve(M, I), code-generated and compiled with the same flags;
* Pinocchio's analytical derivatives (bench/pinocchio_harness.cpp): computeRNEADerivatives,
  computeABADerivatives, computeMinverse.

One small C program (`HARNESS`) holds symdyn's and the CasADi route's functions; `check` compares
them at the first NCHECK states with central differences of symdyn.rnea (relative 1e-6), `time`
runs them in alternating rounds with the Pinocchio harness (c_harness.time_compiled). The table
gives ns per call and the ratios against the goals: <= 0.5x Pinocchio and <= 0.8x the CasADi route.
Pinocchio's model has no friction; symdyn's and the CasADi route's functions include it (the
benchmark robots' viscous terms cost a few additions).
"""

from __future__ import annotations

import json
from pathlib import Path

import casadi_route
import casadi_route_derivatives as crd
import numpy as np
from c_harness import build_harness, parse_harness, time_compiled
from machine import RESULTS, log, run
from row import Row
from states import NCHECK

from symdyn import rnea as rn_rnea
from symdyn.rnea import forward_dynamics as rn_fd

__all__ = ["bench_derivatives", "write_report", "PAIRS", "GOALS"]

#: symdyn function -> (Pinocchio algorithm, CasADi route function)
PAIRS = {
    "inverse_dynamics_derivatives": ("rnea_derivatives", "rnea_derivatives"),
    "forward_dynamics_derivatives": ("aba_derivatives", "aba_derivatives"),
    "mass_matrix_inverse": ("minverse", "minverse"),
}
PIN_NAMES = {
    "rnea_derivatives": "computeRNEADerivatives",
    "aba_derivatives": "computeABADerivatives",
    "minverse": "computeMinverse",
}
GOALS = {"pinocchio": 0.5, "casadi": 0.8}
FD_TOL = 1e-6

HARNESS = r"""/* Derivative timing harness for {name}: written by bench/derivatives.py, do not edit. */
{prelude}
#include "{prefix}_dynamics.h"
#include "crd_{name}.h"

#define N {n}
#define K {nstates}
#define MAXREPS 1000
#define NB 7

static double Q[K][N], QD[K][N], QDD[K][N], TAU[K][N];
static double O1[4 * N * N], O2[4 * N * N], O3[N * N];
static const double *P = NULL;

{cr_work}

static const char *LABELS[NB] = {{
    "inverse_dynamics_derivatives", "cr_rnea_derivatives", "forward_dynamics_derivatives",
    "cr_aba_derivatives", "mass_matrix_inverse", "cr_minverse", "linearize"}};

static void cr(int (*f)(const casadi_real **, casadi_real **, casadi_int *, casadi_real *, int),
               const double *a, const double *b, const double *c)
{{
    const casadi_real *arg[3];
    casadi_real *res[3];
    arg[0] = a; arg[1] = b; arg[2] = c;
    res[0] = O1; res[1] = O2; res[2] = O3;
    f(arg, res, cr_iw, cr_w, 0);
}}

{run_bench}

{print_out}

int main(int argc, char **argv)
{{
{main_head}    casadi_int sz_iw = 1, sz_w = 1;
{read_states}{cr_workspace}    if (strcmp(argv[2], "check") == 0) {{
        for (k = 0; k < {ncheck}; ++k) {{
            {prefix}_inverse_dynamics_derivatives(Q[k], QD[k], QDD[k], P, O1, O2);
            print_out("id_dq", k, O1, N * N); print_out("id_dqd", k, O2, N * N);
            cr(crd_{prefix}_rnea_derivatives, Q[k], QD[k], QDD[k]);
            print_out("cr_id_dq", k, O1, N * N); print_out("cr_id_dqd", k, O2, N * N);
            {prefix}_forward_dynamics_derivatives(Q[k], QD[k], TAU[k], P, O1, O2, O3);
            print_out("fd_dq", k, O1, N * N); print_out("fd_dqd", k, O2, N * N);
            print_out("fd_minv", k, O3, N * N);
            cr(crd_{prefix}_aba_derivatives, Q[k], QD[k], TAU[k]);
            print_out("cr_fd_dq", k, O1, N * N); print_out("cr_fd_dqd", k, O2, N * N);
            print_out("cr_fd_minv", k, O3, N * N);
            {prefix}_mass_matrix_inverse(Q[k], P, O1); print_out("minv", k, O1, N * N);
            cr(crd_{prefix}_minverse, Q[k], NULL, NULL); print_out("cr_minv", k, O1, N * N);
            {prefix}_linearize(Q[k], QD[k], TAU[k], P, O1, O2);
            print_out("lin_A", k, O1, 4 * N * N); print_out("lin_B", k, O2, 2 * N * N);
        }}
        return 0;
    }}
{time_main}}}
"""


SINK = "O1[k % (N * N)] + O2[k % (N * N)]"
LOOPS = (  # run_bench's benchmarks in LABELS order
    f"LOOP({{p}}_inverse_dynamics_derivatives(Q[k], QD[k], QDD[k], P, O1, O2), {SINK})",
    f"LOOP(cr(crd_{{p}}_rnea_derivatives, Q[k], QD[k], QDD[k]), {SINK})",
    f"LOOP({{p}}_forward_dynamics_derivatives(Q[k], QD[k], TAU[k], P, O1, O2, O3), {SINK})",
    f"LOOP(cr(crd_{{p}}_aba_derivatives, Q[k], QD[k], TAU[k]), {SINK})",
    f"LOOP({{p}}_mass_matrix_inverse(Q[k], P, O1), {SINK})",
    f"LOOP(cr(crd_{{p}}_minverse, Q[k], NULL, NULL), {SINK})",
    f"LOOP({{p}}_linearize(Q[k], QD[k], TAU[k], P, O1, O2), {SINK})",
)


def _central(f, x, h=1e-6) -> np.ndarray:
    E = np.eye(len(x)) * h
    return np.column_stack([(f(x + E[j]) - f(x - E[j])) / (2 * h) for j in range(len(x))])


def _wrt(f, args, k):
    """x -> f(args with args[k] replaced by x)."""
    return lambda x: f(*args[:k], x, *args[k + 1 :])


def _rel(got, want) -> float:
    return float(np.max(np.abs(np.asarray(got) - want)) / max(1.0, float(np.max(np.abs(want)))))


def _check(robot, exe: Path, states_file: Path, states) -> dict[str, float]:
    """Largest relative error of every output against central differences of symdyn.rnea."""
    checks, _ = parse_harness(run([exe, states_file, "check"]).stdout)
    n = robot.n
    worst: dict[str, float] = {}
    for k in range(NCHECK):
        q, qd, qdd, tau = (states[x][k] for x in ("q", "qd", "qdd", "tau"))
        id_args, fd_args = (robot, q, qd, qdd), (robot, q, qd, tau)
        want = {
            "dq": _central(_wrt(rn_rnea, id_args, 1), q),
            "dqd": _central(_wrt(rn_rnea, id_args, 2), qd),
            "fdq": _central(_wrt(rn_fd, fd_args, 1), q),
            "fdqd": _central(_wrt(rn_fd, fd_args, 2), qd),
            "minv": _central(_wrt(rn_fd, fd_args, 3), tau),
        }
        A = np.block([[np.zeros((n, n)), np.eye(n)], [want["fdq"], want["fdqd"]]])
        B = np.vstack([np.zeros((n, n)), want["minv"]])
        got = {  # symdyn row-major, CasADi column-major
            "id_dq": (checks["id_dq"][k].reshape(n, n), want["dq"]),
            "id_dqd": (checks["id_dqd"][k].reshape(n, n), want["dqd"]),
            "cr_id_dq": (checks["cr_id_dq"][k].reshape(n, n).T, want["dq"]),
            "cr_id_dqd": (checks["cr_id_dqd"][k].reshape(n, n).T, want["dqd"]),
            "fd_dq": (checks["fd_dq"][k].reshape(n, n), want["fdq"]),
            "fd_dqd": (checks["fd_dqd"][k].reshape(n, n), want["fdqd"]),
            "fd_minv": (checks["fd_minv"][k].reshape(n, n), want["minv"]),
            "cr_fd_dq": (checks["cr_fd_dq"][k].reshape(n, n).T, want["fdq"]),
            "cr_fd_dqd": (checks["cr_fd_dqd"][k].reshape(n, n).T, want["fdqd"]),
            "cr_fd_minv": (checks["cr_fd_minv"][k].reshape(n, n).T, want["minv"]),
            "minv": (checks["minv"][k].reshape(n, n), want["minv"]),
            "cr_minv": (checks["cr_minv"][k].reshape(n, n).T, want["minv"]),
            "lin_A": (checks["lin_A"][k].reshape(2 * n, 2 * n), A),
            "lin_B": (checks["lin_B"][k].reshape(2 * n, n), B),
        }
        for key, (a, b) in got.items():
            worst[key] = max(worst.get(key, 0.0), _rel(a, b))
    return worst


def bench_derivatives(row: Row, robot, gen_dir: Path, work: Path, states_file: Path, states, pin_cmd, opts):
    """Build, check and time the derivative functions of one robot; results in `row.derivatives`."""
    log(f"[{row.name}] derivatives: CasADi route, build, check, time ...")
    fns = crd.derivative_functions(robot)
    stem = f"bench_derivatives_{row.name}"
    exe, build_s = build_harness(
        HARNESS, LOOPS, fns, f"crd_{row.name}", stem, robot, work, gen_dir, name=row.name, ncheck=NCHECK
    )
    checks = _check(robot, exe, states_file, states)
    bad = {k: v for k, v in checks.items() if not v <= FD_TOL}
    if bad:
        raise SystemExit(f"{row.name}: derivatives disagree with differences of symdyn.rnea: {bad}")
    pin_checks = {}
    if pin_cmd is not None:
        pin_checks = {
            line.split()[1]: float(line.split()[2])
            for line in run([*pin_cmd, 1, 0.1]).stdout.splitlines()
            if line.startswith("dcheck ")
        }
        bad = {k: v for k, v in pin_checks.items() if not v <= FD_TOL}
        if bad:
            raise SystemExit(f"{row.name}: Pinocchio's derivatives disagree with its differences: {bad}")
    timed = Row(name=row.name)
    time_compiled(timed, [exe, states_file, "time"], pin_cmd, opts)
    row.derivatives = {
        "ns": dict(timed.c_ns),
        "cr_ns": dict(timed.cr_c_ns),
        "pin_ns": {k: v for k, v in timed.pin_ns.items() if k in PIN_NAMES},
        "checks": checks,
        "pin_checks": pin_checks,
        "cr_ops": {k: casadi_route.flops(f)["total"] for k, f in fns.items()},
        "build_s": build_s,
    }


def _fmt(x) -> str:
    return "-" if x is None or not np.isfinite(x) else f"{x:.0f}"


def _ratio(a, b) -> str:
    return "-" if a is None or b is None or not b else f"{a / b:.2f}"


def report_lines(rows: list[Row]) -> list[str]:
    """The derivative table (ns per call, medians) and one PASS/FAIL line per goal."""
    head = f"{'robot':<10} {'function':<29} {'ops':>6} {'symdyn':>7} {'CasADi':>7} {'Pinocchio':>9} "
    head += f"{'x Pin':>6} {'x CasADi':>8}"
    lines = ["Derivatives (ns per call; CasADi: AD of the traced RNEA/CRBA; Pinocchio: analytical)", head]
    verdicts = []
    for r in rows:
        d = r.derivatives
        if not d:
            continue
        for fn, (pin, cr) in PAIRS.items():
            s, c, p = d["ns"].get(fn), d["cr_ns"].get(cr), d["pin_ns"].get(pin)
            ops = r.ops.get(fn, {}).get("total", "-")
            lines.append(
                f"{r.name:<10} {fn:<29} {ops!s:>6} {_fmt(s):>7} {_fmt(c):>7} {_fmt(p):>9} "
                f"{_ratio(s, p):>6} {_ratio(s, c):>8}"
            )
            for goal, other, what in (("pinocchio", p, PIN_NAMES[pin]), ("casadi", c, f"CasADi route {cr}")):
                if s is not None and other:
                    ok = "PASS" if s / other <= GOALS[goal] else "FAIL"
                    verdicts.append(f"{ok}  {r.name} {fn}: {s / other:.2f}x {what} (goal <= {GOALS[goal]})")
        s = d["ns"].get("linearize")
        lines.append(f"{r.name:<10} {'linearize':<29} {'':>6} {_fmt(s):>7}")
    return lines + [""] + verdicts


def write_report(rows: list[Row]) -> str:
    """Print the table and save it as bench/results/derivatives.txt (numbers in derivatives.json)."""
    text = "\n".join(report_lines(rows)) + "\n"
    RESULTS.mkdir(parents=True, exist_ok=True)
    (RESULTS / "derivatives.txt").write_text(text)
    data = {r.name: r.derivatives for r in rows if r.derivatives}
    (RESULTS / "derivatives.json").write_text(json.dumps(data, indent=1, sort_keys=True) + "\n")
    return text
