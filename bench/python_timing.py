"""Python-side timings of bench/run.py: symdyn.rnea (NumPy) and the CasADi route's casadi.Function.

`time_numpy_and_casadi` fills a Row's `numpy_us` (symdyn.rnea.rnea, one joint-space state
per call), `numpy_batch_us` (one call on 1000 states, per state) and `cr_py_us` (the traced
casadi.Function called from Python with NumPy arguments), each the median of repetitions.
"""

from __future__ import annotations

import statistics
import time

import numpy as np
from row import CASADI_FUNCTIONS, Row
from states import NSTATES

__all__ = ["time_python", "time_numpy_and_casadi"]


def time_python(fn, args_list, reps: int, budget_s: float) -> float:
    """Median over `reps` repetitions of the seconds per call, cycling through args_list."""
    fn(*args_list[0])  # warm-up (and caches)
    t0 = time.perf_counter()
    calls = 0
    while time.perf_counter() - t0 < 0.05:
        fn(*args_list[calls % len(args_list)])
        calls += 1
    per = (time.perf_counter() - t0) / calls
    count = max(3, int(budget_s / reps / per))
    out = []
    for _ in range(reps):
        t = time.perf_counter()
        for i in range(count):
            fn(*args_list[i % len(args_list)])
        out.append((time.perf_counter() - t) / count)
    return statistics.median(out)


def time_numpy_and_casadi(row: Row, robot, fns, states, reps: int, budget_s: float) -> None:
    """Time symdyn.rnea (single and batch) and the casadi.Functions `fns` on `states`."""
    from symdyn.rnea import rnea

    m = min(NSTATES, 64)
    q, qd, qdd = (states[x] for x in ("q", "qd", "qdd"))
    single = [(robot, q[i], qd[i], qdd[i]) for i in range(m)]
    row.numpy_us = 1e6 * time_python(rnea, single, reps, budget_s)
    B = 1000
    idx = np.arange(B) % NSTATES
    batch = [(robot, q[idx], qd[idx], qdd[idx])]
    row.numpy_batch_us = 1e6 * time_python(rnea, batch, reps, budget_s) / B
    argsets = {
        "inverse_dynamics": [(q[i], qd[i], qdd[i]) for i in range(m)],
        "mass_matrix": [(q[i],) for i in range(m)],
        "gravity": [(q[i],) for i in range(m)],
    }
    for fn in CASADI_FUNCTIONS:
        row.cr_py_us[fn] = 1e6 * time_python(fns[fn], argsets[fn], reps, budget_s)
