"""bench/derive.py's table: one Row per derivation, and the text printed from the rows.

`report(rows, args, origin, loads, total)` gives the whole output: the table (plain
aligned text or Markdown, `args.markdown`), the notes, per-row problems, the run's length and the verdict
on the target "PUMA 560 with all inertial parameters symbolic derives M, V, G and tau by
Newton-Euler in under 5 s". bench/README.md explains the columns.
"""

from __future__ import annotations

import os
import platform
from dataclasses import dataclass, field

__all__ = ["Row", "KANE", "METHODS", "PUMA_LABEL", "CHECK_TOL", "time_text", "report"]

KANE = "kane (mechanics)"
METHODS = (KANE, "newton-euler", "lagrange")
PUMA_LABEL = "puma560 (all inertial parameters symbolic)"
TARGET_SECONDS = 5.0
# A derivation is "wrong" if its tau differs from symdyn.rnea.rnea by more than this (relative).
CHECK_TOL = 1e-8


@dataclass
class Row:
    """One derivation: robot, method, its times, op counts and the check against symdyn.rnea."""

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


def _seconds(t: float) -> str:
    if t < 10:
        return f"{t:.3f}"
    if t < 100:
        return f"{t:.2f}"
    return f"{t:.1f}"


def time_text(row: Row, timeout: float) -> str:
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
                time_text(r, timeout),
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
        "processes compete for the CPUs (load average above the CPU count). The machine is shared with other "
        "work, so times move from run to run: compare rows within one run ('vs Kane'), not across runs.",
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
            else time_text(row, timeout) + (f" ({row.note})" if row.note else "")
        )
        return f"Target: {target}: FAIL ({why})"
    passed = row.seconds < TARGET_SECONDS and _check_ok(row)
    extra = "" if _check_ok(row) else ", but its tau does not match rnea"
    return f"Target: {target}: {'PASS' if passed else 'FAIL'} (measured {row.seconds:.3f} s{extra})"


def report(rows: list[Row], args, origin: str, loads: tuple[float, float], total: float) -> str:
    """The table, the notes, per-row problems, the run's length in seconds and the verdict."""
    bullet = "- " if args.markdown else "* "
    lines = [_table(rows, args.timeout, args.markdown), ""]
    lines += [bullet + note for note in _notes(rows, args, origin, loads)]
    lines += [f"{bullet}{r.label}, {r.method}: {r.note}" for r in rows if r.note]
    lines += [bullet + f"Whole run: {total:.0f} s.", "", _verdict(rows, args.timeout)]
    return "\n".join(lines) + "\n"
