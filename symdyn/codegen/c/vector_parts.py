"""A large vector body of the SIMD batch wrappers cut into parts, as the scalar function is.

gcc's time on one function grows faster than the function (symdyn.codegen.c.parts), and the body
of NAME_f over vectors of W lanes (symdyn.codegen.c.vector) is as long as the scalar one: Talos'
contact derivatives (38,000 temporaries), printed as one vector function in NAME_batch.c, did not
build in half an hour, while the scalar function cut into parts builds in about 75 s of one core.
So a vector body is cut by the same rule (more than PART_ABOVE statements and a live span above
LIVE_ABOVE; symdyn.codegen.c.parts.split_body: parts of about PART_STATEMENTS statements, each cut where the
fewest temporaries are alive): part k is a static function NAME_simd_f_partk with the block's
arguments, the array `stash` of vectors that carries the temporaries a later part reads, and the
sines and cosines the block computed; the block computes the sines and cosines, then calls the
parts in order. A temporary of the parameters alone (a scalar) goes through lane 0 of its slot,
so each lane still performs the scalar function's operations, bit for bit.
"""

from __future__ import annotations

from .parts import split_body

__all__ = ["vector_parts"]


def vector_parts(body: list, reads: list, block: str, arguments: list[str]) -> dict | None:
    """{"parts", "slots"} of a vector body (symdyn.codegen.c.vector._interleaved: ("let", vector?,
    name, text) and ("store", groups)) longer than the scalar parts' bound, else None.

    `reads` are the block's (local, input, index, vector?), `arguments` its inputs' and outputs'
    names. Each part is {"name", "reads" (those it needs, as `reads`), "body" (the body's items, with
    ("load", vector?, name, slot) before the first item that reads a temporary of an earlier part
    and ("save", vector?, slot, name) after a temporary that a later part reads)}. A store item
    holds the stores of both widths W = 8 and W = 4 (one preprocessor branch each), so a part may
    read or write an argument in one branch only: the template casts every argument to void.
    """
    flat, original, vector = [], {}, {}
    for item in body:
        if item[0] == "let":
            statement = ("let", item[2], item[3])
            vector[item[2]] = item[1]
        else:
            groups = [g for entries in item[1].values() for g in entries]
            statement = ("store", " ".join(g[0] for g in groups), " ".join(t for g in groups for t in g[3]))
        original[id(statement)] = item
        flat.append(statement)
    plain = [(local, array, index) for local, array, index, _ in reads]
    split = split_body(flat, plain, block, arguments)
    if split is None:
        return None
    lane = {local: flag for local, _, _, flag in reads}
    parts = []
    for part in split["parts"]:
        items = []
        for s in part["body"]:
            if s[0] == "load":
                items.append(("load", vector.get(s[1], lane.get(s[1], True)), s[1], s[2]))
            elif s[0] == "save":
                items.append(("save", vector.get(s[2], True), s[1], s[2]))
            else:
                items.append(original[id(s)])
        parts.append(
            {
                "name": part["name"],
                "reads": [(local, array, index, lane[local]) for local, array, index in part["reads"]],
                "body": items,
            }
        )
    return {"parts": parts, "slots": split["slots"]}
