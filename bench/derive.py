"""Derivation benchmark: symdyn Newton-Euler and Lagrange against sympy.physics.mechanics' Kane.

    python bench/derive.py [--max-joints 7] [--kane-max 7] [--lagrange-max 7]
                           [--timeout 120] [--jobs 1] [--markdown]

Prints one table: generic spatial arms of 1..max-joints joints and the PUMA 560
with all 60 inertial parameters symbolic, each derived by symdyn's
"newton-euler" and "lagrange" and by KanesMethod, every derivation in its own
fresh process with a time budget. See bench/README.md for the columns.

This file plans the rows and runs each in a worker process within its budget; the
worker is bench/derive_jobs.py (robots from bench/robots.py, the Kane twin from
bench/kane.py) and the printed report is bench/derive_report.py's.
"""

from __future__ import annotations

import argparse
import multiprocessing as mp
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

from derive_jobs import job  # noqa: E402
from derive_report import KANE, METHODS, PUMA_LABEL, Row, report, time_text  # noqa: E402
from machine import load_averages  # noqa: E402


def _run(row: Row, timeout: float, ctx) -> Row:
    """Run `row` in a fresh process; kill it (by its own handle) when over budget."""
    recv, send = ctx.Pipe(duplex=False)
    proc = ctx.Process(target=job, args=(row.kind, row.n, row.method, send), daemon=True)
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
            _progress(row, time_text(row, args.timeout))
            if row.status == "timeout" and row.kind == "generic":
                over[row.method] = min(over.get(row.method, row.n), row.n)
        return
    from concurrent.futures import ThreadPoolExecutor

    # threads only wait on the worker processes; each derivation still runs in its own process
    with ThreadPoolExecutor(max_workers=args.jobs) as pool:
        futures = [pool.submit(_run, row, args.timeout, ctx) for row in rows]
        for fut in futures:
            row = fut.result()
            _progress(row, time_text(row, args.timeout))


def _progress(row: Row, text: str) -> None:
    print(f"  [{row.label}, {row.method}] {text}", file=sys.stderr, flush=True)


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
    p.add_argument(
        "--configuration",
        action="store_true",
        help="instead: the configuration-space form of the PUMA 560, Stanford arm and Panda "
        "(bench/configuration_form.py)",
    )
    p.add_argument(
        "--product",
        action="store_true",
        help="instead: the product form (derive --form product) of the PUMA 560, Stanford arm and "
        "Panda, operations and times (bench/product_form.py)",
    )
    args = p.parse_args(argv)
    if args.product:
        from product_form import product_report

        print(product_report(args.markdown), end="")
        return 0
    if args.configuration:
        from configuration_form import configuration_report

        print(configuration_report(args.markdown), end="")
        return 0
    if args.max_joints < 1:
        p.error("--max-joints must be at least 1")

    from robots import puma560_symbolic

    origin = puma560_symbolic()[1]
    rows = _plan(args)
    load0 = load_averages()[0]
    t0 = time.perf_counter()
    _execute(rows, args)
    total = time.perf_counter() - t0
    print(report(rows, args, origin, (load0, load_averages()[0]), total), end="")
    return 0


if __name__ == "__main__":
    sys.exit(main())
