"""Floating-base speed (issue 23): symdyn's generated C against Pinocchio's C++ on Solo-12 and Talos.

    python bench/floating.py [--reps N] [--target-ms MS] [--build-dir DIR]

For each robot of example-robot-data loaded with `floating=True` (solo12, talos_reduced):
`symdyn generate ROBOT --floating --functions dynamics --target c` is timed (wall and CPU of the
child process: the generation target is <= 60 s); the generated inverse_dynamics, mass_matrix and
forward_dynamics are compiled with machine.FLAGS into a small harness, checked against
symdyn.rnea at the first NCHECK states and timed; bench/pinocchio_floating.cpp (Pinocchio's free
flyer, compiled header-only by bench/pin_harness.py) checks its rnea, crba and aba against the same
numbers and times them on the same states.

How it is timed (both sides alike): each function runs in its own hot loop, one call after the
other on the NSTATES states in turn (the state changes every call), for about TARGET_MS per
repetition, after a calibration that also warms the caches; the repetitions are interleaved
across the functions, and the C and Pinocchio programs run in alternating rounds
(bench/c_harness.time_compiled), so that a change of machine load falls on both; the figure is
the median over all repetitions. The clock is the thread's CPU time (CLOCK_THREAD_CPUTIME_ID),
not the wall clock: on a machine with more runnable processes than cores a repetition of a few
milliseconds otherwise either runs in one scheduler slice or also counts the slices of other
processes, which made single repetitions 2-7 times slower and medians unstable (docs/speed.md).
The generated functions write every entry of their outputs, M's zeros included, on every call.
The table goes to stdout and bench/results/floating.txt; the targets are symdyn <= 0.25 x
Pinocchio.
"""

from __future__ import annotations

import argparse
import resource
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
from c_harness import parse_harness, time_compiled
from c_snippets import CPU_CLOCK, skeleton
from machine import C_COMPILER, FLAGS, RESULTS, load_averages, machine, run
from pin_harness import model_and_states_lines, prepare
from row import Row
from states import NCHECK, NSTATES, SEED, rel_err

import symdyn
from symdyn.regenerate import example_robot_data_folder
from symdyn.rnea import forward_dynamics, mass_matrix

ROBOTS = {
    "solo12": "solo_description/robots/solo12.urdf",
    "talos_reduced": "talos_data/robots/talos_reduced.urdf",
}
#: (symdyn function, its arguments, output length, the Pinocchio algorithm it is measured against)
FUNCTIONS = (
    ("inverse_dynamics", "Q[k], V[k], A[k]", "NV", "rnea"),
    ("mass_matrix", "Q[k]", "NV * NV", "crba"),
    ("forward_dynamics", "Q[k], V[k], T[k]", "NV", "aba"),
)

HARNESS = r"""/* Floating-base timing harness: written by bench/floating.py, do not edit. */
{clock}
{prelude}
#include "{prefix}_dynamics.h"

#define NQ {prefix}_NQ
#define NV {prefix}_NV
#define K {nstates}
#define MAXREPS 1000
#define NB 3

static double Q[K][NQ], V[K][NV], A[K][NV], T[K][NV];
static double OUT[NV * NV];
static const double *P = NULL;
static const char *LABELS[NB] = {{{labels}}};

{run_bench}

{print_out}

int main(int argc, char **argv)
{{
{main_head}{read_states}    if (strcmp(argv[2], "check") == 0) {{
        for (k = 0; k < {ncheck}; ++k) {{
{checks}
        }}
        return 0;
    }}
{time_main}}}
"""


def harness_source(prefix: str) -> str:
    loops = [f"LOOP({prefix}_{fn}({args}, P, OUT), OUT[0])" for fn, args, _, _ in FUNCTIONS]
    checks = [
        f'            {prefix}_{fn}({args}, P, OUT); print_out("{fn}", k, OUT, {size});'
        for fn, args, size, _ in FUNCTIONS
    ]
    return HARNESS.format(
        prefix=prefix,
        nstates=NSTATES,
        ncheck=NCHECK,
        labels=", ".join(f'"{fn}"' for fn, *_ in FUNCTIONS),
        checks="\n".join(checks),
        clock=CPU_CLOCK,
        **skeleton(loops, ("Q", "NQ"), ("V", "NV"), ("A", "NV"), ("T", "NV")),
    )


def states(robot, rng) -> dict[str, np.ndarray]:
    """NSTATES states: base position in [-1, 1], a random unit quaternion, joints in [-pi, pi],
    v in [-2, 2], a in [-5, 5]; tau = the frictionless inverse dynamics (so aba returns a)."""
    quat = rng.normal(size=(NSTATES, 4))
    quat /= np.linalg.norm(quat, axis=1, keepdims=True)
    q = np.hstack([rng.uniform(-1, 1, (NSTATES, 3)), quat, rng.uniform(-np.pi, np.pi, (NSTATES, robot.n))])
    v = rng.uniform(-2, 2, (NSTATES, robot.nv))
    a = rng.uniform(-5, 5, (NSTATES, robot.nv))
    return {"q": q, "v": v, "a": a, "tau": symdyn.rnea(robot, q, v, a, friction=False)}


def generate(path: Path, out: Path) -> tuple[float, float]:
    """Wall and CPU seconds of `symdyn generate PATH --floating --functions dynamics --target c`."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    t0 = time.perf_counter()
    cmd = [sys.executable, "-m", "symdyn.cli", "generate", str(path), "--floating", "--functions", "dynamics"]
    subprocess.run([*cmd, "--target", "c", "--out", str(out)], check=True, capture_output=True)
    wall = time.perf_counter() - t0
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    return wall, (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)


def pinocchio_text(robot, st) -> str:
    """MODEL.txt of bench/pinocchio_floating.cpp: the joints (pin_harness), the base body, the states
    and symdyn.rnea's rnea, crba and aba at the first NCHECK states."""
    lines = model_and_states_lines(
        robot, {"q": st["q"][:, 7:], "qd": st["v"][:, 6:], "qdd": st["a"][:, 6:], "tau": st["tau"][:, 6:]}
    )
    lines = lines[: 2 + robot.n]
    b = robot.base_body
    I = np.array(b.inertia, dtype=float)
    base = [
        float(b.mass),
        *np.array(b.com, dtype=float).ravel(),
        *I[np.triu_indices(3)],  # xx xy xz yy yz zz
    ]
    lines.insert(2, "floating " + " ".join(repr(float(x)) for x in base))
    lines.append(f"nstates {NSTATES}")
    for k in range(NSTATES):
        lines.append(
            " ".join(repr(float(x)) for x in np.concatenate([st[x][k] for x in ("q", "v", "a", "tau")]))
        )
    lines.append(f"ncheck {NCHECK}")
    for k in range(NCHECK):
        q, v, a, tau = (st[x][k] for x in ("q", "v", "a", "tau"))
        M = mass_matrix(robot, q)
        vec = np.concatenate([tau, M.ravel(), a])
        lines.append(f"{k} " + " ".join(repr(float(x)) for x in vec))
    return "\n".join(lines) + "\n"


def bench_robot(name: str, path: Path, work: Path, pin_exe: Path | None, opts) -> dict:
    robot = symdyn.load_urdf(path, floating=True)
    gen = work / name
    wall, cpu = generate(path, gen)
    prefix = robot.name
    (work / f"{name}_harness.c").write_text(harness_source(prefix))
    exe = work / f"{name}_harness"
    run(
        [
            C_COMPILER,
            *FLAGS,
            "-I",
            str(gen),
            "-o",
            str(exe),
            str(work / f"{name}_harness.c"),
            str(gen / f"{prefix}_dynamics.c"),
            "-lm",
        ]
    )
    st = states(robot, np.random.default_rng(SEED))
    block = np.hstack([st["q"], st["v"], st["a"], st["tau"]])
    states_file = work / f"{name}.states"
    states_file.write_bytes(np.ascontiguousarray(block, dtype="<f8").tobytes())
    checks, _ = parse_harness(run([str(exe), str(states_file), "check"]).stdout)
    errors = {}
    for k in range(NCHECK):
        q, v, a, tau = (st[x][k] for x in ("q", "v", "a", "tau"))
        ref = {
            "inverse_dynamics": symdyn.rnea(robot, q, v, a),
            "mass_matrix": mass_matrix(robot, q).ravel(),
            "forward_dynamics": forward_dynamics(robot, q, v, tau),
        }
        for fn, want in ref.items():
            errors[fn] = max(errors.get(fn, 0.0), rel_err(checks[fn][k], want))
    result = {"name": name, "joints": robot.n, "nv": robot.nv, "wall": wall, "cpu": cpu, "errors": errors}
    pin_cmd = None
    if pin_exe is not None:
        model = work / f"{name}_model.txt"
        model.write_text(pinocchio_text(robot, st))
        result["pin_errors"] = parse_harness(run([str(pin_exe), str(model), "1", "0.1"]).stdout)[0]
        pin_cmd = [pin_exe, model]
    row = Row(name)
    time_compiled(row, [exe, states_file, "time"], pin_cmd, opts)
    result["symdyn"] = row.c_ns
    if pin_cmd is not None:
        result["pinocchio"] = row.pin_ns
    return result


def table(results: list[dict], note: str) -> str:
    lines = [
        "Floating base (issue 23): symdyn's generated C against Pinocchio's C++ (free flyer)",
        f"machine: {machine()}",
        f"Pinocchio: {note}",
        "",
        f"{'robot':14} {'function':17} {'symdyn ns':>10} {'Pinocchio':>10} {'algorithm':>9} {'ratio':>6} "
        f"{'target':>7}",
    ]
    for r in results:
        for fn, _, _, algorithm in FUNCTIONS:
            ours = r["symdyn"][fn]
            theirs = r.get("pinocchio", {}).get(algorithm)
            ratio = f"{ours / theirs:6.2f}" if theirs else "     -"
            verdict = ("PASS" if ours <= 0.25 * theirs else "FAIL") if theirs else "SKIP"
            pin = f"{theirs:10.0f}" if theirs else "         -"
            lines.append(f"{r['name']:14} {fn:17} {ours:10.0f} {pin} {algorithm:>9} {ratio} {verdict:>7}")
    lines.append("")
    for r in results:
        errs = ", ".join(f"{fn} {e:.1e}" for fn, e in r["errors"].items())
        pin_errs = ", ".join(f"{fn} {e:.1e}" for fn, e in r.get("pin_errors", {}).items())
        verdict = "PASS" if r["wall"] <= 60 else "FAIL"
        lines.append(
            f"{r['name']}: {r['joints']} joints + free flyer (NV = {r['nv']}); generate --floating "
            f"--functions dynamics: {r['wall']:.1f} s wall, {r['cpu']:.1f} s CPU ({verdict} <= 60 s)"
        )
        lines.append(f"  checks against symdyn.rnea (relative): C {errs}; Pinocchio {pin_errs or '-'}")
    return "\n".join(lines) + "\n"


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--reps", type=int, default=21)
    parser.add_argument("--rounds", type=int, default=7, help="alternating rounds, C and Pinocchio")
    parser.add_argument("--target-ms", type=float, default=2.0)
    parser.add_argument("--build-dir", type=Path, default=RESULTS / "build")
    opts = parser.parse_args(argv)
    folder = example_robot_data_folder()
    if folder is None:
        print("example-robot-data is not installed", file=sys.stderr)
        return 1
    pin_exe, note = prepare(opts.build_dir, "pinocchio_floating.cpp")
    with tempfile.TemporaryDirectory() as tmp:
        results = [bench_robot(name, folder / rel, Path(tmp), pin_exe, opts) for name, rel in ROBOTS.items()]
    text = table(results, note)
    text += f"load averages at the end: {', '.join(f'{x:.2f}' for x in load_averages())}\n"
    sys.stdout.write(text)
    RESULTS.mkdir(exist_ok=True)
    (RESULTS / "floating.txt").write_text(text)
    return 0


if __name__ == "__main__":
    sys.exit(main())
