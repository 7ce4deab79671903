"""The numeric oracle of closed loops: closure, its Jacobian and the dynamics in the actuated
coordinates, NumPy only (Khalil and Dombre (2002), ch. 14), one state at a time.

Independent of symdyn.algorithms.closed_loops and the generated code: it reads the model's
loops (symdyn.model.loops), takes every closure row (dependent rows included) from the oracle's
own frame kinematics (symdyn.oracle.frames: the frames' world-aligned Jacobians and drifts), and
solves with least squares instead of choosing rows:

    qd_p = -K_p^+ K_a qd_a,  qdd_p = -K_p^+ (K_a qdd_a + Kdot qd)      (K_p^+ the pseudo-inverse)

exact on the closure, where the dependent rows are consistent. The tree's efforts come from the
spatial RNEA and CRBA of symdyn.oracle.rnea (friction and rotor inertia included):
tau_a = W^T tau(q, qd, qdd), M_a = W^T M W, and forward dynamics solves
M_a qdd_a = tau_a - W^T tau(q, qd, qdd at qdd_a = 0). `solve_loops` is Newton's method on the
passive coordinates with least-squares steps. The actuated and passive coordinates are those of
Robot.actuated_links, in coordinate order.
"""

from __future__ import annotations

import numpy as np

from ..errors import SymdynError
from .frames import placed_frame_state
from .rnea import mass_matrix, rnea

__all__ = ["LoopState", "closure", "split", "solve_loops", "loop_state", "forward_dynamics"]


def _vee(A: np.ndarray) -> np.ndarray:
    return 0.5 * np.array([A[2, 1] - A[1, 2], A[0, 2] - A[2, 0], A[1, 0] - A[0, 1]])


def _placement(point) -> np.ndarray:
    T = np.eye(4)
    T[:3, 3] = np.asarray([float(v) for v in point], dtype=float)
    return T


def closure(robot, q, qd=None, params=None) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(phi, K, Kdot qd) over every row of every loop (3 per point loop, 6 per weld), each block
    of three rows in the axes of the loop's frame B: phi = R_B^T (p_A - p_B) (and
    1/2 vee(R_B^T R_A - R_A^T R_B)), K = R_B^T (J_A - J_B), and the derivative of K qd at
    qdd = 0, R_B^T ((Jdot qd)_A - (Jdot qd)_B - w_B x (J_A - J_B) qd)."""
    num = robot.numeric(params)
    qd = np.zeros(num.n) if qd is None else np.asarray(qd, dtype=float)
    phi, K, drift = [], [], []
    for loop in num.loops:
        A = placed_frame_state(num, loop.link, _placement(loop.point), q, qd)
        B = placed_frame_state(num, loop.to, _placement(loop.to_point), q, qd)
        R = B.pose[:3, :3]
        phi.append(R.T @ (A.pose[:3, 3] - B.pose[:3, 3]))
        if loop.type == "weld":
            phi.append(_vee(R.T @ A.pose[:3, :3]))
        Kw = A.jacobian - B.jacobian
        rel, wB = Kw @ qd, B.jacobian[3:] @ qd
        dw = A.drift - B.drift
        for b in range(loop.equations // 3):
            block = slice(3 * b, 3 * b + 3)
            K.append(R.T @ Kw[block])
            drift.append(R.T @ (dw[block] - np.cross(wB, rel[block])))
    return np.concatenate(phi), np.vstack(K), np.concatenate(drift)


def split(robot) -> tuple[list[int], list[int]]:
    """The actuated and the passive coordinates (coordinate order)."""
    own = {c.index for i, c in enumerate(robot.coordinates) if i in robot.actuated_links}
    act = sorted(own)
    return act, [j for j in range(robot.n) if j not in own]


def solve_loops(robot, qa, q_guess, params=None, tol: float = 1e-12, iterations: int = 100) -> np.ndarray:
    """q with q_a = qa and the passive coordinates closing every loop (Newton, least squares).

    Raises:
        SymdynError: no convergence within `iterations`.
    """
    act, pas = split(robot)
    q = np.array(q_guess, dtype=float)
    q[act] = qa
    for _ in range(iterations):
        phi, K, _ = closure(robot, q, params=params)
        if np.max(np.abs(phi)) < tol:
            return q
        q[pas] -= np.linalg.lstsq(K[:, pas], phi, rcond=None)[0]
    raise SymdynError(f"solve_loops: robot '{robot.name}': the loops do not close from this guess")


class LoopState:
    """W, the full rates and accelerations, and the actuated dynamics at one closed state."""

    def __init__(self, robot, q, qda, qdda, params=None) -> None:
        act, pas = split(robot)
        self.act, self.pas = act, pas
        n = robot.n
        q = np.asarray(q, dtype=float)
        _, K, _ = closure(robot, q, params=params)
        Kp_pinv = np.linalg.pinv(K[:, pas])
        W = np.zeros((n, len(act)))
        W[act] = np.eye(len(act))
        W[pas] = -Kp_pinv @ K[:, act]
        self.W = W
        self.qd = W @ np.asarray(qda, dtype=float)
        drift = closure(robot, q, self.qd, params)[2]
        self.gamma = np.zeros(n)
        self.gamma[pas] = -Kp_pinv @ drift
        self.qdd = W @ np.asarray(qdda, dtype=float) + self.gamma
        self.tau = rnea(robot, q, self.qd, self.qdd, params)
        self.tau_a = W.T @ self.tau
        self.M = mass_matrix(robot, q, params)
        self.Ma = W.T @ self.M @ W
        self.bias_a = W.T @ rnea(robot, q, self.qd, self.gamma, params)
        self.K = K


def loop_state(robot, q, qda, qdda=None, params=None) -> LoopState:
    """The LoopState at a closed q (qdda None: zeros)."""
    qdda = np.zeros(len(qda)) if qdda is None else qdda
    return LoopState(robot, q, qda, qdda, params)


def forward_dynamics(robot, q, qda, tau_a, params=None) -> np.ndarray:
    """qdd_a solving M_a qdd_a = tau_a - bias_a."""
    s = loop_state(robot, q, qda, None, params)
    return np.linalg.solve(s.Ma, np.asarray(tau_a, dtype=float) - s.bias_a)
