"""The PyTorch target on the CPU (and a GPU when torch sees one) against ADAM's PyTorch backend, the
NumPy module and the compiled C batch, in one run (issue 37).

    python bench/torch.py [--batch N] [--reps R] [--threads T] [--no-compile] [--out bench/results/torch.txt]

The Panda of example-robot-data (its URDF cut at panda_hand: 7 joints; bench/jax.py's robot and
states) is generated in double precision for the targets python and torch (--functions dynamics),
and each of inverse dynamics, M and forward dynamics is timed per state over one batch of N states
(default 10,000), float64 throughout, with T threads (torch.set_num_threads, the C batch's
threads and BLAS's through threadpoolctl; default 1), the routes interleaved in each of R rounds
(medians reported):
* the NumPy module on NumPy arrays, one batch call, and one call on one state;
* the torch module (NAME_torch.py) on CPU tensors, eager (a batch, and one state); then
  torch.compile of it (fullgraph, dynamic=False; the compile time of the first call is listed;
  --no-compile skips it);
* the NumPy module on torch tensors (the array API path, through array-api-compat);
* ADAM (adam-robotics, KinDynComputationsBatch of adam.pytorch) on the same batch: M the joint
  block of its floating-base mass_matrix, inverse dynamics M qdd + h, h its bias_force plus the
  URDF's joint damping b qd, forward dynamics torch.linalg.solve(M, tau - h), the base fixed at the
  identity and at rest (bench/jax.py's adam_functions, in torch);
* symdyn.compile's C (the batch wrapper, threads=T), for scale.
On a CUDA device (when torch sees one) the torch module and ADAM are timed there too, the states
already on the device, with torch.cuda.synchronize. Every route is checked against the numeric
oracle (symdyn.rnea) on the batch's first 8 states before timing. The machine may be shared:
compare within one run.
"""

from __future__ import annotations

import argparse
import importlib.util
import statistics
import sys
import tempfile
import time
from pathlib import Path

# bench/ must come after site-packages: this file is named torch.py and `import torch` is the library
_BENCH = str(Path(__file__).resolve().parent)
sys.path[:] = [p for p in sys.path if p != _BENCH] + [_BENCH]

import numpy as np  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
FUNCTIONS = ("inverse_dynamics", "mass_matrix", "forward_dynamics")
NCHECK = 8


def _module(path: str, name: str):
    spec = importlib.util.spec_from_file_location(name, path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


#: bench/jax.py (the Panda's URDF, its states and ADAM's fixed fingers), under a name that is not `jax`
_jax_bench = _module(str(Path(__file__).resolve().parent / "jax.py"), "_bench_jax")


def _sync(device) -> None:
    import torch

    if device.type == "cuda":
        torch.cuda.synchronize()


def _timing(fn, args, count: int, device=None) -> float:
    """Seconds per state of one call on the batch."""
    t = time.perf_counter()
    fn(*args)
    if device is not None:
        _sync(device)
    return (time.perf_counter() - t) / count


def adam_functions(urdf: str, gravity: list[float], device):
    """ADAM's batched joint-space M, inverse and forward dynamics (the base fixed, at rest) on
    `device`, float64, with symdyn's gravity and the URDF's viscous damping (F = b qd)."""
    import torch
    from adam.pytorch import KinDynComputationsBatch

    with tempfile.TemporaryDirectory() as folder:
        fixed, damping = _jax_bench._fixed_fingers(urdf, folder)
        kd = KinDynComputationsBatch(
            fixed,
            list(_jax_bench.JOINTS),
            device=device,
            dtype=torch.float64,
            gravity=torch.tensor([*gravity, 0.0, 0.0, 0.0], dtype=torch.float64),
        )
    b = torch.tensor(damping, dtype=torch.float64, device=device)
    eye = torch.eye(4, dtype=torch.float64, device=device)
    rest = torch.zeros(6, dtype=torch.float64, device=device)

    def mass_matrix(q):
        return kd.mass_matrix(eye.expand(len(q), 4, 4), q)[:, 6:, 6:]

    def bias(q, qd):
        return kd.bias_force(eye.expand(len(q), 4, 4), q, rest.expand(len(q), 6), qd)[:, 6:] + b * qd

    def inverse_dynamics(q, qd, qdd):
        return (mass_matrix(q) @ qdd[..., None])[..., 0] + bias(q, qd)

    def forward_dynamics(q, qd, tau):
        return torch.linalg.solve(mass_matrix(q), tau - bias(q, qd))

    return {
        "inverse_dynamics": inverse_dynamics,
        "mass_matrix": mass_matrix,
        "forward_dynamics": forward_dynamics,
    }


def _generate(urdf: Path, folder: Path):
    import warnings

    from symdyn import generate
    from symdyn.parsers import load

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        robot = load(urdf, tip=_jax_bench.TIP)
    assert tuple(lk.joint_name for lk in robot.links) == _jax_bench.JOINTS
    generate(robot, targets=("python", "torch"), out_dir=folder, functions=("dynamics",))
    return robot, folder / f"{robot.name}_numpy.py", folder / f"{robot.name}_torch.py"


def _error(got, want) -> float:
    got = got.detach().cpu().numpy() if hasattr(got, "detach") else np.asarray(got)
    want = np.asarray(want)
    return float(np.max(np.abs(got - want)) / np.max(np.abs(want)))


def run(opts) -> dict:
    import torch

    from symdyn import compile as compile_c
    from symdyn.rnea import forward_dynamics, mass_matrix, rnea

    torch.set_num_threads(opts.threads)
    from robots import example_robot_file

    urdf = example_robot_file(_jax_bench.URDF_INSIDE)
    if urdf is None:
        raise SystemExit("bench/torch.py needs example-robot-data (the test extra) for the Panda URDF")
    out: dict = {"torch": torch.__version__, "times": {}, "error": {}, "compile": {}}
    with tempfile.TemporaryDirectory(prefix="symdyn-bench-torch-") as tmp:
        log("generating the Panda's NumPy and torch modules")
        robot, numpy_path, torch_path = _generate(urdf, Path(tmp))
        numpy_mod = _module(str(numpy_path), "panda_urdf_numpy")
        torch_mod = _module(str(torch_path), "panda_urdf_torch")
        states = _jax_bench._states(robot.n, opts.batch)
        check = {k: v[:NCHECK] for k, v in states.items()}  # the batch's first states
        reference = {
            "inverse_dynamics": rnea(robot, check["q"], check["qd"], check["qdd"]),
            "mass_matrix": mass_matrix(robot, check["q"]),
            "forward_dynamics": forward_dynamics(robot, check["q"], check["qd"], check["tau"]),
        }
        log("compiling the C (symdyn.compile)")
        fast = compile_c(robot, threads=opts.threads, functions=("dynamics",))
        from importlib.metadata import version

        out["adam_version"] = version("adam-robotics")
        cpu = torch.device("cpu")
        devices = [cpu] + ([torch.device("cuda")] if torch.cuda.is_available() else [])
        out["gpu"] = torch.cuda.get_device_name(0) if torch.cuda.is_available() else None
        routes: dict[str, tuple] = {
            "NumPy": (lambda f: getattr(numpy_mod, f), None, False),
            "C batch": (lambda f: getattr(fast, f), None, False),
        }
        for device in devices:
            tag = "" if device.type == "cpu" else " (GPU)"
            routes[f"torch{tag}"] = (lambda f: getattr(torch_mod, f), device, False)
            if not opts.no_compile and device.type == "cpu":
                routes["torch.compile"] = (
                    lambda f: torch.compile(getattr(torch_mod, f), fullgraph=True, dynamic=False),
                    device,
                    True,
                )
            if device.type == "cpu":
                routes["NumPy module on torch"] = (lambda f: getattr(numpy_mod, f), device, False)
            adam = adam_functions(str(urdf), [float(g) for g in robot.gravity], device)
            routes[f"ADAM{tag}"] = (lambda f, adam=adam: adam[f], device, False)
        calls = []  # (route, function, fn, args, device), each compiled and checked
        for route, (get, device, compiles) in routes.items():
            for f in FUNCTIONS:
                log(f"{route} {f}: {'compiling and ' if compiles else ''}checking")
                fn = get(f)
                args = _jax_bench._arguments(states, f)
                small = _jax_bench._arguments(check, f)
                if device is not None:
                    args = tuple(torch.as_tensor(a, device=device) for a in args)
                    small = tuple(torch.as_tensor(a, device=device) for a in small)
                if compiles:  # compile on the batch's shapes first, then check on them
                    start = time.perf_counter()
                    got = fn(*args)[:NCHECK]
                    out["compile"][f] = time.perf_counter() - start
                else:
                    got = fn(*small)
                    fn(*args)  # warm-up
                out["error"][f"{route} {f}"] = _error(got, reference[f])
                calls.append((route, f, fn, args, opts.batch, device))
                if route in ("NumPy", "torch"):  # one state a call, too
                    one = tuple(a[0] for a in small)
                    calls.append((f"{route}, 1 state", f, fn, one, 1, device))
        samples: dict = {(route, f): [] for route, f, *_ in calls}
        for rep in range(opts.reps):  # interleaved: a change of the machine's load hits every route alike
            log(f"timing, round {rep + 1} of {opts.reps}")
            for route, f, fn, args, count, device in calls:
                tries = 1 if count > 1 else 20  # one state: the best of 20 calls
                samples[route, f].append(min(_timing(fn, args, count, device) for _ in range(tries)))
        for (route, f), times in samples.items():
            out["times"].setdefault(route, {})[f] = statistics.median(times)
    return out


def log(message: str) -> None:
    from machine import log as machine_log

    machine_log(message)


def table(results: dict, opts) -> list[str]:
    times = results["times"]
    routes = list(times)
    head = ["function", *routes, "ADAM/torch", "torch/C"]
    rows = []
    for f in FUNCTIONS:
        row = [f, *(f"{1e9 * times[r][f]:,.0f}" for r in routes)]
        row += [
            f"{times['ADAM'][f] / times['torch'][f]:.0f}x",
            f"{times['torch'][f] / times['C batch'][f]:.0f}x",
        ]
        rows.append(row)
    widths = [max(len(str(r[i])) for r in [head, *rows]) for i in range(len(head))]
    lines = [
        f"The Panda (example-robot-data URDF cut at {_jax_bench.TIP}, 7 joints), float64, ns per state, "
        f"one batch of {opts.batch:,} states (medians of {opts.reps} runs), torch {results['torch']} "
        f"with {opts.threads} thread(s), ADAM {results['adam_version']}",
        _jax_bench._row(head, widths),
        _jax_bench._row(["-" * w for w in widths], widths),
        *(_jax_bench._row(r, widths) for r in rows),
        "",
        "torch: NAME_torch.py eager; torch.compile: the same, compiled (fullgraph, dynamic=False); "
        "NumPy module on torch: NAME_numpy.py on torch tensors (array API); C batch: symdyn.compile; "
        "NumPy, 1 state and torch, 1 state: ns of one call on one state (the best of 20 calls); "
        "ADAM/torch and torch/C: ratios of the batch columns (eager torch)",
    ]
    if results["compile"]:
        lines.append(
            "torch.compile, the first call (compiling): "
            + ", ".join(f"{f} {s:.1f} s" for f, s in results["compile"].items())
        )
    lines += [
        "GPU: " + (results["gpu"] or "none seen by torch on this machine (the GPU columns are absent)"),
        "largest relative error against symdyn.rnea on 8 states: "
        + ", ".join(f"{k} {v:.1e}" for k, v in results["error"].items()),
        f"machine: {results['machine']}; load average {results['load']}",
        f"whole run {results['wall']:.0f} s",
    ]
    return lines


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(prog="python bench/torch.py", description=__doc__.split("\n")[0])
    parser.add_argument("--batch", type=int, default=10_000, help="states per batch call")
    parser.add_argument("--reps", type=int, default=5, help="timed repetitions (medians)")
    parser.add_argument("--threads", type=int, default=1, help="torch's and the C batch's threads")
    parser.add_argument("--no-compile", action="store_true", help="skip torch.compile (a minute)")
    parser.add_argument("--out", default=str(ROOT / "bench" / "results" / "torch.txt"))
    opts = parser.parse_args(argv)
    sys.path.insert(0, str(ROOT))
    from machine import load_averages, machine
    from threadpoolctl import threadpool_limits

    start, load_before = time.perf_counter(), load_averages()
    with threadpool_limits(opts.threads):  # BLAS too (symdyn.compile's check of M's finiteness)
        results = run(opts)
    for key, err in results["error"].items():
        assert err < 1e-9, (key, err)
    results.update(machine=machine(), load=(load_before, load_averages()), wall=time.perf_counter() - start)
    text = "\n".join(table(results, opts)) + "\n"
    Path(opts.out).write_text(text)
    print(text, end="")
    return 0


if __name__ == "__main__":
    sys.exit(main())
