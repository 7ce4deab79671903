"""Compile generated C with gcc (or clang) and call it from Python through ctypes.

A small helper shared by the tests of generated C:

    files = symdyn.codegen.render(robot, targets=("c",))
    lib = build_dynamics(files, tmp_dir, robot.name)          # compiles NAME_dynamics.c
    lib.mass_matrix(q, p)                                        # -> (n, n) NumPy array

Compilation uses the C contract's strict flags (`STRICT_FLAGS`, with -Werror; docs/generated-code.md), so
a warning is a failure. `compile_shared` and `compile_program` raise
`CompileError` with the compiler's messages.

Builds are unoptimised by default (`TEST_OPT`, -O0): the tests that use them are about the values
the code computes, which do not depend on the optimisation level (no -ffast-math), and gcc -O2 takes
about ten times longer than -O0 on a large generated file (the Panda's: 8.4 s against 0.7 s).
The warnings only the optimiser finds are checked by tests/test_c_target.py's -O2 strict builds
(test_optimised_strict_build); the sanitizers (SANITIZE_FLAGS) work unoptimised as well.
"""

from __future__ import annotations

import ctypes
import os
import re
import shutil
import subprocess
import types
from collections.abc import Iterable, Mapping, Sequence
from pathlib import Path

import numpy as np

__all__ = [
    "STRICT_FLAGS",
    "SANITIZE_FLAGS",
    "TEST_OPT",
    "CompileError",
    "compilers",
    "write_files",
    "compile_shared",
    "compile_program",
    "header_macros",
    "CDynamics",
    "source_files",
    "build_dynamics",
    "load_c_and_numpy",
]

STRICT_FLAGS = ("-std=c99", "-Wall", "-Wextra", "-Wpedantic", "-Werror")
SANITIZE_FLAGS = (
    "-fsanitize=address,undefined",
    "-fno-sanitize-recover=all",
    "-fno-omit-frame-pointer",
    "-g",
)
#: the optimisation level of the tests' builds (see the module's docstring)
TEST_OPT = "-O0"


class CompileError(RuntimeError):
    """The compiler failed (or warned, under -Werror)."""


def compilers() -> list[str]:
    """The C compilers to test with: gcc, and clang when installed."""
    return [c for c in ("gcc", "clang") if shutil.which(c)]


def write_files(files: Mapping[str, str | bytes], directory: str | os.PathLike) -> list[Path]:
    """Write rendered files (name -> text or bytes) into `directory`; return their paths."""
    out = Path(directory)
    out.mkdir(parents=True, exist_ok=True)
    paths = []
    for name, content in files.items():
        path = out / name
        if isinstance(content, bytes):
            path.write_bytes(content)
        else:
            path.write_text(content, encoding="utf-8")
        paths.append(path)
    return paths


def _run(cmd: Sequence[str]) -> subprocess.CompletedProcess:
    proc = subprocess.run(list(cmd), capture_output=True, text=True)
    if proc.returncode != 0 or "warning" in proc.stderr.lower():
        raise CompileError(f"{' '.join(cmd)}\nexit {proc.returncode}\n{proc.stdout}{proc.stderr}")
    return proc


def compile_shared(
    sources: Iterable[str | os.PathLike],
    output: str | os.PathLike,
    compiler: str = "gcc",
    opt: str = TEST_OPT,
    flags: Sequence[str] = STRICT_FLAGS,
    extra: Sequence[str] = (),
) -> Path:
    """Compile C sources into a shared library (-shared -fPIC, linked with libm)."""
    return compile_program(sources, output, compiler, opt, flags, (*extra, "-shared", "-fPIC"))


def compile_program(
    sources: Iterable[str | os.PathLike],
    output: str | os.PathLike,
    compiler: str = "gcc",
    opt: str = TEST_OPT,
    flags: Sequence[str] = STRICT_FLAGS,
    extra: Sequence[str] = (),
) -> Path:
    """Compile C sources into an executable (linked with libm)."""
    out = Path(output)
    _run([compiler, *flags, opt, *extra, "-o", str(out), *map(str, sources), "-lm"])
    return out


_DEFINE = re.compile(r"^#define\s+([A-Za-z_][A-Za-z0-9_]*)\s+(\S+)\s*$", re.MULTILINE)


def header_macros(text: str) -> dict[str, str]:
    """Object-like macros of a header: name -> replacement text (aliases resolved to values)."""
    raw = dict(_DEFINE.findall(text))
    resolved = {}
    for name, value in raw.items():
        seen = {name}
        while value in raw and value not in seen:
            seen.add(value)
            value = raw[value]
        resolved[name] = value
    return resolved


class CDynamics:
    """The seven functions of a compiled NAME_dynamics.c, called with NumPy arrays.

    Inputs are vectors of length n (p of length nparam, or None for a NULL p);
    matrices come back as (n, n) arrays read row-major.
    """

    SIGNATURES = {
        "inverse_dynamics": ("q", "qd", "qdd", "p"),
        "mass_matrix": ("q", "p"),
        "coriolis_matrix": ("q", "qd", "p"),
        "coriolis": ("q", "qd", "p"),
        "gravity": ("q", "p"),
        "friction": ("qd", "p"),
        "forward_dynamics": ("q", "qd", "tau", "p"),
    }
    MATRICES = ("mass_matrix", "coriolis_matrix")

    def __init__(self, library: str | os.PathLike, name: str, n: int, nparam: int, precision: str = "double"):
        self.path = Path(library)
        self.lib = ctypes.CDLL(str(self.path))
        self.name, self.n, self.nparam = name, n, nparam
        self.dtype = np.float64 if precision == "double" else np.float32
        ctype = ctypes.c_double if precision == "double" else ctypes.c_float
        self._ptr = ctypes.POINTER(ctype)
        self._functions = {}
        for fname, args in self.SIGNATURES.items():
            f = getattr(self.lib, f"{name}_{fname}")
            f.argtypes = [self._ptr] * (len(args) + 1)
            f.restype = None
            self._functions[fname] = f

    def _vector(self, x, size: int, what: str):
        if x is None:
            if size:
                raise ValueError(f"{what} is required ({size} values)")
            return None, None
        a = np.ascontiguousarray(np.asarray(x, dtype=float).ravel(), dtype=self.dtype)
        if a.size != size:
            raise ValueError(f"{what}: expected {size} values, got {a.size}")
        return a, a.ctypes.data_as(self._ptr)

    def call(self, fname: str, *args) -> np.ndarray:
        names = self.SIGNATURES[fname]
        if len(args) == len(names) - 1:
            args = (*args, None)  # p omitted: NULL
        keep, ptrs = [], []
        for what, x in zip(names, args, strict=True):
            a, ptr = self._vector(x, self.nparam if what == "p" else self.n, what)
            keep.append(a)
            ptrs.append(ptr)
        shape = (self.n, self.n) if fname in self.MATRICES else (self.n,)
        out = np.full(shape, np.nan, dtype=self.dtype)
        self._functions[fname](*ptrs, out.ctypes.data_as(self._ptr))
        return out.astype(float)

    def inverse_dynamics(self, q, qd, qdd, p=None):
        return self.call("inverse_dynamics", q, qd, qdd, p)

    def mass_matrix(self, q, p=None):
        return self.call("mass_matrix", q, p)

    def coriolis_matrix(self, q, qd, p=None):
        return self.call("coriolis_matrix", q, qd, p)

    def coriolis(self, q, qd, p=None):
        return self.call("coriolis", q, qd, p)

    def gravity(self, q, p=None):
        return self.call("gravity", q, p)

    def friction(self, qd, p=None):
        return self.call("friction", qd, p)

    def forward_dynamics(self, q, qd, tau, p=None):
        return self.call("forward_dynamics", q, qd, tau, p)


def source_files(files: Mapping[str, str | bytes], directory: str | os.PathLike, name: str) -> list[Path]:
    """The C target's source files among `files`, in `directory`: NAME_dynamics.c, NAME_dynamics_2.c ..."""
    pattern = re.compile(re.escape(name) + r"_dynamics(_[0-9]+)?\.c\Z")
    return [Path(directory) / k for k in sorted(files) if pattern.match(k)]


def build_dynamics(
    files: Mapping[str, str | bytes],
    directory: str | os.PathLike,
    name: str,
    precision: str = "double",
    compiler: str = "gcc",
    opt: str = TEST_OPT,
    extra: Sequence[str] = (),
) -> CDynamics:
    """Write the C target's files, compile NAME_dynamics.c (and a large robot's NAME_dynamics_2.c
    ...: `source_files`) to a shared library and load it (`extra`: more compiler flags, e.g. -mavx2)."""
    out = Path(directory)
    write_files({k: v for k, v in files.items() if k.startswith(f"{name}_dynamics")}, out)
    macros = header_macros((out / f"{name}_dynamics.h").read_text())
    library = out / f"lib{name}_{precision}_{compiler}.so"
    lib = compile_shared(source_files(files, out, name), library, compiler, opt, extra=extra)
    return CDynamics(lib, name, int(macros[f"{name}_NDOF"]), int(macros[f"{name}_NPARAM"]), precision)


def load_c_and_numpy(files: Mapping[str, str | bytes], directory: str | os.PathLike, name: str):
    """(the compiled NAME_dynamics.c as a ctypes.CDLL, the NumPy target's module): every file
    written to `directory`, the C compiled with the strict flags."""
    out = Path(directory)
    write_files(files, out)
    lib = ctypes.CDLL(str(compile_shared(source_files(files, out, name), out / f"lib{name}.so")))
    module = types.ModuleType(f"{name}_numpy")
    exec(
        compile(files[f"{name}_numpy.py"], f"{name}_numpy.py", "exec"), module.__dict__
    )  # symdyn's own output
    return lib, module
