"""A floating robot's configurations checked before a compiled function reads them.

The generated functions of a floating robot read the base quaternion through |q|^2, which holds
in double precision for norms within QUATERNION_NORM (symdyn.model.quaternion_norm): outside it
they return NaN, or R = 1 without a word. `quaternion_checked` wraps a method of symdyn.compile
that takes a configuration (q of inverse_dynamics, forward_dynamics.., q0 and q_next of
difference) so that such a quaternion is one SymdynError naming the function, the argument and
the state, before the C runs. The check costs about a microsecond on one state (math.hypot of
four Python floats) and a pass over the quaternions of a batch.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from ...model.free_flyer_names import NQ_BASE
from ...model.quaternion_norm import QUATERNION_NORM, check_quaternions, one_quaternion_norm

__all__ = ["CONFIGURATIONS", "quaternion_checked"]

#: the names of a generated function's inputs that are configurations q (NQ entries)
CONFIGURATIONS = ("q", "q0", "q_next")


def quaternion_checked(f: dict, method: Callable, n: int) -> Callable:
    """`method` (the generated function described by `f`, whose robot has n joints) with its
    configuration arguments checked; `method` itself when it takes none (or the base is fixed)."""
    nq = n + NQ_BASE
    names = [name for name, _ in f["inputs"] if name != "p"]
    sizes = [size for name, size in f["inputs"] if name != "p"]
    checked = [
        k
        for k, (name, size) in enumerate(zip(names, sizes, strict=True))
        if name in CONFIGURATIONS and size == nq
    ]
    if not checked:
        return method
    low, high = QUATERNION_NORM["double"]
    ndarray, f64 = np.ndarray, np.dtype(np.float64)

    def call(*args, **options):
        for k in checked:
            if k >= len(args):
                break  # the method says how many arguments it takes
            a = args[k]
            one = a.__class__ is ndarray and a.dtype == f64 and a.shape == (nq,)
            if one and low <= one_quaternion_norm(a) <= high:
                continue  # the usual case: one state, a quaternion of norm near 1
            try:
                a = np.asarray(a, dtype=float)
            except (TypeError, ValueError):
                continue  # not numbers: the method's own message
            if a.ndim and a.shape[-1] == nq:
                check_quaternions(a, f"{f['name']}: {names[k]}")
        return method(*args, **options)

    call.__name__ = method.__name__
    call.__doc__ = method.__doc__
    return call
