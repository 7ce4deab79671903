"""The arithmetic floor of jax.jacfwd, jax.jacrev and jax.grad of the JAX module's functions.

    python bench/jax_ops.py [--robot panda|solo12|talos] [--functions F,..]

The robot is generated as bench/jax.py generates it (example-robot-data's URDF, double
precision, --groups dynamics). For each function of one state the table counts the arithmetic
operations (mul, add, sub, neg, div, integer_pow, sin, cos) of its jaxpr, as JAX traces it
before XLA optimises: the function itself (`primal`), the extra operations of a JVP along one
direction of q (`tangent`: jax.jvp's count less the primal's; the other inputs held, so their
tangents are symbolic zeros that cost nothing) and of a VJP of one output cotangent
(`cotangent`: jax.vjp's forward and backward less the primal's, JAX's own reverse mode of the
body). From them, in units of one forward pass (the primal's count):
* `jacfwd floor` = 1 + NQ x tangent / primal: jax.jacfwd pushes NQ directions through the body
  and needs the primal once;
* `grad floor` = 1 + cotangent / primal and `jacrev floor` = 1 + NOUT x cotangent / primal.
A route measured at its floor does no more arithmetic than forward or reverse mode must; the
time of one forward pass times the floor is what jit(vmap(jacfwd(f))) costs at best, so the
standard of "NQ forward passes" (a tangent for free) lies below it. The ratios of the measured
times (bench/results/jax.txt) to these floors are in docs/jax.md.
"""

from __future__ import annotations

import argparse
import collections
import importlib.util
import sys
import tempfile
from pathlib import Path

# bench/ after site-packages, as in bench/jax.py (whose name hides the library's)
_BENCH = Path(__file__).resolve().parent
sys.path[:] = [p for p in sys.path if p != str(_BENCH)] + [str(_BENCH)]

import jax  # noqa: E402
import jax.numpy as jnp  # noqa: E402

ARITHMETIC = ("mul", "add", "sub", "neg", "div", "integer_pow", "sin", "cos")
FUNCTIONS = ("inverse_dynamics", "mass_matrix", "forward_dynamics")


def bench_jax():
    """bench/jax.py as a module of another name (its own name is the library's)."""
    spec = importlib.util.spec_from_file_location("_symdyn_bench_jax", _BENCH / "jax.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def count(jaxpr) -> int:
    """The arithmetic operations of a closed jaxpr, its sub-jaxprs (custom rules, loops) included."""
    found = collections.Counter()

    def walk(inner) -> None:
        for eqn in inner.eqns:
            found[eqn.primitive.name] += 1
            for value in eqn.params.values():
                for sub in value if isinstance(value, (tuple, list)) else (value,):
                    if hasattr(sub, "jaxpr") and hasattr(sub.jaxpr, "eqns"):
                        walk(sub.jaxpr)
                    elif hasattr(sub, "eqns"):
                        walk(sub)

    walk(jaxpr.jaxpr)
    return sum(found[name] for name in ARITHMETIC)


def floors(module, name: str, nq: int, nv: int) -> dict[str, float | int | str]:
    """The counts and floors of one function of the module (its plain body where it has one; no
    reverse-mode figures for a body in stages, whose reverse mode is the adjoint program)."""
    plain = getattr(module, f"_{name}_plain", None)
    p = jnp.zeros((module.NPARAM,), dtype=jnp.float64)
    q = jnp.full((nq,), 0.3).at[3:7].set(0.5) if nq > nv else jnp.full((nq,), 0.3)
    v = jnp.full((nv,), 0.2)
    if name == "mass_matrix":

        def f(x):
            return module.mass_matrix(x)
    else:

        def f(x):
            return plain(x, v, v, p)

    out = jax.eval_shape(f, q)
    primal = count(jax.make_jaxpr(f)(q))
    tangent = count(jax.make_jaxpr(lambda x, d: jax.jvp(f, (x,), (d,)))(q, q)) - primal

    def pullback(x, w):
        y, back = jax.vjp(f, x)
        return back(w)

    size = int(jnp.prod(jnp.array(out.shape)))
    row = {"primal": primal, "tangent": tangent, "outputs": size, "jacfwd floor": 1 + nq * tangent / primal}
    try:
        cotangent = count(jax.make_jaxpr(pullback)(q, jnp.ones(out.shape))) - primal
    except ValueError:  # a staged body (symdyn.codegen.jax.stages): no reverse mode through its loops
        return {**row, "cotangent": "-", "grad floor": "-", "jacrev floor": "-"}
    return {
        **row,
        "cotangent": cotangent,
        "grad floor": 1 + cotangent / primal,
        "jacrev floor": 1 + size * cotangent / primal,
    }


def main(argv=None) -> int:
    bench = bench_jax()
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--robot", choices=tuple(bench.ROBOTS), default="panda")
    parser.add_argument("--functions", default=",".join(FUNCTIONS))
    opts = parser.parse_args(argv)
    unknown = sorted(set(opts.functions.split(",")) - set(FUNCTIONS))
    if unknown:
        parser.error(f"--functions takes {', '.join(FUNCTIONS)}; not {', '.join(unknown)}")
    jax.config.update("jax_enable_x64", True)
    from robots import example_robot_file  # bench/robots.py

    urdf = example_robot_file(bench.ROBOTS[opts.robot][0])
    if urdf is None:
        raise SystemExit("bench/jax_ops.py needs example-robot-data (the test extra) for the robots' URDFs")
    with tempfile.TemporaryDirectory() as tmp:
        robot, _, jax_path = bench._generate(urdf, Path(tmp), opts.robot, ("dynamics",))
        module = bench._module(str(jax_path), f"_symdyn_ops_{opts.robot}")
        print(f"{opts.robot}: NQ {robot.nq}, NV {robot.nv}; jaxpr operations, floors in forward passes")
        head = ("function", "primal", "tangent", "cotangent", "outputs")
        head += ("jacfwd floor", "grad floor", "jacrev floor")
        print("  ".join(f"{h:>13}" for h in head))
        for name in opts.functions.split(","):
            row = floors(module, name, robot.nq, robot.nv)
            cells = [name, *(f"{row[k]:.2f}" if isinstance(row[k], float) else str(row[k]) for k in head[1:])]
            print("  ".join(f"{c:>13}" for c in cells))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
