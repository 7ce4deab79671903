"""Speed of `symdyn simulate` (issue 16): the Panda for 10 s at 1 kHz with RK4, in one run.

    python bench/sim.py

Rows (wall time of a fresh process, start-up included, and the stepping alone where the
process reports it):
* symdyn simulate, cold: an empty cache (temporary SYMDYN_CACHE_DIR): parse, derive,
  generate, compile the C, then step;
* symdyn simulate, warm: the same command again (the cached library; no SymPy);
* a plain Python RK4 loop around the generated NumPy module (the applications' route
  before the cache and the C loop), forward dynamics per call;
* the anchor: a plain Python RK4 loop around Pinocchio's `aba`, on example-robot-data's
  Panda URDF (pin.buildModelFromUrdf) with its two finger joints locked (buildReducedModel),
  so 7 joints as examples/panda.yaml (the inertial values differ; the cost does not).
Each process runs once (the machine is shared: the ratios of one run are what count), with
Python's bytecode cache on (PYTHONDONTWRITEBYTECODE removed), as a user's start-up has it.
"""

from __future__ import annotations

import os
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


def _stepping(env: dict) -> float:
    """Seconds of symdyn.simulate alone (the C stepping loop), on the warm cache entry of the CLI."""
    import argparse

    os.environ["SYMDYN_CACHE_DIR"] = env["SYMDYN_CACHE_DIR"]
    from symdyn.apps.simulate import simulate
    from symdyn.cli.cache import cached_plant

    args = argparse.Namespace(robot=str(ROBOT), base=None, tip=None)
    plant = cached_plant(args, None, params={}, model_params=None)  # warm: never calls make_robot
    start = time.perf_counter()
    simulate(plant, [0.0] * plant.n, duration=DURATION, dt=DT)
    return time.perf_counter() - start


def main() -> None:
    steps = round(DURATION / DT)
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        env = {**os.environ, "SYMDYN_CACHE_DIR": tmp, "PYTHONPATH": str(ROOT)}
        env.pop("PYTHONDONTWRITEBYTECODE", None)  # start-up as a user has it: modules' bytecode cached
        cmd = [sys.executable, "-m", "symdyn.cli", "simulate", str(ROBOT), "--duration", str(DURATION)]
        cmd += ["--dt", str(DT), "--out", str(Path(tmp) / "panda.csv")]
        cold, _ = _run(cmd, env)
        rows.append(("symdyn simulate, cold (empty cache)", cold, None))
        warm, _ = _run(cmd, env)
        rows.append(("symdyn simulate, warm (cached C, loop in C)", warm, None))
        rows.append(("symdyn.simulate in-process, warm: the C loop", float("nan"), _stepping(env)))
        numpy_file = next(Path(tmp).glob("v1/*/panda_numpy.py"))
        code = NUMPY.format(steps=steps, h=DT)
        wall, out = _run([sys.executable, "-c", code, str(numpy_file)], env)
        rows.append(("Python RK4 loop, generated NumPy module", wall, float(out)))
        try:
            import pinocchio  # noqa: F401
        except ImportError:
            rows.append(("Python RK4 loop, Pinocchio aba (not installed)", float("nan"), None))
        else:
            from symdyn.regenerate import example_robot_data_folder

            urdf = example_robot_data_folder() / "panda_description" / "urdf" / "panda.urdf"
            wall, out = _run([sys.executable, "-c", PINOCCHIO.format(steps=steps, h=DT), str(urdf)], env)
            rows.append(("Python RK4 loop, Pinocchio aba (anchor)", wall, float(out)))
    anchor = rows[-1][1]
    print(f"Panda, {DURATION:g} s at dt = {DT:g} s, RK4 ({steps} steps, {4 * steps} forward dynamics calls)")
    print(f"{'route':<46} {'total s':>8} {'stepping s':>11} {'vs anchor':>10}")
    for name, total, stepping in rows:
        step = f"{stepping:11.3f}" if stepping is not None else f"{'':>11}"
        ratio = f"{total / anchor:9.2f}x" if total == total else f"{'':>10}"
        print(f"{name:<46} {total:8.3f} {step} {ratio}".replace("     nan", "       -"))


if __name__ == "__main__":
    main()
