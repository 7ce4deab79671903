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

Builds are cached by content when the environment variable CBUILD_CACHE names a folder (the suite
sets it: tests/conftest.py, one folder shared by the pytest-xdist workers): the key is a SHA-256 of
the compiler's path and version, the command's flags, each source's name and bytes, and the name
and bytes of every .c and .h file beside a source or in a folder named by -I (the files a source
can include); a folder path in the command counts by those files, not by its name. A build that
succeeded is copied from the cache instead of being compiled again, by another test file or the
other worker (the same C compiled with the same flags: a build that warned or failed is never
stored, so it fails again each time). A build that writes more than its output (-S, -E, -M...,
-save-temps, -fstack-usage, -fdump-...) is never cached.
"""

from __future__ import annotations

import ctypes
import hashlib
import os
import re
import shutil
import subprocess
import threading
import types
from collections.abc import Iterable, Mapping, Sequence
from functools import cache
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
    """Compile C sources into an executable (linked with libm); from the build cache when the same
    build has succeeded before (the module's docstring)."""
    out = Path(output)
    sources = [Path(s) for s in sources]
    options = [*flags, opt, *extra]
    key = _build_key(compiler, options, sources)
    cached = None if key is None else Path(os.environ[CACHE_ENV]) / key
    if cached is not None and cached.is_file():
        partial = out.with_name(f".{out.name}.{_writer()}.part")
        shutil.copy2(cached, partial)
        os.replace(partial, out)  # a new file: a library loaded from `out` before keeps its own
        return out
    _run([compiler, *options, "-o", str(out), *map(str, sources), "-lm"])
    if cached is not None:
        cached.parent.mkdir(parents=True, exist_ok=True)
        partial = cached.with_name(f"{key}.{_writer()}.part")
        shutil.copy2(out, partial)
        os.replace(partial, cached)  # atomic: the other worker reads a whole file or none
    return out


#: the environment variable naming the build cache's folder (unset: no cache)
CACHE_ENV = "CBUILD_CACHE"
#: flags whose build writes files besides its output, or no output: never cached
_UNCACHED = ("-S", "-E", "-M", "-save-temps", "-fstack-usage", "-fdump-", "-fcallgraph-info")


def _writer() -> str:
    """This process and thread: the name of a partial file no other writer uses (test files
    compile in threads: tests/test_c_target.py)."""
    return f"{os.getpid()}.{threading.get_ident()}"


@cache
def _compiler_identity(compiler: str) -> str:
    """The compiler's resolved path and its --version text."""
    path = shutil.which(compiler) or compiler
    version = subprocess.run([path, "--version"], capture_output=True, text=True).stdout
    return f"{os.path.realpath(path)}\n{version}"


def _build_key(compiler: str, options: Sequence[str], sources: Sequence[Path]) -> str | None:
    """The build's cache key (the module's docstring), or None when it is not cached."""
    if not os.environ.get(CACHE_ENV) or any(o == "-I" or o.startswith(_UNCACHED) for o in options):
        return None
    key = hashlib.sha256(_compiler_identity(compiler).encode())
    folders = [Path(o[2:]) for o in options if o.startswith("-I")]
    for option in options:
        key.update(("-I" if option.startswith("-I") else option).encode() + b"\0")
    for source in sources:
        key.update(b"source\0" + source.name.encode() + b"\0" + source.read_bytes() + b"\0")
    # each file by the rank of its folder among the sources' and the -I folders, and its name and
    # content: the same files in another test's folder are the same build
    places = list(dict.fromkeys([*(s.parent for s in sources), *folders]))
    files = [
        (str(places.index(p.parent)) if p.parent in places else str(p.parent), p.name, p)
        for p in _included(sources, folders)
    ]
    for where, name, path in sorted(files):
        key.update(f"{where}\0{name}\0".encode() + hashlib.sha256(path.read_bytes()).digest())
    return key.hexdigest()


_INCLUDE = re.compile(rb'^[ \t]*#[ \t]*include[ \t]*"([^"]+)"', re.MULTILINE)


def _included(sources: Sequence[Path], folders: Sequence[Path]) -> set[Path]:
    """Every .c and .h file beside a source or in `folders` (the -I folders), and every file a
    source includes with #include "..." (looked up as the compiler does: beside the including
    file, then in `folders`; followed through the files it reaches)."""
    found = {p for f in (*folders, *(s.parent for s in sources)) for p in f.glob("*.[ch]")}
    todo = [*sources, *sorted(found)]
    seen = set(todo)
    while todo:
        including = todo.pop()
        for name in _INCLUDE.findall(including.read_bytes()):
            for folder in (including.parent, *folders):
                candidate = folder / os.fsdecode(name)  # an absolute name stays itself
                if candidate.is_file():
                    if candidate not in seen:
                        seen.add(candidate)
                        found.add(candidate)
                        todo.append(candidate)
                    break
    return found


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
