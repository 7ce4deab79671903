"""The task space of a frame: its axes, and its Jacobian J with the drift Jdot qd as numbers.

J is the world-aligned Jacobian of a frame's origin (rows x, y, z (linear) and rx, ry, rz
(angular); without `base:` the world is the base frame), by default the frame of the last link
(its convention frame); a task picks some of these rows. J and Jdot qd are the generated
NAME_F_jacobian and NAME_F_jacobian_dot_qd (symdyn.codegen.frame_functions), compiled and cached
by `symdyn.compile` (CompiledDynamics.frame_jacobian, frame_jacobian_dot_qd): straight-line C,
or the generated NumPy module without a C compiler; no SymPy once the cache holds them.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING

import numpy as np

from ...algorithms.operational_space import TASK_AXES
from ...errors import SymdynError
from ..compilation.compiled import CompiledDynamics, compiled_dynamics

if TYPE_CHECKING:
    from ...model.robot import Robot

__all__ = ["TASK_AXES", "parse_axes", "default_frame", "default_axes", "task_jacobian", "joint_vector"]

#: Configurations (fixed seed) at which default_axes looks for the rows that move.
_PROBES = np.random.default_rng(20240521).uniform(-np.pi, np.pi, (4, 64))


def parse_axes(axes: str | Sequence[str] | None) -> tuple[str, ...] | None:
    """Task axes from "x,y" or a sequence of names among x, y, z, rx, ry, rz (None: default)."""
    if axes is None:
        return None
    names = [a.strip() for a in axes.split(",")] if isinstance(axes, str) else [str(a).strip() for a in axes]
    names = [a for a in names if a]
    if not names:
        raise SymdynError(f"--axes: no axis given (any of {', '.join(TASK_AXES)})")
    bad = [a for a in names if a not in TASK_AXES]
    if bad:
        raise SymdynError(f"--axes: unknown axis {', '.join(bad)} (any of {', '.join(TASK_AXES)})")
    if len(set(names)) != len(names):
        raise SymdynError(f"--axes: repeated axis in {','.join(names)}")
    return tuple(names)


def _dynamics(robot: Robot | CompiledDynamics, params=None) -> CompiledDynamics:
    """The robot compiled (a CompiledDynamics is kept, its parameters bound)."""
    return robot if isinstance(robot, CompiledDynamics) else compiled_dynamics(robot, params)


def default_frame(robot: Robot | CompiledDynamics) -> str:
    """The frame analysed when none is named: the last link's (its convention frame)."""
    dyn = _dynamics(robot)
    found = dyn.__dict__.get("_last_link")
    if found is None:
        entry = dyn.derived_entry("last link", lambda r, folder: {"frame": r.resolved().links[-1].name})
        found = dyn._last_link = entry.meta["frame"]
    return found


def default_axes(robot: Robot | CompiledDynamics, frame: str | None = None) -> tuple[str, ...]:
    """The linear axes x, y, z whose Jacobian rows are not identically zero (x, y for a planar arm).

    A row counts as identically zero when it is below 1e-12 (relative to J) at four random
    configurations: an analytic function of q that vanishes there vanishes everywhere but on a
    set of measure zero.
    """
    dyn = _dynamics(robot)
    frame = frame or default_frame(dyn)
    J = np.asarray(dyn.frame_jacobian(frame, _PROBES[:, : dyn.n]), dtype=float)
    scale = max(1.0, float(np.abs(J).max()))
    live = tuple(TASK_AXES[i] for i in range(3) if np.abs(J[:, i, :]).max() > 1e-12 * scale)
    return live or ("x", "y", "z")


def task_jacobian(
    robot: Robot | CompiledDynamics, q, qd=None, axes=None, params=None, frame: str | None = None
) -> tuple[np.ndarray, np.ndarray]:
    """(J, Jdot qd) of `frame` (default `default_frame`), rows `axes` (default `default_axes`).

    robot: a Robot (free parameters from `params`), compiled on first use, or a CompiledDynamics
    with its parameters bound.
    """
    dyn = _dynamics(robot, params)
    frame = frame or default_frame(dyn)
    names = parse_axes(axes) or default_axes(dyn, frame)
    n = dyn.n
    q = joint_vector(q, n, "q")
    qd = np.zeros(n) if qd is None else joint_vector(qd, n, "qd")
    J = np.asarray(dyn.frame_jacobian(frame, q), dtype=float).reshape(6, n)
    b = np.asarray(dyn.frame_jacobian_dot_qd(frame, q, qd), dtype=float).reshape(6)
    rows = [TASK_AXES.index(a) for a in names]
    return J[rows], b[rows]


def joint_vector(x, n: int, name: str) -> np.ndarray:
    """`x` as a finite float vector of n entries (one per joint); SymdynError naming `name` otherwise."""
    try:
        a = np.array(x, dtype=float).reshape(-1)
    except (TypeError, ValueError) as exc:
        raise SymdynError(f"{name}: expected numbers, got {x!r}") from exc
    if a.shape != (n,):
        raise SymdynError(f"{name} must have {n} entries (one per joint), got {a.size}")
    if not np.all(np.isfinite(a)):
        raise SymdynError(f"{name} must be finite")
    return a
