"""Simulation of a robot with closed loops (docs/closed-loops.md): the actuated coordinates are
integrated, the passive ones solved from them at every stage.

The state is (q_a, qd_a). At every stage of the integrator the loops are closed by Newton's
method on the passive coordinates (the generated NAME_solve_loops, compiled), warm-started
from the configuration of the stage before, then

    qdd_a = actuated_forward_dynamics(q, qd_a, tau_a)          (M_a qdd_a = tau_a - bias_a)

Integrators: "rk4" (the classical Runge-Kutta scheme on (q_a, qd_a)) and "semi-implicit"
(symplectic Euler). The trajectory holds every joint (q and qd = W qd_a from loop_motion; tau
the actuated efforts in their joints' columns, zero in the passive ones) and the largest
closure residual max |phi| over the samples. Torques: zero, NACT constants or expressions of
t (symdyn.apps.simulation.simulate.torque_function), or a callable tau(t, q_a, qd_a).
"""

from __future__ import annotations

import math

import numpy as np

from ...errors import SymdynError
from ..compilation.compiled import CompiledDynamics
from .simulate import torque_function
from .stepping import sample_times
from .trajectory import Trajectory

__all__ = ["LOOP_INTEGRATORS", "close_loops", "simulate_loops"]

LOOP_INTEGRATORS = ("rk4", "semi-implicit")


def _joints(values, n: int, name: str) -> np.ndarray:
    """n finite numbers, or a SymdynError naming `name`."""
    try:
        a = np.asarray(values, dtype=float)
    except (TypeError, ValueError):
        raise SymdynError(f"{name} must hold numbers, got {values!r}") from None
    if a.shape != (n,) or not np.all(np.isfinite(a)):
        raise SymdynError(f"{name} must be {n} finite numbers (one per joint), got shape {a.shape}")
    return a


def close_loops(plant: CompiledDynamics, qa: np.ndarray, guess: np.ndarray) -> tuple[np.ndarray, float]:
    """(q, max |phi|): q with q[ACTUATED] = qa and the passive joints solved by Newton's method
    from `guess` (the plant's solve_loops: the generated NAME_solve_loops, one C call).

    Raises:
        SymdynError: the loops do not close from `guess` (no convergence, K_p singular).
    """
    iterations, q = plant.solve_loops(qa, guess)
    if iterations >= 0:
        return q, float(np.max(np.abs(plant.loop_residual(q))))
    raise SymdynError(
        f"robot '{plant.robot.name}': the loops do not close at q_a = {np.round(qa, 6).tolist()} from "
        "the configuration before (a singular configuration, or q0 far from a closed one)"
    )


def simulate_loops(
    plant: CompiledDynamics, q0, qd0=None, duration: float = 1.0, dt: float = 1e-3, tau=None, integrator="rk4"
) -> tuple[Trajectory, float]:
    """Integrate the actuated coordinates of a robot with loops (module docstring).

    q0: every joint's position (n), a closed configuration or a guess near one (its actuated
    entries are the initial q_a); qd0: every joint's rate (n; its actuated entries are the
    initial qd_a) or None for rest.

    Returns:
        (the Trajectory, the largest closure residual max |phi| over its samples).
    """
    if integrator not in LOOP_INTEGRATORS:
        choices = " or ".join(LOOP_INTEGRATORS)
        raise SymdynError(f"a robot with closed loops is integrated with {choices}, not '{integrator}'")
    for name, v in (("duration", duration), ("dt", dt)):
        if not isinstance(v, (int, float)) or isinstance(v, bool) or not math.isfinite(v) or v <= 0:
            raise SymdynError(f"{name} must be a positive number, got {v!r}")
    m = plant.module
    act, n = list(m.ACTUATED), plant.n
    q = _joints(q0, n, "q0")
    qda = np.zeros(len(act)) if qd0 is None else _joints(qd0, n, "qd0")[act]
    torque = torque_function(tau, len(act))
    t, h = sample_times(duration, dt)
    q, worst = close_loops(plant, q[act], q)
    Q, QD, U = np.zeros((len(t), n)), np.zeros((len(t), n)), np.zeros((len(t), n))

    def accel(qa, rates, s, guess):
        closed, residual = close_loops(plant, qa, guess)
        u = np.broadcast_to(np.asarray(torque(s, qa, rates), dtype=float), (len(act),))
        return plant.actuated_forward_dynamics(closed, rates, u), closed, residual, u

    for k in range(len(t)):
        qa = q[act]
        a1, q, r1, u = accel(qa, qda, t[k], q)
        Q[k], QD[k], U[k, act] = q, plant.loop_motion(q, qda, np.zeros(len(act)))[0], u
        worst = max(worst, r1)
        if k == len(t) - 1:
            break
        dt_k = h[k]
        if integrator == "rk4":
            a2, _, r2, _ = accel(qa + dt_k / 2 * qda, qda + dt_k / 2 * a1, t[k] + dt_k / 2, q)
            a3, _, r3, _ = accel(
                qa + dt_k / 2 * (qda + dt_k / 2 * a1), qda + dt_k / 2 * a2, t[k] + dt_k / 2, q
            )
            a4, _, r4, _ = accel(qa + dt_k * (qda + dt_k / 2 * a2), qda + dt_k * a3, t[k] + dt_k, q)
            worst = max(worst, r2, r3, r4)
            qa_next = qa + dt_k * (qda + dt_k / 6 * (a1 + a2 + a3))
            qda = qda + dt_k / 6 * (a1 + 2 * a2 + 2 * a3 + a4)
        else:
            qda = qda + dt_k * a1
            qa_next = qa + dt_k * qda
        if not np.all(np.isfinite(qda)):
            raise SymdynError(f"robot '{plant.robot.name}': the simulation diverged at t = {t[k]:g} s")
        q = q.copy()
        q[act] = qa_next
    return Trajectory(plant.robot, t, Q, QD, U, integrator, plant=plant), worst
