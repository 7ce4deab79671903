"""Speed of the generated closed-loop functions against Pinocchio C++ (issue 24, item 6).

    python bench/closed_loops.py            # a few minutes once Pinocchio's harness is compiled
    python bench/closed_loops.py --quick    # fewer repetitions

For the four-bar (examples/closed_loops/fourbar.yaml) and the Delta robot: symdyn's C (the
actuated inverse and forward dynamics, NAME_actuated_inverse_dynamics and
NAME_actuated_forward_dynamics, -O3 -march=native) and Pinocchio's C++
(bench/pinocchio_loops.cpp: constraintDynamics with one CONTACT_3D RigidConstraintModel per
loop, initConstraintDynamics once), on the same NSTATES closed states (the configuration
closed by the generated solve_loops, the rates on the closure, random actuated efforts;
cycled, the state changes every call), in alternating rounds, medians. Before anything is
timed, both are checked at NCHECK states: symdyn's qdd_a against Pinocchio's ddq on the
actuated joints, symdyn's tau_a against symdyn.oracle.closed_loops.

Pinocchio has no inverse dynamics for closed loops; both of symdyn's functions are compared
with its constraintDynamics, the one call a Pinocchio user makes for the motion of such a
robot. The Delta's example rods are massless (their mass lumped at the ends, which makes the
tree's M singular and Pinocchio's constraintDynamics return NaN), so the Delta timed here keeps
each rod pair's mass on its rod as a uniform bar (and the arm and the plate their own masses).
The table goes to stdout and bench/results/closed_loops.txt.
"""

from __future__ import annotations

import argparse
import statistics
import sys
import tempfile
import warnings
from pathlib import Path

import numpy as np
import yaml

sys.path.insert(0, str(Path(__file__).resolve().parent))

import pin_harness  # noqa: E402
from c_harness import parse_harness  # noqa: E402
from c_snippets import skeleton  # noqa: E402
from machine import C_COMPILER, FLAGS, RESULTS, ROOT, load_averages, log, machine, pin_to_one_core, run  # noqa: E402
from states import NCHECK  # noqa: E402

from symdyn.algorithms.closed_loops import analyse  # noqa: E402
from symdyn.codegen import render  # noqa: E402
from symdyn.generated_modules import load_module  # noqa: E402
from symdyn.oracle import closed_loops as oc  # noqa: E402
from symdyn.parsers import robot_from_data  # noqa: E402

NSTATES = 64
TARGET = 0.25  # symdyn / Pinocchio
LOOPS = ROOT / "examples" / "closed_loops"

HARNESS = r"""/* Closed-loop timing harness: written by bench/closed_loops.py, do not edit. */
{prelude}
#include "{name}_dynamics.h"

#define N {n}
#define A {na}
#define K {nstates}
#define MAXREPS 1000
#define NB 2

static double Q[K][N], QDA[K][A], QDDA[K][A], TAUA[K][A];
static double OUT[A];
static const char *LABELS[NB] = {{"actuated_inverse_dynamics", "actuated_forward_dynamics"}};

{run_bench}

{print_out}

int main(int argc, char **argv)
{{
{main_head}{read_states}    if (strcmp(argv[2], "check") == 0) {{
        int ncheck = argc > 3 ? atoi(argv[3]) : 4;
        for (k = 0; k < ncheck && k < K; ++k) {{
            {name}_actuated_inverse_dynamics(Q[k], QDA[k], QDDA[k], NULL, OUT);
            print_out("actuated_inverse_dynamics", k, OUT, A);
            {name}_actuated_forward_dynamics(Q[k], QDA[k], TAUA[k], NULL, OUT);
            print_out("actuated_forward_dynamics", k, OUT, A);
        }}
        return 0;
    }}
{time_main}}}
"""


def delta_with_rod_inertia() -> dict:
    """The Delta example with each rod pair's mass on its rod (uniform bar), not lumped."""
    data = yaml.safe_load((LOOPS / "delta.yaml").read_text())
    data["name"] = "delta_rods"
    for link in data["links"]:
        if link["name"].startswith("arm"):
            link.update(
                mass="ma",
                com=["L/2", 0, 0],
                inertia={"ixx": 0.0001, "iyy": "ma*L**2/12", "izz": "ma*L**2/12"},
            )
        elif link["name"].endswith("b") and link["name"].startswith("rod"):
            link.update(
                mass="mr", com=["l/2", 0, 0], inertia={"ixx": 1e-6, "iyy": "mr*l**2/12", "izz": "mr*l**2/12"}
            )
        elif link["name"] == "platform_x":
            link["mass"] = "mp"
    return data


def robots():
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        yield "fourbar", robot_from_data(yaml.safe_load((LOOPS / "fourbar.yaml").read_text()), "fourbar.yaml")
        yield "delta", robot_from_data(delta_with_rod_inertia(), "delta (rods with inertia)")


def closed_states(robot, module, rng):
    """NSTATES closed states: q, qd (full, on the closure), qda, qdda, tau_a, tau (full)."""
    an = analyse(robot.resolved())
    q0 = np.array(an.assembled[0])
    act, _ = oc.split(robot)
    out = {k: [] for k in ("q", "qd", "qda", "qdda", "tau_a", "tau")}
    while len(out["q"]) < NSTATES:
        it, q = module.solve_loops(q0[act] + 0.1 * rng.standard_normal(len(act)), q0)
        if it < 0:
            continue
        qda, qdda, tau_a = (rng.uniform(-1, 1, len(act)) for _ in range(3))
        tau = np.zeros(robot.n)
        tau[act] = tau_a
        for k, v in zip(out, (q, module.loop_motion(q, qda, qdda)[0], qda, qdda, tau_a, tau), strict=True):
            out[k].append(v)
    return {k: np.array(v) for k, v in out.items()}


def model_text(robot, st) -> str:
    """bench/pinocchio_loops.cpp's MODEL.txt: the model, the states and the loops."""
    states = {"q": st["q"], "qd": st["qd"], "qdd": np.zeros_like(st["q"]), "tau": st["tau"]}
    old = pin_harness.NSTATES
    pin_harness.NSTATES = NSTATES
    try:
        lines = pin_harness.model_and_states_lines(robot, states)
    finally:
        pin_harness.NSTATES = old
    num = robot.numeric()
    lines.append(f"nloops {len(num.loops)}")
    for lp in num.loops:
        a, b = (" ".join(repr(float(x)) for x in p) for p in (lp.point, lp.to_point))
        lines.append(f"loop {lp.link} {a} {lp.to} {b}")
    return "\n".join(lines) + "\n"


def bench_robot(name, robot, work: Path, pin_exe, opts) -> dict:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        files = render(robot, targets=("c", "python"))
    for f, text in files.items():
        (work / f).write_text(text)
    module = load_module(str(work / f"{robot.name}_numpy.py"), f"{robot.name}_numpy")
    st = closed_states(robot, module, np.random.default_rng(24))
    na = st["qda"].shape[1]
    block = np.concatenate([st["q"], st["qda"], st["qdda"], st["tau_a"]], axis=1)
    (work / "states.bin").write_bytes(np.ascontiguousarray(block, dtype="<f8").tobytes())
    loops = [
        f"LOOP({robot.name}_actuated_inverse_dynamics(Q[k], QDA[k], QDDA[k], NULL, OUT), OUT[0])",
        f"LOOP({robot.name}_actuated_forward_dynamics(Q[k], QDA[k], TAUA[k], NULL, OUT), OUT[0])",
    ]
    src = HARNESS.format(
        name=robot.name,
        n=robot.n,
        na=na,
        nstates=NSTATES,
        **skeleton(loops, ("Q", "N"), ("QDA", "A"), ("QDDA", "A"), ("TAUA", "A")),
    )
    (work / "harness.c").write_text(src)
    exe = work / "harness"
    run(
        [
            C_COMPILER,
            *FLAGS,
            "-std=c99",
            "-o",
            exe,
            work / "harness.c",
            work / f"{robot.name}_dynamics.c",
            "-lm",
        ]
    )
    checks, _ = parse_harness(run([exe, work / "states.bin", "check", str(NCHECK)]).stdout)
    err = 0.0
    for k in range(NCHECK):
        s = oc.loop_state(robot, st["q"][k], st["qda"][k], st["qdda"][k])
        err = max(err, np.abs(checks["actuated_inverse_dynamics"][k] - s.tau_a).max())
    row = {"name": name, "n": robot.n, "nact": na, "check_oracle": err, "check_pin": None}
    pin_cmd = None
    if pin_exe is not None:
        (work / "model.txt").write_text(model_text(robot, st))
        pin_checks, _ = parse_harness(run([pin_exe, work / "model.txt", "check", str(NCHECK)]).stdout)
        act, _ = oc.split(robot)
        row["check_pin"] = max(
            np.abs(pin_checks["ddq"][k][act] - checks["actuated_forward_dynamics"][k]).max()
            for k in range(NCHECK)
        )
        pin_cmd = [pin_exe, work / "model.txt", "time"]
    samples: dict[str, list[float]] = {}
    for _ in range(opts.rounds):
        for cmd, prefix in (([exe, work / "states.bin", "time"], ""), (pin_cmd, "pin_")):
            if cmd is None:
                continue
            _, times = parse_harness(run([*cmd, str(opts.reps), str(opts.target_ms)]).stdout)
            for label, values in times.items():
                samples.setdefault(prefix + label, []).extend(values)
    row["ns"] = {k: statistics.median(v) for k, v in samples.items()}
    return row


def table(rows: list[dict], note: str) -> str:
    out = [
        "Closed loops: symdyn's generated C against Pinocchio's constraintDynamics (ns per call, medians)",
        f"{machine()}; load {', '.join(f'{x:.2f}' for x in load_averages())}",
        f"Pinocchio: {note}",
        "",
        "| robot | n | nact | function | symdyn C (ns) | Pinocchio constraintDynamics (ns) | ratio "
        "| target |",
        "|---|---|---|---|---|---|---|---|",
    ]
    for r in rows:
        pin = r["ns"].get("pin_constraint_dynamics")
        for f in ("actuated_inverse_dynamics", "actuated_forward_dynamics"):
            ns = r["ns"][f]
            ratio = f"{ns / pin:.3f}" if pin else "-"
            ok = "" if not pin else (" ok" if ns / pin <= TARGET else " MISSED")
            pin_text = f"{pin:.0f}" if pin else "-"
            head = f"| {r['name']} | {r['n']} | {r['nact']} | {f}"
            out.append(f"{head} | {ns:.0f} | {pin_text} | {ratio} | <= {TARGET}{ok} |")
    out.append("")
    for r in rows:
        pin = "not run" if r["check_pin"] is None else f"{r['check_pin']:.1e}"
        out.append(
            f"{r['name']}: checks at {NCHECK} states: tau_a against symdyn.oracle {r['check_oracle']:.1e}, "
            f"qdd_a against Pinocchio's ddq {pin} (max abs)"
        )
    return "\n".join(out) + "\n"


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--quick", action="store_true", help="fewer repetitions")
    opts = ap.parse_args()
    opts.reps, opts.rounds, opts.target_ms = (5, 2, 5.0) if opts.quick else (11, 3, 10.0)
    log(pin_to_one_core())
    pin_exe, note = pin_harness.prepare(
        Path(tempfile.gettempdir()) / "symdyn-bench-pin", "pinocchio_loops.cpp"
    )
    rows = []
    for name, robot in robots():
        with tempfile.TemporaryDirectory(prefix="symdyn-loops-") as tmp:
            log(f"{name} ...")
            rows.append(bench_robot(name, robot, Path(tmp), pin_exe, opts))
    text = table(rows, note)
    print(text, end="")
    RESULTS.mkdir(exist_ok=True)
    (RESULTS / "closed_loops.txt").write_text(text)


if __name__ == "__main__":
    main()
