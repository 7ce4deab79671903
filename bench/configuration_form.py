"""The configuration-space form's table for bench/derive.py --configuration.

For the PUMA 560 (float data as in examples/, and read as exact rationals), the Stanford
arm, the Panda and the PUMA with its 60 inertial parameters symbolic: the time of
`symdyn derive` in the configuration form (derivation, canonical form, text), the size of
its text, and the operation counts (symdyn.symbolic.simplify.count_ops) of M, B, Csq and G
in the configuration form, with lumped constants (entries plus their definitions) and
after 1 % pruning, beside the compact form's (the eliminated program of M, V, G: it has no
B or Csq) and, where it finishes, the expanded form's. Armstrong, Khatib and Burdick (1986)
give 1,165 operations for their full explicit PUMA 560 model.
"""

from __future__ import annotations

import sys
import time
import warnings
from fractions import Fraction
from pathlib import Path

AKB_OPS = 1165
ROOT = Path(__file__).resolve().parents[1]


def _rational_data(x):
    if isinstance(x, float):
        return str(Fraction(str(x)))
    if isinstance(x, list):
        return [_rational_data(y) for y in x]
    if isinstance(x, dict):
        return {k: _rational_data(v) for k, v in x.items()}
    return x


def _robots():
    import yaml

    from symdyn.parsers import load_robot, robot_from_data

    sys.path.insert(0, str(Path(__file__).resolve().parent))
    from robots import puma560_symbolic

    ex = ROOT / "examples"
    raw = yaml.safe_load((ex / "puma560.yaml").read_text())
    return [
        ("PUMA 560", lambda: load_robot(ex / "puma560.yaml"), True),
        ("PUMA 560 (exact)", lambda: robot_from_data(_rational_data(raw), source="puma560"), True),
        ("Stanford", lambda: load_robot(ex / "stanford.yaml"), True),
        ("Panda", lambda: load_robot(ex / "panda.yaml"), None),
        ("PUMA 560 (60 symbolic)", lambda: puma560_symbolic()[0], False),
    ]


def _ops(exprs) -> int:
    from symdyn.symbolic.simplify import count_ops

    return count_ops([], list(exprs)).total


def _row(label: str, make, expanded: bool | None) -> dict:
    """One robot's figures; expanded None: neither the expanded form nor the lumped one (the
    Panda's 200,000 terms make SymPy's term ordering, which lumping needs, take minutes)."""
    import sympy as sp

    from symdyn.algorithms.pruning import prune
    from symdyn.cli.derive_output import configuration_entries, derive_text
    from symdyn.dynamics import derive
    from symdyn.symbolic.simplify import eliminate

    robot = make()
    t0 = time.perf_counter()
    dyn = derive(robot, simplify=False)
    text = derive_text(dyn)
    seconds = time.perf_counter() - t0
    cs = dyn.configuration_space
    row = {"robot": label, "seconds": seconds, "bytes": len(text.encode()), "gamma": len(cs.gamma)}
    row["configuration"] = {k: _ops(cs.matrix(k)) for k in ("M", "B", "Csq", "G")}
    if expanded is not None:
        entries, constants = configuration_entries(dyn, lumped=True)
        lumped = {k: _ops(e for _, e in entries[k]) for k in ("M", "B", "Csq", "G")}
        lumped["constants"] = _ops(v for _, v in constants.definitions())
        row["lumped"] = lumped
    if not dyn.params:
        pruned = prune(cs, 0.01)
        row["pruned"] = {k: _ops(pruned.configuration.matrix(k)) for k in ("M", "B", "Csq", "G")}
        row["bound"] = pruned.worst()
    t1 = time.perf_counter()
    f = sp.lambdify([list(dyn.q), list(dyn.qd), list(dyn.params)], dyn.V, "numpy") if expanded else None
    row["lambdify_V"] = time.perf_counter() - t1 if f is not None else None
    code = eliminate(
        dyn.assignments(("M", "V", "G")), [*dyn.compact["M"], *dyn.compact["V"], *dyn.compact["G"]]
    )
    row["compact"] = code.ops.total
    if expanded:
        row["expanded"] = {k: _ops(dyn.expanded(k)) for k in ("M", "V", "G")}
    return row


def _total(d: dict | None) -> str:
    return "—" if not d else f"{sum(d.values()):,}"


def run_rows(robots, row) -> list[dict]:
    """row(label, make, kind) for every robot, with progress on stderr."""
    warnings.simplefilter("ignore")
    rows = []
    for label, make, kind in robots:
        print(f"  [{label}] ...", file=sys.stderr, flush=True)
        rows.append(row(label, make, kind))
        print(f"  {rows[-1]}", file=sys.stderr, flush=True)
    return rows


def configuration_report(markdown: bool = False) -> str:
    """Run every row once and format the table."""
    rows = run_rows(_robots(), _row)
    head = (
        "| robot | derive (s) | text (KB) | Christoffel symbols | M / B / Csq / G, configuration form | "
        "total | lumped (entries + constants) | 1 % pruned (bound) | compact M, V, G | expanded M, V, G | "
        "lambdify V (s) |"
    )
    out = [head, "|" + "---|" * 11]
    for r in rows:
        c = r["configuration"]
        lumped = r.get("lumped")
        pruned = r.get("pruned")
        bound = f" ({r['bound']:.3g})" if pruned else ""
        lam = f"{r['lambdify_V']:.2f}" if r.get("lambdify_V") is not None else "—"
        out.append(
            f"| {r['robot']} | {r['seconds']:.1f} | {r['bytes'] / 1000:.0f} | {r['gamma']} | "
            f"{c['M']:,} / {c['B']:,} / {c['Csq']:,} / {c['G']:,} | {_total(c)} | "
            + (
                f"{_total({k: v for k, v in lumped.items() if k != 'constants'})} + {lumped['constants']:,}"
                if lumped
                else "—"
            )
            + " | "
            f"{_total(pruned)}{bound} | {r['compact']:,} | {_total(r.get('expanded'))} | {lam} |"
        )
    out.append("")
    out.append(
        f"Armstrong, Khatib and Burdick (1986): {AKB_OPS:,} operations for the full explicit PUMA 560 model."
    )
    text = "\n".join(out) + "\n"
    return text if markdown else text.replace("| ", "").replace(" |", " ")
