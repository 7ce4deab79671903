"""The product form's table for bench/derive.py --product (issue 27).

For the PUMA 560 (float data as in examples/, and read as exact rationals), the PUMA pruned at
1 %, the Stanford arm and the Panda: the time of `symdyn derive --form product` (derivation,
configuration form, product form, text), the time of the product form and its text alone,
and the operations counted with sympy.count_ops over every string of the JSON keys atoms,
shared, M, B, Csq and G, beside the configuration form's strings counted the same way.
Armstrong, Khatib and Burdick (1986) give 1,165 operations for their explicit PUMA 560 model
and 305 for the model with the terms below 1 % dropped.
"""

from __future__ import annotations

import sys
import time
from pathlib import Path

AKB_OPS = 1165
AKB_PRUNED_OPS = 305
ROOT = Path(__file__).resolve().parents[1]
KEYS = ("atoms", "shared", "M", "B", "Csq", "G")


def _count(strings) -> int:
    import sympy as sp

    return sum(sp.count_ops(sp.sympify(s)) for s in strings)


def _robots():
    sys.path.insert(0, str(Path(__file__).resolve().parent))
    from configuration_form import _robots as configuration_robots

    rows = [r for r in configuration_robots() if "symbolic" not in r[0]]
    puma = rows[0][1]
    return [*rows[:2], ("PUMA 560, 1 % pruned", puma, "pruned"), *rows[2:]]


def _row(label: str, make, kind) -> dict:
    from symdyn.algorithms.product_form import product_form
    from symdyn.algorithms.pruning import prune
    from symdyn.cli.derive_output import configuration_entries
    from symdyn.cli.derive_product import product_json, product_text
    from symdyn.dynamics import derive

    robot = make()
    t0 = time.perf_counter()
    dyn = derive(robot, simplify=False)
    cs = dyn.configuration_space
    t1 = time.perf_counter()
    if kind == "pruned":
        cs = prune(cs, 0.01).configuration
    pf = product_form(robot, cs, dyn.closed_form("F"))
    text = product_text(dyn, pf)
    t2 = time.perf_counter()
    doc = product_json(dyn, pf)
    row = {"robot": label, "seconds": t2 - t0, "product_seconds": t2 - t1, "bytes": len(text.encode())}
    ops = {}
    for key in KEYS:
        value = doc[key]
        strings = value.values() if isinstance(value, dict) else _flat(value)
        if key == "M":  # the upper triangle, as printed
            strings = [value[i][j] for i in range(dyn.n) for j in range(i, dyn.n)]
        ops[key] = _count(s for s in strings if s != "0")
    row["product"] = ops
    row["configuration"] = None  # the Panda's strings are too long for sympify (RecursionError)
    if cs.readable:
        entries, _ = configuration_entries(dyn, cs=cs, text=True)
        row["configuration"] = {k: _count(e for _, e in entries[k]) for k in ("M", "B", "Csq", "G")}
    row["names"] = (len(doc["atoms"]), len(doc["shared"]))
    return row


def _flat(value) -> list[str]:
    return [x for row in value for x in (row if isinstance(row, list) else [row])]


def product_report(markdown: bool = False) -> str:
    """Run every row once and format the table."""
    from configuration_form import run_rows

    rows = run_rows(_robots(), _row)
    head = (
        "| robot | derive --form product (s) | product form alone (s) | text (KB) | atoms / shared names | "
        "atoms / shared / M / B / Csq / G, product form | total | configuration form M / B / Csq / G | "
        "total | vs Armstrong-Khatib-Burdick |"
    )
    out = [head, "|" + "---|" * 10]
    for r in rows:
        p, c = r["product"], r["configuration"]
        akb = AKB_PRUNED_OPS if "pruned" in r["robot"] else AKB_OPS
        ratio = f"{sum(p.values()) / akb:.2f} x {akb:,}" if r["robot"].startswith("PUMA") else "—"
        conf = (" / ".join(f"{v:,}" for v in c.values()), f"{sum(c.values()):,}") if c else ("—", "—")
        out.append(
            f"| {r['robot']} | {r['seconds']:.2f} | {r['product_seconds']:.2f} | {r['bytes'] / 1024:.1f} | "
            f"{r['names'][0]} / {r['names'][1]} | {' / '.join(f'{v:,}' for v in p.values())} | "
            f"{sum(p.values()):,} | {conf[0]} | {conf[1]} | {ratio} |"
        )
    if not markdown:
        out = [line.replace("|", " ").strip() for line in out if not line.startswith("|---")]
    return "\n".join(out) + "\n"
