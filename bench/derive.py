"""Derivation benchmark: symdyn Newton-Euler and Lagrange against sympy.physics.mechanics' Kane.

    python bench/derive.py [--max-joints 7] [--kane-max 7] [--lagrange-max 7]
                           [--timeout 120] [--jobs 1] [--markdown]

Prints one table: generic spatial arms of 1..max-joints joints and the PUMA 560
with all 60 inertial parameters symbolic, each derived by symdyn's
"newton-euler" and "lagrange" and by KanesMethod, every derivation in its own
fresh process with a time budget. See bench/README.md for the columns.
"""

from __future__ import annotations

import argparse
import multiprocessing as mp
import os
import platform
import sys
import time
from dataclasses import dataclass, field
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

KANE = "kane (mechanics)"
METHODS = (KANE, "newton-euler", "lagrange")
PUMA_LABEL = "puma560 (all inertial parameters symbolic)"
TARGET_SECONDS = 5.0
SEED = 20240601
# A derivation is "wrong" if its tau differs from symdyn.rnea.rnea by more than this (relative).
CHECK_TOL = 1e-8


# --------------------------------------------------------------------------- child process


def _robot(kind: str, n: int):
    from robots import generic_arm, puma560_symbolic

    if kind == "puma":
        return puma560_symbolic()[0]
    return generic_arm(n)


def _source_digest() -> str:
    """A short hash of the symdyn package source this process imported (to spot edits mid-run)."""
    import hashlib

    import symdyn

    h = hashlib.sha256()
    root = Path(symdyn.__file__).resolve().parent
    for path in sorted(root.rglob("*.py")):
        h.update(str(path.relative_to(root)).encode())
        h.update(path.read_bytes())
    return h.hexdigest()[:12]


def _random_state(robot):
    import numpy as np

    rng = np.random.default_rng(SEED + robot.n)
    q, qd, qdd = (rng.uniform(-1.0, 1.0, robot.n) for _ in range(3))
    params = rng.uniform(0.05, 1.0, len(robot.params)) if robot.params else None
    return q, qd, qdd, params


def _reference_tau(robot, state):
    from symdyn.rnea import rnea

    q, qd, qdd, params = state
    return rnea(robot, q, qd, qdd, params)


def _symdyn_job(robot, method: str, send) -> None:
    import numpy as np
    import sympy as sp

    from symdyn.dynamics import derive

    send(("start", _source_digest()))
    t0, c0 = time.perf_counter(), time.process_time()
    dyn = derive(robot, method, simplify=False)
    send(("time", (time.perf_counter() - t0, time.process_time() - c0)))
    ops = {}
    for name in ("tau", "M", "V", "G"):
        exprs = [e for _, e in dyn.assignments((name,))] + list(dyn.compact[name])
        ops[name] = sum(sp.count_ops(e) for e in exprs)
    state = _random_state(robot)
    q, qd, qdd, params = state
    tau = dyn.evaluate("tau", q, qd, qdd, params)
    ref = _reference_tau(robot, state)
    send(("post", {"ops": ops, "err": float(np.max(np.abs(tau - ref))), "scale": float(np.max(np.abs(ref)))}))


def _kane_job(robot, send) -> None:
    import numpy as np
    import sympy as sp
    from robots import kane_model
    from sympy.physics.mechanics import KanesMethod

    t0 = time.perf_counter()
    model = kane_model(robot)
    build = time.perf_counter() - t0
    send(("start", _source_digest()))
    t0, c0 = time.perf_counter(), time.process_time()
    km = KanesMethod(model.frame, q_ind=model.q, u_ind=model.u, kd_eqs=model.kd_eqs)
    km.kanes_equations(model.bodies, model.loads)
    send(("time", (time.perf_counter() - t0, time.process_time() - c0)))
    n = robot.n
    plain = {}
    for i in range(n):
        plain[model.q[i]] = sp.Symbol(f"q{i + 1}")
        plain[model.u[i]] = sp.Symbol(f"qd{i + 1}")
    M = km.mass_matrix.xreplace(plain)
    f = km.forcing.xreplace(plain)
    ops = {"M": sp.count_ops(list(M)), "V": sp.count_ops(list(f))}
    state = _random_state(robot)
    q, qd, qdd, params = state
    values = {sp.Symbol(f"q{i + 1}"): sp.Float(q[i], 17) for i in range(n)}
    values.update({sp.Symbol(f"qd{i + 1}"): sp.Float(qd[i], 17) for i in range(n)})
    if params is not None:
        values.update({p: sp.Float(v, 17) for p, v in zip(robot.params, params, strict=True)})
    Mn = np.array(M.xreplace(values).evalf(), dtype=float)
    fn = np.array(f.xreplace(values).evalf(), dtype=float).ravel()
    tau = Mn @ qdd - fn
    ref = _reference_tau(robot, state)
    err = float(np.max(np.abs(tau - ref)))
    send(("post", {"ops": ops, "err": err, "scale": float(np.max(np.abs(ref))), "build": build}))


def _job(kind: str, n: int, method: str, conn) -> None:
    """Run one derivation in this process.

    Sends ("start", symdyn source digest) when the timed part begins, ("time", (wall, cpu)) when it ends, then
    ("post", {...}); ("error", text) at any point instead.
    """
    import warnings

    warnings.simplefilter("ignore")
    try:
        robot = _robot(kind, n)
        if method == KANE:
            _kane_job(robot, conn.send)
        else:
            _symdyn_job(robot, method, conn.send)
    except BaseException as exc:  # report anything, the parent prints it
        conn.send(("error", f"{type(exc).__name__}: {exc}"))
    finally:
        conn.close()


# --------------------------------------------------------------------------- parent


@dataclass
class Row:
    label: str
    kind: str  # "generic" | "puma"
    n: int
    method: str
    seconds: float | None = None  # derivation wall time; None if not measured
    cpu: float | None = None  # CPU time of the worker process during the derivation
    source: str | None = None  # digest of the symdyn source the worker imported
    status: str = "pending"  # ok | timeout | skipped | error
    ops: dict = field(default_factory=dict)
    err: float | None = None
    scale: float | None = None
    build: float | None = None
    note: str = ""


def _run(row: Row, timeout: float, ctx) -> Row:
    """Run `row` in a fresh process; kill it (by its own handle) when over budget."""
    recv, send = ctx.Pipe(duplex=False)
    proc = ctx.Process(target=_job, args=(row.kind, row.n, row.method, send), daemon=True)
    proc.start()
    send.close()
    try:
        # interpreter start-up, imports and building the robot do not count against the budget
        if not recv.poll(max(timeout, 60.0)):
            row.status, row.note = "error", "worker did not start"
            return row
        tag, value = recv.recv()
        if tag == "start":
            row.source = value
            if not recv.poll(timeout):
                row.status = "timeout"
                return row
            tag, value = recv.recv()
        if tag == "error":
            row.status, row.note = "error", value
            return row
        (row.seconds, row.cpu), row.status = value, "ok"
        # counting and the numeric check get their own budget
        if not recv.poll(max(timeout, 60.0)):
            row.note = "op counts/check over budget"
            return row
        tag, value = recv.recv()
        if tag == "error":
            row.note = value
            return row
        row.ops, row.err, row.scale = value["ops"], value["err"], value["scale"]
        row.build = value.get("build")
        return row
    except EOFError:
        row.status, row.note = "error", f"worker died (exit code {proc.exitcode})"
        return row
    finally:
        recv.close()
        if proc.is_alive():
            proc.kill()
        proc.join()


def _plan(args) -> list[Row]:
    limit = {KANE: args.kane_max, "newton-euler": args.max_joints, "lagrange": args.lagrange_max}
    rows = []
    for n in range(1, args.max_joints + 1):
        for method in METHODS:
            if n <= limit[method]:
                rows.append(Row(f"generic {n}R", "generic", n, method))
    for method in METHODS:
        # the verdict needs the PUMA's Newton-Euler row whatever the limits
        if method == "newton-euler" or min(limit[method], args.max_joints) >= 6:
            rows.append(Row(PUMA_LABEL, "puma", 6, method))
    return rows


def _execute(rows: list[Row], args) -> None:
    ctx = mp.get_context("spawn")  # fresh interpreter: no SymPy cache carried between rows
    over: dict[str, int] = {}  # method -> smallest generic arm that went over budget
    if args.jobs <= 1:
        for row in rows:
            if row.kind == "generic" and row.method in over and row.n > over[row.method]:
                row.status = "skipped"
                continue
            _progress(row, "...")
            _run(row, args.timeout, ctx)
            _progress(row, _time_text(row, args.timeout))
            if row.status == "timeout" and row.kind == "generic":
                over[row.method] = min(over.get(row.method, row.n), row.n)
        return
    from concurrent.futures import ThreadPoolExecutor

    # threads only wait on the worker processes; each derivation still runs in its own process
    with ThreadPoolExecutor(max_workers=args.jobs) as pool:
        futures = [pool.submit(_run, row, args.timeout, ctx) for row in rows]
        for fut in futures:
            row = fut.result()
            _progress(row, _time_text(row, args.timeout))


def _progress(row: Row, text: str) -> None:
    print(f"  [{row.label}, {row.method}] {text}", file=sys.stderr, flush=True)


# --------------------------------------------------------------------------- formatting


def _seconds(t: float) -> str:
    if t < 10:
        return f"{t:.3f}"
    if t < 100:
        return f"{t:.2f}"
    return f"{t:.1f}"


def _time_text(row: Row, timeout: float) -> str:
    if row.status == "ok":
        return _seconds(row.seconds)
    if row.status in ("timeout", "skipped"):
        return f"> {timeout:g} s" + ("*" if row.status == "skipped" else "")
    return "error"


def _ratio(x: float) -> str:
    return f"{x:.2f}x" if x < 1 else f"{x:.1f}x" if x < 100 else f"{x:.0f}x"


def _vs_kane(row: Row, kane: Row | None, timeout: float) -> str:
    if kane is None:
        return "-"
    mine_ok, kane_ok = row.status == "ok", kane.status == "ok"
    if mine_ok and kane_ok:
        return _ratio(kane.seconds / max(row.seconds, 1e-9))
    if mine_ok and kane.status in ("timeout", "skipped"):
        return "> " + _ratio(timeout / max(row.seconds, 1e-9))
    if kane_ok and row.status in ("timeout", "skipped"):
        return "< " + _ratio(kane.seconds / timeout)
    return "-"


def _check_ok(row: Row) -> bool:
    return row.err is not None and row.err <= CHECK_TOL * max(1.0, row.scale or 0.0)


def _check_text(row: Row) -> str:
    if row.err is None:
        return "-"
    return f"{row.err:.1e}" + ("" if _check_ok(row) else " WRONG")


def _ops_text(row: Row, name: str) -> str:
    if row.method == KANE and name == "G" and row.ops:
        return "in V"
    value = row.ops.get(name)
    return "-" if value is None else str(value)


HEADER = (
    "robot",
    "joints",
    "method",
    "derive (s)",
    "cpu (s)",
    "vs Kane",
    "tau ops",
    "M ops",
    "V ops",
    "G ops",
    "check",
)
RIGHT = set(range(1, len(HEADER))) - {2}


def _table(rows: list[Row], timeout: float, markdown: bool) -> str:
    kane = {(r.kind, r.n): r for r in rows if r.method == KANE}
    body = []
    for r in rows:
        body.append(
            (
                r.label,
                str(r.n),
                r.method,
                _time_text(r, timeout),
                "-" if r.cpu is None else _seconds(r.cpu),
                "1.0x"
                if r.method == KANE and r.status == "ok"
                else _vs_kane(r, kane.get((r.kind, r.n)), timeout),
                _ops_text(r, "tau"),
                _ops_text(r, "M"),
                _ops_text(r, "V"),
                _ops_text(r, "G"),
                _check_text(r),
            )
        )
    widths = [max(len(h), *(len(b[i]) for b in body)) for i, h in enumerate(HEADER)]

    def line(cells):
        out = [
            c.rjust(w) if i in RIGHT else c.ljust(w)
            for i, (c, w) in enumerate(zip(cells, widths, strict=True))
        ]
        return "| " + " | ".join(out) + " |" if markdown else "  ".join(out).rstrip()

    lines = [line(HEADER)]
    if markdown:
        lines.append(
            "|"
            + "|".join(("-" * (w + 1) + ":") if i in RIGHT else ("-" * (w + 2)) for i, w in enumerate(widths))
            + "|"
        )
    else:
        lines.append("  ".join("-" * w for w in widths))
    lines += [line(b) for b in body]
    return "\n".join(lines)


def _notes(rows: list[Row], args, origin: str, loads: tuple[float, float]) -> list[str]:
    import sympy

    builds = [r.build for r in rows if r.build is not None]
    notes = [
        f"Time budget {args.timeout:g} s per derivation, each in a fresh process; '> {args.timeout:g} s' = "
        "killed at the budget, '*' = not run because a smaller arm of the same method already went over it.",
        "derive (s): wall time of symdyn.dynamics.derive(robot, method, simplify=False) (it builds M, C, V, "
        "G, F and tau in one call), or of KanesMethod(...) plus kanes_equations() for Kane"
        + (
            " (building the mechanics frames/points/bodies beforehand, not counted, took at most "
            f"{max(builds):.2f} s)."
            if builds
            else "."
        ),
        "cpu (s): CPU time of the worker process over the same span; wall time exceeds it when other "
        "processes compete for the CPUs (load average above the CPU count).",
        "vs Kane: Kane's wall time on the same robot in this run divided by this row's time "
        "(> 1x = faster than Kane).",
        "ops: sympy.count_ops summed over the named intermediates the quantity needs "
        "(dyn.assignments((name,))) plus its output expressions.",
        "Kane rows: 'M ops' counts KanesMethod.mass_matrix and 'V ops' its forcing vector, which holds the "
        "velocity and gravity terms together (V+G; so 'G ops' says 'in V'); both are closed-form trees "
        "without shared intermediates, counted after replacing q_i(t), u_i(t) by plain symbols.",
        "check: max |tau - symdyn.rnea.rnea| at one random state (q, qd, qdd in [-1, 1]; random parameter "
        "values for the symbolic PUMA); Kane's tau = mass_matrix qdd - forcing. 'WRONG' marks an error over "
        f"{CHECK_TOL:g} x max(1, |tau|).",
        f"PUMA 560: {origin}; mass, com (3) and inertia (6) of every link symbolic (60 parameters, given in "
        "DH frame i and converted to the body frame); motor inertia and friction left out so all methods "
        "derive the same rigid-body equations.",
        f"Machine: {os.cpu_count()} CPUs, Python {platform.python_version()}, SymPy {sympy.__version__}; "
        f"1-minute load average {loads[0]:.1f} at the start, {loads[1]:.1f} at the end.",
    ]
    digests = list(dict.fromkeys(r.source for r in rows if r.source))
    if len(digests) == 1:
        notes.append(f"symdyn source digest {digests[0]} (the same in every row).")
    elif digests:
        notes.append(
            f"WARNING: symdyn's source changed during the run ({len(digests)} versions: "
            + ", ".join(digests)
            + "); rows may have timed different code. Run again on a quiet tree."
        )
    return notes


def _verdict(rows: list[Row], timeout: float) -> str:
    target = (
        "PUMA 560 with all inertial parameters symbolic derives M, V, G and tau by Newton-Euler in under "
        f"{TARGET_SECONDS:g} s"
    )
    row = next((r for r in rows if r.kind == "puma" and r.method == "newton-euler"), None)
    if row is None or row.status != "ok":
        why = (
            "not measured"
            if row is None
            else _time_text(row, timeout) + (f" ({row.note})" if row.note else "")
        )
        return f"Target: {target}: FAIL ({why})"
    passed = row.seconds < TARGET_SECONDS and _check_ok(row)
    extra = "" if _check_ok(row) else ", but its tau does not match rnea"
    return f"Target: {target}: {'PASS' if passed else 'FAIL'} (measured {row.seconds:.3f} s{extra})"


def _load() -> float:
    try:
        return os.getloadavg()[0]
    except (AttributeError, OSError):
        return float("nan")


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--max-joints", type=int, default=7, help="largest generic arm (default 7)")
    p.add_argument("--kane-max", type=int, default=7, help="largest arm derived with KanesMethod (default 7)")
    p.add_argument(
        "--lagrange-max", type=int, default=7, help="largest arm derived by symdyn lagrange (default 7)"
    )
    p.add_argument("--timeout", type=float, default=120.0, help="seconds per derivation (default 120)")
    p.add_argument(
        "--jobs",
        type=int,
        default=1,
        help="derivations run at once (default 1; more finishes sooner but the times share the CPUs)",
    )
    p.add_argument("--markdown", action="store_true", help="print a Markdown table")
    args = p.parse_args(argv)
    if args.max_joints < 1:
        p.error("--max-joints must be at least 1")

    from robots import puma560_symbolic

    origin = puma560_symbolic()[1]
    rows = _plan(args)
    load0 = _load()
    t0 = time.perf_counter()
    _execute(rows, args)
    total = time.perf_counter() - t0
    loads = (load0, _load())

    print(_table(rows, args.timeout, args.markdown))
    print()
    for note in _notes(rows, args, origin, loads):
        print(("- " if args.markdown else "* ") + note)
    for r in rows:
        if r.note:
            print(f"{'- ' if args.markdown else '* '}{r.label}, {r.method}: {r.note}")
    print(("- " if args.markdown else "* ") + f"Whole run: {total:.0f} s.")
    print()
    print(_verdict(rows, args.timeout))
    return 0


if __name__ == "__main__":
    sys.exit(main())
