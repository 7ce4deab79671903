"""Speed of `symdyn identify` on a one-million-sample log of the Panda (issue 26), stage by stage.

    python bench/identify.py             # 1,000,000 samples
    python bench/identify.py --quick     # 100,000 samples

The log (t, q, qd, qdd, tau at 1 kHz, sines; tau from the compiled inverse dynamics plus noise)
is written to a temporary folder (never committed). Timed in this process: reading the CSV
(read_measurements of symdyn.apps.identification.measurements: pandas' parser), the same file
by numpy.loadtxt (the reader before) and the same values as a .npz log, the derivation of the base
parameters (SymPy), the base
regressor alone over the chunks identify uses (batch calls into one reused-size buffer), and
identify itself (regressor chunks folded by incremental QR, both least squares, no prediction);
then the whole command `symdyn identify panda.yaml LOG.csv` (and LOG.npz) as a subprocess, with
its peak resident memory (measured by a wrapper process whose only child it is).
bench/batch.py puts these lines in bench/results/batch.txt.
"""

from __future__ import annotations

import argparse
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))

from machine import load_averages, log, machine  # noqa: E402

import symdyn  # noqa: E402

ROOT = Path(__file__).resolve().parent.parent


def write_log(robot, fast, samples: int, path: Path) -> None:
    """A Panda log of `samples` samples at 1 kHz (sines), tau from the compiled inverse dynamics + noise."""
    from symdyn.apps.simulation.csv_format import csv_bytes

    n = robot.n
    t = np.arange(samples) * 1e-3
    k = np.arange(1, n + 1)
    phase = np.outer(t, 0.5 * k) + k
    q, qd, qdd = 0.8 * np.sin(phase), 0.4 * k * np.cos(phase), -0.2 * k**2 * np.sin(phase)
    tau = fast.inverse_dynamics(q, qd, qdd) + np.random.default_rng(1).normal(0, 0.01, (samples, n))
    header = ["t", *(f"{s}{i}" for s in ("q", "qd", "qdd", "tau") for i in k)]
    path.write_bytes(csv_bytes(header, np.column_stack([t, q, qd, qdd, tau]), fast))


def identify_part(samples: int, folder: Path) -> dict[str, float]:
    """Seconds of each stage of identification on a Panda log of `samples` samples, and of the
    whole command (on the CSV and on the .npz); 'nbase', 'chunk' and 'peak MB', 'peak MB on the
    .npz log' (the command's maximum resident set)."""
    from symdyn.apps.identification.identify import base_regressor_samples, chunk_samples, identify
    from symdyn.apps.identification.measurements import read_measurements
    from symdyn.dynamics import derive

    path = ROOT / "examples" / "panda.yaml"
    robot = symdyn.load_robot(path)
    fast = symdyn.compile(robot)
    big = folder / "log.csv"
    write_log(robot, fast, samples, big)
    times: dict[str, float] = {}
    t0 = time.perf_counter()
    data = read_measurements(big, robot.n)
    times[f"read the CSV ({big.stat().st_size / 1e6:.0f} MB), pandas.read_csv"] = time.perf_counter() - t0
    t0 = time.perf_counter()
    with open(big, "rb") as f:
        f.readline()
        slow = np.loadtxt(f, delimiter=",", comments=None, dtype=np.float64, ndmin=2)
    times["the same CSV by numpy.loadtxt (the read before)"] = time.perf_counter() - t0
    assert np.array_equal(slow, np.column_stack([data.t, data.q, data.qd, data.qdd, data.tau]))
    del slow
    binary = folder / "log.npz"
    np.savez(binary, t=data.t, q=data.q, qd=data.qd, qdd=data.qdd, tau=data.tau)
    t0 = time.perf_counter()
    again = read_measurements(binary, robot.n)
    times[f"read the same log as .npz ({binary.stat().st_size / 1e6:.0f} MB)"] = time.perf_counter() - t0
    assert np.array_equal(again.tau, data.tau)
    del again
    t0 = time.perf_counter()
    base = derive(robot, simplify=False).base_parameters
    times["derive the base parameters (SymPy)"] = time.perf_counter() - t0
    base_regressor_samples(robot, data.q[:16], data.qd[:16], data.qdd[:16])  # warm: cffi's parse
    step = chunk_samples(robot.n, len(base))
    t0 = time.perf_counter()
    for s in range(0, samples, step):
        base_regressor_samples(robot, data.q[s : s + step], data.qd[s : s + step], data.qdd[s : s + step])
    times["base regressor alone, batch calls by chunk"] = time.perf_counter() - t0
    t0 = time.perf_counter()
    identify(robot, data, base, predict=False)
    times["identify (regressor + incremental QR + solves)"] = time.perf_counter() - t0
    del data
    for name, log_file in (("", big), (" on the .npz log", binary)):
        t0 = time.perf_counter()
        proc = subprocess.run(
            [sys.executable, "-c", PEAK, str(path), str(log_file)], capture_output=True, text=True
        )
        times[f"symdyn identify, whole command{name}"] = time.perf_counter() - t0
        assert proc.returncode == 0, proc.stderr
        times[f"peak MB{name}"] = int(proc.stdout.split()[-1]) / 1024
    times["nbase"], times["chunk"] = len(base), step
    return times


#: Runs `symdyn identify ROBOT LOG` as its only child and prints its peak resident memory (KiB):
#: the bench's own children (the compiler) do not count.
PEAK = (
    "import resource, subprocess, sys; "
    "subprocess.run([sys.executable, '-m', 'symdyn.cli', 'identify', *sys.argv[1:]], check=True, "
    "stdout=subprocess.DEVNULL); print(resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss)"
)


def lines(samples: int, times: dict[str, float]) -> list[str]:
    """The report's lines: one per stage, in seconds."""
    out = [
        f"identification of the Panda ({times['nbase']:.0f} base parameters), {samples:,} samples "
        f"(t, q, qd, qdd, tau), chunks of {times['chunk']:.0f} samples, seconds:"
    ]
    for key, value in times.items():
        if key not in ("nbase", "chunk") and not key.startswith("peak MB"):
            out.append(f"  {key:<50} {value:8.2f} s")
    for name in ("", " on the .npz log"):
        out.append(
            f"  {'the command' + name + ': peak resident memory':<50} {times['peak MB' + name]:8.0f} MB"
        )
    return out


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true")
    args = parser.parse_args()
    samples = 100_000 if args.quick else 1_000_000
    with tempfile.TemporaryDirectory(prefix="symdyn-identify-") as tmp:
        log("identify")
        times = identify_part(samples, Path(tmp))
    print(f"# bench/identify.py: {machine()}; load averages {load_averages()}")
    print("\n".join(lines(samples, times)))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
