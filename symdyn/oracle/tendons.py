"""The oracle's fixed tendons and joint springs (symdyn.model.tendons), per body, NumPy only.

A tendon's length over the bodies' joint positions is L = c . q_b, so its Jacobian on the
bodies is c and the efforts are c times the tendon force (a batch of N states):

    tau_b += c (a L'' + d L' + f sign(L') + k (L - L0)),    M_b += a c c^T,

projected onto the independent coordinates with S^T by the callers (symdyn.oracle.rnea). Its
energies: kinetic 1/2 a L'^2, potential k/2 (L - L0)^2.
"""

from __future__ import annotations

import numpy as np

from .inputs import NumericModel

__all__ = ["tendon_efforts", "tendon_mass", "tendon_kinetic", "tendon_potential"]


def tendon_efforts(
    mdl: NumericModel, q_b: np.ndarray, qd_b: np.ndarray, qdd_b: np.ndarray, springs: bool, friction: bool
) -> np.ndarray:
    """The bodies' tendon efforts (N, nb) at q_b, qd_b, qdd_b (N, nb): the armature's always, the
    springs' with `springs` (they belong to G) and damping and frictionloss with `friction` (F)."""
    C = mdl.tendon_coef  # (nt, nb)
    L, Ld, Ldd = q_b @ C.T, qd_b @ C.T, qdd_b @ C.T  # (N, nt)
    force = mdl.tendon_armature * Ldd
    if springs:
        force = force + mdl.tendon_stiffness * (L - mdl.tendon_length)
    if friction:
        force = force + mdl.tendon_damping * Ld + mdl.tendon_friction * np.sign(Ld)
    return force @ C


def tendon_mass(mdl: NumericModel) -> np.ndarray:
    """sum_t a_t c_t c_t^T (nb, nb): the tendons' armature in the bodies' M_b."""
    C = mdl.tendon_coef
    return (C.T * mdl.tendon_armature) @ C


def tendon_kinetic(mdl: NumericModel, qd_b: np.ndarray) -> np.ndarray:
    """sum_t 1/2 a_t L_t'^2 (N,)."""
    return 0.5 * ((qd_b @ mdl.tendon_coef.T) ** 2 * mdl.tendon_armature).sum(axis=1)


def tendon_potential(mdl: NumericModel, q_b: np.ndarray) -> np.ndarray:
    """sum_t 1/2 k_t (L_t - L0_t)^2 (N,): the springs' potential energy."""
    stretch = q_b @ mdl.tendon_coef.T - mdl.tendon_length
    return 0.5 * (stretch**2 * mdl.tendon_stiffness).sum(axis=1)
