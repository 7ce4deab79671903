"""CSV of sampled values: a header line, then one line per row, every value printed as "%.17g".

"%.17g" (17 significant digits, correctly rounded) reads back as the same double, so a CSV
of a trajectory holds its samples exactly. Two routes give the same bytes:

* `csv_text`: Python's `%` operator, about 0.4 us a value (55 ms for the 150,000 values of
  the Panda's 10 s at 1 kHz, measured on the development machine);
* `csv_bytes` with a compiled plant: symdyn_csv of templates/c/csv.c.j2, built into every
  robot's cached library beside the stepping loop, about 40 ns a value (6 ms). It prints the
  digits from exact integer arithmetic (or the C library's snprintf outside its range), as
  correctly rounded as Python's, and spells nan, inf and -0 as Python does (glibc's
  snprintf alone would take 70 ms: it is no faster than Python).

Without a compiled library (the NumPy backend) `csv_bytes` takes the Python route.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    from ..compilation.compile import CompiledDynamics

__all__ = ["csv_text", "csv_bytes"]

#: Bytes the C writer may use for one value and its separator (-d.dddddddddddddddde-ddd,).
_VALUE_BYTES = 25


def csv_text(header: Sequence[str], rows: np.ndarray) -> str:
    """The header line and one line per row of the 2-D array `rows`, every value as "%.17g"."""
    rows = np.asarray(rows, dtype=float)
    row_format = ",".join(["%.17g"] * rows.shape[1]) + "\n"  # the digits of f"{x:.17g}"
    return ",".join(header) + "\n" + (row_format * len(rows)) % tuple(rows.ravel().tolist())


def _csv_function(plant: CompiledDynamics):
    import ctypes

    f = plant.cdll.symdyn_csv
    f.restype = ctypes.c_long
    f.argtypes = [ctypes.c_long, ctypes.c_int, ctypes.c_void_p, ctypes.c_void_p]
    return f


def csv_bytes(header: Sequence[str], rows: np.ndarray, plant: CompiledDynamics | None = None) -> bytes:
    """csv_text(header, rows) encoded, written by the plant's compiled library when it has one."""
    if plant is None or plant.backend != "c":
        return csv_text(header, rows).encode()
    rows = np.ascontiguousarray(rows, dtype=np.float64)
    head = (",".join(header) + "\n").encode()
    out = np.empty(len(head) + rows.size * _VALUE_BYTES, dtype=np.uint8)
    out[: len(head)] = np.frombuffer(head, dtype=np.uint8)
    count = _csv_function(plant)(rows.shape[0], rows.shape[1], rows.ctypes.data, out.ctypes.data + len(head))
    return out[: len(head) + count].tobytes()
