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
    LINKER_SCRIPT,
    QEMU,
    STARTUP,
    cross_compile,
    host_results,
    link_harness,
    random_states,
    relative_errors,
    run_harness,
)

import symdyn  # noqa: E402
from symdyn.codegen import c as c_backend  # noqa: E402
from symdyn.codegen import context  # noqa: E402
from symdyn.regenerate import example_robot_data_folder  # noqa: E402

RESULTS = BENCH / "results" / "embedded.md"
CPU = "m4f"
OPTS = ("-Os", "-O2")
#: -icount shift: 2^7 ns of virtual time per instruction (the SysTick runs at 25 MHz: 3.2 ticks each)
SHIFT = 7
CASADI_FUNCTIONS = ("inverse_dynamics", "mass_matrix", "gravity")


def load(name: str) -> symdyn.Robot:
    if name == "solo12":
        return symdyn.load_urdf(
            example_robot_data_folder() / "solo_description/robots/solo12.urdf", floating=True
        )
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return symdyn.load_robot(BENCH.parent / "examples" / f"{name}.yaml")


def float_errors(robot: symdyn.Robot, folder: Path, name: str, build: Path, k: int) -> dict[str, tuple]:
    """function -> (max, 99th percentile) of the float error over k states, and cond(M)."""
    objects = cross_compile(folder, CPU, "-Os", build / "err")
    elf = link_harness(folder, objects, CPU, name, "float", robot.nq, robot.nv, build / "err")
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


def _timing_main(header: str, calls: dict[str, str], nin: int) -> str:
    """main.c that times each call (SysTick under -icount) on in.bin's first state, after 10,000 nops
    and an empty window for calibration, and writes the tick counts to ticks.bin."""
    body = []
    for fname, call in calls.items():
        body.append(
            f"    SYST_CVR = 0; (void)SYST_CVR; a = SYST_CVR; {call}; b = SYST_CVR;"
            f" ticks[n++] = a - b; /* {fname} */"
        )
    return f"""\
#include <fcntl.h>
#include <stddef.h>
#include <unistd.h>
#include "{header}"
#define SYST_CSR (*(volatile unsigned int *)0xE000E010u)
#define SYST_RVR (*(volatile unsigned int *)0xE000E014u)
#define SYST_CVR (*(volatile unsigned int *)0xE000E018u)
static float in[{nin}];
static float out[4096];
static unsigned int ticks[64];
__attribute__((noinline)) static void nops(void) {{ __asm__ volatile(".rept 10000\\n\\tnop\\n\\t.endr"); }}
__attribute__((noinline)) static void empty(void) {{ __asm__ volatile(""); }}
int main(void)
{{
    unsigned int a, b;
    int n = 0, fd = open("in.bin", O_RDONLY);
    if (fd < 0 || read(fd, in, sizeof in) != (int)sizeof in) {{
        return 1;
    }}
    close(fd);
    SYST_RVR = 0xFFFFFFu;
    SYST_CSR = 5u;
    SYST_CVR = 0; (void)SYST_CVR; a = SYST_CVR; nops(); b = SYST_CVR; ticks[n++] = a - b;
    SYST_CVR = 0; (void)SYST_CVR; a = SYST_CVR; empty(); b = SYST_CVR; ticks[n++] = a - b;
{chr(10).join(body)}
    fd = open("ticks.bin", O_WRONLY | O_CREAT | O_TRUNC, 0644);
    if (fd < 0 || write(fd, ticks, sizeof(unsigned int) * (unsigned int)n) < 0) {{
        return 1;
    }}
    close(fd);
    return 0;
}}
"""


def instructions(
    folder: Path, objects: list[Path], header: str, calls: dict[str, str], x: np.ndarray, build: Path
) -> dict:
    """function -> instructions of one call at the state x (SysTick ticks under -icount, calibrated)."""
    build.mkdir(parents=True, exist_ok=True)
    (build / "startup.c").write_text(STARTUP)
    (build / "link.ld").write_text(LINKER_SCRIPT)
    (build / "main.c").write_text(_timing_main(header, calls, x.size))
    elf = build / "timing.elf"
    cmd = [
        CC,
        "-std=c99",
        *CPUS[CPU][1],
        "-O2",
        f"-I{folder}",
        "--specs=rdimon.specs",
        "-T",
        str(build / "link.ld"),
    ]
    subprocess.run(
        [*cmd, str(build / "startup.c"), str(build / "main.c"), *map(str, objects), "-lm", "-o", str(elf)],
        check=True,
    )
    with tempfile.TemporaryDirectory() as tmp:
        np.asarray(x, dtype=np.float32).tofile(Path(tmp) / "in.bin")
        qemu = [
            QEMU,
            "-M",
            CPUS[CPU][0],
            "-nographic",
            "-monitor",
            "none",
            "-serial",
            "none",
            "-icount",
            f"shift={SHIFT}",
        ]
        subprocess.run(
            [*qemu, "-semihosting-config", "enable=on,target=native", "-kernel", str(elf)],
            cwd=tmp,
            check=True,
            timeout=600,
        )
        ticks = np.fromfile(Path(tmp) / "ticks.bin", dtype=np.uint32).astype(float)
    per_insn = (ticks[0] - ticks[1]) / 10000.0
    return {f: round((t - ticks[1]) / per_insn) for f, t in zip(calls, ticks[2:], strict=True)}


def symdyn_row(robot, ctx, freestanding: bool, opt: str, build: Path, x: np.ndarray) -> dict:
    import dataclasses

    from cbuild import write_files

    folder = build / f"src-{'free' if freestanding else 'libm'}"
    if not folder.exists():
        write_files(
            c_backend.render(dataclasses.replace(ctx, precision="float", freestanding=freestanding)), folder
        )
    name = ctx.name
    objects = cross_compile(folder, CPU, opt, build / f"o{opt}{freestanding}", extra=("-fstack-usage",))
    sizes = symbol_sizes(objects[0])
    helper = sizes.get(f"{name}_sincos", 0)
    stack = stack_usage(build / f"o{opt}{freestanding}")
    calls = {f: f"{name}_{f}({_args(args, robot)}, out)" for f, (args, _) in FUNCTIONS.items()}
    counts = instructions(folder, objects, f"{name}_dynamics.h", calls, x, build / f"t{opt}{freestanding}")
    return {
        "flash": {f: sizes[f"{name}_{f}"] + helper for f in FUNCTIONS},
        "file": section_size(objects),
        "stack": {f: stack.get(f"{name}_{f}", -1) for f in FUNCTIONS},
        "insns": counts,
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
    flags = ("-std=c99", *CPUS[CPU][1], opt, "-fstack-usage")
    row = {"flash": {}, "stack": {}, "insns": {}}
    objects = []
    for f in fns:
        obj = build / f"cr_{f}{opt}.o"
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
    row["insns"] = instructions(folder, objects, "cr_all.h", calls, x[: 3 * n + n], build / f"tc{opt}")
    return row


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
    goals = []
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
            for opt in OPTS if (args.all_opts or not robot.floating) else ("-Os",):
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
                if rname == "panda" and cas:
                    for f in ("inverse_dynamics", "mass_matrix"):
                        c = cas["insns"][f]
                        ratio = {k: row["insns"][f] / c for k, row in (("libm", libm), ("free", free))}
                        verdict = {k: "holds" if r <= 0.5 else "MISSED" for k, r in ratio.items()}
                        goals.append(
                            f"- Panda {f} {opt}: CasADi {c} instructions; symdyn {libm['insns'][f]} with "
                            f"newlib's sinf and cosf as CasADi's (ratio {ratio['libm']:.2f}, goal <= 0.5: "
                            f"{verdict['libm']}), {free['insns'][f]} freestanding "
                            f"(ratio {ratio['free']:.2f}: "
                            f"{verdict['free']}); flash {libm['flash'][f]} B against {cas['flash'][f]} B "
                            f"({'holds' if libm['flash'][f] <= cas['flash'][f] else 'MISSED'})"
                        )
            if rname == "panda":
                p99 = errors["inverse_dynamics"][1]
                goals.append(
                    f"- Panda inverse dynamics float error p99 {p99:.2g} "
                    f"(goal <= 1e-5: {'holds' if p99 <= 1e-5 else 'MISSED'})"
                )
            print(f"{rname} done", file=sys.stderr)
    lines += ["", "**Goals** (issue 38):", "", *goals, ""]
    text = "\n".join(lines)
    RESULTS.write_text(text)
    print(text)
    return 0


if __name__ == "__main__":
    sys.exit(main())
