"""The dynamic conditioning analysis at one state (q, qd): `analyze` and its report `Analysis`.

With M, V, G, F from the robot's compiled functions (symdyn.apps.compilation.compiled), J and Jdot qd
the generated ones of the chosen frame (symdyn.apps.analysis.task_space: by default the last link's,
world-aligned, chosen task rows) and L = diag(torque limits):
    xdd = J M^-1 L tau_hat + v_bias,   v_bias = Jdot qd - J M^-1 (V + G + F) = v_vel + v_grav,
    v_vel = Jdot qd - J M^-1 (V + F),  v_grav = -J M^-1 G,
and the shapes of symdyn.apps.analysis.geometry: the inertia ellipsoid of M, the dynamic
manipulability ellipsoid of J M^-1 L around v_bias, and the acceleration polytope.
`Analysis` writes them as text or as the JSON document of `symdyn analyze`.
"""

from __future__ import annotations

import json
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from ...errors import SymdynError
from ..compilation.compiled import CompiledDynamics, compiled_dynamics
from .geometry import (
    AccelerationPolytope,
    DynamicManipulability,
    InertiaEllipsoid,
    acceleration_polytope,
    dynamic_manipulability,
    inertia_ellipsoid,
)
from .task_space import default_axes, default_frame, joint_vector, parse_axes, task_jacobian

if TYPE_CHECKING:
    from ...model.robot import Robot

__all__ = ["Analysis", "analyze", "MEASURE_NOTE", "LENGTHS_NOTE"]

MEASURE_NOTE = "kappa_d = sqrt(det(J (M^T M)^-1 J^T)), square root taken (the lecture prints it without)"
LENGTHS_NOTE = (
    "lengths = sqrt(eigenvalues of M M^T) = singular values of M (semi-axes of {M qdd : |qdd| <= 1})"
)


def _torque_limits(limits, n: int) -> np.ndarray:
    try:
        a = np.array(limits, dtype=float).reshape(-1)
    except (TypeError, ValueError) as exc:
        raise SymdynError(f"torque limits: expected numbers, got {limits!r}") from exc
    if a.size == 1:
        a = np.full(n, a[0])
    if a.shape != (n,):
        raise SymdynError(f"torque limits: expected 1 or {n} values, got {a.size}")
    if not np.all(np.isfinite(a)) or np.any(a <= 0):
        raise SymdynError("torque limits must be positive numbers")
    return a


@dataclass
class Analysis:
    """Everything `analyze` computes at one state (see the module docstring for the formulas).

    `polytope` is the biased acceleration polytope.
    """

    robot: str
    q: np.ndarray
    qd: np.ndarray
    axes: tuple[str, ...]
    torque_limits: np.ndarray
    M: np.ndarray
    V: np.ndarray
    G: np.ndarray
    F: np.ndarray
    J: np.ndarray
    Jdot_qd: np.ndarray
    v_vel: np.ndarray
    v_grav: np.ndarray
    inertia: InertiaEllipsoid
    manipulability: DynamicManipulability
    polytope: AccelerationPolytope
    frame: str = ""  # the frame whose J and Jdot qd were used

    @property
    def bias(self) -> np.ndarray:
        return self.manipulability.bias

    def to_dict(self) -> dict:
        """The JSON document: the three results under their fixed keys, plus context and notes."""

        def lst(a):
            return (np.asarray(a, dtype=float) + 0.0).tolist()  # + 0.0 turns -0.0 into 0.0

        return {
            "robot": self.robot,
            "q": lst(self.q),
            "qd": lst(self.qd),
            "task_axes": list(self.axes),
            "torque_limits": lst(self.torque_limits),
            "inertia_ellipsoid": {"axes": lst(self.inertia.axes), "lengths": lst(self.inertia.lengths)},
            "dynamic_manipulability": {
                "measure": float(self.manipulability.measure),
                "bias": lst(self.manipulability.bias),
                "matrix": lst(self.manipulability.matrix),
            },
            "acceleration_polytope": {"vertices": lst(self.polytope.vertices)},
            "notes": {
                "inertia_ellipsoid": "axes: unit eigenvectors of M M^T (rows, joint space); " + LENGTHS_NOTE,
                "measure": MEASURE_NOTE,
                "bias": "v_bias = Jdot qd - J M^-1 (V + G + F), task axes as listed",
                "matrix": "J M^-1 L^2 M^-T J^T, L = diag(torque_limits): the ellipsoid "
                "(xdd - bias)^T matrix^-1 (xdd - bias) <= 1",
                "vertices": "extreme points of {J M^-1 L tau_hat + bias : |tau_hat_i| <= 1}"
                + (", counter-clockwise" if len(self.axes) == 2 else ", sorted"),
            },
        }

    def to_json(self) -> str:
        return json.dumps(self.to_dict(), indent=2) + "\n"

    def to_text(self) -> str:
        def vec(a):
            return "(" + ", ".join(f"{x + 0.0:.6g}" for x in np.asarray(a, dtype=float)) + ")"

        dm = self.manipulability
        lines = [
            f"# {self.robot} at q = {vec(self.q)}, qd = {vec(self.qd)}",
            f"# task axes {', '.join(self.axes)} of frame {self.frame} (world-aligned); "
            f"torque limits |tau_i| <= {vec(self.torque_limits)}",
            "",
            "inertia ellipsoid {M qdd : |qdd| <= 1} (joint-torque space):",
            f"  {LENGTHS_NOTE}",
        ]
        for k, (a, length) in enumerate(zip(self.inertia.axes, self.inertia.lengths, strict=True), 1):
            lines.append(f"  axis {k}: length {length:.6g}  direction {vec(a)}")
        lines += [
            "",
            "dynamic manipulability:",
            f"  measure {MEASURE_NOTE}: {dm.measure:.6g}",
            f"  (without the square root, as the lecture prints it: {dm.measure_squared:.6g})",
            f"  bias v_bias = Jdot qd - J M^-1 (V + G + F) = {vec(dm.bias)}",
            f"    velocity part Jdot qd - J M^-1 (V + F) = {vec(self.v_vel)}, gravity part -J M^-1 G = "
            f"{vec(self.v_grav)}",
            "  matrix J M^-1 L^2 M^-T J^T =",
        ]
        lines += [f"    {vec(row)}" for row in dm.matrix]
        for k, (a, length) in enumerate(zip(dm.axes, dm.lengths, strict=True), 1):
            lines.append(f"  ellipsoid semi-axis {k}: {length:.6g} along {vec(a)}")
        order = "counter-clockwise" if len(self.axes) == 2 else "sorted"
        lines += [
            "",
            f"acceleration polytope {{J M^-1 L tau_hat + v_bias : |tau_hat_i| <= 1}}: "
            f"{len(self.polytope.vertices)} vertices ({order}; tau_hat at each vertex):",
        ]
        for v, s in zip(self.polytope.vertices, self.polytope.signs, strict=True):
            signs = " ".join("+" if x > 0 else "-" for x in s)
            lines.append(f"  {vec(v)}  [{signs}]")
        return "\n".join(lines) + "\n"


def analyze(
    robot: Robot | CompiledDynamics,
    q,
    qd=None,
    torque_limits=1.0,
    axes=None,
    params=None,
    dynamics: CompiledDynamics | None = None,
    frame: str | None = None,
) -> Analysis:
    """Inertia ellipsoid, dynamic manipulability and acceleration polytope at (q, qd).

    torque_limits: one bound for every joint or one per joint (N m or N); frame: the frame whose
    Jacobian is used (default: the last link's, symdyn.apps.analysis.task_space.default_frame); axes: task
    rows of its Jacobian (default: the linear axes that move, e.g. x, y for a planar arm).
    `dynamics` reuses a CompiledDynamics of the same robot; `robot` may itself be a
    CompiledDynamics (its parameters bound, its frame functions from the cache).
    """
    if isinstance(robot, CompiledDynamics):
        dynamics = compiled_dynamics(robot, params)
        robot = dynamics
    n = robot.n
    q = joint_vector(q, n, "q")
    qd = np.zeros(n) if qd is None else joint_vector(qd, n, "qd")
    limits = _torque_limits(torque_limits, n)
    dyn = dynamics if dynamics is not None else compiled_dynamics(robot, params)
    frame = frame or default_frame(dyn)
    names = parse_axes(axes) or default_axes(dyn, frame)
    M = np.asarray(dyn.mass_matrix(q), dtype=float)
    V = np.asarray(dyn.coriolis(q, qd), dtype=float)
    G = np.asarray(dyn.gravity(q), dtype=float)
    F = np.asarray(dyn.friction(qd), dtype=float)
    J, Jdq = task_jacobian(dyn, q, qd, names, frame=frame)
    try:
        Minv = np.linalg.inv(M)
    except np.linalg.LinAlgError as exc:
        raise SymdynError(f"the mass matrix is singular at q = {q.tolist()}") from exc
    v_vel = Jdq - J @ Minv @ (V + F)
    v_grav = -J @ Minv @ G
    bias = v_vel + v_grav
    A = J @ Minv @ np.diag(limits)
    return Analysis(
        robot=dyn.robot.name,
        q=q,
        qd=qd,
        axes=names,
        torque_limits=limits,
        M=M,
        V=V,
        G=G,
        F=F,
        J=J,
        Jdot_qd=Jdq,
        v_vel=v_vel,
        v_grav=v_grav,
        inertia=inertia_ellipsoid(M),
        manipulability=dynamic_manipulability(J, M, limits, bias),
        polytope=acceleration_polytope(A, bias),
        frame=frame,
    )
