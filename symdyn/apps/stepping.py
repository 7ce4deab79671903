"""The fixed-step integrators as one C loop: symdyn_simulate of templates/c/step.c.j2.

`sample_times(duration, dt)` gives the sample times t_k and steps h_k of a run (the
last step shorter when the duration is not a multiple of dt). The torque is either
a table with three rows per step, the torque at t_k, t_k + h_k/2 and t_k + h_k (the
evaluations rk4 needs; euler uses the first), or the computed-torque law of
symdyn.apps.control evaluated in C on a reference table (q_ref, qd_ref, qdd_ref at the
same times) with the controller model's inverse dynamics. `run` then integrates one
initial state per C call:

* rk4: k1..k4 at t, t + h/2, t + h/2, t + h;  q += h/6 (k1q + 2 k2q + 2 k3q + k4q), same for qd;
* euler (R. Grupen, "Dynamics" (2015), slide 19): q += qd h + 1/2 a h^2, qd += a h;
* semi-implicit: qd += a h, then q += qd h;

with the same arithmetic, operation for operation, as the NumPy loop of
symdyn.apps.simulate, which remains for user-supplied Python torque functions. This
module imports neither SymPy nor the derivation, so a cached robot simulates without them.
"""

from __future__ import annotations

import math

import numpy as np

from ..errors import SymdynError
from .compile import CompiledDynamics

__all__ = ["SCHEMES", "sample_times", "torque_rows", "run"]

#: The fixed-step schemes, by their number in step.c.j2.
SCHEMES = {"rk4": 0, "euler": 1, "semi-implicit": 2}


def sample_times(duration: float, dt: float) -> tuple[np.ndarray, np.ndarray]:
    """(t, h): the sample times t_0 = 0 .. t_N = duration and the N steps between them."""
    steps = math.ceil(duration / dt - 1e-9)
    t = np.arange(steps + 1) * dt
    t[steps] = float(duration)
    h = np.full(steps, float(dt))
    h[-1] = min(dt, duration - t[steps - 1])
    return t, h


def torque_rows(t: np.ndarray, h: np.ndarray) -> np.ndarray:
    """The times of the torque table: t_k, t_k + h_k/2, t_k + h_k for every step, then t_N."""
    rows = np.empty(3 * len(h) + 1)
    rows[0:-1:3] = t[:-1]
    rows[1:-1:3] = t[:-1] + 0.5 * h
    rows[2:-1:3] = t[:-1] + h
    rows[-1] = t[-1]
    return rows


def _controller_args(plant: CompiledDynamics, controller, reference_table: np.ndarray):
    """The C arguments of the computed-torque law (model pointers, gains, reference)."""
    model = controller.model
    if model.backend != "c" or "inverse_dynamics" not in model.functions:
        return None
    ffi = plant.ffi
    friction = ffi.NULL if controller.friction else model.pointer("friction")
    keep = [np.ascontiguousarray(controller.Kp, dtype=float), np.ascontiguousarray(controller.Kd, dtype=float)]
    keep.append(np.ascontiguousarray(reference_table, dtype=float))
    pm = ffi.NULL if model.p is None else ffi.from_buffer("double[]", model.p)
    return keep, (model.pointer("inverse_dynamics"), friction, pm)


def run(
    plant: CompiledDynamics,
    scheme: str,
    q0: np.ndarray,
    qd0: np.ndarray,
    h: np.ndarray,
    t: np.ndarray,
    torque: np.ndarray | None = None,
    controller=None,
    reference: np.ndarray | None = None,
    bar=None,
) -> tuple[np.ndarray, np.ndarray, np.ndarray] | None:
    """Integrate from one state (q0, qd0) in C; (Q, QD, U) of shapes (N+1, n), U[N] left unset.

    torque: the (3N+1, n) table, or None with `controller` (a ComputedTorque) and its
    (3N+1, 3n) `reference` table. Returns None when the C loop cannot run (NumPy backend,
    a controller model without compiled inverse dynamics); raises SymdynError on divergence.
    """
    if plant.backend != "c" or "forward_dynamics" not in plant.functions:
        return None
    ffi, lib = plant.ffi, plant.lib
    n, steps = plant.n, len(h)
    buf = ffi.from_buffer
    keep: list = []
    if torque is not None:
        keep.append(np.ascontiguousarray(torque, dtype=float))
        table, inverse, friction, pm, ref, Kp, Kd = buf("double[]", keep[0]), *([ffi.NULL] * 6)
    else:
        args = _controller_args(plant, controller, reference)
        if args is None:
            return None
        keep, (inverse, friction, pm) = args
        table, Kp, Kd, ref = ffi.NULL, buf("double[]", keep[0]), buf("double[]", keep[1]), buf("double[]", keep[2])
    Q, QD, U = np.empty((steps + 1, n)), np.empty((steps + 1, n)), np.empty((steps + 1, n))
    Q[0], QD[0] = q0, qd0
    work = np.empty(12 * n)
    h = np.ascontiguousarray(h, dtype=float)
    p = ffi.NULL if plant.p is None else buf("double[]", plant.p)
    forward = plant.pointer("forward_dynamics")
    chunk = max(steps // 100, 1) if bar is not None and bar.enabled else steps
    for k0 in range(0, steps, chunk):
        k1 = min(k0 + chunk, steps)
        bad = lib.symdyn_simulate(
            n, SCHEMES[scheme], k0, k1, buf("double[]", h), forward, p, table, inverse, friction, pm, ref,
            Kp, Kd, buf("double[]", Q), buf("double[]", QD), buf("double[]", U), buf("double[]", work),
        )  # fmt: skip
        if bad >= 0:
            raise SymdynError(
                f"the simulation diverged at t = {t[bad]:.6g} s (the state is no longer finite); "
                "try a smaller dt or the rk4 integrator"
            )
        if bar is not None:
            bar.update(k1, t[k1])
    return Q, QD, U
