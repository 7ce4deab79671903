"""Generated C on ARM Cortex-M: cross-compiled with arm-none-eabi-gcc and run under QEMU.

A helper shared by tests/test_embedded.py and bench/embedded.py:

    objects = cross_compile(folder, "m4f", "-Os", build_dir)   # every .c the C target wrote
    undefined_symbols(objects)                                  # arm-none-eabi-nm -u
    elf = link_harness(folder, objects, "m4f", name, "float", nq, nv, build_dir)
    out = run_harness(elf, "m4f", states, "float", sizes)       # the seven functions, per state

The two cores are QEMU's MPS2 boards: the AN386 (Cortex-M4 with the single-precision FPU,
`-mfpu=fpv4-sp-d16`: a double is computed by libgcc's __aeabi_d* calls) and the AN500
(Cortex-M7 with the double-precision FPU, `-mfpu=fpv5-d16`). The program's vector table
(`STARTUP`) gives the stack and a reset handler that enables the FPU (CPACR: full access to
CP10 and CP11) before newlib's semihosting start-up (`--specs=rdimon.specs`: .bss cleared,
then main); the harness reads the states from the host's file in.bin and writes the outputs to
out.bin through semihosting's open, read and write (no stdio: newlib's malloc is never called).

Objects are cached by the SHA-256 of their source, the headers beside it, the flags and the
compiler's version (`cache_folder`), so a second run compiles nothing; the .c files of one
build compile in parallel (one process per file).
"""

from __future__ import annotations

import hashlib
import os
import re
import shutil
import subprocess
import tempfile
from collections.abc import Sequence
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass
from functools import cache
from pathlib import Path

import numpy as np

__all__ = [
    "CPUS",
    "WARNINGS",
    "FUNCTIONS",
    "available",
    "c_sources",
    "cross_compile",
    "undefined_symbols",
    "link_harness",
    "link_bare",
    "run_harness",
    "harness_source",
    "output_sizes",
    "random_states",
    "host_results",
    "relative_errors",
    "disassembly",
    "static_count",
    "loop_count",
    "timing_source",
    "instructions",
]

CC, NM, QEMU = "arm-none-eabi-gcc", "arm-none-eabi-nm", "qemu-system-arm"
OBJDUMP = "arm-none-eabi-objdump"
#: -icount shift of the timing programs: 2^7 ns of virtual time per instruction (the SysTick runs
#: at 25 MHz: 3.2 ticks each)
SHIFT = 7

#: core -> (QEMU's machine, the compiler's flags for it)
CPUS = {
    "m4f": ("mps2-an386", ("-mcpu=cortex-m4", "-mthumb", "-mfloat-abi=hard", "-mfpu=fpv4-sp-d16")),
    "m7": ("mps2-an500", ("-mcpu=cortex-m7", "-mthumb", "-mfloat-abi=hard", "-mfpu=fpv5-d16")),
}

#: the strict flags of an embedded build: the C contract's (tests/cbuild.STRICT_FLAGS) and the
#: warnings an embedded engineer adds (a float silently widened to double, a narrowing
#: conversion, a shadowed name)
WARNINGS = (
    "-std=c99",
    "-Wall",
    "-Wextra",
    "-Wpedantic",
    "-Wdouble-promotion",
    "-Wconversion",
    "-Wshadow",
    "-Werror",
)

#: the seven functions in the order the harness calls them and writes their outputs:
#: name -> (its arguments, taken from q, qd, qdd, tau and a NULL p; its output's size: "n" or "nn")
FUNCTIONS = {
    "inverse_dynamics": ("q, qd, qdd, NULL", "n"),
    "mass_matrix": ("q, NULL", "nn"),
    "coriolis_matrix": ("q, qd, NULL", "nn"),
    "coriolis": ("q, qd, NULL", "n"),
    "gravity": ("q, NULL", "n"),
    "friction": ("qd, NULL", "n"),
    "forward_dynamics": ("q, qd, tau, NULL", "n"),
}

#: the vector table and reset handler of the harness programs (see the module's docstring)
STARTUP = """\
extern void _start(void);
extern unsigned int __stack_top;
void reset_handler(void);
void fault_handler(void);
__attribute__((section(".vectors"), used)) static void (*const vectors[16])(void) = {
    (void (*)(void))&__stack_top, reset_handler, fault_handler, fault_handler, fault_handler,
    fault_handler, fault_handler, 0, 0, 0, 0, fault_handler, fault_handler, 0, fault_handler,
    fault_handler};
void reset_handler(void)
{
    *(volatile unsigned int *)0xE000ED88u |= 0xFu << 20; /* CPACR: CP10, CP11 full access */
    __asm__ volatile("dsb\\n\\tisb");
    _start();
}
void fault_handler(void)
{
    for (;;) {
    }
}
"""

#: both boards have 4 MB of RAM at 0 (the code) and 4 MB at 0x20000000 (data and stack)
LINKER_SCRIPT = """\
MEMORY { FLASH (rx) : ORIGIN = 0x00000000, LENGTH = 4M  RAM (rwx) : ORIGIN = 0x20000000, LENGTH = 4M }
ENTRY(reset_handler)
SECTIONS {
  .text : { KEEP(*(.vectors)) *(.text*) *(.rodata*) KEEP(*(.init)) KEEP(*(.fini)) . = ALIGN(4); } > FLASH
  .ARM.exidx : { *(.ARM.exidx*) } > FLASH
  .preinit_array : { PROVIDE_HIDDEN(__preinit_array_start = .); KEEP(*(.preinit_array));
                     PROVIDE_HIDDEN(__preinit_array_end = .); } > FLASH
  .init_array : { PROVIDE_HIDDEN(__init_array_start = .); KEEP(*(SORT(.init_array.*)));
                  KEEP(*(.init_array)); PROVIDE_HIDDEN(__init_array_end = .); } > FLASH
  .fini_array : { PROVIDE_HIDDEN(__fini_array_start = .); KEEP(*(.fini_array));
                  PROVIDE_HIDDEN(__fini_array_end = .); } > FLASH
  .data : { *(.data*) . = ALIGN(4); } > RAM AT > FLASH
  .bss (NOLOAD) : { __bss_start__ = .; *(.bss*) *(COMMON) . = ALIGN(4); __bss_end__ = .; } > RAM
  end = .; PROVIDE(_end = .); PROVIDE(__end__ = .);
  __stack_top = ORIGIN(RAM) + LENGTH(RAM);
}
"""


def available() -> bool:
    """Whether the cross compiler, its newlib and QEMU are installed."""
    return all(shutil.which(tool) for tool in (CC, NM, QEMU))


@cache
def _compiler_version() -> str:
    return subprocess.run([CC, "--version"], capture_output=True, text=True, check=True).stdout


def cache_folder() -> Path:
    """Where objects are cached: SYMDYN_CACHE_DIR/embedded (the tests' temporary cache, or the
    user's), else the system's temporary folder."""
    root = os.environ.get("SYMDYN_CACHE_DIR") or os.path.join(tempfile.gettempdir(), "symdyn-embedded")
    folder = Path(root) / "embedded"
    folder.mkdir(parents=True, exist_ok=True)
    return folder


def c_sources(folder: str | os.PathLike) -> list[Path]:
    """Every .c file the C target wrote into `folder` (one or several), in name order."""
    sources = sorted(Path(folder).glob("*.c"))
    if not sources:
        raise FileNotFoundError(f"{folder}: no .c file")
    return sources


def _run(cmd: Sequence[str], cwd: str | os.PathLike | None = None) -> subprocess.CompletedProcess:
    proc = subprocess.run(list(cmd), capture_output=True, text=True, cwd=cwd)
    if proc.returncode != 0 or "warning" in proc.stderr.lower():
        raise RuntimeError(f"{' '.join(map(str, cmd))}\nexit {proc.returncode}\n{proc.stdout}{proc.stderr}")
    return proc


def _compile_one(source: Path, flags: Sequence[str], out_dir: Path) -> Path:
    """One .c file compiled to an object (or taken from the cache)."""
    key = hashlib.sha256()
    for part in (_compiler_version(), "\0".join(flags), source.read_text(encoding="utf-8")):
        key.update(part.encode() + b"\0")
    for header in sorted(source.parent.glob("*.h")):
        key.update(header.read_bytes() + b"\0")
    cached = cache_folder() / f"{key.hexdigest()}.o"
    target = out_dir / f"{source.stem}.o"
    if not cached.exists():
        partial = cached.with_suffix(f".{os.getpid()}.{id(source)}.part")
        _run([CC, *flags, "-c", str(source), "-o", str(partial)])
        os.replace(partial, cached)
        # the -fstack-usage report, when asked for, lands beside the partial object
        su = partial.with_suffix(".su")
        if su.exists():
            os.replace(su, cached.with_suffix(".su"))
    shutil.copyfile(cached, target)
    if cached.with_suffix(".su").exists():
        shutil.copyfile(cached.with_suffix(".su"), target.with_suffix(".su"))
    return target


def cross_compile(
    folder: str | os.PathLike,
    cpu: str,
    opt: str,
    out_dir: str | os.PathLike,
    extra: Sequence[str] = (),
    jobs: int = 2,
) -> list[Path]:
    """Every .c file of `folder` compiled for `cpu` (a key of CPUS) at `opt` with WARNINGS (a
    warning fails): the objects, in `out_dir`."""
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    flags = (*WARNINGS, *CPUS[cpu][1], opt, *extra)
    sources = c_sources(folder)
    with ThreadPoolExecutor(max_workers=max(1, min(jobs, len(sources)))) as pool:
        return list(pool.map(lambda s: _compile_one(s, flags, out), sources))


def undefined_symbols(objects: Sequence[str | os.PathLike]) -> set[str]:
    """The symbols the objects use and do not define (arm-none-eabi-nm -u), taken together."""
    proc = _run([NM, "-u", *map(str, objects)])
    undefined = {line.split()[-1] for line in proc.stdout.splitlines() if line.strip().startswith("U ")}
    defined = _run([NM, "--defined-only", *map(str, objects)]).stdout
    names = {line.split()[-1] for line in defined.splitlines() if len(line.split()) == 3}
    return undefined - names


def output_sizes(nv: int) -> dict[str, int]:
    """The number of values each function writes (FUNCTIONS' order)."""
    return {name: nv * nv if size == "nn" else nv for name, (_, size) in FUNCTIONS.items()}


def harness_source(name: str, precision: str, nq: int, nv: int) -> str:
    """main.c: per state of in.bin (q, qd, qdd, tau), the seven functions' outputs to out.bin."""
    real = precision
    total = sum(output_sizes(nv).values())
    calls, offset = [], 0
    for fname, (args, _) in FUNCTIONS.items():
        calls.append(f"        {name}_{fname}({args}, out + {offset});")
        offset += output_sizes(nv)[fname]
    return f"""\
#include <fcntl.h>
#include <stddef.h>
#include <unistd.h>
#include "{name}_dynamics.h"

static {real} in[{nq + 3 * nv}];
static {real} out[{total}];

int main(void)
{{
    const {real} *q = in, *qd = in + {nq}, *qdd = qd + {nv}, *tau = qdd + {nv};
    int fi = open("in.bin", O_RDONLY), fo = open("out.bin", O_WRONLY | O_CREAT | O_TRUNC, 0644);
    if (fi < 0 || fo < 0) {{
        return 1;
    }}
    while (read(fi, in, sizeof in) == (int)sizeof in) {{
{chr(10).join(calls)}
        if (write(fo, out, sizeof out) != (int)sizeof out) {{
            return 1;
        }}
    }}
    close(fi);
    close(fo);
    return 0;
}}
"""


def link_harness(
    folder: str | os.PathLike,
    objects: Sequence[Path],
    cpu: str,
    name: str,
    precision: str,
    nq: int,
    nv: int,
    out_dir: str | os.PathLike,
) -> Path:
    """The QEMU program: STARTUP, the harness and the generated objects, linked with newlib's
    semihosting library (rdimon) and libm."""
    out = Path(out_dir)
    (out / "startup.c").write_text(STARTUP)
    (out / "link.ld").write_text(LINKER_SCRIPT)
    (out / "main.c").write_text(harness_source(name, precision, nq, nv))
    elf = out / "harness.elf"
    _run(
        [
            CC,
            "-std=c99",
            "-Wall",
            "-Werror",
            *CPUS[cpu][1],
            "-O2",
            f"-I{folder}",
            "--specs=rdimon.specs",
            "-T",
            str(out / "link.ld"),
            str(out / "startup.c"),
            str(out / "main.c"),
            *map(str, objects),
            "-lm",
            "-o",
            str(elf),
        ]
    )
    return elf


def link_bare(objects: Sequence[Path], cpu: str, entry: str, out_dir: str | os.PathLike) -> Path:
    """The objects linked alone with -nostdlib (no C library, no libgcc, no start-up files),
    `entry` as the entry point: fails on any symbol they need from elsewhere."""
    elf = Path(out_dir) / "bare.elf"
    _run([CC, *CPUS[cpu][1], "-nostdlib", f"-Wl,-e,{entry}", *map(str, objects), "-o", str(elf)])
    return elf


def run_harness(
    elf: Path, cpu: str, states: np.ndarray, precision: str, nv: int, seconds: float = 60
) -> np.ndarray:
    """Run the program under QEMU on `states` (one row per state: q, qd, qdd, tau): its outputs,
    one row per state (the seven functions' outputs in FUNCTIONS' order), as float64."""
    dtype = np.float32 if precision == "float" else np.float64
    width = sum(output_sizes(nv).values())
    with tempfile.TemporaryDirectory(prefix="symdyn-qemu-") as tmp:
        np.ascontiguousarray(states, dtype=dtype).tofile(os.path.join(tmp, "in.bin"))
        cmd = [QEMU, "-M", CPUS[cpu][0], "-nographic", "-monitor", "none", "-serial", "none"]
        cmd += ["-semihosting-config", "enable=on,target=native", "-kernel", str(elf)]
        subprocess.run(cmd, cwd=tmp, capture_output=True, timeout=seconds, check=True)
        out = np.fromfile(os.path.join(tmp, "out.bin"), dtype=dtype)
    if out.size != len(states) * width:
        raise RuntimeError(f"{elf}: {out.size} values written, {len(states) * width} expected")
    return out.reshape(len(states), width).astype(np.float64)


def random_states(robot, k: int, seed: int = 38) -> np.ndarray:
    """k rows of (q, qd, qdd, tau): angles over a full turn, a floating base's position within 1 m
    and its orientation a random unit quaternion, rates and efforts in [-2, 2]."""
    rng = np.random.default_rng(seed)
    q = rng.uniform(-np.pi, np.pi, (k, robot.n))
    if robot.floating:
        quat = rng.normal(size=(k, 4))
        q = np.hstack([rng.uniform(-1, 1, (k, 3)), quat / np.linalg.norm(quat, axis=1, keepdims=True), q])
    return np.hstack([q, rng.uniform(-2, 2, (k, 3 * robot.nv))])


def host_results(robot, states: np.ndarray) -> dict[str, np.ndarray]:
    """The host's double results of the numeric oracle symdyn.rnea: each function's output at each
    state (for C, V: the harness's C is compared through C qd), and cond(M) ("cond")."""
    from symdyn.rnea import bias_torque, forward_dynamics, friction_torque, gravity_torque, mass_matrix, rnea

    nq, nv = robot.nq, robot.nv
    q, qd, qdd, tau = np.split(states, [nq, nq + nv, nq + 2 * nv], axis=1)
    m = mass_matrix(robot, q)
    v = bias_torque(robot, q, qd)
    return {
        "inverse_dynamics": rnea(robot, q, qd, qdd),
        "mass_matrix": m.reshape(len(q), -1),
        "coriolis_matrix": v,
        "coriolis": v,
        "gravity": gravity_torque(robot, q),
        "friction": friction_torque(robot, qd),
        "forward_dynamics": forward_dynamics(robot, q, qd, tau),
        "cond": np.linalg.cond(m),
    }


def relative_errors(robot, states: np.ndarray, got: np.ndarray, want: dict) -> dict[str, np.ndarray]:
    """function -> each state's largest error over the largest entry of the host's result (C
    through C qd against V)."""
    nv = robot.nv
    sizes = output_sizes(nv)
    offsets = np.cumsum([0, *sizes.values()])
    out = {f: got[:, a:b] for f, a, b in zip(sizes, offsets[:-1], offsets[1:], strict=True)}
    qd = states[:, robot.nq : robot.nq + nv]
    out["coriolis_matrix"] = np.einsum("kij,kj->ki", out["coriolis_matrix"].reshape(-1, nv, nv), qd)
    errors = {}
    for f in sizes:
        scale = np.max(np.abs(want[f]), axis=1)
        errors[f] = np.max(np.abs(out[f] - want[f]), axis=1) / np.where(scale > 0, scale, 1.0)
    return errors


# --------------------------------------------------------------------------- instructions per call


@dataclass(frozen=True)
class Instruction:
    """One instruction of a disassembled function: its address, mnemonic, operands and the
    symbol a call's relocation names (or the <symbol> objdump resolved), else ""."""

    address: int
    mnemonic: str
    operands: str
    callee: str = ""


_LINE = re.compile(r"^\s*([0-9a-f]+):\t([^\t]+)\t?(.*)$")
_RELOC = re.compile(r"^\s*([0-9a-f]+): R_ARM_THM_(?:CALL|JUMP24)\t(\S+)")
#: data in a function's literal pool, not instructions
_DATA = (".word", ".short", ".byte")
_CONDITIONS = ["eq", "ne", "cs", "hs", "cc", "lo", "mi", "pl", "vs", "vc", "hi", "ls", "ge", "lt", "gt", "le"]


def disassembly(obj: str | os.PathLike, function: str) -> list[Instruction]:
    """The instructions of `function` in the object (arm-none-eabi-objdump -dr), literal-pool data
    left out; a call's callee from its relocation (or objdump's <symbol> for a call within the
    object)."""
    out = _run([OBJDUMP, "-dr", "--no-show-raw-insn", str(obj)]).stdout
    lines, inside = [], False
    for line in out.splitlines():
        if line.endswith(">:"):
            inside = line.split("<", 1)[1][:-2] == function
            continue
        if inside:
            lines.append(line)
    relocs = {int(m.group(1), 16): m.group(2) for m in map(_RELOC.match, lines) if m}
    result = []
    for line in lines:
        m = _LINE.match(line)
        if not m or "R_ARM_" in line or m.group(2).strip() in _DATA:
            continue
        address, mnemonic, operands = int(m.group(1), 16), m.group(2).strip(), m.group(3).strip()
        callee = ""
        if mnemonic in ("bl", "blx"):
            named = re.search(r"<([^>+]+)", operands)
            callee = relocs.get(address) or (named.group(1) if named else "")
        result.append(Instruction(address, mnemonic, operands, callee))
    if not result:
        raise RuntimeError(f"{obj}: no function {function}")
    return result


def _branch_kind(ins: Instruction) -> str:
    """ "" for an instruction that is no branch; else call, return, jump (unconditional) or
    conditional."""
    base = ins.mnemonic.split(".")[0]
    if base in ("bl", "blx"):
        return "call"
    if (
        (base == "bx" and ins.operands == "lr")
        or (base == "pop" and "pc" in ins.operands)
        or (base == "ldr" and ins.operands.startswith("pc, [sp]"))  # pop {pc} of one register
    ):
        return "return"
    if base in ("cbz", "cbnz") or (base[:1] == "b" and base[1:] in _CONDITIONS):
        return "conditional"
    if base in ("b", "bx", "tbb", "tbh") or ("pc" in ins.operands.split("[")[0] and base in ("ldr", "mov")):
        return "jump"
    return ""


def static_count(obj: str | os.PathLike, function: str) -> tuple[int, list[str], list[str]]:
    """(instructions, callees, branches) of a branch-free function: its instruction count (each
    runs once per call), the symbols it calls (one entry per call) and the branches that break the
    property (a conditional branch, or a jump anywhere but over a literal pool: its padding nop and
    data, which do not run). IT-predicated instructions run (and count) whatever their condition."""
    code = disassembly(obj, function)
    callees, broken, skipped = [], [], set()
    for k, ins in enumerate(code):
        kind = _branch_kind(ins)
        if kind == "call":
            callees.append(ins.callee)
        elif kind == "conditional":
            broken.append(f"{ins.address:x}: {ins.mnemonic} {ins.operands}")
        elif kind == "jump":
            target = re.match(r"([0-9a-f]+)", ins.operands)
            over = [i for i in code[k + 1 :] if target and i.address < int(target.group(1), 16)]
            lands = target and any(i.address == int(target.group(1), 16) for i in code)
            if not lands or any(i.mnemonic != "nop" for i in over):
                broken.append(f"{ins.address:x}: {ins.mnemonic} {ins.operands}")
            skipped |= {i.address for i in over}
    return len(code) - len(skipped), callees, broken


def _target(ins: Instruction) -> int | None:
    """The address a branch goes to."""
    m = re.match(r"([0-9a-f]+)", ins.operands)
    return int(m.group(1), 16) if m else None


def loop_count(obj: str | os.PathLike, function: str, trips: int) -> int:
    """The instructions one call of `function` runs when its one loop (the one branch back, taken
    or fallen through at its end: the freestanding NAME_sincos over n >= 1 angles, `trips` = n)
    runs `trips` times: the length of the paths through its code from its entry to its return
    that pass the branch back `trips` times (every conditional branch both ways; they must
    agree). A function with no branch back (an unrolled loop) is straight-line code."""
    code = disassembly(obj, function)
    where = {ins.address: k for k, ins in enumerate(code)}
    branches = {k for k, ins in enumerate(code) if _branch_kind(ins) in ("conditional", "jump")}
    back = [k for k in branches if (_target(code[k]) or 0) <= code[k].address]
    if not back:
        count, _, broken = static_count(obj, function)
        if broken:
            raise RuntimeError(f"{function}: no loop, and branches {broken}")
        return count
    if len(back) != 1:
        raise RuntimeError(f"{function}: {len(back)} branches back, one loop expected")
    lengths, paths = set(), [(0, 0, 0)]  # (instruction, times past the branch back, instructions run)
    while paths:
        k, passed, run = paths.pop()
        while passed <= trips:
            ins, run = code[k], run + 1
            passed += k == back[0]
            kind = _branch_kind(ins)
            if kind == "return":
                if passed == trips:
                    lengths.add(run)
                break
            if k in branches:
                if _target(ins) not in where:
                    raise RuntimeError(f"{function}: a branch out of the function at {ins.address:x}")
                if kind == "conditional":
                    paths.append((k + 1, passed, run))
                k = where[_target(ins)]
                continue
            k += 1
    if len(lengths) != 1:
        raise RuntimeError(f"{function}: {sorted(lengths)} instructions by different paths")
    return lengths.pop()


def timing_source(header: str, calls: dict[str, str], nin: int, prelude: str = "") -> str:
    """main.c that times each call (SysTick under -icount) on in.bin's first state, after 10,000
    nops and an empty window for calibration, and writes the tick counts to ticks.bin."""
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
static unsigned int ticks[256];
__attribute__((noinline)) static void nops(void) {{ __asm__ volatile(".rept 10000\\n\\tnop\\n\\t.endr"); }}
__attribute__((noinline)) static void empty(void) {{ __asm__ volatile(""); }}
{prelude}
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
    folder: Path,
    objects: list[Path],
    header: str,
    calls: dict[str, str],
    x: np.ndarray,
    build: Path,
    cpu: str = "m4f",
    prelude: str = "",
) -> dict[str, int]:
    """call name -> the instructions of one call at the state x, counted under QEMU with -icount
    (SysTick ticks around the call, less the empty window, over the ticks of one instruction from
    a run of 10,000 nops)."""
    build.mkdir(parents=True, exist_ok=True)
    (build / "startup.c").write_text(STARTUP)
    (build / "link.ld").write_text(LINKER_SCRIPT)
    (build / "main.c").write_text(timing_source(header, calls, x.size, prelude))
    elf = build / "timing.elf"
    cmd = [CC, "-std=c99", *CPUS[cpu][1], "-O2", f"-I{folder}", "--specs=rdimon.specs", "-T"]
    _run(
        [
            *cmd,
            str(build / "link.ld"),
            str(build / "startup.c"),
            str(build / "main.c"),
            *map(str, objects),
            "-lm",
            "-o",
            str(elf),
        ]
    )
    with tempfile.TemporaryDirectory(prefix="symdyn-qemu-") as tmp:
        np.asarray(x, dtype=np.float32).tofile(Path(tmp) / "in.bin")
        qemu = [QEMU, "-M", CPUS[cpu][0], "-nographic", "-monitor", "none", "-serial", "none"]
        qemu += ["-icount", f"shift={SHIFT}", "-semihosting-config", "enable=on,target=native"]
        subprocess.run([*qemu, "-kernel", str(elf)], cwd=tmp, check=True, timeout=600, capture_output=True)
        ticks = np.fromfile(Path(tmp) / "ticks.bin", dtype=np.uint32).astype(float)
    per_insn = (ticks[0] - ticks[1]) / 10000.0
    return {f: round((t - ticks[1]) / per_insn) for f, t in zip(calls, ticks[2:], strict=True)}
