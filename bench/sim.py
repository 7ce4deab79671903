"""Speed of `symdyn simulate` (issue 16): the Panda for 10 s at 1 kHz with RK4, in one run.

    python bench/sim.py [--repeat N] [--out bench/results/sim.txt]

Rows (wall time of a fresh process, start-up included, and the stepping alone where the
process reports it):
* symdyn simulate, cold: an empty cache (temporary SYMDYN_CACHE_DIR): parse, derive,
  generate, compile the C, then step and write the CSV;
* symdyn simulate, warm: the same command again (the cached library; no SymPy), writing
  over the CSV of the run before, as a user re-running it does;
* a plain Python RK4 loop around the generated NumPy module (the applications' route
  before the cache and the C loop), forward dynamics per call;
* the anchor: a plain Python RK4 loop around Pinocchio's `aba`, on example-robot-data's
  Panda URDF (pin.buildModelFromUrdf) with its two finger joints locked (buildReducedModel),
  so 7 joints as examples/panda.yaml (the inertial values differ; the cost does not).
Every process runs with Python's bytecode cache on (PYTHONDONTWRITEBYTECODE removed from
the environment), as an installed package has its .pyc files, and every route runs once
untimed first to write them (symdyn: the cold command on a throwaway cache; the loops: one
step). The warm command, the C loop and the anchor then run --repeat times (default 5) and
report their medians; the cold command and the NumPy loop (20 s) run once. The machine's
load average is printed: on a shared machine compare within one run.
"""

from __future__ import annotations

import argparse
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
ROBOT = ROOT / "examples" / "panda.yaml"
DURATION, DT = 10.0, 1e-3

_RK4 = """
import time
import numpy as np
def rk4(f, q, qd, steps, h):
    for _ in range(steps):
        a1 = f(q, qd)
        a2 = f(q + 0.5 * h * qd, qd + 0.5 * h * a1)
        a3 = f(q + 0.5 * h * (qd + 0.5 * h * a1), qd + 0.5 * h * a2)
        a4 = f(q + h * (qd + 0.5 * h * a2), qd + h * a3)
        q, qd = (q + h / 6.0 * (qd + 2 * (qd + 0.5 * h * a1) + 2 * (qd + 0.5 * h * a2) + qd + h * a3),
                 qd + h / 6.0 * (a1 + 2 * a2 + 2 * a3 + a4))
    return q, qd
"""

PINOCCHIO = (
    _RK4
    + """
import sys
import pinocchio as pin
full = pin.buildModelFromUrdf(sys.argv[1])
fingers = [full.getJointId(n) for n in full.names if "finger" in n]
model = pin.buildReducedModel(full, fingers, pin.neutral(full))
data = model.createData()
tau = np.zeros(model.nv)
start = time.perf_counter()
rk4(lambda q, qd: pin.aba(model, data, q, qd, tau), np.full(model.nq, 0.1), np.zeros(model.nv), {steps}, {h})
print(time.perf_counter() - start)
"""
)

NUMPY = (
    _RK4
    + """
import sys, types
path = sys.argv[1]
module = types.ModuleType("panda_numpy")
exec(compile(open(path).read(), path, "exec"), module.__dict__)
tau = np.zeros(7)
start = time.perf_counter()
rk4(lambda q, qd: module.forward_dynamics(q, qd, tau), np.full(7, 0.1), np.zeros(7), {steps}, {h})
print(time.perf_counter() - start)
"""
)


def _run(argv: list[str], env: dict) -> tuple[float, str]:
    start = time.perf_counter()
    proc = subprocess.run(argv, env=env, capture_output=True, text=True, cwd=ROOT)
    wall = time.perf_counter() - start
    if proc.returncode != 0:
        raise SystemExit(f"{' '.join(argv)} failed:\n{proc.stderr}")
    return wall, proc.stdout.strip()


def _median_run(argv: list[str], env: dict, repeat: int, stepping: bool) -> tuple[float, float | None]:
    """Medians of the wall time and, when the process prints it (`stepping`), of its stepping time."""
    runs = [_run(argv, env) for _ in range(repeat)]
    wall = statistics.median(w for w, _ in runs)
    return wall, statistics.median(float(out) for _, out in runs) if stepping else None


def _stepping(env: dict, repeat: int) -> float:
    """Median seconds of symdyn.simulate alone (the C stepping loop), on the warm cache entry of the CLI."""
    os.environ["SYMDYN_CACHE_DIR"] = env["SYMDYN_CACHE_DIR"]
    from symdyn.apps.simulation.simulate import simulate
    from symdyn.cli.cache import cached_plant

    args = argparse.Namespace(robot=str(ROBOT), base=None, tip=None)
    plant = cached_plant(args, None, params={}, model_params=None)  # warm: never calls make_robot
    times = []
    for _ in range(repeat + 1):  # the first run loads the library: not counted
        start = time.perf_counter()
        simulate(plant, [0.0] * plant.n, duration=DURATION, dt=DT)
        times.append(time.perf_counter() - start)
    return statistics.median(times[1:])


def _load() -> str:
    return "load average " + ", ".join(f"{x:.2f}" for x in os.getloadavg())


def main() -> None:
    parser = argparse.ArgumentParser(
        description="symdyn simulate against Python RK4 loops (Panda, 10 s, 1 kHz)"
    )
    parser.add_argument("--repeat", type=int, default=5, help="runs of the warm command, C loop and anchor")
    parser.add_argument("--out", default=str(ROOT / "bench" / "results" / "sim.txt"), help="also write here")
    opts = parser.parse_args()
    steps = round(DURATION / DT)
    rows = []
    loads = [_load()]
    with tempfile.TemporaryDirectory() as tmp, tempfile.TemporaryDirectory() as throwaway:
        env = {**os.environ, "SYMDYN_CACHE_DIR": tmp, "PYTHONPATH": str(ROOT)}
        env.pop("PYTHONDONTWRITEBYTECODE", None)  # start-up as a user has it: modules' bytecode cached
        cmd = [sys.executable, "-m", "symdyn.cli", "simulate", str(ROBOT), "--duration", str(DURATION)]
        cmd += ["--dt", str(DT), "--out", str(Path(tmp) / "panda.csv")]
        _run(cmd, {**env, "SYMDYN_CACHE_DIR": throwaway})  # untimed: writes symdyn's .pyc files
        cold, _ = _run(cmd, env)
        rows.append(("symdyn simulate, cold (empty cache)", cold, None))
        warm, _ = _median_run(cmd, env, opts.repeat, stepping=False)
        rows.append(("symdyn simulate, warm (cached C, loop in C)", warm, None))
        c_loop = _stepping(env, opts.repeat)
        rows.append(("symdyn.simulate in-process, warm: the C loop", float("nan"), c_loop))
        numpy_file = next(Path(tmp).glob("v1/*/panda_numpy.py"))
        _run([sys.executable, "-c", NUMPY.format(steps=1, h=DT), str(numpy_file)], env)  # untimed warm-up
        wall, out = _run([sys.executable, "-c", NUMPY.format(steps=steps, h=DT), str(numpy_file)], env)
        rows.append(("Python RK4 loop, generated NumPy module", wall, float(out)))
        try:
            import pinocchio  # noqa: F401
        except ImportError:
            rows.append(("Python RK4 loop, Pinocchio aba (not installed)", float("nan"), None))
        else:
            from symdyn.regenerate import example_robot_data_folder

            urdf = str(example_robot_data_folder() / "panda_description" / "urdf" / "panda.urdf")
            _run([sys.executable, "-c", PINOCCHIO.format(steps=1, h=DT), urdf], env)  # untimed warm-up
            anchor = [sys.executable, "-c", PINOCCHIO.format(steps=steps, h=DT), urdf]
            wall, stepping = _median_run(anchor, env, opts.repeat, stepping=True)
            rows.append(("Python RK4 loop, Pinocchio aba (anchor)", wall, stepping))
    loads.append(_load())
    lines = _report(rows, steps, opts.repeat, loads)
    print("\n".join(lines))
    Path(opts.out).write_text("\n".join(lines) + "\n", encoding="utf-8")


def _report(rows: list, steps: int, repeat: int, loads: list[str]) -> list[str]:
    anchor = rows[-1][1]
    lines = [
        f"Panda, {DURATION:g} s at dt = {DT:g} s, RK4 ({steps} steps, {4 * steps} forward dynamics calls)",
        "every process with Python's bytecode cache on (PYTHONDONTWRITEBYTECODE removed), after one untimed "
        "run of its route that wrote the .pyc files",
        f"warm command, C loop and anchor: medians of {repeat} runs; cold command and NumPy loop: one run",
        f"{loads[0]} (start), {loads[1].removeprefix('load average ')} (end)",
        "",
        f"{'route':<46} {'total s':>8} {'stepping s':>11} {'vs anchor':>10}",
    ]
    for name, total, stepping in rows:
        step = f"{stepping:11.3f}" if stepping is not None else f"{'':>11}"
        ratio = f"{total / anchor:9.2f}x" if total == total and anchor == anchor else f"{'':>10}"
        lines.append(f"{name:<46} {total:8.3f} {step} {ratio}".replace("     nan", "       -"))
    c_loop, numpy_loop, pin_loop = rows[2][2], rows[3][2], rows[4][2]
    speedups = [f"{numpy_loop / c_loop:.0f}x the NumPy loop"]
    if pin_loop is not None:
        speedups.insert(0, f"{pin_loop / c_loop:.1f}x the Pinocchio loop")
    lines += ["", f"stepping alone, the C loop against: {', '.join(speedups)}"]
    return lines


if __name__ == "__main__":
    main()
