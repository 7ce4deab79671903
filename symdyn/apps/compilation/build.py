"""Compiling generated C into a shared library with the system's C compiler (symdyn.compile).

The compiler is $CC when set (it may carry flags: "clang -m64"), else the first of
cc, gcc and clang on PATH. The flags are COMPILE_FLAGS: optimised (-O2) but with the
floating-point semantics of the source kept (no -ffast-math, and no contraction of
a*b + c into one fused multiply-add, so results are the ones of the NumPy module's
operation order), position-independent code, linked against libm; then `arch_flags()`: the
library is built for the machine it runs on (-march=native: AVX2 or AVX-512 where the CPU has
them, which the batch wrappers use, templates/c/batch.c.j2), unless $SYMDYN_MARCH names another
target: SYMDYN_MARCH=x86-64-v3 (any AVX2 machine), SYMDYN_MARCH=x86-64 (every x86-64), or
SYMDYN_MARCH=none (no -march: the compiler's default) for a library that runs on other machines.
$SYMDYN_OPT sets the optimisation level in place of -O2 (`opt_flag()`: 0, 1, 2, 3, s or g):
SYMDYN_OPT=0 builds a large robot's library several times faster (the PUMA 560's C: 0.3 s of one
core against 1.9 s at -O2) and gives the same values (no -ffast-math, no contraction at any level),
for code that calls it a few times; the test suite builds its libraries so.
A compiler that refuses -march=native (some compilers for ARM) builds without it.
A build reports its size and a rough time (`compile_estimate`) as a progress stage
(symdyn.progress).
The cache key holds the flags, and with -march=native the machine (`machine_fingerprint`), so a
cache shared by several machines never loads a library built for another CPU.
"""

from __future__ import annotations

import os
import re
import shlex
import shutil
from collections.abc import Mapping, Sequence
from functools import lru_cache
from pathlib import Path

from ...errors import SymdynError
from ...progress import stage as progress_stage

__all__ = [
    "COMPILE_FLAGS",
    "BUILD_PREFIX",
    "ARCH_ENV",
    "arch_flags",
    "OPT_ENV",
    "opt_flag",
    "compile_flags",
    "machine_fingerprint",
    "find_compiler",
    "compile_estimate",
    "compile_library",
    "library_suffix",
]

#: The start of the name of the temporary folder the compiler runs in ($TMPDIR/symdyn-build-PID-XXXXXXXX).
BUILD_PREFIX = "symdyn-build-"

COMPILE_FLAGS = ("-std=c99", "-O2", "-fPIC", "-ffp-contract=off", "-shared")

#: The environment variable naming the -march target of symdyn.compile's libraries (default native).
ARCH_ENV = "SYMDYN_MARCH"
_ARCH = re.compile(r"[A-Za-z0-9][A-Za-z0-9_.+-]*\Z")


def arch_flags() -> tuple[str, ...]:
    """("-march=native",), or the target $SYMDYN_MARCH names ("-march=x86-64-v3"); () for "none"."""
    value = os.environ.get(ARCH_ENV, "").strip() or "native"
    if value == "none":
        return ()
    if not _ARCH.match(value):
        raise SymdynError(f"${ARCH_ENV}={value!r} is not a -march target (e.g. native, x86-64-v3, none)")
    return (f"-march={value}",)


#: The environment variable naming the optimisation level of symdyn.compile's libraries (default 2).
OPT_ENV = "SYMDYN_OPT"
#: the levels $SYMDYN_OPT may name (gcc's and clang's -O0 ... -Og)
OPT_LEVELS = ("0", "1", "2", "3", "s", "g")


def opt_flag() -> str:
    """ "-O2", or the level $SYMDYN_OPT names ("-O0" for SYMDYN_OPT=0)."""
    value = os.environ.get(OPT_ENV, "").strip() or "2"
    if value not in OPT_LEVELS:
        levels = ", ".join(OPT_LEVELS)
        raise SymdynError(f"${OPT_ENV}={value!r} is not an optimisation level (one of {levels})")
    return f"-O{value}"


def compile_flags(opt: str = "-O2") -> tuple[str, ...]:
    """COMPILE_FLAGS with the optimisation flag `opt` (opt_flag()) in place of -O2."""
    return tuple(opt if flag == "-O2" else flag for flag in COMPILE_FLAGS)


@lru_cache(maxsize=1)
def machine_fingerprint() -> str:
    """SHA-256 of what -march=native depends on: the architecture, the CPU's model and its feature flags
    (/proc/cpuinfo on Linux, else the platform's processor string)."""
    import hashlib
    import platform

    text = f"{platform.machine()} {platform.processor()}"
    try:
        with open("/proc/cpuinfo", encoding="utf-8", errors="replace") as f:
            keep = ("model name", "flags", "Features", "CPU implementer", "CPU part", "vendor_id")
            lines = sorted({line.strip() for line in f if line.startswith(keep)})
        text += "\n" + "\n".join(lines)
    except OSError:
        pass
    return hashlib.sha256(text.encode()).hexdigest()


def find_compiler() -> list[str] | None:
    """The C compiler command ($CC, else cc, gcc or clang on PATH), or None when there is none."""
    env = os.environ.get("CC", "").strip()
    if env:
        words = shlex.split(env)
        return words if shutil.which(words[0]) else None
    for name in ("cc", "gcc", "clang"):
        path = shutil.which(name)
        if path:
            return [path]
    return None


def library_suffix() -> str:
    """.so, .dylib or .dll: what the platform's dynamic loader opens."""
    import sys

    return {"darwin": ".dylib", "win32": ".dll"}.get(sys.platform, ".so")


#: seconds of one core per byte of generated C at -O2 (gcc 12, x86-64): the PUMA 560's 308 KB
#: file 7.3e-6, the Panda's 729 KB 9.7e-6, Solo-12's floating 435 KB (larger functions) 2.7e-5
SECONDS_PER_BYTE = (7e-6, 3e-5)


def compile_estimate(size: int) -> str:
    """How long `size` bytes of generated C take to compile at -O2, roughly: 'roughly 3-13 s of one
    core' (gcc's time grows faster than the size of one function, hence the range)."""
    low, high = (max(1, round(size * rate)) for rate in SECONDS_PER_BYTE)
    return f"roughly {low}-{high} s of one core at -O2"


def compile_library(
    compiler: list[str],
    sources: Mapping[str, str],
    target: str | os.PathLike,
    arch: Sequence[str] = (),
    objects: Sequence[str | os.PathLike] = (),
    keep: Sequence[str] = (),
    opt: str = "-O2",
) -> Path:
    """Compile the C `sources` (file name -> text; headers included) into the library `target`,
    with COMPILE_FLAGS at the optimisation level `opt` (opt_flag()) and `arch` (arch_flags());
    without -march=native when the compiler refuses it.
    Each .c file compiles in a process of its own, all at once (the large generated files dominate),
    then they are linked, with the object files `objects` (compiled before, with the same flags),
    in $TMPDIR/symdyn-build-PID-XXXXXXXX; the folders that builds killed mid-way left there are
    removed first, once stale (symdyn.leftovers). The objects of the .c files named in `keep` are
    copied beside `target` (NAME.c gives NAME.o), for a later build to link (the batch library,
    symdyn.apps.compilation.batch_library).

    Raises SymdynError with the compiler's messages when it fails.
    """
    import tempfile

    from ...leftovers import sweep_folders

    sweep_folders(Path(tempfile.gettempdir()), BUILD_PREFIX)  # the folders of builds killed mid-way
    size = sum(len(text.encode()) for name, text in sources.items() if name.endswith(".c"))
    count = sum(name.endswith(".c") for name in sources)
    label = f"compiling {Path(target).name}: {size / 1000:.0f} KB of C in {count} files"
    label += f", {min(count, os.cpu_count() or 1)} at once" if count > 1 else ""
    label += f" ({compile_estimate(size)})"
    with (
        progress_stage(label),
        tempfile.TemporaryDirectory(prefix=f"{BUILD_PREFIX}{os.getpid()}-") as tmp,
    ):
        for name, text in sources.items():
            Path(tmp, name).write_text(text, encoding="utf-8")
        c_files = sorted(name for name in sources if name.endswith(".c"))
        try:
            failed = _compile_objects(compiler, c_files, arch, tmp, opt)
            if failed and tuple(arch) == ("-march=native",) and "march" in failed[1]:
                arch = ()
                failed = _compile_objects(compiler, c_files, arch, tmp, opt)
            if not failed:
                compiled = [name[:-2] + ".o" for name in c_files]
                given = [os.fspath(o) for o in objects]
                flags = [*compile_flags(opt), *arch]
                link = [*compiler, *flags, "-o", os.fspath(target), *compiled, *given, "-lm"]
                failed = _run(link, tmp)
        except OSError as exc:
            raise SymdynError(f"cannot run the C compiler {compiler[0]}: {exc}") from exc
        if failed:
            raise SymdynError(_failure(failed, count))
        for name in keep:
            shutil.copyfile(Path(tmp, name[:-2] + ".o"), Path(target).parent / (name[:-2] + ".o"))
    return Path(target)


def _compile_objects(compiler: list[str], c_files: list[str], arch: Sequence[str], folder: str, opt: str):
    """Compile every file of `c_files` to its .o, at most os.cpu_count() at once, the largest first
    (the large generated files dominate; a large robot's C is in several, symdyn.codegen.c.parts);
    (command, messages) of the first that failed, or None. After a failure no further file starts."""
    import subprocess  # here, not at the top: a cached run (find_compiler only) does not need it

    flags = [f for f in compile_flags(opt) if f != "-shared"]
    order = sorted(c_files, key=lambda name: (-Path(folder, name).stat().st_size, name))
    waiting = [[*compiler, *flags, *arch, "-c", name, "-o", name[:-2] + ".o"] for name in order]
    running: list = []
    failed = None
    while waiting or running:
        while waiting and len(running) < (os.cpu_count() or 1) and failed is None:
            cmd = waiting.pop(0)
            running.append(
                (
                    cmd,
                    subprocess.Popen(
                        cmd, cwd=folder, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True
                    ),
                )
            )
        if failed is not None and not running:
            break
        cmd, proc = running.pop(0)
        errors = proc.communicate()[1]
        if proc.returncode and failed is None:
            failed = (cmd, errors)
    return failed


def _failure(failed: tuple[list[str], str], count: int) -> str:
    """One line for a failed build: the command, its first error message and how many lines follow."""
    cmd, messages = failed
    lines = [line.strip() for line in messages.strip().splitlines() if line.strip()]
    first = next((line for line in lines if "error" in line), lines[0] if lines else "no message")
    more = f" (and {len(lines) - 1} more lines)" if len(lines) > 1 else ""
    where = f"{cmd[cmd.index('-c') + 1]}, one of {count} files; " if "-c" in cmd and count > 1 else ""
    return f"the C compiler failed ({where}{shlex.join(cmd)}): {first}{more}"


def _run(cmd: list[str], folder: str):
    """(command, messages) when `cmd` fails in `folder`, else None."""
    import subprocess

    proc = subprocess.run(cmd, cwd=folder, capture_output=True, text=True)
    return (cmd, proc.stderr) if proc.returncode != 0 else None
