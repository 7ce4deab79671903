"""Speed of the generated centroidal momentum matrix of a floating robot against Pinocchio C++
(issue 23, item 5, the centroidal part).

X
    python bench/floating_centroidal.py --talos  # and Talos (32 joints + base: minutes to derive)

For each robot of example-robot-data on a JointModelFreeFlyer: symdyn's C of `--functions
centroidal` (NAME_centroidal_momentum_matrix, NAME_centroidal_momentum_drift) in a C harness and
Pinocchio's computeCentroidalMap and computeCentroidalMapTimeVariation + dAg v
(bench/pinocchio_centroidal.cpp, the model of bench/pinocchio_model.hpp under a free flyer), both
checked against the numeric oracle (symdyn.oracle.centroidal) at NCHECK states, then timed on the
same NSTATES states (random configurations with unit quaternions) in alternating rounds
(bench/c_harness.time_compiled, medians; the target ratio is 0.25). Each function runs in its own
hot loop on the states in turn; both programs read the thread's CPU time
(CLOCK_THREAD_CPUTIME_ID), not the wall clock, so that the scheduler slices of other processes on
a loaded machine are not counted (bench/floating.py says why). The table goes to stdout and
bench/results/floating_centroidal.txt, every number to bench/results/floating_centroidal.json.
"""

from __future__ import annotations

import argparse
import json
import sys
import tempfile
import time
import warnings
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))

import pin_harness  # noqa: E402
from c_harness import parse_harness, time_compiled  # noqa: E402
from c_snippets import CPU_CLOCK, skeleton  # noqa: E402
from machine import C_COMPILER, FLAGS, RESULTS, load_averages, log, machine, pin_to_one_core, run  # noqa: E402
from row import Row  # noqa: E402
from states import CHECK_TOL, NCHECK, NSTATES, SEED, rel_err  # noqa: E402

import symdyn  # noqa: E402
from symdyn.codegen import c as c_target  # noqa: E402
from symdyn.codegen import context  # noqa: E402
from symdyn.oracle.centroidal import centroidal  # noqa: E402
from symdyn.regenerate import example_robot_data_folder  # noqa: E402

ROBOTS = {
    "solo12": "solo_description/robots/solo12.urdf",
    "talos": "talos_data/robots/talos_reduced.urdf",
}
#: table row -> (symdyn label, Pinocchio label)
ROWS = {
    "centroidal map A_g": ("centroidal_momentum_matrix", "centroidal_map"),
    "A_g and Adot_g v": ("map_and_drift", "centroidal_map_time_variation"),
}
TARGET = 0.25

HARNESS = r"""/* Centroidal timing harness: written by bench/floating_centroidal.py, do not edit. */
{clock}
{prelude}
#include "{prefix}_dynamics.h"

#define NQ {nq}
#define NV {nv}
#define K {nstates}
#define MAXREPS 1000
#define NB 2

static double Q[K][NQ], V[K][NV];
static double AG[6 * NV], H[6];
static const char *LABELS[NB] = {{"centroidal_momentum_matrix", "map_and_drift"}};

{print_out}

{run_bench}

int main(int argc, char **argv)
{{
{main_head}{read_states}    if (strcmp(argv[2], "check") == 0) {{
        int ncheck = argc > 3 ? atoi(argv[3]) : 4;
        for (k = 0; k < ncheck && k < K; ++k) {{
            {prefix}_centroidal_momentum_matrix(Q[k], NULL, AG);
            print_out("Ag", k, AG, 6 * NV);
            {prefix}_centroidal_momentum_drift(Q[k], V[k], NULL, H);
            print_out("drift", k, H, 6);
        }}
        return 0;
    }}
{time_main}}}
"""


def load(name: str):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return symdyn.load_urdf(example_robot_data_folder() / ROBOTS[name], floating=True)


def make_states(robot, rng) -> tuple[np.ndarray, np.ndarray]:
    Q = rng.uniform(-1.5, 1.5, (NSTATES, robot.nq))
    quat = rng.normal(size=(NSTATES, 4))
    Q[:, 3:7] = quat / np.linalg.norm(quat, axis=1, keepdims=True)
    return Q, rng.normal(size=(NSTATES, robot.nv))


def pinocchio_model_text(robot, Q, V) -> str:
    """MODEL.txt of bench/pinocchio_centroidal.cpp: the joints (pin_harness), the `floating` line
    of the base body (bench/pinocchio_model.hpp), the states."""
    lines = pin_harness.floating_model_lines(robot)
    lines.append(f"nstates {NSTATES}")
    lines += [" ".join(repr(float(x)) for x in np.r_[q, v]) for q, v in zip(Q, V, strict=True)]
    return "\n".join(lines) + "\n"


def check(what: str, text: str, robot, Q, V) -> float:
    checks, _ = parse_harness(text)
    worst = 0.0
    for k in range(NCHECK):
        st = centroidal(robot, Q[k], V[k])
        worst = max(worst, rel_err(checks["Ag"][k], st.Ag.ravel()), rel_err(checks["drift"][k], st.drift))
    if worst > CHECK_TOL:
        raise SystemExit(f"{what} disagrees with the oracle: {worst:.2e}")
    return worst


def bench_robot(name: str, work: Path, opts, pin_exe: Path | None) -> dict:
    robot = load(name)
    log(f"{name}: deriving and generating the centroidal group ...")
    t0 = time.perf_counter()
    ctx = context(robot, functions=("centroidal",))
    generation = time.perf_counter() - t0
    folder = work / name
    folder.mkdir(parents=True, exist_ok=True)
    for file, text in c_target.render(ctx).items():
        (folder / file).write_text(text)
    prefix = ctx.name
    (folder / "harness.c").write_text(
        HARNESS.format(
            prefix=prefix,
            nq=robot.nq,
            nv=robot.nv,
            nstates=NSTATES,
            clock=CPU_CLOCK,
            **skeleton(
                [
                    f"LOOP({prefix}_centroidal_momentum_matrix(Q[k], NULL, AG), AG[0])",
                    f"LOOP({prefix}_centroidal_momentum_matrix(Q[k], NULL, AG); "
                    f"{prefix}_centroidal_momentum_drift(Q[k], V[k], NULL, H), AG[0] + H[0])",
                ],
                ("Q", "NQ"),
                ("V", "NV"),
            ),
        )
    )
    exe = folder / "harness"
    run([C_COMPILER, *FLAGS, "-o", exe, folder / "harness.c", folder / f"{prefix}_dynamics.c", "-lm"])
    Q, V = make_states(robot, np.random.default_rng(SEED))
    states = folder / "states.bin"
    np.concatenate([Q, V], axis=1).astype(np.float64).tofile(states)
    c_err = check("symdyn's C", run([exe, states, "check", NCHECK]).stdout, robot, Q, V)
    pin_cmd, pin_err = None, None
    if pin_exe is not None:
        model = folder / "MODEL.txt"
        model.write_text(pinocchio_model_text(robot, Q, V))
        pin_err = check("Pinocchio", run([pin_exe, model, "check", NCHECK]).stdout, robot, Q, V)
        pin_cmd = [pin_exe, model, "time"]
    row = Row(name)
    time_compiled(row, [exe, states, "time"], pin_cmd, opts)
    out = {
        "robot": name,
        "nv": robot.nv,
        "generation_s": generation,
        "check_c": c_err,
        "check_pinocchio": pin_err,
    }
    for title, (mine, theirs) in ROWS.items():
        out[title] = {"symdyn_ns": row.c_ns[mine], "pinocchio_ns": row.pin_ns.get(theirs)}
    return out


def table(results: list[dict], note: str) -> list[str]:
    lines = [
        f"Centroidal quantities of floating robots, symdyn's C vs Pinocchio C++ ({machine()})",
        f"Pinocchio: {note}; target: symdyn <= {TARGET}x Pinocchio",
        "",
        f"{'robot':8} {'NV':>3} {'function':20} {'symdyn ns':>10} {'Pinocchio ns':>13} {'ratio':>6}",
    ]
    for r in results:
        for title in ROWS:
            s, p = r[title]["symdyn_ns"], r[title]["pinocchio_ns"]
            ratio = f"{s / p:6.2f}" if p else "     -"
            lines.append(f"{r['robot']:8} {r['nv']:>3} {title:20} {s:10.0f} {p or 0:13.0f} {ratio}")
    lines.append("")
    lines += [
        f"{r['robot']}: generation (derivation + centroidal group) {r['generation_s']:.1f} s" for r in results
    ]
    return lines


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--talos", action="store_true", help="also Talos (its derivation takes minutes)")
    ap.add_argument("--quick", action="store_true", help="fewer repetitions")
    opts = ap.parse_args(argv)
    opts.reps, opts.rounds, opts.target_ms = (6, 2, 5.0) if opts.quick else (30, 3, 20.0)
    log(pin_to_one_core())
    build = Path(tempfile.gettempdir()) / "symdyn_bench_pinocchio"
    pin_exe, note = pin_harness.prepare(build, "pinocchio_centroidal.cpp")
    names = ["solo12", "talos"] if opts.talos else ["solo12"]
    with tempfile.TemporaryDirectory() as tmp:
        results = [bench_robot(name, Path(tmp), opts, pin_exe) for name in names]
    lines = table(results, note)
    lines.append(f"load averages at the end: {', '.join(f'{x:.2f}' for x in load_averages())}")
    print("\n".join(lines))
    RESULTS.mkdir(exist_ok=True)
    (RESULTS / "floating_centroidal.txt").write_text("\n".join(lines) + "\n")
    (RESULTS / "floating_centroidal.json").write_text(json.dumps(results, indent=2) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
