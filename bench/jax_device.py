"""The generated JAX module on every device JAX sees: the CPU and, where there is one, a GPU or TPU.

    python bench/jax_device.py [--robot panda|solo12|talos] [--batch N] [--reps R] [--precision double|float]

The robot is generated as bench/jax.py generates it (example-robot-data's URDF, --groups
dynamics, the precision given: double needs JAX's 64-bit mode, which the script turns on; most
GPUs run float64 at a small fraction of their float32 rate, so --precision float is the one to
compare there). On each device, with the batch's arrays already on it, it times per state:
f_batch (the module's jitted vmap), jax.jit(jax.vmap(f)) under the backend's defaults and
jax.jit(jax.grad(...)) of the vmapped loss by q (through the adjoint program where the module
has one), after a first call that compiles (its seconds listed), medians of --reps runs, each
route checked against the CPU's values first (largest relative difference). Without an
accelerator it times the CPU alone and says so: bench/jax.py is the CPU's full table.
"""

from __future__ import annotations

import argparse
import sys
import tempfile
from pathlib import Path

_BENCH = Path(__file__).resolve().parent
sys.path[:] = [p for p in sys.path if p != str(_BENCH)] + [str(_BENCH)]

import numpy as np  # noqa: E402
from jax_ops import bench_jax  # noqa: E402  (bench/jax_ops.py: bench/jax.py under another name)

FUNCTIONS = ("inverse_dynamics", "mass_matrix", "forward_dynamics")


def main(argv=None) -> int:
    bench = bench_jax()
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--robot", choices=tuple(bench.ROBOTS), default="panda")
    parser.add_argument("--batch", type=int, default=100_000)
    parser.add_argument("--reps", type=int, default=5)
    parser.add_argument("--precision", choices=("double", "float"), default="double")
    opts = parser.parse_args(argv)
    if opts.batch < 1 or opts.reps < 1:
        parser.error("--batch and --reps must be at least 1")
    import jax
    import jax.numpy as jnp

    jax.config.update("jax_enable_x64", True)  # the double module refuses to import without it
    from robots import example_robot_file  # bench/robots.py

    from symdyn import generate
    from symdyn.parsers import load

    urdf = example_robot_file(bench.ROBOTS[opts.robot][0])
    if urdf is None:
        raise SystemExit(
            "bench/jax_device.py needs example-robot-data (the test extra) for the robots' URDFs"
        )
    _, tip, floating = bench.ROBOTS[opts.robot]
    cpu = jax.devices("cpu")[0]
    accelerators = [d for d in jax.devices() if d.platform != "cpu"]
    devices = [cpu, *accelerators]
    dtype = np.float64 if opts.precision == "double" else np.float32
    with tempfile.TemporaryDirectory() as tmp:
        robot = load(urdf, tip=tip, floating=floating)
        generate(robot, targets=("jax",), out_dir=tmp, functions=("dynamics",), precision=opts.precision)
        module = bench._module(str(Path(tmp) / f"{robot.name}_jax.py"), f"_symdyn_device_{opts.robot}")
        states = bench._states(robot.nv, opts.batch, nq=robot.nq if robot.floating else None)
        print(
            f"{opts.robot}: {opts.precision} precision, batch of {opts.batch:,} states, ns per state "
            f"(first call's compile seconds); devices: {', '.join(str(d) for d in devices)}"
            + ("" if accelerators else " (no accelerator: the CPU alone)")
        )
        head = ("f_batch", "jit(vmap(f))", "jit(grad)")
        print(
            f"{'function':<18} {'device':<14} "
            + " ".join(f"{h:>16}" for h in head)
            + f" {'max rel. diff':>14}"
        )
        for name in FUNCTIONS:
            f = getattr(module, name)
            routes = {
                "f_batch": getattr(module, f"{name}_batch"),
                "jit(vmap(f))": jax.jit(jax.vmap(f)),
                "jit(grad)": jax.jit(jax.grad(lambda x, *rest, f=f: jnp.sum(jax.vmap(f)(x, *rest) ** 2))),
            }
            host = [a.astype(dtype) for a in bench._arguments(states, name)]
            reference = {}
            for device in devices:
                args = jax.device_put(host, device)
                cells, worst = [], 0.0
                for route, fn in routes.items():
                    compile_s, seconds = bench._jax_timing(fn, args, opts.batch, opts.reps)
                    cells.append(f"{seconds * 1e9:,.0f} ({compile_s:.1f} s)")
                    out = fn(*args)
                    if device is cpu:
                        reference[route] = np.asarray(out)
                    else:
                        worst = max(worst, bench._relative(out, reference[route]))
                diff = "-" if device is cpu else f"{worst:.1e}"
                print(
                    f"{name:<18} {device.platform + ':' + str(device.id):<14} "
                    + " ".join(f"{c:>16}" for c in cells)
                    + f" {diff:>14}"
                )
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
