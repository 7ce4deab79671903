"""The machine a benchmark runs on: compilers and flags, commands, CPU pinning, and how it is described.

Shared by bench/run.py (and its modules), bench/derive.py and bench/plot.py. Nothing here
prints an absolute path: a report names files relative to the project, or as a package
plus the path inside it (`package_path`).
"""

from __future__ import annotations

import hashlib
import os
import platform
import subprocess
import sys
from pathlib import Path

BENCH = Path(__file__).resolve().parent
ROOT = BENCH.parent
RESULTS = BENCH / "results"

C_COMPILER = "gcc"
CXX_COMPILER = "g++"
FLAGS = ("-O3", "-march=native")  # the same for symdyn's C, the CasADi route's C and the harness
CXX_EXTRA = ("-std=c++17", "-DNDEBUG")  # Pinocchio: a release build (Eigen assertions off)

__all__ = [
    "BENCH",
    "ROOT",
    "RESULTS",
    "C_COMPILER",
    "CXX_COMPILER",
    "FLAGS",
    "CXX_EXTRA",
    "log",
    "run",
    "pin_to_one_core",
    "machine",
    "compiler_version",
    "load_averages",
    "source_digest",
    "project_path",
]


def log(msg: str) -> None:
    """One progress line on stderr."""
    print(msg, file=sys.stderr, flush=True)


def run(cmd, **kw) -> subprocess.CompletedProcess:
    """Run `cmd` (any path-like items allowed); raise RuntimeError with its output if it fails."""
    proc = subprocess.run([str(c) for c in cmd], capture_output=True, text=True, **kw)
    if proc.returncode != 0:
        raise RuntimeError(f"{' '.join(map(str, cmd))}\nexit {proc.returncode}\n{proc.stdout}\n{proc.stderr}")
    return proc


def pin_to_one_core() -> str:
    """Pin this process (and so every child) to one CPU; returns a description."""
    if not hasattr(os, "sched_setaffinity"):
        return "not pinned (no os.sched_setaffinity)"
    cpus = sorted(os.sched_getaffinity(0))
    cpu = cpus[-1]
    try:
        os.sched_setaffinity(0, {cpu})
    except OSError as exc:
        return f"not pinned ({exc})"
    return f"pinned to CPU {cpu} of {len(cpus)}"


def machine() -> str:
    """CPU model, CPU count and operating system, in one line."""
    model = platform.processor() or platform.machine()
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                model = line.split(":", 1)[1].strip()
                break
    except OSError:
        pass
    return f"{model}, {os.cpu_count()} CPUs, {platform.system()} {platform.release()}"


def compiler_version(cc: str) -> str:
    """The first line of `cc --version`."""
    try:
        return run([cc, "--version"]).stdout.splitlines()[0]
    except (RuntimeError, OSError):
        return f"{cc}: not found"


def load_averages() -> tuple[float, float, float]:
    """The 1-, 5- and 15-minute load averages (NaN where the system has none)."""
    try:
        return os.getloadavg()
    except (AttributeError, OSError):
        return (float("nan"),) * 3


def source_digest() -> str:
    """A short hash of the imported symdyn's source and templates (to notice edits during a run)."""
    import symdyn

    h = hashlib.sha256()
    pkg = Path(symdyn.__file__).resolve().parent
    for base in (pkg, ROOT / "templates"):
        for f in sorted(base.rglob("*")):
            if f.is_file() and f.suffix in (".py", ".j2"):
                h.update(str(f.relative_to(base)).encode() + f.read_bytes())
    return h.hexdigest()[:12]


def project_path(path: Path) -> str:
    """`path` relative to the project, or `package: path inside it`, or its bare name: never absolute."""
    path = Path(path).resolve()
    if path.is_relative_to(ROOT):
        return str(path.relative_to(ROOT))
    from importlib.metadata import PackageNotFoundError, distribution

    for package in ("example-robot-data", "pin", "cmeel-eigen"):
        try:
            base = Path(str(distribution(package).locate_file("cmeel.prefix"))).resolve()
        except PackageNotFoundError:
            continue
        if path.is_relative_to(base):
            inside = path.relative_to(base)
            share = Path("share") / package
            if inside.is_relative_to(share):  # cmeel.prefix/share/PACKAGE/robots/... -> robots/...
                return f"{package}: {inside.relative_to(share)}"
            return f"{package}: cmeel.prefix/{inside}"
    return path.name
