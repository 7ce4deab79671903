"""The C target's layout: large function bodies cut into parts, large outputs into several files.

This module alone decides how the generated C is laid out for the compiler; symdyn.codegen.c.target
builds every function's statements, templates/c/*.j2 spell them.

Parts. gcc's time on straight-line code grows faster than the code: most of a -O2 build of a large
function goes to register allocation (LRA's hard register assignment, half of the time of the
Panda's 143 KB forward-dynamics derivatives, two thirds of Talos' floating forward dynamics), which
looks at every value live at once. What it costs follows the function's live span, the sum over its
statements of the temporaries alive there (computed before, read at or after it), more than its
length: with gcc 12 at -O2, Talos' floating `forward_dynamics` (5957 statements, a span of 2.4
million) compiles in 7.5 s of one core, its `coriolis_matrix` (10,909 statements, 35 million) in 317
s. A function of more than PART_ABOVE statements whose live span is above LIVE_ABOVE is cut into
parts of about PART_STATEMENTS consecutive statements
(as many parts as needed, each cut within a quarter of a part of the even cut where the fewest
temporaries are alive); part k is a static function NAME_FUNCTION_partk with the
function's own arguments, called in order by the function, never inlined (NAME_NOINLINE), without
gcc's SLP vectorizer (templates/c/parts.c.j2 says why). A temporary read by a later part than the
one that computes it goes through the function's local array `stash`, passed restrict-qualified:
stored right after it is computed, loaded where each part that reads it first reads it;
a slot is reused after the last part that reads its value (a greedy colouring of the intervals
[defining part, last reading part]). Each part reads the inputs it needs from the input
arrays itself. Measured with gcc 12 at -O2 -march=x86-64-v3 (callgrind, instructions per call), Talos'
floating coriolis_matrix in 8 parts runs 127,850 instructions against 132,969 whole (-3.8%) and its
file compiles in 38 s of one core instead of 317 s; without restrict the parts ran 139,741 (+5.1%),
with gcc's SLP vectorizer as well 150,784 (+13.4%).

Files. `file_units` puts the functions and parts into the source files (`file_groups` on their
sizes): one NAME_dynamics.c while the whole C is below SPLIT_BYTES, else consecutive units in files
of about SPLIT_BYTES each (NAME_dynamics.c, NAME_dynamics_2.c, ...), which a build compiles in
parallel. A function's parts may lie in several files, so that no file holds much more than
SPLIT_BYTES: Menagerie's Talos has a coriolis_matrix of 3.2 MB in 12 parts, 72 s of one core at -O2
in one file. A part in the file of its function is static; one in another file has the hidden
visibility of NAME_HIDDEN and is declared in the internal header NAME_dynamics_parts.h
(templates/c/parts.h.j2), which the files defining or calling it include. Run time (callgrind, gcc
12 -O2): Talos' coriolis_matrix with 11 of its 12 parts in other files runs 228,121 instructions
against 227,790 with all of them static beside it (+0.15%, docs/speed.md#compile-time); its file,
3.2 MB, took 78 s of one core, the largest of the three files now 39 s.
"""

from __future__ import annotations

import re
from collections.abc import Container
from math import ceil

__all__ = [
    "PART_ABOVE",
    "LIVE_ABOVE",
    "PART_STATEMENTS",
    "SPLIT_BYTES",
    "split_body",
    "reads_in",
    "file_groups",
    "file_units",
    "layout",
    "part_counts",
    "placement",
    "source_file_name",
]

#: a function with more statements (temporaries and output stores) than this ...
PART_ABOVE = 4000
#: ... and a live span (the sum over its statements of the temporaries alive) above this is cut into
#: parts: below it gcc builds the function whole in seconds (Talos' floating forward dynamics, 2.4
#: million: 7.5 s), and a part costs run time (its values that a later part reads are stored and
#: loaded again: +8.6% instructions on that function in 4 parts)
LIVE_ABOVE = 5_000_000
#: ... of about this many statements each
PART_STATEMENTS = 1500

#: C text of about this many bytes per source file, when the whole is larger
SPLIT_BYTES = 1_000_000

_IDENTIFIER = re.compile(r"\b[A-Za-z_]\w*")


def _names_read(text: str, known: Container[str]) -> set[str]:
    """The identifiers of `known` (a set or a dict's keys) that the printed C expression `text`
    reads; `known` is looked up, never copied, so that a loop over a large body stays linear."""
    return {word for word in _IDENTIFIER.findall(text) if word in known}


def split_body(
    body: list, reads: list, c_name: str, arguments: list[str], count: int | None = None
) -> dict | None:
    """{"parts", "slots": the size of the array `stash`} of a function whose `body` (("let", name,
    value) and ("store", target, value) in order, symdyn.codegen.c.target) has more than
    PART_STATEMENTS statements; None when it has not. `count`, when given, is the number of parts
    to cut (below 2: None, the function stays whole) instead of the rule's: `--precision both`
    cuts the float function as the double one, so that both put the same parts in the same files.

    `reads` are the function's (local, input, index): each input value it copies into a local;
    `arguments` the names of its inputs and outputs, which each part takes too.
    Each part is {"name", "reads" (the reads it needs), "loads" ((name, slot): the temporaries of
    earlier parts it reads), "body" (its statements, ("load", name, slot) before the first that
    reads a temporary of an earlier part, ("save", slot, name) after a temporary a later part
    reads), "unused" (the arguments it neither reads nor writes, and the stash's name "" when it
    neither loads nor saves)}.
    """
    if count is None:
        if len(body) <= max(PART_ABOVE, PART_STATEMENTS):
            return None
        alive = _alive(body)
        if sum(alive) <= LIVE_ABOVE:
            return None
        count = ceil(len(body) / PART_STATEMENTS)
    elif count < 2 or len(body) < count:
        return None
    else:
        alive = _alive(body)
    chunks = [body[a:b] for a, b in _cuts(body, alive, count)]
    defined_in = {s[1]: c for c, chunk in enumerate(chunks) for s in chunk if s[0] == "let"}
    inputs = {local for local, _, _ in reads}
    known = set(defined_in) | inputs
    used = [set().union(*(_names_read(s[2], known) for s in chunk)) for chunk in chunks]
    # the temporaries each part loads from an earlier one, and the last part that loads each
    loads = [
        sorted((n for n in names if n in defined_in and defined_in[n] < c), key=_number)
        for c, names in enumerate(used)
    ]
    last = {n: c for c, names in enumerate(loads) for n in names}
    argument_set = set(arguments)
    slot_of: dict[str, int] = {}
    free: list[int] = []
    slots = 0
    parts = []
    for c, chunk in enumerate(chunks):
        statements = []
        part_loads = [(n, slot_of[n]) for n in loads[c]]
        pending = dict(part_loads)
        for s in chunk:
            # each temporary of an earlier part loaded right before its first use: a load at the
            # part's start could not move past the stores to the outputs (they may alias the
            # stash), and the value would stay alive, in a register or spilled, through the part
            for n in sorted(_names_read(s[2], pending), key=_number):
                statements.append(("load", n, str(pending.pop(n))))
            statements.append(s)
            if s[0] == "let" and s[1] in last:
                slot = free.pop() if free else slots
                slots = max(slots, slot + 1)
                slot_of[s[1]] = slot
                statements.append(("save", str(slot), s[1]))
        # a slot is free again after the last part that reads its value (it loads it where it first reads it)
        free.extend(slot for n, slot in part_loads if last[n] == c)
        free.sort(reverse=True)
        part_reads = [r for r in reads if r[0] in used[c]]
        touched = {r[1] for r in part_reads}
        touched |= set().union(*(_names_read(s[1], argument_set) for s in chunk if s[0] == "store"))
        stashed = bool(part_loads) or any(s[0] == "save" for s in statements)
        parts.append(
            {
                "name": f"{c_name}_part{c + 1}",
                "reads": part_reads,
                "loads": part_loads,
                "body": statements,
                "unused": [a for a in arguments if a not in touched] + ([] if stashed else [""]),
            }
        )
    return {"parts": parts, "slots": slots}


def _alive(body: list) -> list[int]:
    """alive[i]: the temporaries alive across a cut before statement i of `body` (defined before i,
    read at i or later), for i from 0 to len(body)."""
    n = len(body)
    defined = {s[1]: k for k, s in enumerate(body) if s[0] == "let"}
    last: dict[str, int] = {}
    for k, s in enumerate(body):
        for name in _names_read(s[2], defined):
            last[name] = k
    change = [0] * (n + 2)
    for name, k in defined.items():
        if name in last:
            change[k + 1] += 1
            change[last[name] + 1] -= 1
    alive, running = [], 0
    for i in range(n + 1):
        running += change[i]
        alive.append(running)
    return alive


def _cuts(body: list, alive: list[int], count: int) -> list[tuple[int, int]]:
    """The `count` parts' [start, end) in `body`, each cut placed, within a quarter of a part's
    length of the even cut, where the fewest temporaries are alive (`alive`, `_alive`): every such
    value costs a store and a load per later part reading it."""
    n = len(body)
    size = n / count
    cuts, start = [], 0
    for part in range(1, count):
        even = round(part * size)
        window = range(max(start + 1, even - int(size) // 4), min(n, even + int(size) // 4) + 1)
        cut = min(window, key=lambda i: (alive[i], abs(i - even), i))
        cuts.append((start, cut))
        start = cut
    return [*cuts, (start, n)]


def reads_in(texts: list[str], reads: list) -> list:
    """The (local, input, index) of `reads` whose local the printed C expressions `texts` read."""
    known = {local for local, _, _ in reads}
    used = set().union(*(_names_read(text, known) for text in texts))
    return [r for r in reads if r[0] in used]


def _number(name: str) -> tuple[int, str]:
    """Temporaries x12 in their numeric order."""
    digits = name[1:]
    return (int(digits), name) if digits.isdigit() else (0, name)


def file_groups(sizes: list[int], split: int | None = None) -> list[list[int]]:
    """The functions of each source file, as indices into `sizes` (each function's bytes of C):
    all in one file while the sum is at most `split` (default SPLIT_BYTES), else consecutive
    functions in about sum / `split` files of balanced size."""
    split = SPLIT_BYTES if split is None else split
    total = sum(sizes)
    if total <= split or len(sizes) < 2:
        return [list(range(len(sizes)))]
    count = min(len(sizes), ceil(total / split))
    groups: list[list[int]] = [[]]
    done = 0
    for k, size in enumerate(sizes):
        # a new file when this function's middle lies past the current file's share of the whole
        if groups[-1] and len(groups) < count and done + size / 2 > total * len(groups) / count:
            groups.append([])
        groups[-1].append(k)
        done += size
    return groups


def file_units(
    whole: list[int], parts: list[list[int]], split: int | None = None
) -> list[list[tuple[int, int]]]:
    """The units of each source file: (i, 0) is function i itself (its body, or the calls of its
    parts), (i, k) its part k. `whole[i]` is the bytes of function i's own code, `parts[i]` those
    of each of its parts (empty: the function is whole). The units, each function's parts then the
    function, are grouped by `file_groups` on their sizes: a function's parts may lie in several
    files, the function in the file of its last part; `split`: file_groups'."""
    units = [(i, k) for i, sizes in enumerate(parts) for k in [*range(1, len(sizes) + 1), 0]]
    sizes = [whole[i] if k == 0 else parts[i][k - 1] for i, k in units]
    return [[units[j] for j in group] for group in file_groups(sizes, split)]


def _size(statements: list) -> int:
    """The bytes of a function's or a part's statements (their names and printed values)."""
    return sum(len(s[1]) + len(s[2]) for s in statements)


def layout(functions: list[dict]) -> list[list[tuple[int, int]]]:
    """The units of each source file (`file_units`) of the function views `functions`
    (symdyn.codegen.c.target): a function in parts counts the angles it prints and a line per call
    of a part."""
    whole = [
        _size(f["body"])
        if not f["parts"]
        else sum(map(len, f["sincos"]["angles"] if f["sincos"] else [])) + 80 * len(f["parts"]["parts"])
        for f in functions
    ]
    sizes = [[_size(p["body"]) for p in f["parts"]["parts"]] if f["parts"] else [] for f in functions]
    return file_units(whole, sizes)


def part_counts(groups: list[list[tuple[int, int]]], count: int) -> list[int]:
    """The number of parts of each of `count` functions in the files' units `groups` (0: whole)."""
    counts = [0] * count
    for group in groups:
        for i, n in group:
            counts[i] = max(counts[i], n)
    return counts


def placement(groups: list[list[tuple[int, int]]], parts: list[list]) -> tuple[list, list]:
    """Where the units of each file (`file_units`) put each function and part, `parts[i]` being
    function i's parts (empty: whole): (the parts in another file than their function, which are
    not static and are declared in an internal header, as (i, part) in order; for each file, ([(i,
    here, defined)] for each function with a unit in it, `here` its parts in the file as (k, part,
    static) and `defined` whether the function itself is there, and whether the file calls or is
    called from another file)). The scalar files (symdyn.codegen.c.target) and the batch files
    (symdyn.codegen.c.runtime) are laid out by it."""
    file_of = {unit: k for k, group in enumerate(groups) for unit in group}
    shared = [(i, parts[i][n - 1]) for i, n in sorted(file_of) if n and file_of[i, n] != file_of[i, 0]]
    files = []
    for k, group in enumerate(groups):
        members, linked = [], False
        for i in sorted({i for i, _ in group}):
            units = range(len(parts[i]) + 1)
            here = [
                (n, parts[i][n - 1], file_of[i, n] == file_of[i, 0]) for n in units[1:] if (i, n) in group
            ]
            members.append((i, here, (i, 0) in group))
            linked = linked or any(file_of[i, n] != k for n in units)
        files.append((members, linked))
    return shared, files


def source_file_name(name: str, index: int, stem: str = "dynamics") -> str:
    """NAME_dynamics.c for the first file (index 0), NAME_dynamics_2.c ... for the others (`stem`:
    NAME_batch.c, NAME_batch_2.c ... for the batch files)."""
    return f"{name}_{stem}.c" if index == 0 else f"{name}_{stem}_{index + 1}.c"
