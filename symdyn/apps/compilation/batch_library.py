"""The batch library of a `symdyn.compile` entry, built when a batch call first needs it.

`symdyn.compile` builds the scalar library: the generated C (the files `symdyn generate` writes),
the stepping loop and the CSV writer, everything a one-state call, `cdll`, `pointer` and
`simulate` use. The batch wrappers (NAME_batch.c, NAME_batch_2.c ...: the vector twin of every
function, symdyn.codegen.c.runtime) are about as much compiler work again (Menagerie's G1: 69 of
142 s of one core), and most uses never call a batch. Their sources wait in the robot's entry
(symdyn.apps.compilation.entry); the first batch call (leading axes, `batch_width`, `solve_loops`
on a batch) compiles them, in parallel as the scalar build does and reporting its size and rough
time as a progress stage (symdyn.apps.compilation.build), and links them with the object files the
scalar build kept: the batch library holds the wrappers and its own copy of the scalar functions
(the tail of a batch, count mod W states, goes through them), the same objects, so a batch still
equals the one-state calls bit for bit.

The batch library is a cache entry of its own (symdyn.apps.compilation.cache), keyed by the scalar
entry's key (the robot, symdyn's code, the compiler, its flags and the machine) plus "batch": later
calls and later processes load it from there; two processes building it at once both end with one
entry (the cache's staging folders and rename). In one process a lock per entry makes threads
that call a batch at once for the first time build it once. A failed build raises one SymdynError
line and leaves the scalar library as it was: one-state calls keep working, and the next batch call
tries again.
"""

from __future__ import annotations

import threading

from ...errors import SymdynError
from . import cache

__all__ = ["batch_entry", "batch_key"]

_LOCKS: dict[str, threading.Lock] = {}
_ENTRIES: dict[str, cache.Entry] = {}


def batch_key(entry: cache.Entry) -> str:
    """The batch library's cache key: the scalar entry's, which holds everything its sources and
    flags depend on, plus "batch"."""
    return cache.entry_key(scalar=entry.key, kind="batch")


def batch_entry(entry: cache.Entry) -> cache.Entry:
    """The cache entry of the batch library of the scalar `entry`, built when missing with the
    compiler and flags of the scalar library (its metadata's "batch"); once per process and entry,
    whichever threads ask at once.

    Raises:
        SymdynError: the compiler failed (one line), or the cache cannot be written.
        cache.CorruptEntryError: a file of the scalar entry changed since it was built.
    """
    key = batch_key(entry)
    where = f"{entry.path}:{key}"  # the scalar entry's folder: another cache folder, another entry
    found = _ENTRIES.get(where)
    if found is not None:
        return found
    with _LOCKS.setdefault(where, threading.Lock()):
        found = _ENTRIES.get(where)
        if found is None:
            try:
                found = cache.get_or_build(key, lambda folder: _build(entry, folder))
            except cache.CorruptEntryError:
                raise
            except SymdynError as exc:
                name, robot = entry.meta["batch"]["library"], entry.meta["robot"]["name"]
                raise SymdynError(
                    f"symdyn.compile: the batch library {name} of robot '{robot}' was not built "
                    f"(one-state calls still work): {exc}"
                ) from None
            _ENTRIES[where] = found
    return found


def _build(entry: cache.Entry, folder) -> dict:
    """Compile the batch sources of `entry` and link them with its scalar objects into `folder`."""
    from .build import compile_library

    batch = entry.meta["batch"]
    headers = [name for name in entry.digests if name.endswith(".h") and name not in batch["sources"]]
    sources = {name: entry.file(name).read_text(encoding="utf-8") for name in [*headers, *batch["sources"]]}
    objects = [entry.file(name) for name in batch["objects"]]
    compile_library(
        batch["compiler"], sources, folder / batch["library"], batch["arch"], objects, opt=batch["opt"]
    )
    return {"library": batch["library"], "scalar": entry.key}
