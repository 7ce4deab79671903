"""Compiling generated C into a shared library with the system's C compiler (symdyn.compile).

The compiler is $CC when set (it may carry flags: "clang -m64"), else the first of
cc, gcc and clang on PATH. The flags are COMPILE_FLAGS: optimised (-O2) but with the
floating-point semantics of the source kept (no -ffast-math, and no contraction of
a*b + c into one fused multiply-add, so results are the ones of the NumPy module's
operation order), position-independent code, linked against libm.
"""

from __future__ import annotations

import os
import shlex
import shutil
from collections.abc import Mapping
from pathlib import Path

from ..errors import SymdynError

__all__ = ["COMPILE_FLAGS", "find_compiler", "compile_library", "library_suffix"]

COMPILE_FLAGS = ("-std=c99", "-O2", "-fPIC", "-ffp-contract=off", "-shared")


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


def compile_library(compiler: list[str], sources: Mapping[str, str], target: str | os.PathLike) -> Path:
    """Compile the C `sources` (file name -> text; headers included) into the library `target`.

    Raises SymdynError with the compiler's messages when it fails.
    """
    import subprocess  # here, not at the top: a cached run (find_compiler only) does not need it
    import tempfile

    with tempfile.TemporaryDirectory(prefix="symdyn-build-") as tmp:
        for name, text in sources.items():
            Path(tmp, name).write_text(text, encoding="utf-8")
        c_files = sorted(name for name in sources if name.endswith(".c"))
        cmd = [*compiler, *COMPILE_FLAGS, "-o", os.fspath(target), *c_files, "-lm"]
        try:
            proc = subprocess.run(cmd, cwd=tmp, capture_output=True, text=True)
        except OSError as exc:
            raise SymdynError(f"cannot run the C compiler {compiler[0]}: {exc}") from exc
        if proc.returncode != 0:
            raise SymdynError(f"the C compiler failed ({shlex.join(cmd)}):\n{proc.stderr.strip()}")
    return Path(target)
