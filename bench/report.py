"""bench/run.py's report: the table (plain text or Markdown), the notes, the targets, the JSON.

`write(rows, sym, info)` prints the report (Markdown with --markdown) and writes it to
bench/results/STEM.txt and STEM.md, every number (every timing repetition included) to
STEM.json; STEM is run, run_quick or run_partial. The columns are explained in
bench/README_run.md. Files are named relative to the project (machine.project_path).
"""

from __future__ import annotations

import json
import platform
from dataclasses import asdict, dataclass

import numpy as np
from machine import C_COMPILER, CXX_COMPILER, CXX_EXTRA, FLAGS, RESULTS, compiler_version, machine
from robots import ARMS, TREES
from row import CASADI_FUNCTIONS, FUNCTIONS, PINOCCHIO, PINOCCHIO_NAMES, SHORT, Row
from states import CHECK_TOL, NCHECK, NSTATES

__all__ = ["RunInfo", "render_table", "targets", "write"]


@dataclass
class RunInfo:
    """What a report says about the run besides its rows."""

    opts: object  # bench/run.py's parsed options
    loads: tuple[str, str]  # load averages at the start and at the end
    pinned: str  # pin_to_one_core()'s description
    pin_note: str  # Pinocchio's version and headers, or why it was skipped
    digests: tuple[str, str]  # symdyn's source digest at the start and at the end
    have_pin: bool
    nparams: int  # free parameters of puma560_symbolic
    seconds: float  # the whole run


def fmt(x, digits: int = 1) -> str:
    """A number for the table: thousands separated, NaN and None as -."""
    if x is None or (isinstance(x, float) and not np.isfinite(x)):
        return "-"
    if isinstance(x, int):
        return f"{x:,}"
    if abs(x) >= 1000:
        return f"{x:,.0f}"
    return f"{x:.{digits}f}"


def ratio(a, b) -> str:
    """a / b as 0.00x, or - when either is missing."""
    if a is None or b is None or not np.isfinite(a) or not np.isfinite(b) or b == 0:
        return "-"
    return f"{a / b:.2f}x"


COLUMNS = (
    ("robot", "robot"),
    ("n", "n"),
    ("gen", "gen s wall/cpu"),
    ("function", "function"),
    ("ops", "ops"),
    ("cr_ops", "CasADi ops"),
    ("ops_ratio", "ops sd/CasADi"),
    ("c_ns", "symdyn C ns"),
    ("cr_c_ns", "CasADi C ns"),
    ("cr_ratio", "sd/CasADi-C"),
    ("pin_ns", "Pinocchio ns"),
    ("pin_ratio", "sd/Pin"),
    ("cr_py", "CasADi py us"),
    ("np1", "NumPy us"),
    ("npb", "NumPy batch us/state"),
)


def table_rows(rows: list[Row]) -> list[dict]:
    """One dict of cells (COLUMNS keys) per robot and function."""
    out = []
    for row in rows:
        for j, fn in enumerate(FUNCTIONS):
            ops = row.ops.get(fn, {}).get("total")
            cro = row.casadi_ops.get(fn, {}).get("total")
            c = row.c_ns.get(fn)
            crc = row.cr_c_ns.get(fn)
            pin_alg = PINOCCHIO.get(fn)
            pin = row.pin_ns.get(pin_alg) if pin_alg else None
            out.append(
                {
                    "robot": row.name if j == 0 else "",
                    "n": str(row.n) if j == 0 else "",
                    "gen": f"{row.gen_wall:.2f}/{row.gen_cpu:.2f}" if j == 0 else "",
                    "function": f"{fn} ({SHORT[fn]})",
                    "ops": fmt(ops),
                    "cr_ops": fmt(cro) if cro else "",
                    "ops_ratio": ratio(ops, cro) if cro else "",
                    "c_ns": fmt(c),
                    "cr_c_ns": fmt(crc) if crc is not None else "",
                    "cr_ratio": ratio(c, crc) if crc is not None else "",
                    "pin_ns": (fmt(pin) + f" ({PINOCCHIO_NAMES[pin_alg]})") if pin is not None else "",
                    "pin_ratio": ratio(c, pin) if pin is not None else "",
                    "cr_py": fmt(row.cr_py_us.get(fn)) if fn in row.cr_py_us else "",
                    "np1": fmt(row.numpy_us) if fn == "inverse_dynamics" and row.c_ns else "",
                    "npb": fmt(row.numpy_batch_us, 2) if fn == "inverse_dynamics" and row.c_ns else "",
                }
            )
    return out


def render_table(rows: list[Row], markdown: bool) -> str:
    """The table, aligned plain text or Markdown."""
    data = table_rows(rows)
    keys = [k for k, _ in COLUMNS]
    heads = [h for _, h in COLUMNS]
    if markdown:
        lines = ["| " + " | ".join(heads) + " |"]
        lines.append("|" + "|".join("---" if k in ("robot", "function") else "---:" for k in keys) + "|")
        for d in data:
            lines.append("| " + " | ".join(d[k] for k in keys) + " |")
        return "\n".join(lines)
    widths = [max(len(h), *(len(d[k]) for d in data)) for k, h in zip(keys, heads, strict=True)]
    left = {"robot", "function", "pin_ns"}

    def line(cells):
        return "  ".join(
            c.ljust(w) if k in left else c.rjust(w) for k, c, w in zip(keys, cells, widths, strict=True)
        ).rstrip()

    out = [line(heads), line(["-" * w for w in widths])]
    for i, d in enumerate(data):
        if i and d["robot"]:
            out.append("")
        out.append(line([d[k] for k in keys]))
    return "\n".join(out)


def verdict(ok: bool | None) -> str:
    return "SKIP" if ok is None else ("PASS" if ok else "FAIL")


def _against_pinocchio(r: Row, fn: str, alg: str, goal: float, have_pin: bool) -> str:
    """The target line `fn` <= goal x Pinocchio's `alg` of robot `r` (SKIP without Pinocchio's time)."""
    what = f"{r.name} {fn} <= {goal:g}x Pinocchio's {PINOCCHIO_NAMES[alg]}"
    c, p = r.c_ns.get(fn), r.pin_ns.get(alg)
    if not have_pin or p is None:
        why = "no Pinocchio" if not have_pin else "Pinocchio not run for this robot (see its notes)"
        return f"SKIP  {what}: {why}"
    best = min(r.samples[fn]) / min(r.samples["pin_" + alg])
    ok = verdict(c <= goal * p)
    return f"{ok}  {what}: {c:.1f} ns vs {p:.1f} ns = {c / p:.2f}x (fastest repetitions {best:.2f}x)"


def targets(rows: dict[str, Row], sym: Row | None, have_pin: bool) -> list[str]:
    """One PASS/FAIL/SKIP line per target, with its numbers (medians; ARMS and TREES only)."""
    lines = []
    arms = [rows[a] for a in ARMS if a in rows]
    trees = [rows[t] for t in TREES if t in rows]
    for fn in CASADI_FUNCTIONS:
        for r in arms:
            c, cr = r.c_ns.get(fn), r.cr_c_ns.get(fn)
            best = min(r.samples[fn]) / min(r.samples["cr_" + fn])
            ops, cro = r.ops[fn]["total"], r.casadi_ops[fn]["total"]
            lines.append(
                f"{verdict(c < cr)}  {r.name} {fn}: faster than the CasADi route's C: "
                f"{c:.1f} ns vs {cr:.1f} ns = {c / cr:.2f}x (< 1x; fastest repetitions {best:.2f}x)"
            )
            lines.append(
                f"{verdict(c <= 0.8 * cr)}  {r.name} {fn}: goal 0.8x the CasADi route's time: {c / cr:.2f}x"
            )
            lines.append(
                f"{verdict(ops <= 0.8 * cro)}  {r.name} {fn}: goal 0.8x the CasADi route's flops: "
                f"{ops} ops vs {cro} = {ops / cro:.2f}x"
            )
    for fn, alg in (
        ("coriolis_matrix", "coriolis_matrix"),
        ("forward_dynamics", "aba"),
        ("regressor", "regressor"),
    ):
        lines += [_against_pinocchio(r, fn, alg, 0.5, have_pin) for r in arms]
    for fn in ("inverse_dynamics", "mass_matrix", "gravity"):
        lines += [_against_pinocchio(r, fn, PINOCCHIO[fn], 0.25, have_pin) for r in trees]
    for r in arms:
        lines.append(
            f"{verdict(r.gen_wall < 3.0)}  {r.name}: symdyn generate --target c (7 functions) < 3 s: "
            f"{r.gen_wall:.2f} s wall ({r.gen_cpu:.2f} s CPU)"
        )
    for r in trees:
        lines.append(
            f"{verdict(r.gen_wall < 30.0)}  {r.name} (tree, {r.n} joints): symdyn generate --target c "
            f"(7 functions) < 30 s: {r.gen_wall:.2f} s wall ({r.gen_cpu:.2f} s CPU)"
        )
    if sym is not None:
        lines.append(
            f"{verdict(sym.gen_wall < 5.0)}  puma560, all 60 inertial parameters symbolic: generate < 5 s: "
            f"{sym.gen_wall:.2f} s wall ({sym.gen_cpu:.2f} s CPU)"
        )
        tau = sym.ops["inverse_dynamics"]["total"]
        lines.append(
            f"{verdict(tau <= 800)}  puma560, all inertial parameters symbolic: tau <= 800 operations: {tau}"
        )
    for r in [*arms, *([sym] if sym else [])]:
        C, V = r.ops["coriolis_matrix"]["total"], r.ops["coriolis"]["total"]
        lines.append(
            f"{verdict(C <= 3 * V)}  {r.name}: Coriolis matrix <= 3x the operations of V: "
            f"{C} vs {V} = {C / V:.2f}x"
        )
    return lines


def _notes(rows: list[Row], info: RunInfo) -> list[str]:
    """The notes under the table (also in the JSON)."""
    import casadi

    import symdyn

    opts = info.opts
    friction = [r.name for r in rows if r.c_ns and r.ops.get("friction", {}).get("total")]
    notes = [
        f"machine: {machine()}; load average {info.loads[0]} at the start, {info.loads[1]} at the end; "
        f"timing process {info.pinned}",
        "the machine is shared with other work on the same cores (see the load average), so absolute ns "
        "move by tens of percent from run to run: the benchmark judges ratios within one run "
        "(sd/CasADi-C, sd/Pin, the Targets lines), whose repetitions are interleaved",
        f"C: {compiler_version(C_COMPILER)}, flags {' '.join(FLAGS)} for symdyn's C, the CasADi route's C "
        "and the harness (separate translation units, no LTO)",
        f"C++: {compiler_version(CXX_COMPILER)}, flags {' '.join(FLAGS + CXX_EXTRA)} (header-only Pinocchio)",
        f"Pinocchio: {info.pin_note}",
        f"symdyn {getattr(symdyn, '__version__', '?')}, casadi {casadi.__version__}, numpy {np.__version__}, "
        f"Python {platform.python_version()}",
        f"ns/call: median of {opts.reps} repetitions of ~{opts.target_ms:g} ms each (after calibration and "
        f"warm-up), cycling through {NSTATES} random states (state changes every call), one output element "
        "per call into a volatile sink; repetitions interleaved across the functions of one harness, and "
        f"the C and Pinocchio harnesses run in {opts.rounds} alternating rounds",
        "gen s: `symdyn generate ROBOT --target c` in a fresh process (import, load, derive, render, "
        f"write), wall / CPU (user+sys) seconds, best of {opts.gen_runs} run(s)",
        "ops: symdyn's OpCount per function (NAME_dynamics.c); CasADi ops: the same categories counted "
        "over the traced SX algorithm (add/sub, mul/sq, div, sin/cos, others; negations not counted, "
        "as symdyn does not count unary minus)",
        "friction: INCLUDED on both symdyn's and the CasADi route's inverse dynamics (viscous qd + "
        "coulomb sign(qd)); Pinocchio's rnea and aba have no joint friction (its model gets the reflected "
        f"rotor inertia as `armature`), so for {', '.join(friction) or 'no robot'} (the timed robots with "
        "friction) Pinocchio does up to 2n multiplications, 2n additions and n signs less",
        "the Targets lines judge the medians; 'fastest repetitions' is the ratio of the minima over all "
        "repetitions, a view less sensitive to the load of a shared machine",
        "Pinocchio crba fills the upper triangle only; symdyn's mass_matrix and the CasADi route write "
        "all n*n entries",
        "NumPy us: symdyn.rnea.rnea, one state per call; batch: one call on 1000 states, divided by 1000",
        "CasADi py us: the casadi.Function called from Python with NumPy arguments",
        "puma560_symbolic: bench/chains/puma560_symbolic.yaml (examples/puma560.yaml with all 60 inertial "
        "parameters free, no motor inertia, no friction); generated, not timed",
    ]
    trees = [r.name for r in rows if r.name in TREES]
    if trees:
        notes.append(
            f"{', '.join(trees)}: whole URDF trees of example-robot-data on a fixed base, loaded without a "
            "tip (joint order = Pinocchio's); no mimic joints (n = nb); Pinocchio's model gets each "
            "joint's parent, the CasADi route runs its RNEA and CRBA on the same parents"
        )
    if any(r.name == "puma560_float" for r in rows):
        notes.append(
            "puma560_float: bench/chains/puma560_float.yaml, examples/puma560.yaml with every twist pi/2 "
            "written as the float 1.5707963267948966 (bench/robots.py); the same arm as puma560, but "
            "cos(alpha) = 6.1e-17 instead of 0 unless the loader snaps such angles to exact multiples of "
            "pi/2, so its extra operations are what that snapping saves (the CasADi route, too, folds "
            "only exact zeros)"
        )
    before, after = info.digests
    if after == before:
        notes.append(f"symdyn source digest {before} (unchanged during the run)")
    else:
        notes.append(
            f"WARNING: symdyn's source changed during the run ({before} -> {after}): "
            "rows may have generated code from different versions; run again"
        )
    return notes


def _check_line(rows: list[Row]) -> str:
    worst: dict[str, float] = {}
    for r in rows:
        for k, v in r.checks.items():
            kind = k.split(" ")[0]
            worst[kind] = max(worst.get(kind, 0.0), v)
    return (
        "checks against symdyn.rnea (max relative error over all robots, "
        f"{NCHECK} states each for C/C++, 5 for casadi.Function): "
        + ", ".join(f"{k} {v:.1e}" for k, v in sorted(worst.items()))
        + f"; tolerance {CHECK_TOL:g}: all passed"
    )


def _extra(rows: list[Row], sym: Row, info: RunInfo) -> list[str]:
    return [
        *(f"{r.name}: " + "; ".join(r.notes) for r in rows if r.notes),
        f"puma560_symbolic: {sym.n} joints, {info.nparams} free parameters, generation {sym.gen_wall:.2f} s "
        f"wall / {sym.gen_cpu:.2f} s CPU, ops "
        + ", ".join(f"{SHORT[f]} {sym.ops[f]['total']}" for f in FUNCTIONS),
        f"whole run: {info.seconds:.0f} s",
    ]


def write(rows: list[Row], sym: Row, info: RunInfo) -> None:
    """Print the report (Markdown with --markdown) and write bench/results/STEM.{txt,md,json}."""
    opts = info.opts
    notes = _notes(rows, info)
    verdicts = targets({r.name: r for r in rows}, sym, info.have_pin)
    lines = [*notes, _check_line(rows), *_extra(rows, sym, info)]

    def report(markdown: bool) -> str:
        bullet = "- " if markdown else ""
        text = [render_table([*rows, sym], markdown), ""]
        text.append("**Notes**" if markdown else "Notes:")
        text += [bullet + n for n in lines]
        text += ["", "**Targets**" if markdown else "Targets:"]
        text += ["```", *verdicts, "```"] if markdown else verdicts
        return "\n".join(text) + "\n"

    print(report(opts.markdown), end="")
    stem = "run" + ("_quick" if opts.quick else "") + ("_partial" if opts.robots else "")
    RESULTS.mkdir(parents=True, exist_ok=True)
    (RESULTS / f"{stem}.txt").write_text(report(False))
    (RESULTS / f"{stem}.md").write_text(report(True))
    payload = {
        "rows": [asdict(r) for r in rows],
        "puma560_symbolic": asdict(sym),
        "notes": notes,
        "targets": verdicts,
        "seconds": info.seconds,
    }
    (RESULTS / f"{stem}.json").write_text(json.dumps(payload, indent=1, default=str))
