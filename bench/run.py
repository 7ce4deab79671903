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
installed), with ratio columns. The robots are chains and, when example-robot-data is
installed, whole URDF trees on a fixed base (talos_reduced, solo12; bench/robots.py).
Under the table: notes, the correctness checks (every timed function is first compared
with symdyn.rnea at random states; a mismatch stops the run) and one PASS/FAIL line per
target of the issue.
Progress goes to stderr; the table, notes and verdicts go to stdout and to
bench/results/run.txt (or run.md with --markdown); every number to
bench/results/run.json. See bench/README_run.md.

Modules: robots.py (the robot list), generation.py (`symdyn generate` timed, op counts),
states.py (random states, symdyn.rnea's reference numbers), casadi_route.py (the CasADi
route), c_harness.py (the C harness: build, check, time), pin_harness.py (Pinocchio),
python_timing.py (NumPy and casadi.Function from Python), report.py (text, Markdown, JSON).
"""

from __future__ import annotations

import argparse
import shutil
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))

import casadi_route  # noqa: E402
import derivatives  # noqa: E402
import pin_harness  # noqa: E402
import report  # noqa: E402
import robots  # noqa: E402
from c_harness import build_c, check_c, time_compiled  # noqa: E402
from generation import generate_best  # noqa: E402
from machine import (  # noqa: E402
    C_COMPILER,
    RESULTS,
    load_averages,
    log,
    pin_to_one_core,
    project_path,
    source_digest,
)
from python_timing import time_numpy_and_casadi  # noqa: E402
from row import CASADI_FUNCTIONS, Row  # noqa: E402
from states import CHECK_TOL, NCHECK, SEED, make_states, references, write_states  # noqa: E402


def bench_robot(name: str, path: Path, work: Path, opts, pin_exe: Path | None) -> Row:
    """Generate, count, check and time one robot (robots without free parameters are timed)."""
    row = Row(name=name, file=project_path(path))
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
        pin_cmd = pin_harness.check_pinocchio(row, robot, pin_exe, work, states, refs)
    log(f"[{name}] time the C" + (" and Pinocchio" if pin_cmd else "") + " ...")
    time_compiled(row, [exe, states_file, "time"], pin_cmd, opts)
    if name in robots.ARMS:  # the arms the derivative goals name (a 32-joint tree's CasADi route is huge)
        derivatives.bench_derivatives(row, robot, gen_dir, work, states_file, states, pin_cmd, opts)

    log(f"[{name}] NumPy RNEA and casadi.Function from Python ...")
    time_numpy_and_casadi(row, robot, fns, states, opts.py_reps, opts.py_budget)
    return row


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--quick", action="store_true", help="fewer robots and repetitions")
    ap.add_argument("--markdown", action="store_true", help="print the table in Markdown")
    ap.add_argument("--robots", nargs="+", choices=list(robots.ROBOTS), help="only these robots")
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
    names = opts.robots or (robots.QUICK_ROBOTS if opts.quick else tuple(robots.ROBOTS))

    t_start = time.perf_counter()
    load_before = _loads()
    digest_before = source_digest()
    pinned = pin_to_one_core()
    robot_files = robots.write_robot_files()

    pin_exe, pin_note = None, "Pinocchio skipped (--no-pinocchio)"
    if not opts.no_pinocchio:
        pin_exe, pin_note = pin_harness.prepare(opts.build_dir)

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
            rows.append(bench_robot(name, robots.ROBOTS[name], work, opts, pin_exe))
        sym = bench_robot("puma560_symbolic", robot_files["puma560_symbolic"], work, opts, None)
    finally:
        if work_ctx is not None:
            work_ctx.cleanup()

    info = report.RunInfo(
        opts=opts,
        loads=(load_before, _loads()),
        pinned=pinned,
        pin_note=pin_note,
        digests=(digest_before, source_digest()),
        have_pin=pin_exe is not None,
        nparams=len(robots.load(robot_files["puma560_symbolic"]).params),
        seconds=time.perf_counter() - t_start,
    )
    report.write(rows, sym, info)
    print(derivatives.write_report(rows))
    return 0


def _loads() -> str:
    return " ".join(f"{x:.2f}" for x in load_averages())


if __name__ == "__main__":
    shutil.which(C_COMPILER) or sys.exit(f"{C_COMPILER} not found")
    sys.exit(main())
