"""The fixed-step integrators as one C loop: symdyn_simulate of templates/c/step.c.j2.

`sample_times(duration, dt)` gives the sample times t_k and steps h_k of a run (the
last step shorter when the duration is not a multiple of dt). The torque is either
a table with three rows per step, the torque at t_k, t_k + h_k/2 and t_k + h_k (the
evaluations rk4 needs; euler uses the first), or the computed-torque law of
symdyn.apps.simulation.control evaluated in C on a reference table (q_ref, qd_ref, qdd_ref at the
same times) with the controller model's inverse dynamics. `run` then integrates one
initial state per C call:

* rk4: k1..k4 at t, t + h/2, t + h/2, t + h;  q += h/6 (k1q + 2 k2q + 2 k3q + k4q), same for qd;
* euler (R. Grupen, "Dynamics" (2015), slide 19): q += qd h + 1/2 a h^2, qd += a h;
* semi-implicit: qd += a h, then q += qd h;

with the same arithmetic, operation for operation, as the NumPy loop of
symdyn.apps.simulation.simulate, which remains for user-supplied Python torque functions. This
module imports neither SymPy nor the derivation, so a cached robot simulates without them.
"""

from __future__ import annotations

import math

import numpy as np

from ..compilation.compile import CompiledDynamics
from ..compilation.singular import divergence_error

__all__ = ["INTEGRATORS", "ADAPTIVE", "SCHEMES", "sample_times", "torque_rows", "run"]

#: The integrators of symdyn.apps.simulation.simulate; "lecture" is another name for "euler" (slide 19).
INTEGRATORS = ("rk4", "euler", "lecture", "semi-implicit", "rk45", "dop853")
#: The adaptive ones (scipy's solve_ivp with error control); the others take fixed steps.
ADAPTIVE = ("rk45", "dop853")
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


def _address(a: np.ndarray) -> int:
    return a.ctypes.data


def _controller_args(controller, reference_table: np.ndarray):
    """The C arguments of the computed-torque law (model pointers, gains, reference), or None."""
    model = controller.model
    if model.backend != "c" or "inverse_dynamics" not in model.functions:
        return None
    keep = [np.ascontiguousarray(x, dtype=float) for x in (controller.Kp, controller.Kd, reference_table)]
    friction = None if controller.friction else model.pointer("friction")
    pm = None if model.p is None else _address(model.p)
    keep.append(model)
    return keep, [
        model.pointer("inverse_dynamics"),
        friction,
        pm,
        _address(keep[2]),
        *map(_address, keep[:2]),
    ]


def _simulate_function(plant: CompiledDynamics):
    import ctypes

    f = plant.cdll.symdyn_simulate
    f.restype = ctypes.c_long
    f.argtypes = [ctypes.c_int, ctypes.c_int, ctypes.c_long, ctypes.c_long, *[ctypes.c_void_p] * 14]
    return f


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

    bar: a progress bar (symdyn.progress.Steps) moved 100 times, or None.
    torque: the (3N+1, n) table, or None with `controller` (a ComputedTorque) and its
    (3N+1, 3n) `reference` table. Returns None when the C loop cannot run (NumPy backend,
    a controller model without compiled inverse dynamics); raises SymdynError on divergence.
    """
    if plant.backend != "c" or "forward_dynamics" not in plant.functions:
        return None
    n, steps = plant.n, len(h)
    if torque is not None:
        keep: list = [np.ascontiguousarray(torque, dtype=float)]
        law = [_address(keep[0]), None, None, None, None, None, None]
    else:
        args = _controller_args(controller, reference)
        if args is None:
            return None
        keep, (inverse, friction, pm, ref, Kp, Kd) = args
        law = [None, inverse, friction, pm, ref, Kp, Kd]
    Q, QD, U = np.empty((steps + 1, n)), np.empty((steps + 1, n)), np.empty((steps + 1, n))
    Q[0], QD[0] = q0, qd0
    work = np.empty(12 * n)
    h = np.ascontiguousarray(h, dtype=float)
    p = None if plant.p is None else _address(plant.p)
    simulate = _simulate_function(plant)
    head = [_address(h), plant.pointer("forward_dynamics"), p]
    tail = [_address(Q), _address(QD), _address(U), _address(work)]
    chunk = max(steps // 100, 1) if bar is not None and bar.enabled else steps
    for k0 in range(0, steps, chunk):
        k1 = min(k0 + chunk, steps)
        bad = simulate(n, SCHEMES[scheme], k0, k1, *head, *law, *tail)
        if bad >= 0:
            raise divergence_error(plant, t[bad], Q[max(bad - 1, 0)])
        if bar is not None:
            bar.update(k1, t[k1])
    del keep
    return Q, QD, U
