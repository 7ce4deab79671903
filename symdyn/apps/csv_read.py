"""Reading a large CSV of numbers fast: a small C parser (strtod) over the file's bytes, in threads.

numpy.loadtxt parses about 0.6 million values a second here and holds the GIL (a million-sample
log of 29 columns: about 40 s); this parser, compiled once into the symdyn cache (portable flags,
no -march) and called through cffi, which releases the GIL, reads the same file in a few seconds,
the text cut at line boundaries into one part per thread.

It accepts only the plain decimal syntax, [+-]digits[.digits][(e|E)[+-]digits] with spaces or
tabs around it and a '\\r' before the newline, `width` values a line, blank lines skipped; C's
strtod rounds correctly (as numpy and Python do), so every value it gives is the one
numpy.loadtxt gives. Anything else (another syntax, a wrong count, a value strtod would read
differently under another locale) makes `parse_rows` return None and the caller reads the file
the slow way, which names the line and column of the problem. Without a C compiler (or a
writable symdyn cache) it returns None too.
"""

from __future__ import annotations

import os

import numpy as np

from ..errors import SymdynError

__all__ = ["parse_rows", "READER_SOURCE", "PART_BYTES"]

#: The parser: symdyn_parse_rows(text, length, width, out, capacity) -> rows, or -1 on anything
#: outside the plain syntax (module docstring). `text` ends with a NUL (a Python bytes object's).
READER_SOURCE = r"""
#include <stdlib.h>

static int plain(const char *a, const char *b)
{
    if (a == b) return 0;
    for (; a < b; ++a) {
        const char c = *a;
        if (!((c >= '0' && c <= '9') || c == '.' || c == 'e' || c == 'E' || c == '+' || c == '-')) return 0;
    }
    return 1;
}

long symdyn_parse_rows(const char *text, long length, long width, double *out, long capacity);
long symdyn_parse_rows(const char *text, long length, long width, double *out, long capacity)
{
    const char *s = text, *end = text + length;
    long rows = 0, k;
    while (s < end) {
        const char *t = s;
        while (t < end && (*t == ' ' || *t == '\t' || *t == '\r')) ++t;
        if (t == end) break;
        if (*t == '\n') {
            s = t + 1;
            continue;
        }
        if (rows == capacity) return -1;
        for (k = 0; k < width; ++k) {
            char *stop;
            while (t < end && (*t == ' ' || *t == '\t')) ++t;
            if (t == end || *t == ',' || *t == '\n') return -1;
            out[rows * width + k] = strtod(t, &stop);
            if (stop > end || !plain(t, stop)) return -1;
            t = stop;
            while (t < end && (*t == ' ' || *t == '\t' || *t == '\r')) ++t;
            if (k + 1 < width) {
                if (t == end || *t != ',') return -1;
                ++t;
            } else if (t < end && *t != '\n') {
                return -1;
            }
        }
        ++rows;
        s = t < end ? t + 1 : end;
    }
    return rows;
}
"""

#: A part a thread parses has at least this many bytes (a smaller file is one part).
PART_BYTES = 2**20

_LIBRARY: list = []  # [(ffi, lib)] once loaded, [None] without a compiler


def _library():
    """(ffi, lib) of the compiled parser (built into the symdyn cache once), or None without a compiler."""
    if not _LIBRARY:
        from . import cache
        from .build import compile_library, find_compiler, library_suffix

        compiler = find_compiler()
        if compiler is None:
            _LIBRARY.append(None)
            return None
        name = f"libsymdyn_read{library_suffix()}"

        def build(folder):
            compile_library(compiler, {"symdyn_read.c": READER_SOURCE}, folder / name)
            return {"library": name}

        import cffi

        try:  # a cache that cannot be written, a compiler that fails: numpy.loadtxt reads the file
            entry = cache.get_or_build(cache.entry_key(kind="csv-reader", compiler=compiler), build)
            ffi = cffi.FFI()
            ffi.cdef("long symdyn_parse_rows(const char *, long, long, double *, long);")
            _LIBRARY.append((ffi, ffi.dlopen(str(entry.file(name)))))
        except (SymdynError, OSError):
            _LIBRARY.append(None)
    return _LIBRARY[0]


def _parts(text: bytes, start: int, count: int) -> list[tuple[int, int]]:
    """(start, stop) of `count` parts of text[start:], each ending after a newline (the last at the end)."""
    bounds = [start]
    for k in range(1, count):
        cut = text.find(b"\n", max(bounds[-1], start + k * (len(text) - start) // count))
        if cut < 0:
            break
        bounds.append(cut + 1)
    bounds.append(len(text))
    return [(a, b) for a, b in zip(bounds[:-1], bounds[1:], strict=True) if b > a]


def parse_rows(text: bytes, start: int, width: int, threads: int | None = None) -> np.ndarray | None:
    """The values of text[start:] as a (rows, width) float64 array, or None (module docstring).

    `threads`: parts parsed at once (default: the CPUs this process may use, at most 8).
    """
    library = _library()
    if library is None:
        return None
    ffi, lib = library
    if threads is None:
        cpus = os.sched_getaffinity(0) if hasattr(os, "sched_getaffinity") else range(os.cpu_count() or 1)
        threads = min(8, len(cpus))
    pointer = ffi.from_buffer(text)
    parts = _parts(text, start, max(1, min(threads, (len(text) - start) // PART_BYTES)))
    if not parts:
        return np.empty((0, width))
    lines = [text.count(b"\n", a, b) for a, b in parts]  # at least the rows of each part: every part
    lines[-1] += 1  # but the last ends with a newline, the last maybe not
    first = np.cumsum([0, *lines])
    values = np.empty((int(first[-1]), width))  # one array: part k's rows from row first[k] on
    outs = [values[first[k] : first[k + 1]] for k in range(len(parts))]

    def run(k: int) -> int:
        (a, b), out = parts[k], outs[k]
        return lib.symdyn_parse_rows(pointer + a, b - a, width, ffi.from_buffer("double[]", out), len(out))

    if len(parts) > 1:
        from concurrent.futures import ThreadPoolExecutor

        with ThreadPoolExecutor(max_workers=len(parts)) as pool:
            rows = list(pool.map(run, range(len(parts))))
    else:
        rows = [run(k) for k in range(len(parts))]
    if any(r < 0 for r in rows):
        return None
    if all(r == len(out) for r, out in zip(rows[:-1], outs[:-1], strict=True)):  # full: no blank line
        return values[: first[-2] + rows[-1]]
    return np.concatenate([out[:r] for out, r in zip(outs, rows, strict=True)])
