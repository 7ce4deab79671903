"""Calling a compiled library's functions from Python: one state, or a batch through NAME_batch.

The methods of `CompiledDynamics` (symdyn.apps.compilation.compile) are built here from the library's
function table (symdyn.codegen.c.runtime.function_table) through cffi's ABI mode. One state
(vectors of their size) is one C call of the scalar library. A batch (leading axes, e.g. (B, n))
is one call of NAME_batch, in the batch library built on the first batch call
(symdyn.apps.compilation.batch_library), which evaluates W states per instruction
(templates/c/batch.c.j2): the arrays are
passed to C without a copy when they are C-contiguous float64 of the batch's full shape (a state's
values contiguous, the states one after the other); any other array (another dtype, a strided
view, an input broadcast against the others) is copied once into that layout. With threads > 1 a
batch is cut into that many chunks (a multiple of 16 states each, so every chunk keeps whole
vectors of any W, and at least MIN_STATES_PER_THREAD states), evaluated at once by the threads of
a pool kept between calls (cffi releases the GIL during the call):
each state's result is computed by the same instructions whatever the chunk, so it equals the
one-thread result bit for bit.
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

import numpy as np

from ...errors import SymdynError

__all__ = [
    "load_library",
    "c_method",
    "solve_loops_method",
    "numpy_solve_loops",
    "check_threads",
    "batch_layout",
    "CHUNK",
    "MIN_STATES_PER_THREAD",
]

#: The states of a thread's chunk are a multiple of this (every vector width W divides it).
CHUNK = 16
#: A thread gets at least this many states: below, starting and joining it (tens of microseconds)
#: costs more than it saves (about 100 ns a state), so a small batch runs in the calling thread.
MIN_STATES_PER_THREAD = 4096

_POOL: list = []  # [(workers, ThreadPoolExecutor)], kept between calls; replaced by a larger one when needed

_LIBRARIES: dict[str, tuple] = {}


def _declarations(functions: list[dict], solve: dict | None = None) -> str:
    """The cdef of every generated function, its batch wrapper and the batch's vector width, and of
    NAME_solve_loops and its batch when `solve` describes them (runtime.solve_loops_entry)."""
    lines = ["int symdyn_batch_width(void);"]
    for f in functions:
        ins = ", ".join(f"const double {name}[]" for name, _ in f["inputs"])
        outs = ", ".join(f"double {name}[]" for name, *_ in f["outputs"])
        lines.append(f"void {f['c_name']}({ins}, {outs});")
        lines.append(f"void {f['c_name']}_batch(long count, {ins}, {outs});")
    if solve:
        ins = "const double qa[], const double q_guess[], const double p[], double q[]"
        lines.append(f"int {solve['c_name']}({ins});")
        lines.append(f"void {solve['c_name']}_batch(long count, {ins}, int iterations[]);")
    return "\n".join(lines)


def load_library(
    path: Path, functions: list[dict], width: str, real: str = "double", solve: dict | None = None, ffi=None
):
    """(ffi, lib) for the library at `path` (opened once per process); `width` names its
    NAME_batch_width function (the states NAME_batch evaluates per instruction, in the batch
    library); `real` is the floating type of its functions (symdyn.compile's are double); `solve`:
    NAME_solve_loops of a robot with loops (symdyn.codegen.c.runtime.solve_loops_entry), or None.
    `ffi`: the cffi.FFI of the scalar library of the same functions, which a batch library
    (symdyn.apps.compilation.batch_library) shares, so that the arrays handed to either are of one FFI."""
    key = str(path)
    if key not in _LIBRARIES:
        if ffi is None:
            import cffi

            ffi = cffi.FFI()
            ffi.cdef(
                _declarations(functions, solve).replace("symdyn_batch_width", width).replace("double", real)
            )
        _LIBRARIES[key] = (ffi, ffi.dlopen(key))
    return _LIBRARIES[key]


def batch_layout(a: np.ndarray, lead: tuple, size: int, count: int) -> np.ndarray:
    """`a` as a C-contiguous float64 (count, size) array: a view of it when it already is one
    (no copy), else a copy (its broadcast to the batch's leading axes `lead`)."""
    if a.shape == (*lead, size):
        return np.ascontiguousarray(a, dtype=np.float64).reshape(count, size)
    return np.ascontiguousarray(np.broadcast_to(a, (*lead, size)), dtype=np.float64).reshape(count, size)


def c_method(ffi, lib, f: dict, p_ptr, owner, batch_library: Callable[[], object]) -> Callable:
    """One generated function as a Python callable: one state per C call of `lib`, a batch through
    NAME_batch of batch_library() (the batch library, built on the first batch call:
    symdyn.apps.compilation.batch_library).

    `owner.threads` is the default number of threads of a batch; a call may give its own (threads=).
    """
    single = getattr(lib, f["c_name"])
    batch_name = f["c_name"] + "_batch"
    sizes = [size for name, size in f["inputs"] if name != "p"]
    names = [name for name, _ in f["inputs"] if name != "p"]
    with_p = len(sizes) != len(f["inputs"])
    shapes = [(rows, cols) if matrix else (rows,) for _, rows, cols, matrix in f["outputs"]]
    one = len(shapes) == 1
    buf = ffi.from_buffer
    p_args = (p_ptr,) if with_p else ()
    f64, ndarray = np.dtype(np.float64), np.ndarray
    one_state = [(size,) for size in sizes]

    def call(*args, threads: int | None = None, out=None):
        if len(args) != len(sizes):
            raise TypeError(f"{f['name']}({', '.join(names)}) takes {len(sizes)} arguments, got {len(args)}")
        pointers = []
        for a, shape in zip(args, one_state, strict=True):  # the fast path: one state, float64 arrays
            if (
                out is not None
                or a.__class__ is not ndarray
                or a.dtype != f64
                or a.shape != shape
                or not a.flags.c_contiguous
            ):
                break
            pointers.append(buf("double[]", a))
        else:
            outs = [np.empty(shape) for shape in shapes]
            single(*pointers, *p_args, *[buf("double[]", o) for o in outs])
            return outs[0] if one else tuple(outs)
        arrays = [a if isinstance(a, ndarray) else np.asarray(a, dtype=f64) for a in args]
        if out is None and all(a.shape == shape for a, shape in zip(arrays, one_state, strict=True)):
            return call(*[np.ascontiguousarray(a, dtype=f64) for a in arrays])
        for a, s, n in zip(arrays, sizes, names, strict=True):
            if a.ndim == 0 or a.shape[-1] != s:
                raise ValueError(f"{f['name']}: {n} must have shape ({s},) or (..., {s}); got {a.shape}")
        lead = np.broadcast_shapes(*(a.shape[:-1] for a in arrays))
        count = int(np.prod(lead, dtype=np.int64))
        flat = [batch_layout(a, lead, s, count) for a, s in zip(arrays, sizes, strict=True)]
        outs = (
            [np.empty((*lead, *shape)) for shape in shapes]
            if out is None
            else _given(f, out, lead, shapes, flat)
        )
        flat_outs = [o.reshape(count, int(np.prod(shape))) for o, shape in zip(outs, shapes, strict=True)]
        chunks = _chunks(count, owner.threads if threads is None else threads)
        if count:
            _run(getattr(batch_library(), batch_name), buf, chunks, flat, p_args, flat_outs)
        return outs[0] if one else tuple(outs)

    call.__name__ = f["name"]
    call.__doc__ = (
        f"{f['doc']} (generated C; inputs {', '.join(names)}; a batch may give threads= and out=, "
        "arrays it fills and returns)"
    )
    return call


def solve_loops_method(ffi, lib, solve: dict, p_ptr, owner, batch_library: Callable[[], object]) -> Callable:
    """NAME_solve_loops as a Python callable solve_loops(qa, q_guess, threads=None) -> (iterations, q):
    one state (qa of NACT values, q_guess of n) is one C call returning (int, q of shape (n,)); a
    batch (leading axes, qa and q_guess broadcast) is one call of NAME_solve_loops_batch, a loop
    over the states in C (batch_library(), as c_method's), in `threads` chunks, returning
    (iterations of the leading shape, int32, and q of shape (..., n))."""
    single = getattr(lib, solve["c_name"])
    buf = ffi.from_buffer
    sizes = {"qa": solve["nact"], "q_guess": solve["n"]}

    def call(qa, q_guess, threads: int | None = None):
        arrays = {"qa": np.asarray(qa, dtype=np.float64), "q_guess": np.asarray(q_guess, dtype=np.float64)}
        for name, a in arrays.items():
            if a.ndim == 0 or a.shape[-1] != sizes[name]:
                size = sizes[name]
                raise ValueError(
                    f"solve_loops: {name} must have shape ({size},) or (..., {size}); got {a.shape}"
                )
        lead = np.broadcast_shapes(*(a.shape[:-1] for a in arrays.values()))
        if not lead:
            q = np.empty(solve["n"])
            qa, guess = (np.ascontiguousarray(a) for a in arrays.values())
            return int(single(buf("double[]", qa), buf("double[]", guess), p_ptr, buf("double[]", q))), q
        count = int(np.prod(lead, dtype=np.int64))
        qa, guess = (batch_layout(a, lead, sizes[k], count) for k, a in arrays.items())
        q, iterations = np.empty((*lead, solve["n"])), np.empty(lead, dtype=np.int32)
        flat_q, flat_it = q.reshape(count, solve["n"]), iterations.reshape(count)
        batch = getattr(batch_library(), solve["c_name"] + "_batch") if count else None

        def run(chunk: tuple[int, int]) -> None:
            start, stop = chunk
            batch(
                stop - start,
                buf("double[]", qa[start:stop]),
                buf("double[]", guess[start:stop]),
                p_ptr,
                buf("double[]", flat_q[start:stop]),
                buf("int[]", flat_it[start:stop]),
            )

        if count:
            _each(_chunks(count, owner.threads if threads is None else threads), run)
        return iterations, q

    call.__name__ = "solve_loops"
    call.__doc__ = (
        f"{solve['c_name']} (generated C): (iterations, q), the passive joints solved by Newton's "
        "method from q_guess with q[actuated] = qa; iterations -1: no convergence (docs/closed-loops.md)."
    )
    return call


def numpy_solve_loops(module, qa, q_guess, p):
    """solve_loops_method's answer from the generated NumPy module `module` (symdyn.compile without
    a C compiler): its solve_loops, over a batch's states one by one."""
    qa, q_guess = np.asarray(qa, dtype=np.float64), np.asarray(q_guess, dtype=np.float64)
    if max(qa.ndim, q_guess.ndim) <= 1 or min(qa.ndim, q_guess.ndim) == 0:  # one state (or refused)
        return module.solve_loops(qa, q_guess, p)
    lead = np.broadcast_shapes(qa.shape[:-1], q_guess.shape[:-1])
    qa = np.broadcast_to(qa, (*lead, qa.shape[-1])).reshape(-1, qa.shape[-1])
    q_guess = np.broadcast_to(q_guess, (*lead, q_guess.shape[-1])).reshape(-1, q_guess.shape[-1])
    solved = [module.solve_loops(a, g, p) for a, g in zip(qa, q_guess, strict=True)]
    iterations = np.array([i for i, _ in solved], dtype=np.int32).reshape(lead)
    return iterations, np.array([q for _, q in solved]).reshape(*lead, -1)


def _given(f: dict, out, lead: tuple, shapes: list[tuple], inputs: list[np.ndarray]) -> list[np.ndarray]:
    """The arrays of out= (one array, or a tuple of one per output) when each is a C-contiguous
    float64 array of its output's shape over the batch's leading axes `lead`, sharing no memory with
    the inputs; else SymdynError."""
    given = list(out) if isinstance(out, tuple) else [out]
    if len(given) != len(shapes):
        raise SymdynError(f"{f['name']}: out= takes {len(shapes)} array(s), got {len(given)}")
    for o, shape in zip(given, shapes, strict=True):
        want = (*lead, *shape)
        if not (
            isinstance(o, np.ndarray) and o.dtype == np.float64 and o.shape == want and o.flags.c_contiguous
        ):
            got = f"{o.dtype} {o.shape}" if isinstance(o, np.ndarray) else type(o).__name__
            raise SymdynError(
                f"{f['name']}: out= must be a C-contiguous float64 array of shape {want}, got {got}"
            )
        if not o.flags.writeable or any(np.may_share_memory(o, a) for a in inputs):
            raise SymdynError(f"{f['name']}: out= must be writeable and share no memory with the inputs")
    return given


def check_threads(threads) -> int:
    """`threads` when it is a whole number >= 1; else SymdynError."""
    if isinstance(threads, bool) or not isinstance(threads, (int, np.integer)) or threads < 1:
        raise SymdynError(f"threads must be a whole number >= 1, got {threads!r}")
    return int(threads)


def _chunks(count: int, threads) -> list[tuple[int, int]]:
    """(start, stop) of each thread's states: `threads` chunks of a multiple of CHUNK states."""
    check_threads(threads)
    per = max(-(-count // int(threads)), MIN_STATES_PER_THREAD)
    per = -(-per // CHUNK) * CHUNK
    if per >= count:
        return [(0, count)]
    return [(start, min(start + per, count)) for start in range(0, count, per)]


def _run(batch, buf, chunks, flat, p_args, outs) -> None:
    """NAME_batch on each chunk, each in its own thread when there are several (the C call runs
    without the GIL)."""

    def run(chunk: tuple[int, int]) -> None:
        start, stop = chunk
        batch(
            stop - start,
            *[buf("double[]", a[start:stop]) for a in flat],
            *p_args,
            *[buf("double[]", o[start:stop]) for o in outs],
        )

    _each(chunks, run)


def _each(chunks: list[tuple[int, int]], run: Callable) -> None:
    """run(chunk) for every chunk, each in its own thread when there are several."""
    if len(chunks) == 1:
        run(chunks[0])
        return
    if not _POOL or _POOL[0][0] < len(chunks):
        from concurrent.futures import ThreadPoolExecutor

        if _POOL:
            _POOL.pop()[1].shutdown(wait=False)
        _POOL.append((len(chunks), ThreadPoolExecutor(len(chunks), thread_name_prefix="symdyn-batch")))
    list(_POOL[0][1].map(run, chunks))
