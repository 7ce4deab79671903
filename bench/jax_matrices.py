"""How the JAX target's matrices are built, timed in one process (issue 37): jnp.array against _matrix_of.

    python bench/jax_matrices.py [MODULE_jax.py] [--functions F,..] [--batch N] [--reps R]
                                 [--routes vmap,batch,scan]

MODULE_jax.py (default generated/panda/panda_jax.py) is a generated JAX module, double precision.
It is loaded twice: as generated, where each matrix is built as symdyn.codegen.jax.target.
matrix_builders says (one selection, _selection_of; a concatenate of selected blocks,
_matrix_of; those of a body of more than 1,000 statements by _array_of, jnp.array, the same in
both ways), and with _selection_of and _matrix_of replaced by jnp.array(entries).reshape(shape),
the module before issue 37's matrices (a concatenate of every entry). For each of --functions
(default the matrix functions the module holds of mass_matrix, link7_jacobian, coriolis_matrix
and regressor),
each way and each route is timed per state over a batch of N random states (default 20,000):
jax.jit(jax.vmap(f)) under XLA's defaults, f_batch (the module's batch twin: the fusion emitters
off) and a jit of jax.lax.scan over the states (one call a step, per step). The routes are timed
in turns, --reps times (median), after a first call that compiles (its seconds listed), each
checked against the other way's result. The compiled HLO of vmap and scan (64 states) gives the
number of fusions and of sines in it (the statements XLA computes more than once show there).
The machine is shared: compare within one run.
"""

from __future__ import annotations

import argparse
import importlib.util
import inspect
import os
import re
import statistics
import sys
import time
from pathlib import Path

# bench/ must come after site-packages: bench/jax.py is named as the library
_BENCH = str(Path(__file__).resolve().parent)
sys.path[:] = [p for p in sys.path if p != _BENCH] + [_BENCH]

import numpy as np  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
FUNCTIONS = ("mass_matrix", "link7_jacobian", "coriolis_matrix", "regressor")
ROUTES = ("vmap", "batch", "scan")
WAYS = ("jnp.array", "generated")


def _load(path: Path, way: str):
    """The module at `path`, its _selection_of and _matrix_of replaced by its own _array_of
    (jnp.array of every entry) for the way 'jnp.array'."""
    spec = importlib.util.spec_from_file_location(f"_bench_{way.replace('.', '_')}", path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    if way == "jnp.array":
        module._matrix_of = module._selection_of = module._array_of
    return module


def _arguments(module, function: str, count: int, rng) -> list:
    """Random arguments of `function` but p (q of NQ entries, a unit quaternion, on a floating base)."""
    import jax.numpy as jnp

    nq = getattr(module, "NQ", module.NDOF)
    out = []
    for name in inspect.signature(getattr(module, function)).parameters:
        if name == "p":
            continue
        x = rng.uniform(-1.0, 1.0, (count, nq if name == "q" else module.NDOF))
        if name == "q" and nq != module.NDOF:
            u = rng.normal(size=(count, 4))
            x[:, 3:7] = u / np.linalg.norm(u, axis=1, keepdims=True)
        out.append(jnp.asarray(x))
    return out


def _routes(jax, module, function: str) -> dict:
    """The routes of `function`, the free parameters (if any) 1.0 each, shared by the states."""
    p = np.ones(module.NPARAM) if module.NPARAM else None
    one, batch = getattr(module, function), getattr(module, f"{function}_batch")

    def f(*x):
        return one(*x, p)

    return {
        "vmap": jax.jit(jax.vmap(f)),
        "batch": lambda *xs: batch(*xs, p),
        "scan": jax.jit(lambda *xs: jax.lax.scan(lambda c, x: (c, f(*x)), 0.0, xs)[1]),
    }


def hlo_counts(text: str) -> tuple[int, int]:
    """(fusions, sines) in the text of a compiled HLO module."""
    return len(re.findall(r"= [^=\n]*? fusion\(", text)), text.count(" sine(")


def _flat(jnp, out):
    return jnp.concatenate([jnp.ravel(x) for x in (out if isinstance(out, tuple) else (out,))])


def measure(path: Path, functions, count: int, reps: int, routes) -> list[dict]:
    """One row per (function, route): per way, the seconds per state, of the first call, and the
    compiled HLO's fusions and sines; the largest relative difference between the ways."""
    import jax
    import jax.numpy as jnp

    jax.config.update("jax_enable_x64", True)
    modules = {way: _load(path, way) for way in WAYS}
    rng = np.random.default_rng(37)
    rows = []
    for function in functions:
        args = _arguments(modules[WAYS[0]], function, count, rng)
        small = [a[:64] for a in args]
        runs, outs = {}, {}
        for way, module in modules.items():
            for route, fn in _routes(jax, module, function).items():
                if route not in routes:
                    continue
                start = time.perf_counter()
                outs[way, route] = _flat(jnp, jax.block_until_ready(fn(*args)))
                first = time.perf_counter() - start
                compiled = fn.lower(*small).compile().as_text() if route != "batch" else None
                counts = hlo_counts(compiled) if compiled else (None, None)
                runs[way, route] = {"fn": fn, "first": first, "times": [], "counts": counts}
        for _ in range(reps):
            for run in runs.values():
                start = time.perf_counter()
                jax.block_until_ready(run["fn"](*args))
                run["times"].append(time.perf_counter() - start)
        for route in routes:
            old, new = outs["jnp.array", route], outs["generated", route]
            error = float(jnp.max(jnp.abs(new - old)) / jnp.max(jnp.abs(old)))
            row = {"function": function, "route": route, "error": error}
            for way in WAYS:
                run = runs[way, route]
                row[way] = (statistics.median(run["times"]) / count, run["first"], *run["counts"])
            rows.append(row)
    return rows


def table(rows: list[dict]) -> list[str]:
    head = f"{'function':30} {'route':6} {'jnp.array ns':>13} {'generated ns':>14} {'ratio':>6}"
    head += f" {'fusions':>9} {'sines':>9} {'first s':>11} {'rel. diff':>9}"
    lines = [head]
    for r in rows:
        old, new = r["jnp.array"], r["generated"]
        fusions = f"{old[2]}/{new[2]}" if old[2] is not None else "-"
        sines = f"{old[3]}/{new[3]}" if old[3] is not None else "-"
        times = f"{old[0] * 1e9:13,.0f} {new[0] * 1e9:14,.0f} {old[0] / new[0]:6.2f}"
        lines.append(
            f"{r['function']:30} {r['route']:6} {times} {fusions:>9} {sines:>9}"
            f" {old[1]:5.1f}/{new[1]:<5.1f} {r['error']:9.1e}"
        )
    return lines


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("module", nargs="?", type=Path, default=ROOT / "generated" / "panda" / "panda_jax.py")
    parser.add_argument("--functions", help="comma-separated (default: those of FUNCTIONS the module holds)")
    parser.add_argument("--batch", type=int, default=20_000)
    parser.add_argument("--reps", type=int, default=5)
    parser.add_argument("--routes", default=",".join(ROUTES))
    opts = parser.parse_args(argv)
    if opts.batch < 1 or opts.reps < 1:
        parser.error("--batch and --reps must be at least 1")
    if not opts.module.is_file():
        parser.error(f"{opts.module}: no such module file")
    text = opts.module.read_text()
    held = [f for f in FUNCTIONS if f"\ndef {f}(" in text]
    functions = opts.functions.split(",") if opts.functions else held
    missing = [f for f in functions if f"\ndef {f}(" not in text]
    if missing:
        parser.error(f"{opts.module.name} has no function {', '.join(missing)}")
    routes = [r for r in opts.routes.split(",") if r]
    if not set(routes) <= set(ROUTES):
        parser.error(f"--routes takes {', '.join(ROUTES)}")
    before = os.getloadavg()
    rows = measure(opts.module, functions, opts.batch, opts.reps, routes)
    print(f"{opts.module.name}: {opts.batch:,} states, median of {opts.reps} (per state; scan: per step)")
    print(f"load average {before[0]:.1f} before, {os.getloadavg()[0]:.1f} after (the machine is shared)")
    print("\n".join(table(rows)))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
