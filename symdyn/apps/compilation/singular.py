"""Run-time singular M: the functions that invert M raise instead of returning NaN.

A robot whose M is singular by construction has no forward dynamics at all (symdyn.codegen
leaves it out). With free parameters, M can still be singular for the numbers given at run
time (a zero mass at the end of a chain, `symdyn.compile(robot, {"m2": 0})`) or at a
particular q: the generated code's L D L^T factorisation of M then divides by a zero pivot
and returns infinities or NaN. The generated C does not check (docs/generated-code.md,
"Singular M at run time"); the Python methods of `CompiledDynamics` check their output and
raise SymdynError naming the state.
"""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np

from ...errors import SymdynError

__all__ = ["INVERTING", "NotGeneratedError", "divergence_error", "guarded"]

#: The generated functions that solve with or invert M (docs/generated-code.md).
INVERTING = frozenset(
    {"forward_dynamics", "forward_dynamics_derivatives", "mass_matrix_inverse", "linearize"}
)


class NotGeneratedError(SymdynError, AttributeError):
    """A function that inverts M asked of a robot whose M is singular by construction, so that
    symdyn.codegen left it out (an AttributeError too, so that hasattr() answers False)."""

    def __init__(self, robot_name: str, name: str) -> None:
        super().__init__(
            f"robot '{robot_name}': {name} was not generated: M(q) is singular by construction "
            "(the warning given when the robot was compiled names the joint), so the functions "
            "that invert M are left out"
        )


def _finite(a: np.ndarray) -> bool:
    flat = a.ravel()
    return math.isfinite(flat.dot(flat)) or bool(np.isfinite(flat).all())  # the dot may overflow


def guarded(owner, name: str, method: Callable) -> Callable:
    """`method` (owner's generated function `name`) checked for a singular M when it inverts M.

    The check costs one dot product of the first output (about 1 us) on the usual path; a
    non-finite output with finite inputs raises SymdynError with M's smallest eigenvalue.
    """
    if name not in INVERTING:
        return method

    def call(*args, **options):
        out = method(*args, **options)
        if all(_finite(o) for o in (out if isinstance(out, tuple) else (out,))):
            return out
        inputs = [np.asarray(a, dtype=float) for a in args]
        if not all(np.isfinite(a).all() for a in inputs):
            return out  # NaN or infinity in, NaN out: nothing to say about M
        raise SymdynError(_message(owner, name, inputs[0]))

    call.__name__ = method.__name__
    call.__doc__ = method.__doc__
    return call


def _message(owner, name: str, q: np.ndarray) -> str:
    """Where M is singular: the first state of a batch whose M is, and its smallest eigenvalue."""
    given = "" if owner.p is None else f" with parameters {_listing(owner)}"
    width = q.shape[-1] if q.ndim else owner.n  # NQ for a floating robot's q
    rows = q.reshape(-1, width)
    worst, where = math.inf, rows[0]
    for row in rows:
        smallest = float(np.linalg.eigvalsh(owner.mass_matrix(row))[0])
        if smallest < worst:
            worst, where = smallest, row
    return (
        f"{name}: the mass matrix M(q) is singular at q = [{', '.join(f'{x:g}' for x in where)}]"
        f"{given} (its smallest eigenvalue is {worst:.3g}), so qdd is undefined; give every link "
        "that moves a joint some mass or inertia"
    )


def divergence_error(owner, t: float, q: np.ndarray) -> SymdynError:
    """The error of a simulation whose state stopped being finite at time t, q the last finite
    configuration: a singular M(q) there (smallest eigenvalue at most 1e-12 of the largest) is
    named as the cause, since no step size helps then; otherwise the step is blamed."""
    q = np.asarray(q, dtype=float)
    if q.ndim == 1 and np.isfinite(q).all():
        with np.errstate(all="ignore"):
            eig = np.linalg.eigvalsh(np.asarray(owner.mass_matrix(q), dtype=float))
        if np.isfinite(eig).all() and eig[0] <= 1e-12 * max(abs(eig[-1]), 1e-300):
            given = "" if owner.p is None else f" with parameters {_listing(owner)}"
            return SymdynError(
                f"the simulation stopped at t = {t:.6g} s: the mass matrix M(q) is singular at q = "
                f"[{', '.join(f'{x:g}' for x in q)}]{given} (its smallest eigenvalue is {eig[0]:.3g}), "
                "so qdd is undefined there; give every link that moves a joint some mass or inertia"
            )
    return SymdynError(
        f"the simulation diverged at t = {t:.6g} s (the state is no longer finite); "
        "try a smaller dt or the rk4 integrator"
    )


def _listing(owner) -> str:
    return ", ".join(f"{n} = {v:g}" for n, v in zip(owner.param_names, owner.p, strict=True))
