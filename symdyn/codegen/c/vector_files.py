"""The batch wrappers of a large robot spread over several files, as its scalar functions are.

symdyn.compile builds, beside the files `generate` writes, the SIMD twin of every function
(symdyn.codegen.c.vector) and its batch wrapper. For MuJoCo Menagerie's humanoids that C is
larger than the scalar C (both widths' output stores, the vector types' names): Unitree G1's was
4.7 MB in one file, 105 s of one core at -O2 -march=native (gcc 12, a busy machine) while the
largest of its three scalar files took 35 s, so the batch file alone set the build's wall time.
Its units, each vector block's parts
then the block with its wrapper (a function without a vector form: its wrapper alone), go into files
as the scalar units do (symdyn.codegen.c.parts.file_units, in files of half the statements):
NAME_batch.c, NAME_batch_2.c, ..., which symdyn.compile builds in parallel. A part in the file of
its block is static; one in another file has the hidden visibility of NAME_SIMD_HIDDEN and is
declared in the internal header NAME_batch_parts.h (templates/c/batch_parts.h.j2). Each lane
still performs the scalar function's operations in the same order: a batch equals the scalar
function bit for bit, whichever file a part lies in.
"""

from __future__ import annotations

from . import parts as layout

__all__ = ["WRAPPER_BYTES", "BATCH_SHARE", "vector_layout", "batch_file_name"]

#: a batch file holds about SPLIT_BYTES / BATCH_SHARE of statements: vector C costs gcc more per
#: byte than scalar C (Menagerie's Talos, with files of about SPLIT_BYTES: its forward dynamics'
#: seven vector parts and block, 2.1 MB in one file, took 48 s of one core, the largest of its
#: scalar files 28 s)
BATCH_SHARE = 2

#: the bytes of C of a batch wrapper (its loops over the states, the block layout's copies)
WRAPPER_BYTES = 2000


def _items_size(items: list) -> int:
    """The bytes of a vector body's items (symdyn.codegen.c.vector_parts) that the compiler sees:
    the stores of one width only (the W = 8 and W = 4 branches hold the same values)."""
    size = 0
    for item in items:
        if item[0] == "let":
            size += len(item[2]) + len(item[3])
        elif item[0] == "store":
            groups = [g for width, entries in item[1].items() if abs(width) != 4 for g in entries]
            size += sum(len(text) for g in groups for text in g[3])
        else:  # a load or a save of the stash
            size += 40
    return size


def vector_layout(views: list[dict | None]) -> list[list[tuple[int, int]]]:
    """The units of each batch file (symdyn.codegen.c.parts.file_units) for the vector views
    `views` of the functions (symdyn.codegen.c.vector.vector_view; None: no vector form): (i, 0)
    is function i's block and wrapper, (i, k) its block's part k."""
    whole, parts = [], []
    for v in views:
        if v is None:
            whole.append(WRAPPER_BYTES)
            parts.append([])
        elif v["parts"]:
            angles = sum(map(len, [*v["angles"], *v["lane_pairs"]]))
            whole.append(WRAPPER_BYTES + angles + 80 * len(v["parts"]["parts"]))
            parts.append([_items_size(p["body"]) for p in v["parts"]["parts"]])
        else:
            whole.append(WRAPPER_BYTES + _items_size(v["body"]))
            parts.append([])
    return layout.file_units(whole, parts, layout.SPLIT_BYTES // BATCH_SHARE)


def batch_file_name(name: str, index: int) -> str:
    """NAME_batch.c for the first file (index 0), NAME_batch_2.c ... for the others."""
    return layout.source_file_name(name, index, "batch")
