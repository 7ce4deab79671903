"""The fixed-step integrators of a floating robot (symdyn.apps.simulation.simulate with Robot.floating):
the configuration q (NQ = 7 + n, symdyn.model.free_flyer) moves on SE(3) x R^n by the generated
integrate (q (+) xi, symdyn.algorithms.lie_group), the velocity v (NV = 6 + n) in a vector space
by the generated forward dynamics a = vdot(q, v, tau). With step h:

* "rk4": the Runge-Kutta-Munthe-Kaas scheme of order 4 (Munthe-Kaas, BIT 38 (1998)): stages
  q_i = q (+) Theta_i, v_i, a_i = vdot(q_i, v_i, tau),
      Theta_1 = 0,          v_1 = v
      Theta_2 = h/2 K_1,    v_2 = v + h/2 a_1
      Theta_3 = h/2 K_2,    v_3 = v + h/2 a_2
      Theta_4 = h K_3,      v_4 = v + h a_3,
  K_i = dexp^-1 (Theta_i, v_i) = v_i + 1/2 [Theta_i, v_i] + 1/12 [Theta_i, [Theta_i, v_i]]
  (the series truncated after the terms order 4 needs; [.,.] the Lie bracket of se(3) on the
  base's twist, zero on the joints), then q <- q (+) h/6 (K_1 + 2 K_2 + 2 K_3 + K_4),
  v <- v + h/6 (a_1 + 2 a_2 + 2 a_3 + a_4);
* "euler" (also "lecture", slide 19): q <- q (+) (v h + 1/2 a h^2), v <- v + a h;
* "semi-implicit": v <- v + a h, then q <- q (+) v h.

The torque is a table with three rows per step as in symdyn.apps.simulation.stepping (or a callable).
No contact: the robot flies or falls freely (docs/centroidal.md).
"""

from __future__ import annotations

import numpy as np

from ...errors import SymdynError

__all__ = [
    "FLOATING_SCHEMES",
    "bracket",
    "dexp_inverse",
    "floating_sizes",
    "initial_configuration",
    "run_floating",
]

#: the integrators a floating robot supports (the adaptive ones and --track do not apply)
FLOATING_SCHEMES = ("rk4", "euler", "semi-implicit")


def bracket(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """[a, b] on se(3) x R^n, twists (v, w) first: ([w_a] v_b - [w_b] v_a, w_a x w_b), joints 0."""
    out = np.zeros_like(b)
    va, wa, vb, wb = a[..., :3], a[..., 3:6], b[..., :3], b[..., 3:6]
    out[..., :3] = np.cross(wa, vb) - np.cross(wb, va)
    out[..., 3:6] = np.cross(wa, wb)
    return out


def dexp_inverse(theta: np.ndarray, v: np.ndarray) -> np.ndarray:
    """dexp^-1 (theta, v) to second order: v + [theta, v]/2 + [theta, [theta, v]]/12."""
    first = bracket(theta, v)
    return v + 0.5 * first + bracket(theta, first) / 12.0


def floating_sizes(plant) -> tuple[int, int] | None:
    """(NQ, NV) of a compiled floating robot (it has the generated integrate), else None."""
    if "integrate" not in plant.functions:
        return None
    return int(plant.module.NQ), int(plant.module.NV)


def initial_configuration(nq: int) -> np.ndarray:
    """The configuration at the origin: base at the world's origin, identity quaternion, joints 0."""
    q = np.zeros(nq)
    q[6] = 1.0
    return q


def run_floating(
    plant, scheme: str, q0, v0, h: np.ndarray, t: np.ndarray, tau_at, accel=None, flat: bool = False
) -> tuple:
    """(Q (N+1, NQ), V (N+1, NV), U (N+1, NV)) from one state; tau_at(row, t, q, v) -> (NV,);
    accel(q, v, tau) -> a: the accelerations (default plant.forward_dynamics; the constrained
    dynamics of symdyn.apps.simulation.contact_simulate); flat: q lives in a vector space (a fixed
    base, plant.integrate adds), where dexp^-1 is the identity."""
    if scheme not in FLOATING_SCHEMES:
        raise SymdynError(
            f"robot '{plant.robot.name}' has a floating base: integrator '{scheme}' does not apply "
            f"(one of {', '.join(FLOATING_SCHEMES)})"
        )
    needed = ("forward_dynamics", "integrate") if accel is None else ("integrate",)
    missing = [f for f in needed if f not in plant.functions]
    if missing:
        raise SymdynError(f"robot '{plant.robot.name}': no {missing[0]} function, cannot simulate")
    steps = len(h)
    Q, V, U = np.empty((steps + 1, len(q0))), np.empty((steps + 1, len(v0))), np.empty((steps + 1, len(v0)))
    Q[0], V[0] = q0, v0
    q, v = np.asarray(q0, dtype=float), np.asarray(v0, dtype=float)
    one = np.ones(1)
    accel = plant.forward_dynamics if accel is None else accel

    def step_to(q, xi):
        return plant.integrate(q, xi, one)

    with np.errstate(all="ignore"):
        for k in range(steps):
            hk, tk = h[k], t[k]
            U[k] = tau_at(3 * k, tk, q, v)
            a1 = accel(q, v, U[k])
            if scheme == "rk4":
                K, A, theta, vel = [v], [a1], v * 0.0, v
                for i, (c, row) in enumerate(((0.5, 1), (0.5, 1), (1.0, 2))):
                    theta, vel = c * hk * K[i], v + c * hk * A[i]
                    qi = step_to(q, theta)
                    A.append(accel(qi, vel, tau_at(3 * k + row, tk + c * hk, qi, vel)))
                    K.append(vel if flat else dexp_inverse(theta, vel))
                q = step_to(q, hk / 6.0 * (K[0] + 2 * K[1] + 2 * K[2] + K[3]))
                v = v + hk / 6.0 * (A[0] + 2 * A[1] + 2 * A[2] + A[3])
            elif scheme == "euler":
                q = step_to(q, v * hk + 0.5 * a1 * hk * hk)
                v = v + a1 * hk
            else:
                v = v + a1 * hk
                q = step_to(q, v * hk)
            if not (np.all(np.isfinite(q)) and np.all(np.isfinite(v))):
                raise SymdynError(
                    f"robot '{plant.robot.name}': the simulation diverged at t = {t[k + 1]:g} s "
                    "(the state is not finite); try a smaller dt"
                )
            Q[k + 1], V[k + 1] = q, v
        U[steps] = tau_at(3 * steps, t[steps], q, v)
    return Q, V, U
