"""The JAX target on the CPU against the NumPy module and ADAM (issues 26 and 37), in one run.

    python bench/jax.py [--robot panda|solo12|talos] [--groups G,..] [--functions F,..]
                        [--batch N] [--reps R] [--xla-grad] [--no-xla-flags] [--no-jacobians]
                        [--adam-python PATH] [--out FILE]

The robot's URDF of example-robot-data is generated in double precision for the targets python
and jax (--groups, default dynamics,derivatives; the JAX inverse dynamics is a jax.custom_jvp
function whose tangent is a linear primitive transposed by its generated adjoint program, the
forward dynamics the same, transposed through the inverse dynamics' adjoint program at M^-1 w),
into a temporary
folder of the run: the Panda cut at panda_hand (7 joints, the hand and fingers merged into link
7), Solo-12 and the Talos (talos_reduced) on a free flyer (q of NQ = NV + 1 entries, a unit quaternion). Each
of --functions (default inverse dynamics, M and forward dynamics) is timed per state:
* NumPy, one state per call (the generated NumPy module, from Python);
* NumPy, one call on the whole batch of N states (default 100,000), divided by N;
* JAX: the module's f_batch (jax.vmap of the one-state function, jax.jit with XLA's CPU fusion
  emitters off, the module's own compiler option) on the batch, the arrays already on the device,
  after a first call that compiles (its time is listed); jax.jit(f) of the one-state function
  called from Python on one state, per call (dispatch included); then jax.jit(jax.vmap(f)) of the
  one-state function with XLA's defaults, as one's own jit gets it, and
  jax.jit(jax.grad(lambda x: jnp.sum(jax.vmap(f)(x, ...) ** 2))), its gradient with respect to
  the first argument (q), through the adjoint program where there is one, with --xla-grad also
  by XLA's autodiff of the body it differentiates, each checked against central differences of
  the same loss along one direction; jax.jit(jax.vmap(jax.jacfwd(f))) (by q) and
  jax.jit(jax.vmap(jax.jacrev(f))), and jax.jit(jax.vmap(f_derivatives)) where the module has the
  generated derivative functions of f (--groups with derivatives); a jax.lax.scan over the
  states, one call a step, and one over steps of ROLLOUTS (50) states, jax.vmap(f) a step (a
  batch of rollouts, as learning and MPC pipelines scan them); then (unless --no-xla-flags)
  f_batch again in a process with XLA_FLAGS turning the emitters off for everything;
* ADAM (adam-robotics, its JAX backend; the Panda only) on the same URDF and batch,
  jax.jit(jax.vmap(..)):
  M is the joint block of its floating-base mass_matrix, inverse dynamics M qdd + h, h its
  bias_force plus the URDF's joint damping b qd (ADAM's RNEA takes no accelerations, and it
  ignores damping, which symdyn reads as viscous friction), and forward dynamics
  jnp.linalg.solve(M, tau - h) (its aba is floating-base), the base fixed at the identity, at rest.
ADAM 0.5 requires jax <= 0.6 while symdyn pins a newer jax, so ADAM runs in another Python
given by --adam-python (a virtual environment with `pip install "adam-robotics[jax]==0.5.0"`),
which times the symdyn JAX module there as well, for a ratio under one jax version. Without it
the ADAM columns are left empty. Every route is checked against the numeric oracle
(symdyn.rnea) on 8 states before timing; the medians of --reps runs are reported. The machine
is shared: compare within one run. The table goes to bench/results/jax.txt (the Panda) or
bench/results/jax_ROBOT.txt.
"""

from __future__ import annotations

import argparse
import functools
import importlib.util
import json
import math
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

# bench/ must come after site-packages: this file is named jax.py and `import jax` is the library
_BENCH = str(Path(__file__).resolve().parent)
sys.path[:] = [p for p in sys.path if p != _BENCH] + [_BENCH]

import numpy as np  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
URDF_INSIDE = "panda_description/urdf/panda.urdf"
TIP = "panda_hand"
JOINTS = tuple(f"panda_joint{i}" for i in range(1, 8))
#: --robot: the URDF in example-robot-data, its tip (None: the whole tree) and floating base
ROBOTS = {
    "panda": (URDF_INSIDE, TIP, False),
    "solo12": ("solo_description/robots/solo12.urdf", None, True),
    "talos": ("talos_data/robots/talos_reduced.urdf", None, True),
}
FUNCTIONS = ("inverse_dynamics", "mass_matrix", "forward_dynamics")
NCHECK = 8
#: States a step of the scan of a batch of rollouts (column "scan, 50 a step"): 100,000, 20,000 and
#: 2,000 states are whole numbers of steps.
ROLLOUTS = 50
#: Calls of a run of the column "jit(f), 1 state".
ONE_STATE_CALLS = 2000
#: XLA's CPU fusion emitters (the default in recent jax) can make a large fused function far slower
NO_EMITTERS = "--xla_cpu_use_fusion_emitters=false"


def _module(path: str, name: str):
    spec = importlib.util.spec_from_file_location(name, path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def _states(n: int, count: int, seed: int = 26, nq: int | None = None) -> dict[str, np.ndarray]:
    """Random states; a floating robot's q (nq given) is its base position, a quaternion of norm
    about 1 and the joints."""
    rng = np.random.default_rng(seed)
    q = rng.uniform(-np.pi, np.pi, (count, nq or n))
    if nq:
        quaternion = rng.normal(size=(count, 4))
        q[:, 3:7] = quaternion / np.linalg.norm(quaternion, axis=1, keepdims=True)
    return {
        "q": q,
        "qd": rng.uniform(-2.0, 2.0, (count, n)),
        "qdd": rng.uniform(-4.0, 4.0, (count, n)),
        "tau": rng.uniform(-20.0, 20.0, (count, n)),
    }


def _arguments(states, function: str):
    names = {
        "inverse_dynamics": ("q", "qd", "qdd"),
        "mass_matrix": ("q",),
        "forward_dynamics": ("q", "qd", "tau"),
    }
    return tuple(states[n] for n in names[function])


def _relative(got, want) -> float:
    """max |got - want| over max |want| (the oracle's largest entry; 1e-300 when it is all zeros)."""
    got, want = np.asarray(got, dtype=np.float64), np.asarray(want, dtype=np.float64)
    return float(np.max(np.abs(got - want)) / max(float(np.max(np.abs(want))), 1e-300))


def _jax_timing(fn, args, count: int, reps: int, calls: int = 1) -> tuple[float, float]:
    """(seconds of the first call, which compiles; the median over `reps` runs of the seconds per
    state of `calls` calls each waited for, on `count` states a call): with calls > 1 on one state,
    a jitted one-state function called from Python, dispatch included."""
    import jax

    t = time.perf_counter()
    jax.block_until_ready(fn(*args))
    compile_s = time.perf_counter() - t
    times = []
    for _ in range(reps):
        t = time.perf_counter()
        for _ in range(calls):
            jax.block_until_ready(fn(*args))
        times.append(time.perf_counter() - t)
    return compile_s, statistics.median(times) / (count * calls)


def _fixed_fingers(urdf: str, folder: str) -> tuple[str, list[float]]:
    """A copy of the URDF whose joints other than JOINTS are fixed: ADAM 0.5.0 fails on a prismatic
    joint anywhere in the file (its prismatic motion subspace stacks arrays of unequal shapes),
    and it holds every joint outside its list at 0 anyway, as symdyn's cut at panda_hand does.
    Also the viscous damping of JOINTS, which symdyn reads as friction and ADAM ignores."""
    import xml.etree.ElementTree as ET

    tree = ET.parse(urdf)
    damping = {}
    for joint in tree.getroot().iter("joint"):
        if joint.get("name") not in JOINTS:
            joint.set("type", "fixed")
        else:
            dynamics = joint.find("dynamics")
            damping[joint.get("name")] = float(dynamics.get("damping", 0.0)) if dynamics is not None else 0.0
    path = str(Path(folder) / "panda_fixed_fingers.urdf")
    tree.write(path)
    return path, [damping[j] for j in JOINTS]


def adam_functions(urdf: str, gravity: list[float]):
    """ADAM's joint-space M, inverse and forward dynamics of one state (the base fixed, at rest),
    with symdyn's gravity (ADAM's default is 9.80665 m/s^2, the URDF loader's 9.81) and the URDF's
    viscous damping added as symdyn adds it (F = b qd)."""
    import jax.numpy as jnp
    from adam.jax import KinDynComputations

    with tempfile.TemporaryDirectory() as folder:
        fixed, damping = _fixed_fingers(urdf, folder)
        kd = KinDynComputations(fixed, list(JOINTS), gravity=jnp.array([*gravity, 0, 0, 0]))
    b = jnp.array(damping)
    base, rest = jnp.eye(4), jnp.zeros(6)

    def mass_matrix(q):
        return kd.mass_matrix(base, q)[6:, 6:]

    def bias(q, qd):
        return kd.bias_force(base, q, rest, qd)[6:] + b * qd

    def inverse_dynamics(q, qd, qdd):
        return mass_matrix(q) @ qdd + bias(q, qd)

    def forward_dynamics(q, qd, tau):
        return jnp.linalg.solve(mass_matrix(q), tau - bias(q, qd))

    return {
        "inverse_dynamics": inverse_dynamics,
        "mass_matrix": mass_matrix,
        "forward_dynamics": forward_dynamics,
    }


def _grad_route(jax, jnp, f):
    """jit(grad) of the sum of squares of jax.vmap(f) over the batch, with respect to argument 0."""
    return jax.jit(jax.grad(lambda x, *rest: jnp.sum(jax.vmap(f)(x, *rest) ** 2)))


def _grad_error(jax, jnp, f, grad, args) -> float:
    """Relative error of grad's derivative along one direction against central differences."""
    loss = jax.jit(lambda x, *rest: jnp.sum(jax.vmap(f)(x, *rest) ** 2))
    x = jnp.asarray(args[0])
    rest = tuple(jnp.asarray(a) for a in args[1:])
    d = jnp.asarray(np.random.default_rng(7).uniform(-1.0, 1.0, x.shape))
    h = 1e-6
    fd = float((loss(x + h * d, *rest) - loss(x - h * d, *rest)) / (2 * h))
    exact = float(jnp.sum(grad(x, *rest) * d))
    return abs(fd - exact) / max(abs(exact), 1e-300)


def worker(
    module_path: str,
    urdf: str | None,
    count: int,
    reps: int,
    reference: dict,
    gravity=None,
    own=False,
    functions=FUNCTIONS,
    xla_grad=False,
    jacobians=True,
) -> dict:
    """Time the generated JAX module (and ADAM when `urdf` is given; when `own`, jax.jit(jax.vmap(f))
    of the one-state functions, jit(grad) through it, jit(vmap(jacfwd(f))), jit(vmap(jacrev(f)))
    and a jax.lax.scan over the states, and with `xla_grad` jit(grad) by XLA's autodiff of the
    functions that have an adjoint program; without `jacobians` no jacfwd or jacrev) in this
    interpreter; check each against `reference` (the oracle's values on the first NCHECK states)."""
    import jax

    jax.config.update("jax_enable_x64", True)
    import jax.numpy as jnp

    arm = _module(module_path, "symdyn_bench_jax")
    nq = getattr(arm, "NQ", None)
    states = _states(arm.NDOF, count, nq=nq)
    device = {k: jnp.asarray(v) for k, v in states.items()}
    check = _states(arm.NDOF, NCHECK, nq=nq)  # the states of `reference`
    out: dict = {"jax": jax.__version__, "symdyn": {}, "adam": {}, "error": {}}
    routes = {"symdyn": {f: getattr(arm, f"{f}_batch") for f in functions}}
    if own:
        out.update(own={}, one={}, grad={}, jacfwd={}, jacrev={}, derivatives={}, scan={}, scan_batch={})
        out.update(xla_grad={})
        routes["own"] = {f: jax.jit(jax.vmap(getattr(arm, f))) for f in functions}
        routes["scan"] = {f: _scan_route(jax, getattr(arm, f)) for f in functions}
        routes["scan_batch"] = {f: _scan_route(jax, getattr(arm, f), ROLLOUTS) for f in functions}
        for f in functions:  # jax.jit(f) called from Python on one state
            log(f"jit(f), 1 state {f}")
            one = jax.jit(getattr(arm, f))
            state = tuple(a[0] for a in _arguments(device, f))
            out["one"][f] = _jax_timing(one, state, 1, reps, ONE_STATE_CALLS)  # its first call compiles
            got = one(*(a[0] for a in _arguments(check, f)))
            out["error"][f"jit(f), 1 state {f}"] = _relative(got, np.asarray(reference[f])[0])
        gradients = {}
        for f in functions:
            fn, args = getattr(arm, f), _arguments(device, f)
            grads = {"grad": fn}
            if xla_grad and hasattr(arm, f"_{f}_plain"):  # the body the adjoint program differentiates
                grads["xla_grad"] = functools.partial(getattr(arm, f"_{f}_plain"), p=jnp.zeros((0,)))
            for key, g in grads.items():
                log(f"{key} {f}")
                grad = _grad_route(jax, jnp, g)
                error = _grad_error(jax, jnp, g, grad, _arguments(check, f))
                out["error"][f"{key} {f} (against central differences)"] = error
                out[key][f] = _jax_timing(grad, args, count, max(1, reps // 2))
                gradients[key, f] = grad
            for key, jacobian in (("jacfwd", jax.jacfwd), ("jacrev", jax.jacrev)) if jacobians else ():
                log(f"{key} {f}")
                out[key][f] = _jax_timing(jax.jit(jax.vmap(jacobian(fn))), args, count, max(1, reps // 2))
            if jacobians and hasattr(arm, f"{f}_derivatives"):  # the analytic Jacobians, for comparison
                log(f"derivatives {f}")
                derivatives = jax.jit(jax.vmap(getattr(arm, f"{f}_derivatives")))
                out["derivatives"][f] = _jax_timing(derivatives, args, count, max(1, reps // 2))
    if urdf is not None:
        from importlib.metadata import version

        out["adam_version"] = version("adam-robotics")
        routes["adam"] = {f: jax.jit(jax.vmap(g)) for f, g in adam_functions(urdf, gravity).items()}
    for route, fns in routes.items():
        for f in functions:
            log(f"{route} {f}")
            out["error"][f"{route} {f}"] = _relative(fns[f](*_arguments(check, f)), reference[f])
            out[route][f] = _jax_timing(fns[f], _arguments(device, f), count, reps)
    if own:  # grad/vmap from interleaved calls: the load of a shared machine moves between routes
        for f in functions:
            log(f"own and grad {f}, interleaved")
            args = _arguments(device, f)
            pair = (("own", routes["own"][f]), ("grad", gradients["grad", f]))
            times: dict = {key: [] for key, _ in pair}
            for _ in range(reps):
                for key, fn in pair:
                    times[key].append(_jax_timing(fn, args, count, 1)[1])
            for key, _ in pair:
                out[key][f] = (out[key][f][0], statistics.median(times[key]))
    return out


def _scan_route(jax, f, rollouts: int = 0):
    """jit of a jax.lax.scan over the states, one call of the one-state f a step; with `rollouts`,
    the states taken as a trajectory of steps of that many states (or of the largest divisor of the
    batch below it), jax.vmap(f) a step: a batch of rollouts, as a learning or MPC pipeline scans
    them, its output flattened back to one row a state."""
    if not rollouts:
        return jax.jit(lambda *xs: jax.lax.scan(lambda c, x: (c, f(*x)), 0.0, xs)[1])
    batched = jax.vmap(f)

    def scan(*xs):
        width = math.gcd(xs[0].shape[0], rollouts)
        steps = [x.reshape((x.shape[0] // width, width, *x.shape[1:])) for x in xs]
        out = jax.lax.scan(lambda c, x: (c, batched(*x)), 0.0, steps)[1]
        return out.reshape((xs[0].shape[0], *out.shape[2:]))

    return jax.jit(scan)


def log(text: str) -> None:
    """A line of progress on stderr (the worker's stdout is its JSON)."""
    print(f"[{time.strftime('%H:%M:%S')}] {text}", file=sys.stderr, flush=True)


def _external(python: str, payload: dict, tmp: str, **env) -> dict:
    """worker(**payload) run by another Python (or this one with other XLA flags)."""
    path = Path(tmp) / "worker.json"
    path.write_text(json.dumps(payload))
    done = subprocess.run(
        [python, __file__, "--worker", path], capture_output=True, text=True, env={**os.environ, **env}
    )
    if done.returncode != 0:
        raise SystemExit(f"the run of {python} failed:\n{done.stderr[-3000:]}")
    return json.loads(done.stdout.strip().splitlines()[-1])


def _numpy_timing(arm, states, function: str, reps: int) -> tuple[float, float]:
    """(median seconds of one call on one state, median seconds per state of one batch call)."""
    from python_timing import time_python

    fn = getattr(arm, function)
    args = _arguments(states, function)
    singles = [tuple(a[i] for a in args) for i in range(64)]
    one = time_python(fn, singles, reps, 1.0)
    batch = time_python(fn, [args], reps, 2.0 * reps) / len(states["q"])
    return one, batch


def _generate(urdf: Path, folder: Path, robot_name: str, groups: tuple[str, ...]):
    import warnings

    from symdyn import generate
    from symdyn.parsers import load

    _, tip, floating = ROBOTS[robot_name]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        robot = load(urdf, tip=tip, floating=floating)
    if robot_name == "panda":
        assert tuple(lk.joint_name for lk in robot.links) == JOINTS, [lk.joint_name for lk in robot.links]
    generate(robot, targets=("python", "jax"), out_dir=folder, functions=groups)
    return robot, folder / f"{robot.name}_numpy.py", folder / f"{robot.name}_jax.py"


def _row(cells, widths) -> str:
    return "  ".join(
        f"{c:>{w}}" if i else f"{c:<{w}}" for i, (c, w) in enumerate(zip(cells, widths, strict=True))
    )


def _title(robot, opts) -> str:
    kind = f"{robot.nv} velocities, q of {robot.nq}" if robot.floating else f"{robot.n} joints"
    where = f"cut at {TIP}" if opts.robot == "panda" else "on a free flyer"
    return (
        f"{opts.robot} (example-robot-data URDF {where}, {kind}), --functions {','.join(opts.groups)}, "
        f"double precision, on the CPU: ns per state, batch of {opts.batch:,} states "
        f"(medians of {opts.reps} runs)"
    )


def table(results: dict, opts, robot) -> list[str]:
    here, plain, there = results["here"], results.get("plain"), results.get("there")
    ns = lambda s: f"{1e9 * s:,.0f}"  # noqa: E731
    pick = lambda route, f: ns(route[f][1]) if route and f in route else "-"  # noqa: E731
    head = ["function", "NumPy 1 state", "NumPy batch", f"JAX f_batch (jax {here['jax']})", "jit(f), 1 state"]
    head += ["jit(vmap(f))", "jit(grad)", "jit(grad), XLA", "jacfwd", "jacrev", "f_derivatives", "scan"]
    head += [f"scan, {ROLLOUTS} a step"]
    head += ["f_batch, XLA_FLAGS"]
    if there:
        head += [f"JAX (jax {there['jax']})", f"ADAM {there.get('adam_version', '')}"]
    head += ["vmap/f_batch", "grad/vmap", "JAX/NumPy batch"] + (["JAX/ADAM"] if there else [])
    rows = [head]
    for f in opts.functions:
        one, batch = results["numpy"][f]
        jx = min(here["symdyn"][f][1], plain["symdyn"][f][1]) if plain else here["symdyn"][f][1]
        row = [f, ns(one), ns(batch), pick(here["symdyn"], f), pick(here["one"], f)]
        row += [pick(here["own"], f), pick(here["grad"], f)]
        row += [pick(here[key], f) for key in ("xla_grad", "jacfwd", "jacrev", "derivatives", "scan")]
        row += [pick(here["scan_batch"], f)]
        row += [pick(plain and plain["symdyn"], f)]
        if there:
            row += [ns(there["symdyn"][f][1]), ns(there["adam"][f][1])]
        own, grad = here["own"][f][1], here["grad"][f][1]
        row += [f"{own / here['symdyn'][f][1]:.2f}x", f"{grad / own:.2f}x"]
        row += [f"{jx / batch:.2f}x"]
        if there:
            row += [f"{there['symdyn'][f][1] / there['adam'][f][1]:.2f}x"]
        rows.append(row)
    widths = [max(len(r[i]) for r in rows) for i in range(len(head))]

    def compiles(name: str, route) -> str:
        return f"{name} " + ", ".join(f"{f} {route[f][0]:.1f}" for f in opts.functions if f in route)

    routes = [("f_batch", here["symdyn"]), ("jit(f), 1 state", here["one"])]
    routes += [("jit(vmap(f))", here["own"]), ("jit(grad)", here["grad"])]
    routes += [("jit(grad), XLA", here["xla_grad"]), ("jacfwd", here["jacfwd"]), ("jacrev", here["jacrev"])]
    routes += [("f_derivatives", here["derivatives"])]
    routes += [("scan", here["scan"]), (f"scan, {ROLLOUTS} a step", here["scan_batch"])]
    routes += [("XLA_FLAGS", plain["symdyn"])] if plain else []
    routes += [("ADAM", there["adam"])] if there else []
    lines = [
        _title(robot, opts),
        _row(head, widths),
        _row(["-" * w for w in widths], widths),
        *(_row(r, widths) for r in rows[1:]),
        "",
        "f_batch: the module's batch twin (compiled with the CPU fusion emitters off); jit(f), 1 state: "
        f"jax.jit of the one-state function called from Python on one state, per call ({ONE_STATE_CALLS:,} "
        "calls, each waited for, dispatch included); jit(vmap(f)): "
        "the one-state function under XLA's defaults; jit(grad): jax.jit(jax.grad(lambda x: "
        "jnp.sum(jax.vmap(f)(x, ...) ** 2))), argument 0 (q), XLA's defaults, through the module's "
        "adjoint program or custom_jvp rule where it has one (the inverse dynamics' linear primitive, the "
        "forward dynamics' through the inverse dynamics' adjoint); "
        "jit(grad), XLA: the same by XLA's autodiff of the body (--xla-grad); "
        "jacfwd, jacrev: jax.jit(jax.vmap(jax.jacfwd(f))), the same with jax.jacrev (by q); "
        "f_derivatives: jax.jit(jax.vmap(f_derivatives)), the generated derivative functions "
        "(every Jacobian); "
        "scan: jax.jit of jax.lax.scan over the "
        f"states, one call a step; scan, {ROLLOUTS} a step: the same over steps of {ROLLOUTS} states, "
        "jax.vmap(f) a step (a batch of rollouts); "
        f"XLA_FLAGS: {NO_EMITTERS} for the process; vmap/f_batch and grad/vmap: ratios of those columns "
        "(one run; jit(vmap(f)) and jit(grad) timed in turns, call by call); "
        "JAX/NumPy batch: the faster f_batch column; JAX/ADAM: f_batch and ADAM under ADAM's jax",
        "compile time of the first call (s): " + "; ".join(compiles(n, r) for n, r in routes if r),
        "largest relative error against symdyn.rnea on 8 states (grad: its derivative along one direction): "
        + ", ".join(f"{k} {v:.1e}" for k, v in {**here["error"], **(there or {}).get("error", {})}.items()),
    ]
    if not there:
        lines.append("ADAM: not run (give --adam-python, a Python with adam-robotics[jax] installed)")
    lines += [
        f"machine: {results['machine']}; load average {results['load']} (before, after)",
        f"whole run {results['wall']:.0f} s",
    ]
    return lines


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(prog="python bench/jax.py", description=__doc__.split("\n")[0])
    parser.add_argument("--robot", choices=tuple(ROBOTS), default="panda", help="the robot (default panda)")
    parser.add_argument("--groups", default="dynamics,derivatives", help="--functions of the generation")
    parser.add_argument("--functions", default=",".join(FUNCTIONS), help="the functions timed")
    parser.add_argument("--batch", type=int, default=100_000, help="states per batch call")
    parser.add_argument("--reps", type=int, default=5, help="timed repetitions (medians)")
    parser.add_argument(
        "--xla-grad", action="store_true", help="also jit(grad) by XLA's autodiff of the adjoints' bodies"
    )
    parser.add_argument("--no-xla-flags", action="store_true", help="skip the run with the emitters off")
    parser.add_argument("--no-jacobians", action="store_true", help="skip jit(vmap(jacfwd)) and jacrev")
    parser.add_argument("--adam-python", help="a Python with adam-robotics[jax] (and its jax) installed")
    parser.add_argument("--out", help="the table's file (default bench/results/jax.txt, jax_ROBOT.txt)")
    parser.add_argument("--worker", help=argparse.SUPPRESS)  # a JSON file of worker()'s arguments
    opts = parser.parse_args(argv)
    if opts.worker:
        print(json.dumps(worker(**json.loads(Path(opts.worker).read_text()))))
        return 0
    opts.groups = tuple(opts.groups.split(","))
    opts.functions = tuple(opts.functions.split(","))
    if opts.batch < 1 or opts.reps < 1:
        parser.error("--batch and --reps must be at least 1")
    unknown = sorted(set(opts.functions) - set(FUNCTIONS))
    if unknown:
        parser.error(f"--functions takes {', '.join(FUNCTIONS)}; not {', '.join(unknown)}")
    if opts.adam_python and opts.robot != "panda":
        raise SystemExit("bench/jax.py: --adam-python compares the Panda only")
    suffix = "" if opts.robot == "panda" else f"_{opts.robot}"
    out = Path(opts.out or ROOT / "bench" / "results" / f"jax{suffix}.txt")
    sys.path.insert(0, str(ROOT))
    from machine import load_averages, machine
    from robots import example_robot_file

    from symdyn.rnea import forward_dynamics, mass_matrix, rnea

    urdf = example_robot_file(ROBOTS[opts.robot][0])
    if urdf is None:
        raise SystemExit("bench/jax.py needs example-robot-data (the test extra) for the robots' URDFs")
    start, load_before = time.perf_counter(), load_averages()
    with tempfile.TemporaryDirectory(prefix="symdyn-bench-jax-") as tmp:
        log(f"generating the {opts.robot}'s NumPy and JAX modules (--functions {','.join(opts.groups)})")
        robot, numpy_path, jax_path = _generate(urdf, Path(tmp), opts.robot, opts.groups)
        nq = robot.nq if robot.floating else None
        check = _states(robot.nv, NCHECK, nq=nq)
        every = {
            "inverse_dynamics": lambda: rnea(robot, check["q"], check["qd"], check["qdd"]),
            "mass_matrix": lambda: mass_matrix(robot, check["q"]),
            "forward_dynamics": lambda: forward_dynamics(robot, check["q"], check["qd"], check["tau"]),
        }
        reference = {f: every[f]().tolist() for f in opts.functions}
        arm = _module(str(numpy_path), "symdyn_bench_numpy")
        states = _states(robot.nv, opts.batch, nq=nq)
        results: dict = {"numpy": {}}
        for f in opts.functions:
            log(f"NumPy {f}")
            results["numpy"][f] = _numpy_timing(arm, states, f, opts.reps)
            got = getattr(arm, f)(*_arguments(check, f))
            err = float(np.max(np.abs(got - reference[f])) / np.max(np.abs(reference[f])))
            assert err < 1e-9, (f, err)
        log("JAX (this Python)")
        args = {"module_path": str(jax_path), "urdf": None, "count": opts.batch, "reps": opts.reps}
        args["functions"] = opts.functions
        results["here"] = worker(
            **args, reference=reference, own=True, xla_grad=opts.xla_grad, jacobians=not opts.no_jacobians
        )
        if not opts.no_xla_flags:
            log(f"JAX (this Python, XLA_FLAGS={NO_EMITTERS})")
            flags = f"{os.environ.get('XLA_FLAGS', '')} {NO_EMITTERS}".strip()
            payload = {**args, "reference": reference}
            results["plain"] = _external(sys.executable, payload, tmp, XLA_FLAGS=flags)
        if opts.adam_python:
            log(f"JAX and ADAM ({opts.adam_python})")
            gravity = [float(g) for g in robot.gravity]
            payload = {**args, "urdf": str(urdf), "reference": reference, "gravity": gravity}
            results["there"] = _external(opts.adam_python, payload, tmp)
    for route in ("here", "plain", "there"):
        for key, err in results.get(route, {}).get("error", {}).items():
            assert err < (1e-5 if "grad" in key else 1e-9), (route, key, err)
    results.update(machine=machine(), load=(load_before, load_averages()), wall=time.perf_counter() - start)
    text = "\n".join(table(results, opts, robot)) + "\n"
    out.write_text(text)
    print(text, end="")
    return 0


if __name__ == "__main__":
    sys.exit(main())
