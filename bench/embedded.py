"""The generated C on a Cortex-M4F: flash, stack, instructions per call and float error, beside CasADi.

    python bench/embedded.py [--states 10000] [--robots puma560 panda solo12]

writes bench/results/embedded.md (and prints it). For each robot (the PUMA 560, the Panda,
Solo-12 on its floating base) and each of the seven functions of symdyn's float C, built for the
Cortex-M4F (arm-none-eabi-gcc, `-mcpu=cortex-m4 -mthumb -mfloat-abi=hard -mfpu=fpv4-sp-d16`) at
-Os and at -O2:

- flash: the function's own bytes (its symbol's size from arm-none-eabi-nm -S: code and literal
  pool) plus the file's static helpers it calls (the freestanding NAME_sincos), and the whole
  object's .text + .rodata (arm-none-eabi-size);
- stack: the function's frame from -fstack-usage (the generated functions call nothing but the
  sines and cosines: newlib's sinf and cosf use at most a few dozen bytes more);
- instructions per call: counted on QEMU (mps2-an386) with `-icount shift=7` (every instruction
  advances the virtual clock by 128 ns) by the SysTick timer read around one call, calibrated by
  a run of 10,000 nops: one state, the same for every function; the sines and cosines included
  (newlib's sinf and cosf in the default build, symdyn's own with --freestanding);
- float error over the states (10,000 by default: angles over a full turn, rates and efforts in
  [-2, 2], a floating base's random unit quaternion): each state's largest error relative to the
  largest entry of the double result (the numeric oracle symdyn.rnea; C qd against V for C), max
  and 99th percentile; beside forward dynamics the condition number of M (median and max).

The CasADi route (bench/casadi_route.py: an RNEA and a CRBA traced in casadi.SX, compiled by
CasADi's code generator with casadi_real float, one file per function) is built and measured the
same way for its three functions (inverse dynamics, M, G; fixed-base robots). Its float C calls
the double sin and cos; they are renamed sinf and cosf here, as an embedded user would, so that the
two are compared on float arithmetic.

Goals (issue 38): the Panda's inverse dynamics and M in float on the M4F in at most half the
CasADi route's instructions and no more flash; the float error of inverse dynamics at most 1e-5
at the 99th percentile. The end of the report says whether they hold. Instruction counts do not
depend on the machine's load; the report names the tools' versions.
"""

from __future__ import annotations

import argparse
import re
import subprocess
import sys
import tempfile
import warnings
from pathlib import Path

import numpy as np

BENCH = Path(__file__).resolve().parent
sys.path.insert(0, str(BENCH))
sys.path.insert(0, str(BENCH.parent / "tests"))

import casadi_route  # noqa: E402
from embedded import (  # noqa: E402
    CC,
    CPUS,
    FUNCTIONS,
    QEMU,
    cross_compile,
    host_results,
    instructions,
    link_harness,
    loop_count,
    random_states,
    relative_errors,
    run_harness,
    static_count,
)

import symdyn  # noqa: E402
from symdyn.codegen import c as c_backend  # noqa: E402
from symdyn.codegen import context  # noqa: E402
from symdyn.regenerate import example_robot_data_folder  # noqa: E402

RESULTS = BENCH / "results" / "embedded.md"
CPU = "m4f"
#: the builds measured: the -O level and the flags added to it, the same for symdyn's C and the
#: CasADi route's; -ffp-contract=fast lets gcc fuse a*b + c into one vfma (C99 mode's default is
#: off), which the Cortex-M4F's FPU has
OPTS = ("-Os", "-O2")
CONTRACT = ("-ffp-contract=fast",)
CASADI_FUNCTIONS = ("inverse_dynamics", "mass_matrix", "gravity")


def load(name: str) -> symdyn.Robot:
    if name == "solo12":
        return symdyn.load_urdf(
            example_robot_data_folder() / "solo_description/robots/solo12.urdf", floating=True
        )
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return symdyn.load_robot(BENCH.parent / "examples" / f"{name}.yaml")


def float_errors(
    robot: symdyn.Robot, folder: Path, name: str, build: Path, k: int, extra: tuple[str, ...] = ()
) -> dict[str, tuple]:
    """function -> (max, 99th percentile) of the float error over k states, and cond(M) (at -Os,
    with the `extra` flags)."""
    out = build / f"err{len(extra)}"
    objects = cross_compile(folder, CPU, "-Os", out, extra=extra)
    elf = link_harness(folder, objects, CPU, name, "float", robot.nq, robot.nv, out)
    x = random_states(robot, k)
    got = run_harness(elf, CPU, x, "float", robot.nv, seconds=3600)
    want = host_results(robot, x)
    result = {
        f: (float(e.max()), float(np.percentile(e, 99)))
        for f, e in relative_errors(robot, x, got, want).items()
    }
    result["cond"] = (float(np.median(want["cond"])), float(want["cond"].max()))
    return result


def symbol_sizes(obj: Path) -> dict[str, int]:
    """Every defined function's (or object's) size in bytes: name -> size."""
    out = subprocess.run(
        ["arm-none-eabi-nm", "-S", str(obj)], capture_output=True, text=True, check=True
    ).stdout
    sizes = {}
    for line in out.splitlines():
        parts = line.split()
        if len(parts) == 4:
            sizes[parts[3]] = int(parts[1], 16)
    return sizes


def section_size(objects: list[Path]) -> int:
    """.text + .rodata of the objects (arm-none-eabi-size -A)."""
    total = 0
    for obj in objects:
        out = subprocess.run(
            ["arm-none-eabi-size", "-A", str(obj)], capture_output=True, text=True, check=True
        )
        for line in out.stdout.splitlines():
            parts = line.split()
            if parts and (parts[0].startswith(".text") or parts[0].startswith(".rodata")):
                total += int(parts[1])
    return total


def stack_usage(folder: Path) -> dict[str, int]:
    """function -> bytes of stack (the .su files of -fstack-usage)."""
    usage = {}
    for su in folder.glob("*.su"):
        for line in su.read_text().splitlines():
            where, size, _ = line.rsplit("\t", 2)
            usage[where.rsplit(":", 1)[-1]] = int(size)
    return usage


#: timed beside the functions: newlib's sinf and cosf of each q, and a call of the same shape
#: that runs one instruction (its return), to take the harness's part out of their counts
TRIG_PRELUDE = """\
#include <math.h>
static volatile float sink;
__attribute__((noinline)) static float ident(float x) { __asm__ volatile("" : "+t"(x)); return x; }
"""


def _function_text(folder: Path, c_name: str) -> str:
    """The body of a generated function in the folder's C files."""
    for source in sorted(folder.glob("*.c")):
        m = re.search(rf"\nvoid {c_name}\(.*?\n\}}\n", source.read_text(), re.S)
        if m:
            return m.group(0)
    raise KeyError(c_name)


def static_total(obj: Path, folder: Path, name: str, f: str, trig: dict[str, int]) -> tuple[int | None, str]:
    """The static count of one call of NAME_f: its own instructions (branch-free: each runs once)
    plus its calls' instructions, NAME_sincos's from its disassembly (its one loop n times) and
    newlib's sinf and cosf as measured once at the same angle (`trig`: "sinf3" -> count); and
    a note naming what breaks the count (a branch, a call it cannot price), else ""."""
    c_name = f"{name}_{f}"
    count, callees, broken = static_count(obj, c_name)
    if broken:
        return None, f"not branch-free: {len(broken)} branch{'es' * (len(broken) > 1)}"
    text = _function_text(folder, c_name)
    local = dict(re.findall(r"const float (\w+) = q\[(\d+)\];", text))
    libm = [(c, local.get(a)) for c, a in re.findall(r"\b(sinf|cosf)\((\w+)\)", text)]
    for callee in callees:
        if callee.startswith(f"{name}_sincos"):
            count += loop_count(obj, callee, int(re.search(rf"{name}_sincos\((\d+),", text).group(1)))
        elif callee in ("sinf", "cosf"):
            matching = [k for c, k in libm if c == callee and k is not None]
            if not matching:
                return None, f"a call of {callee} at an angle that is no q"
            libm.remove((callee, matching[0]))
            count += trig[f"{callee}{matching[0]}"]
        else:
            return None, f"calls {callee}"
    return count, ""


def symdyn_row(robot, ctx, freestanding: bool, opt: str, build: Path, x: np.ndarray) -> dict:
    import dataclasses

    from cbuild import write_files

    folder = build / f"src-{'free' if freestanding else 'libm'}"
    if not folder.exists():
        write_files(
            c_backend.render(dataclasses.replace(ctx, precision="float", freestanding=freestanding)), folder
        )
    name = ctx.name
    level, *more = opt.split()
    tag = f"{opt.replace(' ', '').replace('=', '')}{freestanding}"
    objects = cross_compile(folder, CPU, level, build / f"o{tag}", extra=(*more, "-fstack-usage"))
    sizes = symbol_sizes(objects[0])
    helper = sizes.get(f"{name}_sincos", 0)
    stack = stack_usage(build / f"o{tag}")
    calls = {f: f"{name}_{f}({_args(args, robot)}, out)" for f, (args, _) in FUNCTIONS.items()}
    for k in range(robot.nq):
        # the volatile asm statements pin each call inside its window (gcc may otherwise move a
        # call of sinf, which only sets errno, across the SysTick reads)
        calls |= {
            f"{t}{k}": f'{{ float v = in[{k}]; __asm__ volatile("" : "+t"(v)); v = {t}(v); '
            f'__asm__ volatile("" : "+t"(v)); sink = v; }}'
            for t in ("sinf", "cosf", "ident")
        }
    counts = instructions(
        folder, objects, f"{name}_dynamics.h", calls, x, build / f"t{tag}", CPU, TRIG_PRELUDE
    )
    trig = {
        f"{t}{k}": counts[f"{t}{k}"] - counts[f"ident{k}"] + 1
        for t in ("sinf", "cosf")
        for k in range(robot.nq)
    }
    return {
        "flash": {f: sizes[f"{name}_{f}"] + helper for f in FUNCTIONS},
        "file": section_size(objects),
        "stack": {f: stack.get(f"{name}_{f}", -1) for f in FUNCTIONS},
        "insns": {f: counts[f] for f in FUNCTIONS},
        "static": {f: static_total(objects[0], folder, name, f, trig) for f in FUNCTIONS},
    }


def _args(args: str, robot) -> str:
    """The harness's argument names as offsets into in[] (q, qd, qdd, tau)."""
    nq, nv = robot.nq, robot.nv
    where = {"q": "in", "qd": f"in + {nq}", "qdd": f"in + {nq + nv}", "tau": f"in + {nq + 2 * nv}"}
    return ", ".join(where.get(a.strip(), a.strip()) for a in args.split(","))


def casadi_row(robot, opt: str, build: Path, x: np.ndarray) -> dict:
    """The CasADi route's three functions in float: flash (each in its own file), stack, instructions."""
    import casadi as cs

    fns = casadi_route.casadi_functions(robot)
    folder = build / "casadi"
    folder.mkdir(parents=True, exist_ok=True)
    for f, fn in fns.items():
        cg = cs.CodeGenerator(f"cr_{f}.c", {"with_header": True, "casadi_real": "float"})
        cg.add(fn)
        cg.generate(str(folder) + "/")
        path = folder / f"cr_{f}.c"
        text = re.sub(r"\b(sin|cos)\(", r"\1f(", path.read_text())
        path.write_text(text)
    flags = ("-std=c99", *CPUS[CPU][1], *opt.split(), "-fstack-usage")
    tag = opt.replace(" ", "").replace("=", "")
    row = {"flash": {}, "stack": {}, "insns": {}}
    objects = []
    for f in fns:
        obj = build / f"cr_{f}{tag}.o"
        subprocess.run(
            [CC, *flags, "-c", str(folder / f"cr_{f}.c"), "-o", str(obj)], check=True, capture_output=True
        )
        objects.append(obj)
        row["flash"][f] = section_size([obj])
        usage = [int(line.rsplit("\t", 2)[1]) for line in obj.with_suffix(".su").read_text().splitlines()]
        row["stack"][f] = max(usage)
    n = robot.n
    # CasADi's calling convention: arg[] and res[] of pointers, work arrays iw and w (none needed)
    calls = {}
    for f in fns:
        inputs = {"inverse_dynamics": f"in, in + {n}, in + {2 * n}", "mass_matrix": "in", "gravity": "in"}[f]
        calls[f] = (
            f"{{ const float *arg[3] = {{ {inputs} }}; float *res[1] = {{ out }}; static float w[4096]; "
            f"cr_{robot.name}_{f}(arg, res, NULL, w, 0); }}"
        )
    headers = "".join(f'#include "cr_{f}.h"\n' for f in fns)
    (folder / "cr_all.h").write_text(headers)
    row["insns"] = instructions(folder, objects, "cr_all.h", calls, x[: 3 * n + n], build / f"tc{tag}")
    return row


def _static_cells(static: tuple[int | None, str], measured: int) -> str:
    """static | QEMU | difference, or the reason there is no static count."""
    count, note = static
    if count is None:
        return f"({note}) | {measured} | "
    return f"{count} | {measured} | {measured - count:+d}"


def _goal_lines(opt: str, libm: dict, free: dict, cas: dict) -> list[str]:
    """The Panda's goals of issue 38 at one build: instructions against the CasADi route, flash."""
    lines = []
    for f in ("inverse_dynamics", "mass_matrix"):
        c = cas["insns"][f]
        ratio = {k: row["insns"][f] / c for k, row in (("libm", libm), ("free", free))}
        verdict = {k: "holds" if r <= 0.5 else "MISSED" for k, r in ratio.items()}
        lines.append(
            f"- Panda {f} {opt}: CasADi {c} instructions; symdyn {libm['insns'][f]} with "
            f"newlib's sinf and cosf as CasADi's (ratio {ratio['libm']:.3f}, goal <= 0.5: "
            f"{verdict['libm']}), {free['insns'][f]} freestanding (ratio {ratio['free']:.3f}: "
            f"{verdict['free']}); flash {libm['flash'][f]} B against {cas['flash'][f]} B "
            f"({'holds' if libm['flash'][f] <= cas['flash'][f] else 'MISSED'})"
        )
    return lines


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--states", type=int, default=10000)
    parser.add_argument("--robots", nargs="+", default=["puma560", "panda", "solo12"])
    parser.add_argument(
        "--all-opts",
        action="store_true",
        help="also build Solo-12 at -O2 (gcc takes over a minute of CPU per build; -Os only by default)",
    )
    args = parser.parse_args(argv)
    lines = [
        "**The generated C on a Cortex-M4F** (bench/embedded.py)",
        "",
        f"{subprocess.run([CC, '--version'], capture_output=True, text=True).stdout.splitlines()[0]}; "
        f"{subprocess.run([QEMU, '--version'], capture_output=True, text=True).stdout.splitlines()[0]}; "
        f"symdyn {symdyn.__version__}. Float, `{' '.join(CPUS[CPU][1])}`. Instructions per call counted "
        f"under QEMU (-icount, SysTick), one state; flash = the function's bytes (+ NAME_sincos when "
        f"freestanding); stack from -fstack-usage; float error over {args.states} states relative to the "
        "double oracle (at -Os; the error does not depend on -O). libm: newlib's sinf, cosf; free: "
        "--freestanding. A floating robot (Solo-12) at -Os only: gcc takes over a minute of CPU per "
        "-O2 build of its 430 KB file (--all-opts adds it). Stack: the function's frame.",
        "",
        "| robot | function | -O | flash B (libm / free) | stack B | instructions (libm / free) "
        "| CasADi flash B | CasADi instructions | float error max | p99 | cond(M) median / max |",
        "|---|---|---|---:|---:|---:|---:|---:|---:|---:|---|",
    ]
    goals, static_lines, contract_lines = [], [], []
    with tempfile.TemporaryDirectory(prefix="symdyn-embedded-bench-") as tmp:
        for rname in args.robots:
            robot = load(rname)
            ctx = context(robot, functions=("dynamics",))
            build = Path(tmp) / rname
            x = random_states(robot, 1, seed=1)[0]
            from cbuild import write_files

            err_folder = build / "err-src"
            import dataclasses

            write_files(c_backend.render(dataclasses.replace(ctx, precision="float")), err_folder)
            errors = float_errors(robot, err_folder, ctx.name, build, args.states)
            opts = OPTS if (args.all_opts or not robot.floating) else ("-Os",)
            for opt in opts:
                libm = symdyn_row(robot, ctx, False, opt, build, x)
                free = symdyn_row(robot, ctx, True, opt, build, x)
                cas = None if robot.floating else casadi_row(robot, opt, build, x)
                for f in FUNCTIONS:
                    e = errors[f]
                    cond = (
                        f"{errors['cond'][0]:.3g} / {errors['cond'][1]:.3g}"
                        if f == "forward_dynamics"
                        else ""
                    )
                    cf = str(cas["flash"][f]) if cas and f in cas["flash"] else ""
                    ci = str(cas["insns"][f]) if cas and f in cas["insns"] else ""
                    lines.append(
                        f"| {rname} | {f} | {opt} | {libm['flash'][f]} / {free['flash'][f]} | "
                        f"{libm['stack'][f]} | {libm['insns'][f]} / {free['insns'][f]} | {cf} | {ci} | "
                        f"{e[0]:.2g} | {e[1]:.2g} | {cond} |"
                    )
                    static_lines.append(
                        f"| {rname} | {f} | {opt} | "
                        + " | ".join(_static_cells(row["static"][f], row["insns"][f]) for row in (libm, free))
                        + " |"
                    )
                if rname == "panda" and cas:
                    goals += _goal_lines(opt, libm, free, cas)
            if robot.floating:
                continue
            for opt in (f"{o} {' '.join(CONTRACT)}" for o in opts):
                libm = symdyn_row(robot, ctx, False, opt, build, x)
                free = symdyn_row(robot, ctx, True, opt, build, x)
                cas = casadi_row(robot, opt, build, x)
                for f in CASADI_FUNCTIONS:
                    c = cas["insns"][f]
                    contract_lines.append(
                        f"| {rname} | {f} | {opt} | {libm['insns'][f]} / {free['insns'][f]} | {c} | "
                        f"{libm['insns'][f] / c:.3f} / {free['insns'][f] / c:.3f} |"
                    )
                if rname == "panda":
                    goals += _goal_lines(opt, libm, free, cas)
            if rname == "panda":
                p99 = errors["inverse_dynamics"][1]
                fused = float_errors(robot, err_folder, ctx.name, build, args.states, CONTRACT)
                goals.append(
                    f"- Panda inverse dynamics float error p99 {p99:.2g} (goal <= 1e-5: "
                    f"{'holds' if p99 <= 1e-5 else 'MISSED'}); {fused['inverse_dynamics'][1]:.2g} built "
                    f"with {' '.join(CONTRACT)} (max {fused['inverse_dynamics'][0]:.2g})"
                )
            print(f"{rname} done", file=sys.stderr)
    lines += [
        "",
        f"**With {' '.join(CONTRACT)}** (gcc fuses a*b + c into one vfma; the same flags for both "
        "routes' C; instructions per call under QEMU as above):",
        "",
        "| robot | function | flags | symdyn instructions (libm / free) | CasADi instructions "
        "| ratio (libm / free) |",
        "|---|---|---|---:|---:|---:|",
        *contract_lines,
        "",
        "**Static counts against QEMU's** (instructions of one call: the function's own from "
        "arm-none-eabi-objdump -d, each run once as the function has no branch but its calls and its "
        "return; plus NAME_sincos's from its disassembly, its one loop once per angle, or newlib's "
        "sinf and cosf as counted under QEMU at the same angle; difference = QEMU - static, the "
        "harness's argument set-up and call):",
        "",
        "| robot | function | -O | libm: static | QEMU | difference | free: static | QEMU | difference |",
        "|---|---|---|---:|---:|---:|---:|---:|---:|",
        *static_lines,
    ]
    lines += ["", "**Goals** (issue 38):", "", *goals, ""]
    text = "\n".join(lines)
    RESULTS.write_text(text)
    print(text)
    return 0


if __name__ == "__main__":
    sys.exit(main())
