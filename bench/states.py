"""The states bench/run.py times and checks at, and symdyn.rnea's numbers for them.

NSTATES random joint-space states (q, qd, qdd, tau) per robot, fixed by a seed; the
compiled harnesses cycle through them (the state changes every call). Before anything is
timed, every compiled function is compared at the first NCHECK states with the NumPy
oracle symdyn.rnea (`references`); a relative error above CHECK_TOL stops the run.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

__all__ = ["NSTATES", "NCHECK", "CHECK_TOL", "SEED", "make_states", "write_states", "references", "rel_err"]

NSTATES = 256  # pre-generated random states, cycled through (a power of two)
NCHECK = 4  # states at which every compiled function is checked against symdyn.rnea
CHECK_TOL = 1e-9  # relative (to max(1, |reference|)) error allowed
SEED = 20240604


def make_states(robot, rng) -> dict[str, np.ndarray]:
    """NSTATES states: q in [-pi, pi], qd in [-2, 2], qdd in [-5, 5], tau in [-20, 20] (uniform)."""
    n = robot.n
    return {
        "q": rng.uniform(-np.pi, np.pi, (NSTATES, n)),
        "qd": rng.uniform(-2, 2, (NSTATES, n)),
        "qdd": rng.uniform(-5, 5, (NSTATES, n)),
        "tau": rng.uniform(-20, 20, (NSTATES, n)),
    }


def write_states(states, path: Path) -> None:
    """Binary doubles, state by state: q[n] qd[n] qdd[n] tau[n]."""
    block = np.stack([states[k] for k in ("q", "qd", "qdd", "tau")], axis=1)  # (K, 4, n)
    path.write_bytes(np.ascontiguousarray(block, dtype="<f8").tobytes())


def references(robot, states, k: int) -> dict[str, np.ndarray]:
    """symdyn.rnea's numbers at state k, for every function (and the frictionless Pinocchio ones)."""
    from symdyn import rnea as oracle

    q, qd, qdd, tau = (states[x][k] for x in ("q", "qd", "qdd", "tau"))
    z = np.zeros_like(q)
    M = oracle.mass_matrix(robot, q)
    h0 = oracle.rnea(robot, q, qd, z, friction=False)
    from symdyn.oracle.regressor import regressor

    return {
        "inverse_dynamics": oracle.rnea(robot, q, qd, qdd),
        "regressor": regressor(robot, q, qd, qdd),
        "mass_matrix": M,
        "coriolis": oracle.bias_torque(robot, q, qd),
        "gravity": oracle.gravity_torque(robot, q),
        "friction": oracle.friction_torque(robot, qd),
        "forward_dynamics": oracle.forward_dynamics(robot, q, qd, tau),
        # Pinocchio has no joint friction: its references leave friction out.
        "rnea_nofriction": oracle.rnea(robot, q, qd, qdd, friction=False),
        "aba_nofriction": np.linalg.solve(M, tau - h0),
    }


def rel_err(got, want) -> float:
    """max |got - want| / max(1, max |want|)."""
    want = np.asarray(want, dtype=float)
    got = np.asarray(got, dtype=float).reshape(want.shape)
    return float(np.max(np.abs(got - want)) / max(1.0, float(np.max(np.abs(want)))))
