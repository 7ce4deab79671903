"""Pictures of the dynamic conditioning analysis: the task-space plot and the slide-24 workspace.

Drawn in a 2-D task space (two axes): the manipulability ellipse around zero
(unbiased) and around v_bias (biased), the biased acceleration polytope and the
bias arrow. Gravity is made to point down on the page where it lies along a task
axis (the page stays a proper rotation of the task plane). Accelerations in m/s^2
(rad/s^2 for rx, ry, rz); the workspace plot draws them at the hand, to scale.
"""

from __future__ import annotations

import os
from collections.abc import Sequence
from typing import TYPE_CHECKING

import numpy as np

from ...errors import SymdynError
from ..output import figure, figure_bytes, plot_format, write_atomic
from .conditioning import Analysis
from .geometry import ellipse_points
from .task_space import TASK_AXES

if TYPE_CHECKING:
    from ...model.robot import Robot

__all__ = ["plot_analysis", "plot_workspace"]


def _unit(axis: str) -> str:
    return "rad/s²" if axis.startswith("r") else "m/s²"


def _closed(points: np.ndarray) -> np.ndarray:
    return np.vstack([points, points[:1]])


def _draw_shapes(ax, a: Analysis, origin=(0.0, 0.0), scale: float = 1.0, swap=False, labels=True) -> None:
    """Unbiased ellipse, biased ellipse, biased polytope and the bias arrow, scaled and shifted."""

    def tr(p):
        p = np.atleast_2d(p) * scale + np.asarray(origin)
        return (p[:, 1], p[:, 0]) if swap else (p[:, 0], p[:, 1])

    dm = a.manipulability
    zero = np.zeros(2)
    poly = a.polytope.vertices
    biased = "gravity-biased" if not np.any(a.qd) else "biased (gravity and velocity)"
    if len(poly) > 2:
        ax.fill(*tr(_closed(poly)), color="C2", alpha=0.18, lw=0)
    ax.plot(*tr(_closed(poly)), color="C2", lw=1.6, label=f"polytope, {biased}" if labels else None)
    ax.plot(
        *tr(ellipse_points(zero, dm.matrix)),
        color="C0",
        lw=1.4,
        ls="--",
        label="ellipse, unbiased" if labels else None,
    )
    ax.plot(
        *tr(ellipse_points(dm.bias, dm.matrix)),
        color="C3",
        lw=1.6,
        label=f"ellipse, {biased}" if labels else None,
    )
    (x0,), (y0,) = tr(zero)
    (x1,), (y1,) = tr(dm.bias)
    ax.annotate(
        "",
        xy=(x1, y1),
        xytext=(x0, y0),
        arrowprops={"arrowstyle": "-|>", "color": "k", "lw": 1.3, "mutation_scale": 9},
    )
    ax.plot([x0], [y0], "k.", ms=4, label="bias v_bias (arrow from zero)" if labels else None)


def _gravity_layout(robot: Robot, axes: tuple[str, ...], params=None) -> tuple[bool, bool, bool]:
    """(swap, invert vertical, invert horizontal) so that gravity points down on the page."""
    from ...oracle.inputs import numeric_model

    g = numeric_model(robot, robot.param_values(params) if robot.params else None).gravity
    idx = [TASK_AXES.index(a) for a in axes]
    g2 = np.array([g[i] if i < 3 else 0.0 for i in idx])
    if not np.any(g2):
        return False, False, False
    k = int(np.argmax(np.abs(g2)))
    if abs(g2[1 - k]) > 1e-9 * abs(g2[k]):
        return False, False, False  # gravity not along an axis: plain layout
    swap = k == 0  # the gravity axis goes vertical
    inv_v = g2[k] > 0  # positive gravity component points down
    # a swap is a reflection; inverting one axis makes the page a proper rotation again
    inv_h = swap != inv_v
    return swap, inv_v, inv_h


def _finish_axes(ax, xlabel: str, ylabel: str, invert_v: bool, invert_h: bool) -> None:
    """Axis labels, the inversions of `_gravity_layout` (gravity down), equal scales and a grid."""
    ax.set_xlabel(xlabel)
    ax.set_ylabel(ylabel + (", gravity down" if invert_v else ""))
    if invert_v:
        ax.invert_yaxis()
    if invert_h:
        ax.invert_xaxis()
    ax.set_aspect("equal", adjustable="datalim")
    ax.grid(True, alpha=0.3)


def plot_analysis(
    a: Analysis, path: str | os.PathLike | None = None, robot: Robot | None = None, params=None
) -> bytes:
    """Task-space acceleration plot (2 axes only): unbiased and biased ellipses, biased polytope."""
    if len(a.axes) != 2:
        raise SymdynError(f"--plot draws a 2-D task space: give two --axes (got {','.join(a.axes)})")
    fmt = plot_format(path) if path is not None else "png"
    fig = figure(1, width=6.4, height_per_row=6.0)
    ax = fig.subplots()
    swap, inv_v, inv_h = (
        _gravity_layout(robot, a.axes, params) if robot is not None else (False, False, False)
    )
    _draw_shapes(ax, a, swap=swap)
    h, v = (a.axes[1], a.axes[0]) if swap else a.axes
    _finish_axes(ax, f"acceleration {h} ({_unit(h)})", f"acceleration {v} ({_unit(v)})", inv_v, inv_h)
    ax.legend(loc="best", fontsize="small")
    q = ", ".join(f"{x:.3g}" for x in a.q)
    qd = f", qd = ({', '.join(f'{x:.3g}' for x in a.qd)})" if np.any(a.qd) else ""
    lim = ", ".join(f"{x:.3g}" for x in a.torque_limits)
    ax.set_title(
        f"{a.robot}: q = ({q}){qd}, |tau_i| <= ({lim})\n"
        f"kappa_d = sqrt(det J (M^T M)^-1 J^T) = {a.manipulability.measure:.4g}",
        fontsize="medium",
    )
    data = figure_bytes(fig, fmt)
    if path is not None:
        write_atomic(path, data)
    return data


def plot_workspace(
    robot: Robot,
    analyses: Sequence[Analysis],
    path: str | os.PathLike | None = None,
    scale: float | None = None,
    params=None,
    title: str | None = None,
) -> bytes:
    """The slide-24 picture: the arm at each analysed configuration, and at its hand the
    unbiased ellipse, the gravity-biased ellipse and the gravity-biased polytope, drawn
    to scale (`scale` metres per unit acceleration; automatic when None). Axes x, y only.
    """
    from ...algorithms.kinematics import numeric_pose

    if not analyses:
        raise SymdynError("plot_workspace needs at least one analysis")
    axes = analyses[0].axes
    if any(a.axes != axes for a in analyses) or len(axes) != 2 or any(x not in ("x", "y", "z") for x in axes):
        raise SymdynError("plot_workspace draws two linear task axes (e.g. x,y), the same for all analyses")
    fmt = plot_format(path) if path is not None else "png"
    rows = [TASK_AXES.index(x) for x in axes]
    frames = [lk.frame.p for lk in robot.resolved().links]  # points with the values substituted
    arms, hands = [], []
    for a in analyses:
        pts = [np.zeros(2)]
        for k in range(robot.nb):  # every body, mimic joints included
            T = numeric_pose(robot, a.q, link=k, point=list(frames[k]), params=params)
            pts.append(T[rows, 3])
        arms.append(np.array(pts))
        hands.append(pts[-1])
    hands_arr = np.array(hands)
    if scale is None:
        extent = max(
            float(np.max(np.linalg.norm(np.vstack([a.polytope.vertices, a.bias[None, :]]), axis=1)))
            for a in analyses
        )
        gaps = [
            np.linalg.norm(hands_arr[i] - hands_arr[j])
            for i in range(len(hands_arr))
            for j in range(i + 1, len(hands_arr))
        ]
        reach = float(np.max(np.linalg.norm(np.vstack(arms), axis=1)))
        room = 0.5 * min(gaps) if gaps else 0.3 * reach
        scale = room / extent if extent > 0 else 1.0
    swap, inv_v, inv_h = _gravity_layout(robot, axes, params)
    fig = figure(1, width=8.0, height_per_row=7.4)
    ax = fig.subplots()
    for k, (a, arm) in enumerate(zip(analyses, arms, strict=True)):
        xs, ys = (arm[:, 1], arm[:, 0]) if swap else (arm[:, 0], arm[:, 1])
        ax.plot(xs, ys, "-o", color="0.72", lw=1.6, ms=3, zorder=0, label="arm" if k == 0 else None)
        _draw_shapes(ax, a, origin=arm[-1], scale=scale, swap=swap, labels=k == 0)
    ax.plot([0], [0], "ks", ms=7, label="base (joint 1)")
    h, v = (axes[1], axes[0]) if swap else axes
    _finish_axes(ax, f"{h} (m)", f"{v} (m)", inv_v, inv_h)
    ax.legend(loc="upper left", fontsize="small", framealpha=0.9)
    lim = analyses[0].torque_limits
    lim_text = f"{lim[0]:g}" if np.all(lim == lim[0]) else ", ".join(f"{x:g}" for x in lim)
    head = title or f"{robot.name}: hand accelerations for |tau_i| <= {lim_text}"
    ax.set_title(
        f"{head}\nshapes drawn at the hand to scale: 1 m/s² = {scale * 1000:.3g} mm", fontsize="medium"
    )
    data = figure_bytes(fig, fmt)
    if path is not None:
        write_atomic(path, data)
    return data
