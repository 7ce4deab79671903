"""The task space of the end-effector: its axes, and its Jacobian J with the bias Jdot qd as numbers.

J is the geometric Jacobian of the origin of the last convention frame (the last link's frame),
in the base frame, rows x, y, z (linear) and rx, ry, rz (angular); a task picks some of these
rows. J and Jdot qd come from symdyn.algorithms.frame_kinematics (the drift by its outward
recursion at qdd = 0), over named intermediates.
"""

from __future__ import annotations

import inspect
import re
from collections.abc import Sequence
from functools import lru_cache
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from ..algorithms.operational_space import TASK_AXES
from ..errors import SymdynError
from ..loading import load_module
from .compile import CompiledDynamics

if TYPE_CHECKING:
    from ..model.robot import Robot

__all__ = ["TASK_AXES", "parse_axes", "default_axes", "task_jacobian", "joint_vector"]


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


@lru_cache(maxsize=32)
def _kinematics(robot: Robot):
    """(f(q, qd, p) -> (J 6xn, Jdot qd 6), the linear rows not identically zero, free params)."""
    from dataclasses import replace

    import sympy as sp

    from ..algorithms.frame_kinematics import FrameKinematics
    from ..model.symbols import joint_symbols
    from ..spatial.transform import Transform
    from ..symbolic.program import Program

    r = robot.resolved()
    q, qd, _ = joint_symbols(r.n)
    fk = FrameKinematics(replace(r, base=Transform.identity()), list(q), list(qd), Program())
    tip = r.links[-1].name
    J, bias = fk.jacobian(tip), fk.jacobian_dot_qd(tip)
    steps = fk.program.needed([*J, *bias])
    args = [list(q), list(qd), list(r.params)]
    f = sp.lambdify(args, [J, bias], modules="numpy", cse=lambda exprs: (steps, exprs))
    live = tuple(TASK_AXES[i] for i in range(3) if any(x != 0 for x in J[i, :]))
    return f, live, tuple(str(p) for p in r.params)


_SOURCE = "task_space.py"


def _store_kinematics(robot: Robot, folder: Path) -> dict:
    """The cache entry of the kinematics: lambdify's source (numpy names only) and the live axes."""
    f, live, params = _kinematics(robot)
    text = inspect.getsource(f)
    names = sorted(set(re.findall(r"\b([A-Za-z_][A-Za-z0-9_]*)\(", text)) - {f.__name__})
    portable = all(getattr(np, name, None) is f.__globals__.get(name) for name in names)
    if portable:
        (folder / _SOURCE).write_text(text, encoding="utf-8")
    return {
        "live": list(live),
        "params": list(params),
        "function": f.__name__,
        "names": names if portable else None,
    }


def _cached_kinematics(plant: CompiledDynamics):
    """_kinematics from the plant's cache entry (no SymPy on a hit), or derived when not portable."""
    found = plant.__dict__.get("_task_space")
    if found is None:
        entry = plant.derived_entry("task-space", _store_kinematics)
        meta = entry.meta
        if meta["names"] is None:
            found = _kinematics(plant.robot)
        else:
            namespace = {name: getattr(np, name) for name in meta["names"]}
            path = entry.file(_SOURCE)
            # symdyn's own lambdify output for this robot, verified against the manifest's digest,
            # imported from its file (never exec'd from a string)
            module = load_module(path, "symdyn_task_space", namespace)
            found = getattr(module, meta["function"]), tuple(meta["live"]), tuple(meta["params"])
        plant._task_space = found
    return found


def _kinematics_any(robot: Robot | CompiledDynamics):
    return _cached_kinematics(robot) if isinstance(robot, CompiledDynamics) else _kinematics(robot)


def default_axes(robot: Robot | CompiledDynamics) -> tuple[str, ...]:
    """The linear axes x, y, z whose Jacobian rows are not identically zero (x, y for a planar arm)."""
    live = _kinematics_any(robot)[1]
    return live or ("x", "y", "z")


def task_jacobian(
    robot: Robot | CompiledDynamics, q, qd=None, axes=None, params=None
) -> tuple[np.ndarray, np.ndarray]:
    """(J, Jdot qd) of the end-effector, rows `axes` (default `default_axes`), as numbers.

    robot: a Robot (free parameters from `params`), or a CompiledDynamics with its parameters
    bound, whose kinematics come from the cache.
    """
    f, _, free = _kinematics_any(robot)
    names = parse_axes(axes) or default_axes(robot)
    n = robot.n
    q = joint_vector(q, n, "q")
    qd = np.zeros(n) if qd is None else joint_vector(qd, n, "qd")
    if isinstance(robot, CompiledDynamics):
        by_name = dict(zip(robot.param_names, [] if robot.p is None else robot.p, strict=True))
    else:
        values = robot.param_values(params) if robot.params else {}
        by_name = {str(k): v for k, v in values.items()}
    p = [by_name[s] for s in free]
    J, b = f(q, qd, p)
    J = np.asarray(J, dtype=float).reshape(6, n)
    b = np.asarray(b, dtype=float).reshape(6)
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
